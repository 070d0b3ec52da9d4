//! Vector output: the limit surface as PDF tensor-product shadings (type 7) and as SVG 2 mesh
//! gradients.
//!
//! On a regular face of a refined level the limit surface is exactly a uniform bicubic
//! B-spline patch in position, colour and opacity, so its Bézier control net is exact
//! geometry. Near extraordinary vertices and creases faces are refined locally; the
//! descendants that stay irregular at the last depth become flat patches within
//! [`ExportOptions::geometry_tolerance_px`]. Viewers interpolate colour bilinearly between a
//! patch's corners, so patches are split until that stays within [`ExportOptions::tolerance`]
//! (ΔE00) of the surface's colour, in the space the viewer interpolates in. Each layer is
//! clipped to its outline, the exact Bézier curves of its limit boundary; opacity goes into a
//! soft mask.
//!
//! ```
//! use gradmesh::export::{write_pdf, ExportOptions, View};
//! use gradmesh::{ColourSpace, Document, GradientMesh};
//! use kurbo::Point;
//!
//! let mut mesh = GradientMesh::new(ColourSpace::Lab);
//! let a = mesh.add_point(Point::new(0.0, 0.0), [50.0, 60.0, 40.0]);
//! let b = mesh.add_point(Point::new(100.0, 0.0), [90.0, -10.0, 80.0]);
//! let c = mesh.add_point(Point::new(50.0, 90.0), [40.0, 10.0, -50.0]);
//! mesh.add_face(vec![a, b, c]);
//! let doc = Document::new(vec![mesh]);
//!
//! let opts = ExportOptions::new(128, 128, View::new(-10.0, -10.0, 110.0, 110.0));
//! let (pdf, info) = write_pdf(&doc, &opts)?;
//! assert!(pdf.starts_with(b"%PDF-") && info.patches > 0);
//! # Ok::<(), gradmesh::Error>(())
//! ```

mod bezier;
mod classic;
mod pdf;
mod split;
mod surface;
mod svg;

use std::time::Instant;

use rayon::prelude::*;

use crate::error::{Error, ErrorKind, Warning};
use crate::formats::svg::{FillRule, MeshFill};
use crate::mesh::{Document, GradientMesh};
use crate::size_limits::Limits;
use crate::view::{check_image, ToPixels, MAX_PIXELS};

use split::{OutPatch, Splitter, Target};
use surface::{layer_surface, Curve, SurfaceOptions};

pub use crate::view::View;
pub use pdf::{write_pdf, write_pdf_picture, POINTS_PER_PIXEL};
pub use svg::{write_svg, write_svg_picture};

/// One layer of a picture to export, bottom first.
#[derive(Clone, Copy, Debug)]
pub enum ExportLayer<'a> {
    /// A mesh of the scheme: its limit surface, clipped to its outline.
    Scheme(&'a GradientMesh),
    /// An SVG mesh gradient's patches as they are (not converted into the scheme), clipped to
    /// its shape: Coons patches with colour bilinear in sRGB, a `type="bicubic"` patch cut
    /// into the cells of its smoothed colours.
    SvgMesh(&'a MeshFill),
}

impl<'a> ExportLayer<'a> {
    /// The layers of `doc`, each of the scheme.
    pub fn of_document(doc: &'a Document) -> Vec<ExportLayer<'a>> {
        doc.layers.iter().map(ExportLayer::Scheme).collect()
    }
}

/// The default colour tolerance, in ΔE00 ([`ExportOptions::tolerance`]).
pub const DEFAULT_TOLERANCE: f64 = 0.5;
/// The default geometry tolerance, in pixels ([`ExportOptions::geometry_tolerance_px`]).
pub const DEFAULT_GEOMETRY_TOLERANCE_PX: f64 = 0.1;

/// The colour space a PDF's shadings are written in.
///
/// sRGB is the default: every viewer tested draws it within the tolerance's reach, while `/Lab`
/// depends on each viewer's Lab conversion (MuPDF without a colour management module is
/// several ΔE00 off, and viewers that interpolate in RGB whatever the space darken Lab
/// mid-tones); see `docs/export.md`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PdfColour {
    /// CIE L*a*b* with the D65 white point (`/Lab`), for viewers that interpolate in the
    /// shading's space and convert Lab exactly (poppler's `pdftoppm` matches best in it).
    Lab,
    /// `/DeviceRGB` taken as sRGB, with patches split so that interpolating sRGB values also
    /// stays within the tolerance.
    #[default]
    Srgb,
}

impl PdfColour {
    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            PdfColour::Lab => "lab",
            PdfColour::Srgb => "srgb",
        }
    }
}

/// How to export a document.
#[derive(Clone, Debug, PartialEq)]
pub struct ExportOptions {
    /// Picture width in CSS pixels: the page is `width` x `height` pixels of a render of the
    /// same options, at 96 pixels to the inch (a PDF page is 0.75 point a pixel).
    pub width: u32,
    /// Picture height in CSS pixels.
    pub height: u32,
    /// The page's exact size in CSS pixels when it is not `width` x `height` (an SVG file's
    /// own size, say 489.33 x 924.23 for 129.47 mm x 244.54 mm): the picture is scaled to it.
    pub page_px: Option<(f64, f64)>,
    /// The rectangle of the plane mapped onto the page.
    pub view: View,
    /// Largest colour difference (ΔE00) between the viewer's bilinear colour and the surface's,
    /// checked at nine points of each patch (default [`DEFAULT_TOLERANCE`]).
    pub tolerance: f64,
    /// Largest distance, in pixels, between the flat patches standing for the surface's
    /// irregular spots and the surface (default [`DEFAULT_GEOMETRY_TOLERANCE_PX`]).
    pub geometry_tolerance_px: f64,
    /// The colour space of a PDF's shadings (SVG is always sRGB).
    pub colour: PdfColour,
    /// Limits on the input and its refinement; [`Limits::refined_faces`] also caps the patches
    /// of a layer.
    pub limits: Limits,
}

impl ExportOptions {
    /// Options for a `width` x `height` page showing `view`, other fields at their defaults.
    pub fn new(width: u32, height: u32, view: View) -> Self {
        ExportOptions {
            width,
            height,
            page_px: None,
            view,
            tolerance: DEFAULT_TOLERANCE,
            geometry_tolerance_px: DEFAULT_GEOMETRY_TOLERANCE_PX,
            colour: PdfColour::default(),
            limits: Limits::DEFAULT,
        }
    }

    /// The page's size in CSS pixels: [`ExportOptions::page_px`], or else `width` x `height`.
    pub fn page_size_px(&self) -> (f64, f64) {
        self.page_px
            .unwrap_or((f64::from(self.width), f64::from(self.height)))
    }

    /// Refuses a page or view that
    /// [`RenderOptions::check`](crate::render::RenderOptions::check) refuses for an image of
    /// the same size (at most [`MAX_PIXELS`] pixels), a page size that is not positive and
    /// finite, and tolerances that are not positive and finite.
    pub fn check(&self) -> Result<(), Error> {
        check_image(self.width, self.height, &self.view, MAX_PIXELS)?;
        let (pw, ph) = self.page_size_px();
        if !(pw.is_finite() && ph.is_finite() && pw > 0.0 && ph > 0.0) {
            return Err(ErrorKind::Invalid {
                what: "the page size".into(),
                message: format!("must be positive, not {pw} x {ph}"),
            }
            .into());
        }
        for (name, value) in [
            ("export tolerance", self.tolerance),
            ("export geometry tolerance", self.geometry_tolerance_px),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(ErrorKind::Invalid {
                    what: name.into(),
                    message: format!("must be positive, not {value}"),
                }
                .into());
            }
        }
        Ok(())
    }
}

/// What an export wrote.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ExportInfo {
    /// Patches written, over all layers (the soft masks' copies not counted).
    pub patches: usize,
    /// Per layer: patches written.
    pub layer_patches: Vec<usize>,
    /// Of those, flat patches standing for irregular spots of the surface.
    pub approximated: usize,
    /// The largest distance found between a flat patch and the surface, in pixels.
    pub geometry_error_px: f64,
    /// Layers with a soft mask (not fully opaque).
    pub masked_layers: usize,
    /// Seconds spent.
    pub seconds: f64,
    /// The validation's warnings, with their layers.
    pub warnings: Vec<Warning>,
}

/// The cells one Bézier patch was split into: `patches[first..first + n * m]`, row by row.
pub(crate) struct SplitGrid {
    pub first: usize,
    pub n: usize,
    pub m: usize,
}

/// One layer's output: its patches, how they were split, its outline (and the rule that tells
/// its inside), the space of its colours when it is not the export's, and whether it needs a
/// soft mask.
pub(crate) struct LayerPatches {
    pub patches: Vec<OutPatch>,
    pub grids: Vec<SplitGrid>,
    pub outline: Vec<Vec<Curve>>,
    pub clip_rule: FillRule,
    pub colour: Option<Target>,
    pub masked: bool,
    pub approximated: usize,
    pub geometry_error: f64,
    pub warnings: Vec<Warning>,
}

/// Every layer of `layers` as patches, those of the scheme split in `target`'s space, with
/// what was done so far.
pub(crate) fn layer_patches(
    layers: &[ExportLayer],
    opts: &ExportOptions,
    target: Target,
) -> Result<(Vec<LayerPatches>, ExportInfo), Error> {
    let start = Instant::now();
    opts.check()?;
    let surface_opts = SurfaceOptions {
        xf: ToPixels::new(&opts.view, opts.width, opts.height),
        width: opts.width as f64,
        height: opts.height as f64,
        geometry_tolerance: opts.geometry_tolerance_px,
        colour_tolerance: opts.tolerance,
        limits: opts.limits.clone(),
    };
    let layers: Vec<Option<LayerPatches>> = layers
        .par_iter()
        .enumerate()
        .map(|(index, layer)| -> Result<Option<LayerPatches>, Error> {
            let mesh = match layer {
                ExportLayer::Scheme(mesh) => mesh,
                ExportLayer::SvgMesh(fill) => {
                    return Ok(Some(classic::svg_fill_patches(fill, &surface_opts.xf)));
                }
            };
            let Some(surface) = layer_surface(mesh, index, &surface_opts)? else {
                return Ok(None);
            };
            let splitter = Splitter {
                space: surface.space,
                target,
                tolerance: opts.tolerance,
                opacity: !surface.opaque,
            };
            let mut patches = Vec::new();
            let mut grids = Vec::with_capacity(surface.nets.len());
            for net in &surface.nets {
                let first = patches.len();
                let (n, m) = splitter.split(net, &mut patches);
                grids.push(SplitGrid { first, n, m });
                // The patches count against the refinement's face limit: a runaway split
                // stops before it holds much more memory than a refinement may.
                if patches.len() as u64 > opts.limits.refined_faces {
                    return Err(Error::new(ErrorKind::LimitExceeded {
                        what: "the exported patch count".into(),
                        found: patches.len() as u64,
                        limit: opts.limits.refined_faces,
                    })
                    .in_layer(index));
                }
            }
            Ok(Some(LayerPatches {
                patches,
                grids,
                outline: surface.outline,
                clip_rule: FillRule::NonZero,
                colour: None,
                masked: !surface.opaque,
                approximated: surface.approximated,
                geometry_error: surface.geometry_error,
                warnings: surface.warnings,
            }))
        })
        .collect::<Result<_, _>>()?;
    let mut info = ExportInfo::default();
    let layers: Vec<LayerPatches> = layers.into_iter().flatten().collect();
    for l in &layers {
        info.warnings.extend(l.warnings.iter().cloned());
        info.patches += l.patches.len();
        info.layer_patches.push(l.patches.len());
        info.masked_layers += l.masked as usize;
        info.approximated += l.approximated;
        info.geometry_error_px = info.geometry_error_px.max(l.geometry_error);
    }
    info.seconds = start.elapsed().as_secs_f64();
    Ok((layers, info))
}
