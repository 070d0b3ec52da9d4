//! Fitted conversion: the control colours of layers converted from SVG mesh gradients (or PDF
//! patch meshes) fitted by least squares to the classic painting of the fill each came from.
//!
//! A converted layer keeps its fill's topology, positions and handles; only its colours change.
//! Each fill is painted classically on its own, unclipped (the layer has no clip) and at a scale
//! where its patches span enough pixels, and the layer, placed in that picture's pixels, has
//! its colours fitted to it by [`crate::fit_colours`], pixels weighing by the painting's alpha.

use kurbo::{Affine, Point, Rect, Vec2};

use crate::error::{Error, ErrorKind};
use crate::fit::{fit_colours, fit_colours_with_detail, DetailOptions, Quality, RgbaImage};
use crate::mesh::GradientMesh;
use crate::render::{render_picture_into, LayerSource, PictureLayer, RenderOptions, View};

/// How a fitted conversion samples each fill's classic painting.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClassicFitOptions {
    /// Pixels per unit of the plane at which the fill is painted and fitted, at least (the
    /// picture's own scale, say, 1 for an SVG file at 96 dpi).
    pub pixels_per_unit: f64,
    /// The fewest pixels across the larger side of a fill's painting: small fills are painted
    /// larger so that every patch spans enough pixels.
    pub min_side_px: u32,
    /// The most pixels across the larger side of a fill's painting.
    pub max_side_px: u32,
    /// How densely the fit samples the surface and how long it solves.
    pub quality: Quality,
    /// Refined-level colour edits where the control colours cannot follow the painting
    /// (`None`: the control colours only).
    pub detail: Option<DetailOptions>,
}

impl Default for ClassicFitOptions {
    fn default() -> Self {
        ClassicFitOptions {
            pixels_per_unit: 1.0,
            min_side_px: 512,
            max_side_px: 2048,
            quality: Quality::Best,
            detail: Some(DetailOptions::default()),
        }
    }
}

/// Pixels of margin around a fill's painting, so that its outline's anti-aliasing is inside.
const MARGIN_PX: f64 = 2.0;

/// Fits the colours of `layers[i]` to the classic painting of `sources[i]` (see the module's
/// documentation). Returns, per layer, the PSNR (dB) of its fitted surface against the
/// painting as the fit samples it.
pub fn fit_to_classic(
    layers: &mut [GradientMesh],
    sources: &[LayerSource<'_>],
    options: &ClassicFitOptions,
) -> Result<Vec<f64>, Error> {
    let single: Vec<&[LayerSource<'_>]> = sources.iter().map(std::slice::from_ref).collect();
    fit_joined_to_classic(layers, &single, options)
}

/// [`fit_to_classic`] for layers that each hold several fills, as [`crate::join_meshes`] joins
/// them: `layers[i]` is fitted to the classic painting of the fills `sources[i]`, painted
/// together in their order (the lowest first).
pub fn fit_joined_to_classic(
    layers: &mut [GradientMesh],
    sources: &[&[LayerSource<'_>]],
    options: &ClassicFitOptions,
) -> Result<Vec<f64>, Error> {
    if layers.len() != sources.len() {
        return Err(Error::new(ErrorKind::Invalid {
            what: "fitted conversion".into(),
            message: format!(
                "{} layers for {} sets of fills",
                layers.len(),
                sources.len()
            ),
        }));
    }
    layers
        .iter_mut()
        .zip(sources)
        .enumerate()
        .map(|(i, (layer, fills))| fit_layer(layer, fills, options).map_err(|e| e.in_layer(i)))
        .collect()
}

/// [`fit_joined_to_classic`] for one layer.
fn fit_layer(
    layer: &mut GradientMesh,
    fills: &[LayerSource<'_>],
    options: &ClassicFitOptions,
) -> Result<f64, Error> {
    let Some(extent) = mesh_extent(layer) else {
        return Ok(f64::INFINITY);
    };
    let (to_pixels, width, height) = picture_frame(extent, options);
    let painting = paint_alone(fills, to_pixels, width, height)?;
    let mut placed = transformed(layer, to_pixels);
    let psnr = match &options.detail {
        Some(detail) => {
            fit_colours_with_detail(&mut placed, &painting, options.quality, detail)?.psnr
        }
        None => fit_colours(&mut placed, &painting, options.quality)?,
    };
    for (point, fitted) in layer.points.iter_mut().zip(&placed.points) {
        point.colour = fitted.colour;
        point.colour_text = None;
    }
    layer.edits = placed.edits;
    Ok(psnr)
}

/// The box of the mesh's points and handle tips (the hull of its patches' control polygons),
/// or `None` for a mesh without points or with a coordinate that is not finite.
fn mesh_extent(mesh: &GradientMesh) -> Option<Rect> {
    let tips = mesh
        .handles
        .iter()
        .filter_map(|(&(p, _), h)| mesh.points.get(p as usize).map(|q| q.position + *h));
    let mut all = mesh.points.iter().map(|p| p.position).chain(tips);
    let first = all.next()?;
    let rect = all.fold(Rect::from_points(first, first), |r, p| r.union_pt(p));
    (rect.is_finite() && rect.area().is_finite()).then_some(rect)
}

/// The map from the plane to the pixels of a fill's painting, and its width and height: the
/// `extent` at the options' scale, enlarged or reduced so its larger side spans
/// `min_side_px..=max_side_px` pixels, within a margin.
fn picture_frame(extent: Rect, options: &ClassicFitOptions) -> (Affine, u32, u32) {
    let side = extent.width().max(extent.height()).max(1e-9);
    let (lo, hi) = (
        f64::from(options.min_side_px.max(1)),
        f64::from(options.max_side_px.max(options.min_side_px).max(1)),
    );
    let scale = (options.pixels_per_unit.max(1e-9) * side).clamp(lo, hi) / side;
    let size = |length: f64| ((length * scale + 2.0 * MARGIN_PX).ceil() as u32).max(1);
    let origin = Vec2::new(extent.x0, extent.y0);
    let to_pixels = Affine::translate((MARGIN_PX, MARGIN_PX))
        * Affine::scale(scale)
        * Affine::translate(-origin);
    (to_pixels, size(extent.width()), size(extent.height()))
}

/// The `fills` painted alone (without the rest of the picture), in order and unclipped, into a
/// `width` x `height` picture, the plane mapped to its pixels by `to_pixels` (a scale and a
/// translation).
fn paint_alone(
    fills: &[LayerSource<'_>],
    to_pixels: Affine,
    width: u32,
    height: u32,
) -> Result<RgbaImage, Error> {
    let from_pixels = to_pixels.inverse();
    let corner = |x: f64, y: f64| from_pixels * Point::new(x, y);
    let (a, b) = (
        corner(0.0, 0.0),
        corner(f64::from(width), f64::from(height)),
    );
    let mut opts = RenderOptions::new(width, height, View::new(a.x, a.y, b.x, b.y));
    opts.dither = false;
    let mut data = vec![0f32; 4 * width as usize * height as usize];
    let layers: Vec<PictureLayer> = fills
        .iter()
        .map(|&source| PictureLayer { source, clip: None })
        .collect();
    render_picture_into(&layers, &opts, &mut data)?;
    let pixels = data
        .chunks_exact(4)
        .map(|p| [p[0], p[1], p[2], p[3]])
        .collect();
    Ok(RgbaImage {
        width,
        height,
        pixels,
    })
}

/// A copy of `mesh` with its points moved by `to_pixels` and its handles scaled with it.
fn transformed(mesh: &GradientMesh, to_pixels: Affine) -> GradientMesh {
    let mut out = mesh.clone();
    for p in &mut out.points {
        p.position = to_pixels * p.position;
    }
    let linear = Affine::new({
        let c = to_pixels.as_coeffs();
        [c[0], c[1], c[2], c[3], 0.0, 0.0]
    });
    for h in out.handles.values_mut() {
        *h = (linear * h.to_point()).to_vec2();
    }
    out
}
