//! Rendering the limit surface to pixels, by hand: no rendering crate.
//!
//! For each layer (a [`GradientMesh`] of a [`Document`], bottom first):
//!
//! 1. **Density.** The colours the triangles show must be within
//!    [`RenderOptions::colour_tolerance`] (about Delta E) of the limit surface, the quads at most
//!    [`RenderOptions::max_quad_px`] across and the boundary edges within
//!    [`RenderOptions::tolerance_px`] of the outline. The colour error is measured, not
//!    predicted: the surface at a quad's centre and at its sides' midpoints (the face and edge
//!    points of the next level) against what the triangles show at the same position in the
//!    plane, so the non-affine map from mesh to plane (usually the larger term) is included.
//!    - **Fast path (feature-adaptive).** The mesh is refined to level 3 only (all quads,
//!      extraordinary vertices isolated). Each face of that level gets its own grid density,
//!      doubled until its cells pass the measure (colour held to three quarters of the
//!      tolerance, since each face now stops right at it). A face whose neighbourhood is
//!      regular (valence-4 interior, valence-3 boundary or corner vertices, no sharpness but
//!      the boundary's) is exactly a uniform bicubic B-spline patch in position, colour and
//!      opacity, with phantom points beyond a boundary, and is evaluated directly; any other
//!      face (extraordinary vertex, crease, semi-sharp feature) is refined on its own, keeping
//!      at each depth only the faces around its descendants. Faces of different densities are
//!      stitched without cracks: a face rises to half its finest neighbour's count (the full
//!      count where the surface folds), each edge takes the finer count of its faces, both
//!      sides use bit-identical samples along it, and the coarser side fans its boundary cells
//!      out to them. Cells are drawn in the order and with the diagonals of the quads uniform
//!      refinement would make (see `adaptive.rs`).
//!      A face whose cells fail with linear colour is also measured with *quadratic* colour
//!      (six-node triangles, see `quadratic.rs`; [`RenderOptions::quadratic`]) against the
//!      surface at the triangles' quarter points, and keeps whichever passes first: where
//!      colour is smooth, quadratic pieces converge as the cube of the cell size and need far
//!      fewer cells; near extraordinary vertices and folds the faces stay linear.
//!      Faces whose control points all lie off the image are not refined.
//!    - **Uniform path** (reference mode, [`RenderOptions::level`], a
//!      [`RenderOptions::max_level`] under 3, or a layer the fast path does not handle). The
//!      mesh is refined uniformly until every quad reaching the image passes. Errors inside
//!      quads under a pixel across are not counted there: what survives refinement that far
//!      sits at extraordinary and degenerate points (a handle of length zero, say), where
//!      uniform refinement converges only linearly and would refine the whole layer for a few
//!      pixels. (The fast path counts them where the quad's box holds a pixel centre: only
//!      that face goes deeper.)
//!
//!    The rendering notes' measurement (quads of about 3 px within 0.011 CIEDE2000 of quads of
//!    0.7 px) says colour needs no more than a few pixels per quad; the tests measure the result
//!    against the reference mode. [`LayerInfo`] reports the (finest) level, whether a cap
//!    ([`RenderOptions::max_level`], [`RenderOptions::max_quads`]) stopped it, and the time of
//!    each stage ([`LayerTimings`], [`RenderTimings`]).
//! 2. **Interior.** Every quad (cell), with the limit positions and colours of its corners, is
//!    drawn as two triangles; colour and opacity are interpolated linearly (quadratically on a
//!    quadratic face, through the nodes at the sides' midpoints, which two triangles sharing a
//!    side share bit for bit) in the mesh's working space at each pixel centre and only then
//!    converted. Vertices are snapped to
//!    1/256 pixel and tested with exact integer edge functions and the top-left rule, so interior
//!    edges have neither gaps nor double coverage. Where the surface folds over itself, later
//!    faces cover earlier ones (face order of the refinement; see [`find_folds`]).
//! 3. **Outline.** Only the outline is anti-aliased: the limit boundary curves (exact cubic
//!    Béziers of the boundary B-spline, flattened to 0.002 px) are covered with exact signed
//!    area, accumulated per cell and prefix-summed per row as font rasterisers do. Holes come
//!    out empty, and the two sides of a discontinuous edge cancel: no seam. Outline pixels whose
//!    centre no triangle covers take the colour of the nearest point of the tessellation's
//!    boundary. Alpha is coverage times the interpolated opacity.
//! 4. **Colour.** Working space to linear sRGB, [`GamutMapping`] (default: chroma reduction in
//!    Oklch), sRGB transfer function; layers composited source-over with premultiplied alpha in
//!    the [`BlendSpace`] (default: sRGB-encoded, as SVG and image viewers do). The bands
//!    composite front to back (the same sum, taken from the top layer down), so a pixel an
//!    opaque layer already covers is not evaluated again for the layers beneath.
//!
//! Rows are split into bands of 16 drawn in parallel with rayon; every band does the same
//! arithmetic whichever thread runs it, so the output does not depend on the thread count.
//!
//! Steps 1 and 2 make each layer's *prepared* form (triangles, outline, nearest-boundary table,
//! binned into bands); steps 3 and 4 draw. A [`RenderCache`] keeps prepared layers between
//! renders, so an editor pays only for the layers an edit changed.
//!
//! ```
//! use gradmesh::render::{render_document, RenderOptions, View};
//! use gradmesh::{ColourSpace, Document, GradientMesh};
//! use kurbo::Point;
//!
//! let mut mesh = GradientMesh::new(ColourSpace::Lab);
//! let a = mesh.add_point(Point::new(0.0, 0.0), [50.0, 60.0, 40.0]);
//! let b = mesh.add_point(Point::new(100.0, 0.0), [90.0, -10.0, 80.0]);
//! let c = mesh.add_point(Point::new(50.0, 90.0), [40.0, 10.0, -50.0]);
//! mesh.add_face(vec![a, b, c]);
//! let doc = Document { layers: vec![mesh] };
//!
//! let opts = RenderOptions::fit(&doc, 64);
//! let image = render_document(&doc, &opts)?;
//! assert_eq!(image.width, 64);
//! let png = gradmesh::render::encode_png(&image, 8, true)?;
//! assert_eq!(&png[1..4], b"PNG");
//! # Ok::<(), gradmesh::Error>(())
//! ```

mod adaptive;
mod coverage;
mod folds;
mod gamut;
mod layer;
mod measure;
mod nearest;
mod outline;
mod output;
mod overlay;
mod patches;
mod quadratic;
mod triangles;
mod view;

use std::ops::Range;
use std::sync::Arc;
use std::time::{Duration, Instant};

use rayon::prelude::*;

use crate::colour::{srgb_decode, ColourSpace};
use crate::error::{Error, ErrorKind, Warning};
use crate::mesh::{Document, GradientMesh};

pub use folds::{find_folds, find_folds_at, Fold, FOLD_LEVEL};
pub use gamut::{BlendSpace, GamutMapping};
pub use output::{
    encode_png, encode_png_rgba16, encode_png_rgba8, write_png, write_png_rgba16, write_png_rgba8,
    Image, OutputPixel,
};
pub use overlay::draw_outlines;
pub use view::{document_bounds, View};

use gamut::RUN;
use layer::{Columns, PreparedLayer, BAND};
use patches::ShapeCache;
use view::ToPixels;

/// The largest image side accepted.
pub const MAX_SIDE: u32 = 1 << 15;
/// The default largest pixel count ([`RenderOptions::max_pixels`]): 100 megapixels.
pub const MAX_PIXELS: u64 = 100_000_000;
/// The largest magnitude of a view's coordinates: that of a mesh's
/// ([`crate::validate::MAX_MAGNITUDE`]).
pub const MAX_VIEW_MAGNITUDE: f64 = crate::validate::MAX_MAGNITUDE;
/// The smallest pixel, in plane units: a mesh's shortest edge
/// ([`crate::validate::MIN_EDGE_LENGTH`]).
pub const MIN_PIXEL_SIZE: f64 = crate::validate::MIN_EDGE_LENGTH;
/// The smallest pixel relative to the view's largest coordinate (2^-32): smaller pixels leave
/// too few bits of a coordinate to place anti-aliased edges within them.
pub const MIN_RELATIVE_PIXEL_SIZE: f64 = 1.0 / 4_294_967_296.0;

/// How to render a document.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// The rectangle of the plane mapped onto the image.
    pub view: View,
    /// What lies under the first layer: non-linear sRGB and alpha in `0..=1`, straight alpha.
    /// `None` is transparent.
    pub background: Option<[f64; 4]>,
    /// Largest distance, in pixels, between the outline (drawn exactly) and the boundary edges of
    /// the triangles (default 0.25). Outline pixels between the two take the colour of the
    /// nearest boundary point.
    pub tolerance_px: f64,
    /// Largest colour error of the triangles against the limit surface, approximately in Delta E
    /// (CIE Lab units), measured at quad and edge centres (default 0.2).
    pub colour_tolerance: f64,
    /// Largest diagonal, in pixels, of a refined quad that reaches the image (default 64): keeps
    /// the colour measurement's samples dense. The colour measure does not depend on the image
    /// size, so this cap is what makes large images need more quads: a smaller cap multiplies
    /// the quads of large images for no difference the accuracy tests can see.
    pub max_quad_px: f64,
    /// Slow and simple: colours within 0.002 (about Delta E, counted in quads from 0.1 pixel
    /// across) and quads under half a pixel; outline flattened to 0.0002 px. One more level changes no 16-bit
    /// channel of the test meshes by more than one step (see the tests). Still bounded by
    /// [`RenderOptions::max_quads`]: keep reference images small.
    pub reference: bool,
    /// Use this refinement level (at least 2) instead of choosing one.
    pub level: Option<usize>,
    /// The deepest level ever chosen (default 10).
    pub max_level: usize,
    /// Most quads in any level built (default 2^21: about 1.2 GB at the peak, refinement tables
    /// of every level included); the level stops below it and [`LayerInfo::capped`] says so.
    pub max_quads: usize,
    /// Interpolate in this space instead of each mesh's own (control colours are converted).
    pub colour_space_override: Option<ColourSpace>,
    /// What to do with colours outside the sRGB gamut.
    pub gamut: GamutMapping,
    /// Where layers are composited.
    pub blend: BlendSpace,
    /// Dither 8-bit output of [`render_document_into`] (deterministic triangular noise).
    pub dither: bool,
    /// The largest image accepted, in pixels (default [`MAX_PIXELS`]): a larger request is
    /// refused before anything is allocated.
    pub max_pixels: u64,
    /// Let the fast path interpolate colour quadratically over the triangles of faces where
    /// that passes the colour tolerance with fewer cells than linear colour (default `true`).
    /// `false` draws every face with linear colour (more triangles), for comparison.
    pub quadratic: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 256,
            height: 256,
            view: View::default(),
            background: None,
            tolerance_px: 0.25,
            colour_tolerance: 0.2,
            max_quad_px: 64.0,
            reference: false,
            level: None,
            max_level: 10,
            max_quads: 1 << 21,
            colour_space_override: None,
            gamut: GamutMapping::default(),
            blend: BlendSpace::default(),
            dither: true,
            max_pixels: MAX_PIXELS,
            quadratic: true,
        }
    }
}

impl RenderOptions {
    /// Options for a `width` x `height` image of `view`, other fields at their defaults.
    pub fn new(width: u32, height: u32, view: View) -> Self {
        RenderOptions {
            width,
            height,
            view,
            ..RenderOptions::default()
        }
    }

    /// Options showing the whole document ([`View::fit`] with a 2% margin) in an image whose
    /// larger side is `max_side` pixels, with the document's aspect ratio.
    pub fn fit(doc: &Document, max_side: u32) -> Self {
        let view = View::fit(doc, 0.02);
        let (width, height) = view.size_for(max_side);
        // Make the view's aspect exactly the image's, so pixels are square.
        let scale = (view.width() / width as f64).max(view.height() / height as f64);
        let (cx, cy) = (0.5 * (view.x0 + view.x1), 0.5 * (view.y0 + view.y1));
        let (hw, hh) = (0.5 * scale * width as f64, 0.5 * scale * height as f64);
        RenderOptions::new(width, height, View::new(cx - hw, cy - hh, cx + hw, cy + hh))
    }

    /// Refuses options that cannot be rendered: an empty image, a side above [`MAX_SIDE`], more
    /// pixels than [`RenderOptions::max_pixels`], a view that is empty, not finite, beyond
    /// ±[`MAX_VIEW_MAGNITUDE`] or whose pixels are smaller than its coordinates can resolve
    /// ([`MIN_PIXEL_SIZE`], [`MIN_RELATIVE_PIXEL_SIZE`]), and tolerances or a background that
    /// are not finite. (A forced [`RenderOptions::level`] is checked against
    /// [`RenderOptions::max_quads`] for each layer, from its base mesh, before it is built.)
    ///
    /// Every render function calls it first, before allocating anything; a caller that
    /// allocates its own output buffer for [`render_document_into`] calls it before that.
    pub fn check(&self) -> Result<(), Error> {
        let invalid = |what: &str, message: String| -> Error {
            ErrorKind::Invalid {
                what: what.into(),
                message,
            }
            .into()
        };
        if self.width == 0 || self.height == 0 {
            return Err(invalid(
                "image size",
                format!("{}x{} has no pixels", self.width, self.height),
            ));
        }
        let pixels = self.width as u64 * self.height as u64;
        if pixels > self.max_pixels {
            return Err(ErrorKind::LimitExceeded {
                what: "pixel count".into(),
                found: pixels,
                limit: self.max_pixels,
            }
            .into());
        }
        let side = self.width.max(self.height);
        if side > MAX_SIDE {
            return Err(ErrorKind::LimitExceeded {
                what: "image side".into(),
                found: side as u64,
                limit: MAX_SIDE as u64,
            }
            .into());
        }
        self.check_view()?;
        for (name, value) in [
            ("tolerance", self.tolerance_px),
            ("colour tolerance", self.colour_tolerance),
            ("largest quad size", self.max_quad_px),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(invalid(name, format!("must be positive, not {value}")));
            }
        }
        if let Some(bg) = self.background {
            if bg.iter().any(|c| !c.is_finite()) {
                return Err(invalid("background", format!("{bg:?} is not finite")));
            }
        }
        Ok(())
    }

    /// Refuses a view that is empty or not finite, reaches beyond ±[`MAX_VIEW_MAGNITUDE`], or
    /// whose pixels are smaller than [`MIN_PIXEL_SIZE`] or than [`MIN_RELATIVE_PIXEL_SIZE`]
    /// times its largest coordinate (adjacent pixels would map to the same plane coordinates).
    fn check_view(&self) -> Result<(), Error> {
        let v = &self.view;
        let corners = [v.x0, v.y0, v.x1, v.y1];
        let shown = format!("({:?}, {:?}) to ({:?}, {:?})", v.x0, v.y0, v.x1, v.y1);
        let invalid = |message: String| -> Error {
            ErrorKind::Invalid {
                what: "view".into(),
                message: format!("{shown}: {message}"),
            }
            .into()
        };
        if !corners.iter().all(|x| x.is_finite()) {
            return Err(invalid("every coordinate must be a finite number".into()));
        }
        let largest = corners.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        if largest > MAX_VIEW_MAGNITUDE {
            return Err(invalid(format!(
                "a coordinate is beyond ±{MAX_VIEW_MAGNITUDE:e}, the largest a mesh may have"
            )));
        }
        if !(v.width() > 0.0 && v.height() > 0.0) {
            return Err(invalid("x1 must exceed x0 and y1 must exceed y0".into()));
        }
        let pixel = (v.width() / self.width as f64).min(v.height() / self.height as f64);
        let smallest = MIN_PIXEL_SIZE.max(MIN_RELATIVE_PIXEL_SIZE * largest);
        if pixel < smallest {
            return Err(invalid(format!(
                "a pixel would be {pixel:e} units across, below the {smallest:e} that \
                 coordinates of this size resolve"
            )));
        }
        Ok(())
    }
}

/// What was drawn for one layer.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LayerInfo {
    /// The refinement level drawn (0 for a layer without faces); on the fast path, the level
    /// whose density the finest face has (faces each have their own).
    pub level: usize,
    /// Whether [`RenderOptions::max_level`] or [`RenderOptions::max_quads`] stopped the
    /// refinement before the quads met the size and tolerance asked for.
    pub capped: bool,
    /// Quads at that level (on the fast path, the cells of all faces' grids).
    pub quads: usize,
    /// Triangles that reach the image.
    pub triangles: usize,
    /// Largest diagonal of a quad that reaches the image, in pixels (NaN when not measured:
    /// forced level, or capped at level 2).
    pub max_quad_px: f64,
    /// Largest distance between the outline and the boundary edges of the triangles, in pixels
    /// (NaN when not measured).
    pub max_outline_deviation_px: f64,
    /// Largest difference, approximately in Delta E (CIE Lab units; opacity counts 100 per
    /// unit), between the colour the triangles show at the centre of a quad or edge and the
    /// limit colour there (NaN when not measured).
    pub max_colour_error: f64,
    /// Whether the three figures above are estimated from the level above (size halving per
    /// level, the outline's distance quartering, the colour error falling at the rate it fell
    /// over the level before, between a quarter and a half) rather than measured at the level
    /// drawn.
    pub estimated: bool,
    /// Time spent on each stage of preparing this layer (zero when [`LayerInfo::reused`]).
    pub timings: LayerTimings,
    /// Whether the layer was taken from a [`RenderCache`] rather than prepared.
    pub reused: bool,
    /// Faces whose plans (grid density and samples) were taken from a [`RenderCache`] when
    /// the layer was prepared again: after an edit, the faces it left alone.
    pub reused_faces: usize,
}

/// Wall-clock time of the stages that prepare one layer (layers are prepared in parallel, so
/// these add up to more than [`RenderTimings::prepare`] when there are several).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LayerTimings {
    /// Validation, the first step and the topology and data of the levels built.
    pub refine: Duration,
    /// Limit stencils or patch evaluation, and measuring the error to choose the density.
    pub evaluate: Duration,
    /// Triangles, outline and nearest-boundary table built and binned into bands.
    pub tessellate: Duration,
}

/// Wall-clock time of the stages of a whole render.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderTimings {
    /// Every layer prepared (see [`LayerTimings`] for the split per layer).
    pub prepare: Duration,
    /// Rasterisation, outline coverage, colour conversion and compositing, all bands.
    pub draw: Duration,
}

/// What was drawn.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RenderInfo {
    /// One entry per layer of the document.
    pub layers: Vec<LayerInfo>,
    /// Warnings from validating the layers (legal but suspicious input).
    pub warnings: Vec<Warning>,
    /// Time spent on each stage.
    pub timings: RenderTimings,
    /// How many bands of rows were drawn: all of them, unless a [`RenderCache`] held the last
    /// image and some bands draw exactly as before (they are copied from it).
    pub drawn_bands: usize,
    /// How many pixels were drawn: all of them, unless a [`RenderCache`] held the last image
    /// (the others are copied from it). Within a band drawn again, only the columns where some
    /// layer may draw differently are drawn.
    pub drawn_pixels: u64,
}

/// Renders `doc` into a new `f32` image: straight alpha, sRGB-encoded colour.
pub fn render_document(doc: &Document, opts: &RenderOptions) -> Result<Image, Error> {
    render_image(doc, opts).map(|(image, _)| image)
}

/// Renders `doc` into a new `f32` image, with what was drawn.
pub fn render_image(doc: &Document, opts: &RenderOptions) -> Result<(Image, RenderInfo), Error> {
    opts.check()?;
    let mut image = Image::new(opts.width, opts.height);
    let info = render_document_into(doc, opts, &mut image.data)?;
    Ok((image, info))
}

/// Renders one mesh alone (a document of one layer) into a new image.
pub fn render_mesh(mesh: &GradientMesh, opts: &RenderOptions) -> Result<Image, Error> {
    let doc = Document {
        layers: vec![mesh.clone()],
    };
    render_document(&doc, opts)
}

/// Renders `doc` into a caller's buffer of `4 * width * height` channels (`f32`, `u16` or `u8`):
/// RGBA, straight alpha, sRGB-encoded colour, rows top to bottom. 8-bit output is dithered when
/// [`RenderOptions::dither`] is set.
pub fn render_document_into<P: OutputPixel>(
    doc: &Document,
    opts: &RenderOptions,
    out: &mut [P],
) -> Result<RenderInfo, Error> {
    render(doc, opts, None, out)
}

/// Layers prepared for drawing (refined, tessellated and binned), kept between renders of a
/// document being edited: [`render_document_into_cached`] prepares again only the layers whose
/// mesh changed, or all of them when an option that shapes the preparation (size, view,
/// tolerances, levels, colour space) did. Background, dither, gamut mapping and blend space
/// only affect drawing.
///
/// An editor that drags a point of one layer then pays for that layer's preparation and the
/// drawing, not for the other layers. The cache holds a copy of each mesh it compares against,
/// and the prepared triangles and outlines (a few megabytes for a dense layer at 1024 pixels).
/// It also keeps the structure of the local refinements around extraordinary vertices and
/// creases, which depends on the topology alone. A layer whose points or colours moved
/// reuses those.
///
/// An edited layer whose topology (faces, edge kinds and sharpness, rules) stayed also keeps
/// the topology of its refinement levels and their stencils ([`crate::Refinement::rebase`]),
/// the plan of each face (its grid density and samples, which depend on the points of the
/// faces around it alone), and the triangles of each block of faces: it plans again only
/// the faces within reach of what moved ([`LayerInfo::reused_faces`]), and builds again only
/// the blocks of triangles next to them.
///
/// It keeps the last image drawn, too: only the pixels where some layer's triangles, outline
/// or outline colours changed are drawn, and the others are copied from it. Within a band of
/// rows ([`RenderInfo::drawn_bands`]) that is a range of columns ([`RenderInfo::drawn_pixels`]):
/// those of the triangles that differ, those within reach of a changed boundary segment, and
/// from the leftmost changed outline line to the layer's right end (coverage is a prefix sum
/// along the row). Each pixel is computed alone, so the image is the one drawing every pixel
/// would give. The output buffer may be a fresh one each time; the copy costs one image of
/// memory.
#[derive(Default)]
pub struct RenderCache {
    /// Local refinements by shape of neighbourhood, for all layers (cleared when they pile
    /// up past [`MAX_CACHED_SHAPES`]).
    shapes: Arc<ShapeCache>,
    /// The options the entries were prepared with, with the drawing-only fields reset.
    key: Option<RenderOptions>,
    /// Per layer, by position: the mesh prepared and what preparing it gave.
    layers: Vec<Option<(GradientMesh, layer::Prepared)>>,
    /// Per layer, by position: the plans of its regular faces at its last preparation, once
    /// it has been prepared again (edited), which a layer prepared again after an edit takes
    /// for the faces the edit left alone.
    plans: Vec<adaptive::PlanMemo>,
    /// The last image drawn through the cache: bands that no layer draws differently are
    /// copied from it rather than drawn again.
    drawn: Option<Drawn>,
}

/// An image [`render_document_into_cached`] drew, and the options it drew it with.
struct Drawn {
    opts: RenderOptions,
    /// A `Vec<P>` of the [`OutputPixel`] type it was drawn in.
    pixels: Box<dyn std::any::Any + Send + Sync>,
    /// Per band, then per layer: the farthest an outline pixel's colour was taken from (the
    /// nearest boundary point, see [`nearest`]); negative infinity where none was.
    reach: Vec<f64>,
}

/// The most shapes of local refinement a [`RenderCache`] keeps: a few hundred kilobytes each
/// at most, and a layer has a few dozen.
const MAX_CACHED_SHAPES: usize = 1024;

impl RenderCache {
    /// An empty cache.
    pub fn new() -> Self {
        RenderCache::default()
    }

    /// The fields of `opts` that preparing a layer reads.
    fn key(opts: &RenderOptions) -> RenderOptions {
        RenderOptions {
            background: None,
            dither: false,
            gamut: GamutMapping::default(),
            blend: BlendSpace::default(),
            max_pixels: 0,
            ..opts.clone()
        }
    }
}

/// [`render_document_into`], reusing the layers of `cache` that are unchanged (see
/// [`RenderCache`]); the result is identical. [`LayerInfo::reused`] tells which layers were
/// taken from the cache.
pub fn render_document_into_cached<P: OutputPixel>(
    doc: &Document,
    opts: &RenderOptions,
    cache: &mut RenderCache,
    out: &mut [P],
) -> Result<RenderInfo, Error> {
    render(doc, opts, Some(cache), out)
}

fn render<P: OutputPixel>(
    doc: &Document,
    opts: &RenderOptions,
    mut cache: Option<&mut RenderCache>,
    out: &mut [P],
) -> Result<RenderInfo, Error> {
    opts.check()?;
    let (w, h) = (opts.width as usize, opts.height as usize);
    if out.len() != 4 * w * h {
        return Err(ErrorKind::Invalid {
            what: "output buffer".into(),
            message: format!(
                "holds {} channels, a {w}x{h} RGBA image needs {}",
                out.len(),
                4 * w * h
            ),
        }
        .into());
    }
    let xf = ToPixels::new(&opts.view, opts.width, opts.height);
    let start = Instant::now();
    if let Some(cache) = cache.as_deref_mut() {
        let key = RenderCache::key(opts);
        if cache.key.as_ref() != Some(&key) {
            cache.key = Some(key);
            cache.layers.clear();
            cache.plans.clear();
        }
        // A document with other layers, or other drawing options, draws every band again.
        if cache.layers.len() != doc.layers.len()
            || cache.drawn.as_ref().is_some_and(|d| d.opts != *opts)
        {
            cache.drawn = None;
        }
        cache.layers.resize_with(doc.layers.len(), || None);
        cache.plans.resize_with(doc.layers.len(), Default::default);
        if cache.shapes.len() > MAX_CACHED_SHAPES {
            cache.shapes = Arc::default();
        }
    }
    let shapes: Arc<ShapeCache> = cache
        .as_deref()
        .map(|c| Arc::clone(&c.shapes))
        .unwrap_or_default();
    // The layers to prepare (`None`: taken from the cache).
    let (cached, mut memos) = match cache.as_deref_mut() {
        Some(c) => (
            Some(c.layers.as_slice()),
            c.plans.iter_mut().map(Some).collect(),
        ),
        None => (
            None,
            (0..doc.layers.len()).map(|_| None).collect::<Vec<_>>(),
        ),
    };
    let fresh: Vec<Option<layer::Prepared>> = doc
        .layers
        .par_iter()
        .zip(memos.par_iter_mut())
        .enumerate()
        .map(|(i, (mesh, memo))| {
            let entry = cached.and_then(|c| c[i].as_ref());
            if entry.is_some_and(|(old, _)| old == mesh) {
                return Ok(None);
            }
            // Plans are kept for layers prepared again (edited): keeping every layer's would
            // cost a copy of its plans at its first preparation, and memory, for nothing.
            let memo = memo.as_deref_mut().filter(|_| entry.is_some());
            layer::prepare(mesh, i, opts, &xf, &shapes, memo).map(Some)
        })
        .collect::<Vec<_>>()
        // The first failing layer's error, whatever the thread count.
        .into_iter()
        .collect::<Result<_, _>>()?;
    drop(memos);
    let reused: Vec<bool> = fresh.iter().map(Option::is_none).collect();
    let kept: Vec<layer::Prepared>;
    let bands = h.div_ceil(BAND);
    // Entries per band of `Drawn::reach`.
    let nl = doc.layers.len().max(1);
    // The columns of each band to draw, and the last image drawn through the cache (taken out
    // while drawing: a drawing cut short leaves none), whose other pixels are as they would be
    // drawn.
    let mut dirty = vec![Columns::all(w); bands];
    let mut last: Option<Drawn> = None;
    let mut last_slot: Option<&mut Option<Drawn>> = None;
    let prepared: Vec<&layer::Prepared> = match cache {
        Some(cache) => {
            last = cache.drawn.take();
            if last.is_some() {
                dirty.fill(Columns::NONE);
            }
            for (i, fresh) in fresh.into_iter().enumerate() {
                if let Some(p) = fresh {
                    let reach: Vec<f64> = match &last {
                        Some(d) => (0..bands).map(|b| d.reach[b * nl + i]).collect(),
                        None => Vec::new(),
                    };
                    match cache.layers[i].as_ref().map(|(_, old)| (&old.1, &p.1)) {
                        Some((Some(old), Some(new))) if last.is_some() => {
                            new.mark_changed_columns(old, &reach, w, &mut dirty)
                        }
                        Some((None, None)) => {}
                        _ => dirty.fill(Columns::all(w)),
                    }
                    cache.layers[i] = Some((doc.layers[i].clone(), p));
                }
            }
            // Drawn in another pixel type or size (or never): every band is drawn.
            let same_kind = last
                .as_ref()
                .and_then(|d| d.pixels.downcast_ref::<Vec<P>>())
                .is_some_and(|p| p.len() == out.len());
            if !same_kind {
                dirty.fill(Columns::all(w));
                last = Some(Drawn {
                    opts: opts.clone(),
                    pixels: Box::new(out.to_vec()),
                    reach: vec![f64::NEG_INFINITY; bands * nl],
                });
            }
            last_slot = Some(&mut cache.drawn);
            // Every entry was just filled or matched.
            cache
                .layers
                .iter()
                .map(|entry| &entry.as_ref().expect("filled or matched above").1)
                .collect()
        }
        None => {
            kept = fresh
                .into_iter()
                .map(|p| p.expect("prepared: there is no cache"))
                .collect();
            kept.iter().collect()
        }
    };
    let mut info = RenderInfo::default();
    let mut layers: Vec<&PreparedLayer> = Vec::new();
    // The document's index of each layer drawn (those with nothing to draw are left out).
    let mut layer_of: Vec<usize> = Vec::new();
    for ((layer_info, layer, warnings), reused) in prepared.into_iter().zip(reused) {
        let mut layer_info = layer_info.clone();
        if reused {
            layer_info.reused = true;
            layer_info.timings = LayerTimings::default();
            layer_info.reused_faces = 0;
        }
        info.layers.push(layer_info);
        info.warnings.extend(warnings.iter().cloned());
        if let Some(layer) = layer {
            layer_of.push(info.layers.len() - 1);
            layers.push(layer);
        }
    }
    info.timings.prepare = start.elapsed();

    let background = opts.background.map(|bg| {
        let a = bg[3].clamp(0.0, 1.0);
        let rgb = [bg[0], bg[1], bg[2]].map(|c| c.clamp(0.0, 1.0));
        let rgb = match opts.blend {
            BlendSpace::Srgb => rgb,
            BlendSpace::Linear => rgb.map(srgb_decode),
        };
        [rgb[0] * a, rgb[1] * a, rgb[2] * a, a].map(|v| v as f32)
    });
    let start = Instant::now();
    // Draws columns `cols` of a band, and puts in `reach` (per layer of the document) what
    // [`Band::reach`] gets: for part of the band, the farther of that and what it held (the
    // other columns' outline pixels keep theirs).
    let draw = |band: usize, cols: Columns, chunk: &mut [P], reach: &mut [f64]| {
        let mut drawn_reach = vec![f64::NEG_INFINITY; layers.len()];
        Scratch::with(w, |scratch| {
            let job = Band {
                wide: false,
                index: band,
                columns: cols.start..cols.end,
                out: chunk,
                layers: &layers,
                opts,
                background,
                reach: &mut drawn_reach,
            };
            draw_band_dispatched(job, scratch)
        });
        if cols == Columns::all(w) {
            reach.fill(f64::NEG_INFINITY);
        }
        for (&i, r) in layer_of.iter().zip(drawn_reach) {
            reach[i] = reach[i].max(r);
        }
    };
    let chunks = out.par_chunks_mut(4 * w * BAND).enumerate();
    let kept = last
        .as_mut()
        .and_then(|Drawn { pixels, reach, .. }| Some((pixels.downcast_mut::<Vec<P>>()?, reach)));
    match kept {
        // Pixels drawn again are kept for the next render; the others are taken from the last.
        Some((pixels, reach)) => chunks
            .zip(pixels.par_chunks_mut(4 * w * BAND))
            .zip(reach.par_chunks_mut(nl))
            .for_each(|(((band, chunk), last), reach)| {
                let cols = dirty[band];
                if cols == Columns::all(w) {
                    draw(band, cols, chunk, reach);
                    last.copy_from_slice(chunk);
                    return;
                }
                chunk.copy_from_slice(last);
                if !cols.is_empty() {
                    draw(band, cols, chunk, reach);
                    let window = 4 * cols.start..4 * cols.end;
                    for (last, row) in last.chunks_exact_mut(4 * w).zip(chunk.chunks_exact(4 * w)) {
                        last[window.clone()].copy_from_slice(&row[window.clone()]);
                    }
                }
            }),
        None => {
            chunks.for_each(|(band, chunk)| draw(band, Columns::all(w), chunk, &mut vec![0.0; nl]))
        }
    }
    info.drawn_bands = dirty.iter().filter(|c| !c.is_empty()).count();
    info.drawn_pixels = (0..bands)
        .map(|b| dirty[b].len() as u64 * (h - b * BAND).min(BAND) as u64)
        .sum();
    if let Some(slot) = last_slot {
        *slot = last;
    }
    info.timings.draw = start.elapsed();
    Ok(info)
}

/// `[f(0), f(1), f(2)]`. Written out: in the hottest loops `array::map` and `array::from_fn`
/// with closures were left as chains of calls (seen with cachegrind).
#[inline(always)]
pub(crate) fn each3<T>(mut f: impl FnMut(usize) -> T) -> [T; 3] {
    [f(0), f(1), f(2)]
}

/// `[f(0), f(1), f(2), f(3)]` (see [`each3`]).
#[inline(always)]
pub(crate) fn each4<T>(mut f: impl FnMut(usize) -> T) -> [T; 4] {
    [f(0), f(1), f(2), f(3)]
}

/// Per-thread working buffers, fully reset by each band that uses them.
struct Scratch {
    attributes: Vec<[f32; 4]>,
    covered: Vec<bool>,
    /// Pixels of the band that layers above have made opaque (a byte each: the span loop
    /// tests it at random places, where the colour rows would miss the cache).
    opaque: Vec<bool>,
    accumulation: coverage::Accumulator,
    coverage: Vec<f32>,
    /// The pixels of a run that a layer shows, before and after conversion to the blend space.
    run: Box<Run>,
    /// Premultiplied colour in the blend space. Single precision: compositing a few layers
    /// loses far less than a 16-bit step, and half the bytes keep a wide band in cache.
    colour: Vec<[f32; 4]>,
}

thread_local! {
    /// Each thread's scratch, kept between bands and renders: allocating it per rayon job
    /// (`for_each_init`) cost fresh pages, and so page faults, for every job.
    static SCRATCH: std::cell::Cell<Option<Scratch>> = const { std::cell::Cell::new(None) };
}

/// The widest rows whose scratch a thread keeps between bands and renders.
const KEEP_SCRATCH_MAX_WIDTH: usize = 8192;

impl Scratch {
    /// Runs `f` with this thread's scratch for rows `w` pixels wide.
    fn with<R>(w: usize, f: impl FnOnce(&mut Scratch) -> R) -> R {
        // Taken out of the slot while in use: a band that re-entered here (draw_band does not
        // call into rayon) or one that panicked leaves no half-used scratch behind.
        let kept = SCRATCH.with(|cell| cell.take());
        let mut scratch = match kept {
            Some(s) if s.accumulation.width() == w => s,
            _ => Scratch::new(w),
        };
        let r = f(&mut scratch);
        // Very wide images get a scratch for the band only: a thread keeps at most about
        // 7 MB between renders.
        if w <= KEEP_SCRATCH_MAX_WIDTH {
            SCRATCH.with(|cell| cell.set(Some(scratch)));
        }
        r
    }

    fn new(w: usize) -> Self {
        Scratch {
            attributes: vec![[0.0; 4]; w * BAND],
            covered: vec![false; w * BAND],
            opaque: vec![false; w * BAND],
            accumulation: coverage::Accumulator::new(w, BAND),
            coverage: vec![0.0; w],
            colour: vec![[0.0; 4]; w * BAND],
            run: Box::new(Run {
                colour: [[0.0; RUN]; 3],
                pixel: [0; RUN],
                alpha: [0.0; RUN],
                block: [false; RUN],
                rgb: [[0.0; 3]; RUN],
            }),
        }
    }
}

/// Up to [`RUN`] pixels of a row that one layer shows: their working-space colours (one array
/// per channel, for [`gamut::RunConverter`]), where they go, their opacity, and their colours
/// in the blend space.
struct Run {
    colour: [[f32; RUN]; 3],
    pixel: [u32; RUN],
    alpha: [f32; RUN],
    /// Whether a whole block ([`whole_block`]) starts at this entry: its pixels follow the
    /// first's, and their alpha is one (only the first entry's `pixel` is written).
    block: [bool; RUN],
    rgb: [[f32; 3]; RUN],
}

/// [`draw_band`] compiled for the x86-64-v3 level (AVX2, FMA, BMI) where the CPU has it, else
/// for the baseline: the same code, with the same results bit for bit (Rust never fuses a
/// multiply and an add on its own). The wider vectors take a sixth off drawing a large image.
fn draw_band_dispatched<P: OutputPixel>(job: Band<'_, P>, s: &mut Scratch) {
    #[cfg(target_arch = "x86_64")]
    if wide_vectors::available() {
        return wide_vectors::draw_band(Band { wide: true, ..job }, s);
    }
    draw_band_baseline(job, s)
}

/// [`draw_band`] for the baseline CPU.
// Not inlined into the rayon closure: inlined there, its loops compile worse.
#[inline(never)]
fn draw_band_baseline<P: OutputPixel>(job: Band<'_, P>, s: &mut Scratch) {
    draw_band(job, s)
}

/// The one place with `unsafe` code: calling [`draw_band`] (and the gamut mapping of many
/// colours) compiled for x86-64-v3, which is sound only on a CPU that has those instructions,
/// after checking that it does.
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod wide_vectors {
    use super::{draw_band as draw_band_inlined, Band, GamutMapping, OutputPixel, Scratch};

    /// Whether the CPU has every feature [`draw_band_v3`] is compiled for (detected once, then
    /// read from a cache). Tests can turn the wide path off to compare the two.
    pub fn available() -> bool {
        #[cfg(test)]
        if BASELINE_ONLY.load(std::sync::atomic::Ordering::Relaxed) {
            return false;
        }
        std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma")
            && std::arch::is_x86_feature_detected!("bmi1")
            && std::arch::is_x86_feature_detected!("bmi2")
            && std::arch::is_x86_feature_detected!("lzcnt")
            && std::arch::is_x86_feature_detected!("popcnt")
    }

    #[cfg(test)]
    pub static BASELINE_ONLY: std::sync::atomic::AtomicBool =
        std::sync::atomic::AtomicBool::new(false);

    pub fn draw_band<P: OutputPixel>(job: Band<'_, P>, s: &mut Scratch) {
        assert!(available(), "the CPU lacks x86-64-v3");
        // SAFETY: `draw_band_v3` only needs the CPU to have the features it is compiled for,
        // and the assertion above checked that it has them.
        unsafe { draw_band_v3(job, s) }
    }

    /// # Safety
    /// The CPU must have the features named below ([`available`]).
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
    #[inline(never)]
    unsafe fn draw_band_v3<P: OutputPixel>(job: Band<'_, P>, s: &mut Scratch) {
        draw_band_inlined(job, s)
    }

    pub fn map_gamut(gamut: GamutMapping, colours: &mut [[f64; 3]]) {
        assert!(available(), "the CPU lacks x86-64-v3");
        // SAFETY: as in `draw_band`.
        unsafe { map_gamut_v3(gamut, colours) }
    }

    /// # Safety
    /// The CPU must have the features named below ([`available`]).
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
    #[inline(never)]
    unsafe fn map_gamut_v3(gamut: GamutMapping, colours: &mut [[f64; 3]]) {
        gamut.apply_to_all_inlined(colours)
    }
}

/// [`GamutMapping::apply_to_all`] compiled for x86-64-v3 where the CPU has it (a third less
/// time in the `gamut_map_1m` bench), else for the baseline.
pub(crate) fn map_gamut_dispatched(gamut: GamutMapping, colours: &mut [[f64; 3]]) {
    #[cfg(target_arch = "x86_64")]
    if wide_vectors::available() {
        return wide_vectors::map_gamut(gamut, colours);
    }
    gamut.apply_to_all_inlined(colours)
}

/// One band of the image to draw: columns `columns` of rows `index * BAND ..`, whose pixels
/// are `out` (the others are left as they are).
struct Band<'a, P> {
    /// Whether this is the x86-64-v3 compilation, whose vectors some loops are written for.
    wide: bool,
    index: usize,
    columns: Range<usize>,
    out: &'a mut [P],
    layers: &'a [&'a PreparedLayer],
    opts: &'a RenderOptions,
    background: Option<[f32; 4]>,
    /// Receives, per layer, the farthest an outline pixel's colour was taken from.
    reach: &'a mut [f64],
}

/// Draws every layer into a band. Inlined into the two compilations of
/// [`draw_band_dispatched`], with the hot functions it calls.
#[inline(always)]
fn draw_band<P: OutputPixel>(job: Band<'_, P>, s: &mut Scratch) {
    let Band {
        wide,
        index: band,
        columns: Range { start: x0, end: x1 },
        out,
        layers,
        opts,
        background,
        reach,
    } = job;
    reach.fill(f64::NEG_INFINITY);
    let w = opts.width as usize;
    let y0 = band * BAND;
    let rows = out.len() / (4 * w);
    let dither = opts.dither && P::DITHERED;
    let linear = opts.blend == BlendSpace::Linear;
    // Every pixel is computed alone (its coverage's prefix sum from the layer's left end):
    // drawing some columns gives them the bits drawing all would.
    let whole_rows = x0 == 0 && x1 == w;

    // Rows no layer reaches (a canvas larger than the drawing) are the background: one pixel,
    // encoded once, unless dithering would give each of them its own noise.
    if layers.iter().all(|l| l.line_bins.get(band).is_empty()) {
        let rgba = straight_srgb::<P>(&background.unwrap_or([0.0; 4]), linear);
        if !dither || rgba.iter().all(|&v| v == 0.0 || v == 1.0) {
            let pixel = each4(|ch| P::encode(rgba[ch], 0.0));
            for row in out.chunks_exact_mut(4 * w) {
                for px in row[4 * x0..4 * x1].chunks_exact_mut(4) {
                    px.copy_from_slice(&pixel);
                }
            }
            return;
        }
    }

    let colour = &mut s.colour[..w * rows];
    if whole_rows {
        // One call each (a loop per row was compiled into a slower inline fill).
        colour.fill([0.0; 4]);
        s.opaque[..w * rows].fill(false);
    } else {
        for r in 0..rows {
            colour[r * w + x0..r * w + x1].fill([0.0; 4]);
            s.opaque[r * w + x0..r * w + x1].fill(false);
        }
    }

    // Front to back ("under"): a pixel that is already opaque is not evaluated again, and the
    // band stops once all of its pixels are.
    let mut opaque = 0usize;
    // Whether no layer above has drawn into the band: its pixels are then all clear.
    let mut fresh = true;
    for (li, layer) in layers.iter().enumerate().rev() {
        if opaque == (x1 - x0) * rows {
            break;
        }
        let tris = layer.triangle_bins.get(band);
        let lines = layer.line_bins.get(band);
        if lines.is_empty() {
            continue;
        }
        // Coverage is summed over the layer's columns `c0..c1`, and shown over `d0..d1`.
        let (c0, c1) = layer.columns;
        let (d0, d1) = (c0.max(x0), c1.min(x1));
        if d0 >= d1 {
            continue;
        }
        let shading = Shading {
            space: layer.space,
            converter: gamut::RunConverter::new(layer.space, opts.gamut, opts.blend, wide),
            gamut: opts.gamut,
            blend: opts.blend,
            rarely_outside: layer.space == ColourSpace::Srgb
                && opts.blend == BlendSpace::Srgb
                && layer.colours_in_unit_range,
        };
        let bounds = layer.bounds.as_ref().unwrap_or(&triangles::UNBOUNDED);
        // Outline colours of a layer with quadratic sides are clamped as its triangles are.
        let farthest = std::cell::Cell::new(f64::NEG_INFINITY);
        let nearest = |p: [f64; 2]| {
            let (a, distance) = layer.nearest.attributes_and_distance_at(p)?;
            farthest.set(farthest.get().max(distance));
            Some(match layer.bounds {
                Some(b) => each4(|k| a[k].clamp(b[0][k], b[1][k])),
                None => a,
            })
        };
        for r in 0..rows {
            s.covered[r * w + d0..r * w + d1].fill(false);
        }
        let mut cursor = layer.triangles.cursor();
        for &ti in tris {
            let t = cursor.get(ti as usize);
            if !whole_rows {
                let (a, b) = t.columns(w);
                if b <= d0 || a >= d1 {
                    continue;
                }
            }
            let (r0, r1) = t.rows();
            let (j0, j1) = (r0.max(y0 as i64), r1.min((y0 + rows) as i64));
            t.for_each_span(j0..j1, w as i64, |j, a, b| {
                let (a, b) = ((a as usize).max(d0), (b as usize).min(d1));
                if a >= b {
                    return;
                }
                let row = (j as usize - y0) * w;
                let y = j as f64 + 0.5;
                let span = row + a..row + b;
                t.fill_row(y, a as f64 + 0.5, &mut s.attributes[span.clone()], bounds);
                s.covered[span].fill(true);
            });
        }
        for &li in lines {
            let line = &layer.lines[li as usize];
            // A line changes the cells from the one holding its left end: one right of the
            // columns drawn changes no sum they take.
            if !whole_rows && line.p0[0].min(line.p1[0]) >= d1 as f64 {
                continue;
            }
            s.accumulation.add(y0 as i64, rows, line);
        }
        for r in 0..rows {
            // Left of the layer's columns the accumulation is all zeros, so its prefix sums
            // may start there. Only columns `a..b` are covered at all.
            let (a, b) = s.accumulation.resolve(r, c0, d1, &mut s.coverage);
            // Bounds the loops below can see, so that they index without checks.
            let coverage = &s.coverage[..d1];
            let (a, b) = (a.max(d0), b.min(d1));
            let y = (y0 + r) as f64 + 0.5;
            let band = BandPixels {
                row: r * w,
                opaque: &mut s.opaque,
                covered: &s.covered,
                attributes: &s.attributes,
                run: &mut s.run,
                colour,
            };
            // Separate loops for the first layer, which has nothing to test and nothing to
            // read: the tests are a noticeable share of drawing.
            opaque += if fresh {
                shade_row::<true>(a..b, coverage, y, band, &nearest, &shading)
            } else {
                shade_row::<false>(a..b, coverage, y, band, &nearest, &shading)
            };
        }
        fresh = false;
        reach[li] = farthest.get();
    }
    if let Some(bg) = background {
        for row in colour.chunks_exact_mut(w) {
            for dst in &mut row[x0..x1] {
                let keep = 1.0 - dst[3];
                if keep > 0.0 {
                    for c in 0..4 {
                        dst[c] += bg[c] * keep;
                    }
                }
            }
        }
    }

    // Straight alpha, sRGB-encoded.
    for (r, (row_out, row_colour)) in out
        .chunks_exact_mut(4 * w)
        .zip(colour.chunks_exact(w))
        .enumerate()
    {
        let y = (y0 + r) as u32;
        let (row_out, row_colour) = (&mut row_out[4 * x0..4 * x1], &row_colour[x0..x1]);
        let pixels = row_out.chunks_exact_mut(4).zip(row_colour);
        if dither && !linear {
            encode_row_dithered(row_out, row_colour, x0, y);
        } else if dither {
            for (x, (px, c)) in (x0..).zip(pixels) {
                let rgba = straight_srgb::<P>(c, linear);
                let noise = output::dither_noise(x as u32, y);
                for ch in 0..4 {
                    px[ch] = P::encode(rgba[ch], noise[ch]);
                }
            }
        } else if linear {
            for (px, c) in pixels {
                let rgba = straight_srgb::<P>(c, linear);
                for ch in 0..4 {
                    px[ch] = P::encode_plain(rgba[ch]);
                }
            }
        } else {
            encode_row_plain(row_out, row_colour);
        }
    }
}

/// Pixels per block of a row that [`encode_row_plain`] and [`encode_row_dithered`] encode at
/// once when all of them are opaque.
const BLOCK: usize = 8;

/// Whether the pixels of `block` (premultiplied colour) are all opaque: their straight colour is
/// then the colour itself. `fold` with `&` rather than `all`: without an early exit the test
/// vectorises.
#[inline(always)]
fn all_opaque(block: &[[f32; 4]; BLOCK]) -> bool {
    block.iter().fold(true, |all, c| all & (c[3] >= 1.0))
}

/// Splits a row into blocks of [`BLOCK`] pixels: calls `opaque(start, colour, out)` for each
/// whole block whose pixels are all opaque, and `one(i, colour, out)` for every other pixel
/// (`out`: the pixels' channels).
#[inline(always)]
fn for_each_block<P>(
    out: &mut [P],
    colour: &[[f32; 4]],
    mut opaque: impl FnMut(usize, &[[f32; 4]; BLOCK], &mut [P; 4 * BLOCK]),
    mut one: impl FnMut(usize, &[f32; 4], &mut [P]),
) {
    let mut out_blocks = out.chunks_exact_mut(4 * BLOCK);
    let mut colour_blocks = colour.chunks_exact(BLOCK);
    for (b, (dst, c)) in out_blocks.by_ref().zip(colour_blocks.by_ref()).enumerate() {
        let (dst, c): (&mut [P; 4 * BLOCK], &[[f32; 4]; BLOCK]) = (
            dst.try_into().expect("a whole block"),
            c.try_into().expect("a whole block"),
        );
        if all_opaque(c) {
            opaque(b * BLOCK, c, dst);
        } else {
            for (k, (px, c)) in dst.chunks_exact_mut(4).zip(c).enumerate() {
                one(b * BLOCK + k, c, px);
            }
        }
    }
    let start = colour.len() - colour_blocks.remainder().len();
    let pixels = out_blocks.into_remainder().chunks_exact_mut(4);
    for (k, (px, c)) in pixels.zip(colour_blocks.remainder()).enumerate() {
        one(start + k, c, px);
    }
}

/// Encodes a row of premultiplied sRGB-encoded colour without dither. Blocks of opaque pixels
/// (most of them) take a loop of fixed length without branches, which vectorises; the others
/// go pixel by pixel.
// Always inlined: see `wide_vectors`.
#[inline(always)]
fn encode_row_plain<P: OutputPixel>(out: &mut [P], colour: &[[f32; 4]]) {
    let opaque = |_: usize, c: &[[f32; 4]; BLOCK], dst: &mut [P; 4 * BLOCK]| {
        // Alpha, at least 1, encodes as 1.
        for (o, &v) in dst.iter_mut().zip(c.as_flattened()) {
            *o = P::encode_plain(if P::SATURATES { v } else { v.clamp(0.0, 1.0) });
        }
    };
    let one = |_: usize, c: &[f32; 4], px: &mut [P]| {
        let rgba = straight_srgb::<P>(c, false);
        for ch in 0..4 {
            px[ch] = P::encode_plain(rgba[ch]);
        }
    };
    for_each_block(out, colour, opaque, one);
}

/// [`encode_row_plain`] with dither noise, for the pixels of row `y` from column `x0`. In a
/// block of opaque pixels the hashes come first (64-bit, one at a time), then the noise
/// ([`output::dither_noise_block`]) and the encoding, which vectorise.
// Always inlined: see `wide_vectors`.
#[inline(always)]
fn encode_row_dithered<P: OutputPixel>(out: &mut [P], colour: &[[f32; 4]], x0: usize, y: u32) {
    let opaque = |start: usize, c: &[[f32; 4]; BLOCK], dst: &mut [P; 4 * BLOCK]| {
        let noise = output::dither_noise_block::<BLOCK, { 4 * BLOCK }>((x0 + start) as u32, y);
        // Alpha, at least 1, encodes as 1.
        for ((px, &v), &noise) in dst.iter_mut().zip(c.as_flattened()).zip(&noise) {
            let v = if P::SATURATES { v } else { v.clamp(0.0, 1.0) };
            *px = P::encode_branchless(v, noise);
        }
    };
    let one = |i: usize, c: &[f32; 4], px: &mut [P]| {
        let rgba = straight_srgb::<P>(c, false);
        let noise = output::dither_noise((x0 + i) as u32, y);
        for ch in 0..4 {
            px[ch] = P::encode(rgba[ch], noise[ch]);
        }
    };
    for_each_block(out, colour, opaque, one);
}

/// How one layer's attributes become colours of the blend space.
struct Shading {
    space: ColourSpace,
    converter: gamut::RunConverter,
    gamut: GamutMapping,
    blend: BlendSpace,
    /// Whether colours outside the gamut are rare enough to be mapped one by one, in the
    /// plain pixel loop (an sRGB layer blended in sRGB with colours in range).
    rarely_outside: bool,
}

/// One row of a band's buffers, as a layer shades it.
struct BandPixels<'a> {
    /// The index of the row's first pixel in the band.
    row: usize,
    opaque: &'a mut [bool],
    covered: &'a [bool],
    attributes: &'a [[f32; 4]],
    run: &'a mut Run,
    colour: &'a mut [[f32; 4]],
}

/// Composites a layer under the band's colour in columns `cols` of one row, whose coverage is
/// `coverage` (indexed by column): the attributes its triangles filled in, or else the nearest
/// outline's (the sliver between the tessellation and the outline). `FRESH`: no layer has drawn
/// into the band yet. Returns how many pixels became opaque.
#[inline(always)]
fn shade_row<const FRESH: bool>(
    cols: Range<usize>,
    coverage: &[f32],
    y: f64,
    band: BandPixels<'_>,
    nearest: &impl Fn([f64; 2]) -> Option<[f32; 4]>,
    shading: &Shading,
) -> usize {
    let BandPixels {
        row,
        opaque,
        covered,
        attributes,
        run,
        colour,
    } = band;
    let mut made_opaque = 0;
    // Composites pixel `k`'s colour; 1 if it became opaque. The buffers are arguments, so
    // that the loops below may also write them directly.
    let put = |colour: &mut [[f32; 4]], opaque: &mut [bool], k: usize, rgb: [f32; 3], alpha| {
        if under(&mut colour[k], rgb, alpha, FRESH) {
            opaque[k] = true;
            1
        } else {
            0
        }
    };
    // The pixel's attributes and opacity, unless the layer leaves it alone.
    let shown = |i: usize, opaque: &[bool]| -> Option<([f32; 4], f32)> {
        let (cov, k) = (coverage[i], row + i);
        if cov == 0.0 || (!FRESH && opaque[k]) {
            return None;
        }
        let attr = if covered[k] {
            attributes[k]
        } else {
            nearest([i as f64 + 0.5, y])?
        };
        let alpha = cov * attr[3].clamp(0.0, 1.0);
        (alpha > 0.0).then_some((attr, alpha))
    };
    if shading.space == ColourSpace::Lab {
        // In runs: first the pixels this layer shows (whole blocks under nothing at once),
        // then their colours all at once (vectorised), then compositing.
        let gather = |j: usize, n: &mut usize, run: &mut Run, opaque: &[bool]| {
            if let Some((attr, alpha)) = shown(j, opaque) {
                for c in 0..3 {
                    run.colour[c][*n] = attr[c];
                }
                run.alpha[*n] = alpha;
                run.pixel[*n] = (row + j) as u32;
                run.block[*n] = false;
                *n += 1;
            }
        };
        let mut i = cols.start;
        while i < cols.end {
            let mut n = 0;
            while i < cols.end && n < RUN {
                if i + BLOCK > cols.end || n + BLOCK > RUN {
                    gather(i, &mut n, run, opaque);
                    i += 1;
                    continue;
                }
                let k = row + i;
                // A block that layers above have made opaque shows nothing of this one.
                if !FRESH && all_true(&opaque[k..]) {
                    i += BLOCK;
                    continue;
                }
                // A block under nothing: a fresh layer's, or one no layer above has drawn
                // into (compositing under a clear pixel gives what a fresh layer writes).
                // Whole, it is gathered at once; otherwise pixel by pixel, without testing
                // a block again from each of them.
                let under = (!FRESH).then(|| &colour[k..]);
                match whole_block(&coverage[i..], &covered[k..], &attributes[k..], under) {
                    Some(at) => {
                        for (m, a) in at.iter().enumerate() {
                            for c in 0..3 {
                                run.colour[c][n + m] = a[c];
                            }
                        }
                        run.pixel[n] = k as u32;
                        run.block[n] = true;
                        n += BLOCK;
                    }
                    None => {
                        for j in i..i + BLOCK {
                            gather(j, &mut n, run, opaque);
                        }
                    }
                }
                i += BLOCK;
            }
            shading.converter.convert(&run.colour, n, &mut run.rgb);
            let mut m = 0;
            while m < n {
                let k = run.pixel[m] as usize;
                if run.block[m] {
                    made_opaque += put_opaque_block(colour, opaque, k, &run.rgb[m..]);
                    m += BLOCK;
                } else {
                    made_opaque += put(colour, opaque, k, run.rgb[m], run.alpha[m]);
                    m += 1;
                }
            }
        }
    } else {
        // Pixel by pixel: the other spaces have no vector path, and gathering them into runs
        // costs more than it saves.
        let (gamut, blend) = (shading.gamut, shading.blend);
        if shading.rarely_outside {
            // Colours in range need nothing (SVG's, Cairo's), and the search below cost the
            // `vs_cairo` scene 8 % more time. One pixel:
            let one = |i: usize, opaque: &mut [bool], colour: &mut [[f32; 4]]| -> usize {
                let Some((attr, alpha)) = shown(i, opaque) else {
                    return 0;
                };
                let c = [attr[0], attr[1], attr[2]];
                let rgb = gamut::to_blend_space_f32(shading.space, c, gamut, blend);
                put(colour, opaque, row + i, rgb, alpha)
            };
            let mut i = cols.start;
            // Most blocks of a fresh layer's interior are whole ([`whole_block`]) and in range:
            // each pixel's colour is then its attributes with an alpha of one, copied without
            // branches (vectorised). The `vs_cairo` scene's drawing took a fifth less time.
            // The same holds under pixels no layer above has drawn into.
            while i + BLOCK <= cols.end {
                let k = row + i;
                // Hidden by layers above.
                if !FRESH && all_true(&opaque[k..]) {
                    i += BLOCK;
                    continue;
                }
                let under = (!FRESH).then(|| &colour[k..]);
                let whole = whole_block(&coverage[i..], &covered[k..], &attributes[k..], under)
                    .filter(|at| at.iter().fold(true, |all, a| all & in_unit_f32(a)));
                if let Some(at) = whole {
                    made_opaque += put_opaque_block(colour, opaque, k, at);
                } else {
                    for j in i..i + BLOCK {
                        made_opaque += one(j, opaque, colour);
                    }
                }
                i += BLOCK;
            }
            for j in i..cols.end {
                made_opaque += one(j, opaque, colour);
            }
            return made_opaque;
        }
        // Colours that need the chroma search wait, and take it many at a time. In stretches
        // of as many pixels as the search has lanes, so that the pixel loop need not test for
        // room.
        let mut waiting = gamut::WaitingColours::new();
        let mut start = cols.start;
        while start < cols.end {
            let end = (start + gamut::GAMUT_LANES).min(cols.end);
            for i in start..end {
                if let Some((attr, alpha)) = shown(i, opaque) {
                    let c = [attr[0], attr[1], attr[2]];
                    match gamut::to_blend_space_f32_or_outside(shading.space, c, gamut, blend) {
                        Ok(rgb) => made_opaque += put(colour, opaque, row + i, rgb, alpha),
                        Err(linear) => waiting.add(row + i, linear, alpha),
                    }
                }
            }
            waiting.map_group(gamut, blend, |k, rgb, alpha| {
                made_opaque += put(colour, opaque, k, rgb, alpha)
            });
            start = end;
        }
        waiting.map_rest(gamut, blend, |k, rgb, alpha| {
            made_opaque += put(colour, opaque, k, rgb, alpha)
        });
    }
    made_opaque
}

/// The attributes of the first [`BLOCK`] pixels of a row if all of them are whole: covered by
/// the outline and by triangles, opaque, and with nothing under them (the layer is the band's
/// first, or `under`, the band's colour there, is still clear: compositing under a clear pixel
/// gives what a first layer writes). The per-pixel loops would composite each of them with an
/// alpha of one.
#[inline(always)]
fn whole_block<'a>(
    coverage: &[f32],
    covered: &[bool],
    attributes: &'a [[f32; 4]],
    under: Option<&[[f32; 4]]>,
) -> Option<&'a [[f32; 4]; BLOCK]> {
    // `fold` with `&`: without an early exit the tests vectorise.
    if let Some(under) = under {
        let under: &[[f32; 4]; BLOCK] = under[..BLOCK].try_into().expect("a block");
        if !under.iter().fold(true, |all, c| all & (c[3] == 0.0)) {
            return None;
        }
    }
    let cov: &[f32; BLOCK] = coverage[..BLOCK].try_into().expect("a block");
    let cv: &[bool; BLOCK] = covered[..BLOCK].try_into().expect("a block");
    let at: &[[f32; 4]; BLOCK] = attributes[..BLOCK].try_into().expect("a block");
    let whole = (0..BLOCK).fold(true, |all, j| {
        all & (cov[j] == 1.0) & cv[j] & (at[j][3] >= 1.0)
    });
    whole.then_some(at)
}

/// Writes the first [`BLOCK`] colours of `rgb` (three channels or more) with an alpha of one
/// to the band's pixels from `k`, and marks them opaque: what `under` gives pixels under
/// nothing with an alpha of one, a block at once without branches (vectorised). Returns
/// [`BLOCK`], the pixels made opaque.
#[inline(always)]
fn put_opaque_block<const C: usize>(
    colour: &mut [[f32; 4]],
    opaque: &mut [bool],
    k: usize,
    rgb: &[[f32; C]],
) -> usize {
    for (dst, c) in colour[k..k + BLOCK].iter_mut().zip(&rgb[..BLOCK]) {
        *dst = [c[0], c[1], c[2], 1.0];
    }
    opaque[k..k + BLOCK].fill(true);
    BLOCK
}

/// Whether the first [`BLOCK`] flags of `flags` are all set.
#[inline(always)]
fn all_true(flags: &[bool]) -> bool {
    let block: &[bool; BLOCK] = flags[..BLOCK].try_into().expect("a block");
    block.iter().fold(true, |all, &f| all & f)
}

/// Whether the three colour channels of `a` lie in `0..=1`.
#[inline(always)]
fn in_unit_f32(a: &[f32; 4]) -> bool {
    (0.0..=1.0).contains(&a[0]) & (0.0..=1.0).contains(&a[1]) & (0.0..=1.0).contains(&a[2])
}

/// Composites `rgb` with coverage `alpha` under the premultiplied pixel `dst`, which is clear
/// when `fresh`; whether it is now opaque.
#[inline(always)]
fn under(dst: &mut [f32; 4], rgb: [f32; 3], alpha: f32, fresh: bool) -> bool {
    // a + (1 - a) is 1, but not always in floating point.
    let cover = |a: f32| if alpha >= 1.0 { 1.0 } else { a };
    if fresh {
        // The sum below with a clear pixel, bit for bit, without reading it.
        *dst = [rgb[0] * alpha, rgb[1] * alpha, rgb[2] * alpha, cover(alpha)];
    } else {
        let weight = alpha * (1.0 - dst[3]);
        for c in 0..3 {
            dst[c] += rgb[c] * weight;
        }
        dst[3] = cover(dst[3] + weight);
    }
    dst[3] >= 1.0
}

/// A premultiplied colour of the blend space as straight-alpha, sRGB-encoded channels, ready
/// for `P::encode` (clamped to `0..=1` unless that saturates by itself).
// Always inlined: called once per pixel from two loops, it was left as a call.
#[inline(always)]
fn straight_srgb<P: OutputPixel>(c: &[f32; 4], linear: bool) -> [f32; 4] {
    let a = c[3];
    if a.is_nan() || a <= 0.0 {
        return [0.0; 4];
    }
    // Opaque pixels (most of them) skip the division, which would be exact.
    let opaque = a >= 1.0;
    let mut out = [1.0f32; 4];
    for ch in 0..3 {
        let v = if opaque { c[ch] } else { c[ch] / a };
        out[ch] = if linear {
            gamut::srgb_encode_f32(v.clamp(0.0, 1.0))
        } else if P::SATURATES {
            v
        } else {
            v.clamp(0.0, 1.0)
        };
    }
    if !opaque {
        out[3] = a;
    }
    out
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;
    use std::sync::atomic::Ordering;

    /// Renders `doc` with `opts` into pixels of type `P`, on the baseline compilation or not.
    fn pixels<P: OutputPixel + Default>(
        doc: &Document,
        opts: &RenderOptions,
        baseline: bool,
    ) -> Vec<P> {
        wide_vectors::BASELINE_ONLY.store(baseline, Ordering::Relaxed);
        let mut out = vec![P::default(); 4 * (opts.width * opts.height) as usize];
        let result = render_document_into(doc, opts, &mut out);
        wide_vectors::BASELINE_ONLY.store(false, Ordering::Relaxed);
        result.unwrap();
        out
    }

    /// The x86-64-v3 compilation of the drawing draws the same bits as the baseline one: 8-bit
    /// (dithered or not), 16-bit and float output, sRGB and linear blending, Lab (the run
    /// converter) and other working spaces, several layers, holes and outlines.
    #[test]
    fn wide_vectors_draw_the_same_bits_as_the_baseline() {
        if !wide_vectors::available() {
            eprintln!("this CPU lacks x86-64-v3: nothing to compare");
            return;
        }
        let dir = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../../shared/realdata/gradientmeshimproved-off/"
        );
        let read = |name: &str| {
            crate::formats::read_path(&std::path::PathBuf::from(dir).join(name))
                .unwrap()
                .layers
        };
        let mut layers = read("Tucan_Tucan_Layer5.off");
        layers.extend(read("Tucan_Tucan_Layer2.off"));
        layers.extend(read("Glasses.off"));
        let lab = Document { layers };
        let mut other_spaces = lab.clone();
        other_spaces.layers[1].colour_space = ColourSpace::Oklab;
        other_spaces.layers[2].colour_space = ColourSpace::Srgb;
        for doc in [&lab, &other_spaces] {
            let mut opts = RenderOptions::fit(doc, 200);
            let same_u8 = |opts: &RenderOptions| {
                pixels::<u8>(doc, opts, false) == pixels::<u8>(doc, opts, true)
            };
            assert!(same_u8(&opts), "8-bit, dithered");
            opts.dither = false;
            assert!(same_u8(&opts), "8-bit");
            opts.blend = BlendSpace::Linear;
            assert!(same_u8(&opts), "8-bit, linear blending");
            opts.background = Some([1.0, 1.0, 1.0, 1.0]);
            assert!(same_u8(&opts), "8-bit on a background");
            assert!(pixels::<u16>(doc, &opts, false) == pixels::<u16>(doc, &opts, true));
            let (wide, baseline) = (
                pixels::<f32>(doc, &opts, false),
                pixels::<f32>(doc, &opts, true),
            );
            assert!(wide
                .iter()
                .zip(&baseline)
                .all(|(a, b)| a.to_bits() == b.to_bits()));
        }
    }
}

/// Deterministic pseudo-random numbers for tests: xorshift64 from `seed` (not zero).
#[cfg(test)]
pub(crate) fn test_random(mut seed: u64) -> impl FnMut() -> u64 {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    }
}

#[cfg(test)]
mod encode_tests {
    use super::*;

    /// A row of premultiplied colours: a block of opaque pixels (one above the range), a block
    /// with clear and translucent pixels, and five after the last whole block.
    fn row() -> Vec<[f32; 4]> {
        (0..2 * BLOCK + 5)
            .map(|i| {
                let alpha = match i {
                    9 => 0.5,
                    12 => 0.0,
                    18 => 0.25,
                    _ => 1.0,
                };
                let t = i as f32 / 21.0;
                let rgb = [t, 1.0 - t, if i == 3 { 1.2 } else { 0.5 * t }];
                [rgb[0] * alpha, rgb[1] * alpha, rgb[2] * alpha, alpha]
            })
            .collect()
    }

    fn plain_by_blocks_matches_pixels<P: OutputPixel + Default + PartialEq + std::fmt::Debug>() {
        let colour = row();
        let mut blocks = vec![P::default(); 4 * colour.len()];
        encode_row_plain(&mut blocks, &colour);
        let pixels: Vec<P> = colour
            .iter()
            .flat_map(|c| straight_srgb::<P>(c, false).map(P::encode_plain))
            .collect();
        assert_eq!(blocks, pixels);
    }

    /// Encoding a row by blocks gives the bits of encoding each pixel on its own.
    #[test]
    fn rows_encode_by_blocks_as_pixel_by_pixel() {
        plain_by_blocks_matches_pixels::<u8>();
        plain_by_blocks_matches_pixels::<u16>();
        let colour = row();
        let mut f = vec![0.0f32; 4 * colour.len()];
        encode_row_plain(&mut f, &colour);
        let expected: Vec<f32> = colour
            .iter()
            .flat_map(|c| straight_srgb::<f32>(c, false))
            .collect();
        assert!(f
            .iter()
            .zip(&expected)
            .all(|(a, b)| a.to_bits() == b.to_bits()));

        let y = 7;
        let mut dithered = vec![0u8; 4 * colour.len()];
        encode_row_dithered(&mut dithered, &colour, 0, y);
        let expected: Vec<u8> = colour
            .iter()
            .enumerate()
            .flat_map(|(x, c)| {
                let (rgba, noise) = (
                    straight_srgb::<u8>(c, false),
                    output::dither_noise(x as u32, y),
                );
                each4(|ch| u8::encode(rgba[ch], noise[ch]))
            })
            .collect();
        assert_eq!(dithered, expected);
    }
}
