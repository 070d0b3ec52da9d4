//! How to render: the options, their defaults and the limits they are checked against.

use crate::error::{Error, ErrorKind};
use crate::mesh::Document;

use crate::colour::gamut::{BlendSpace, GamutMapping};
use crate::colour::ColourSpace;
use crate::view::{check_image, View, MAX_PIXELS};

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
    /// [`RenderOptions::max_quads`](super::RenderOptions::max_quads): keep reference images small.
    pub reference: bool,
    /// Use this refinement level (at least 2) instead of choosing one.
    pub level: Option<usize>,
    /// The deepest level ever chosen (default 10).
    pub max_level: usize,
    /// Most quads in any level built (default 2^21: about 1.2 GB at the peak, refinement tables
    /// of every level included); the level stops below it and [`LayerInfo::capped`](super::LayerInfo::capped) says so.
    pub max_quads: usize,
    /// Interpolate in this space instead of each mesh's own (control colours are converted).
    pub colour_space_override: Option<ColourSpace>,
    /// What to do with colours outside the sRGB gamut.
    pub gamut: GamutMapping,
    /// Where layers are composited.
    pub blend: BlendSpace,
    /// Dither 8-bit output of [`render_document_into`](super::render_document_into) (deterministic triangular noise).
    pub dither: bool,
    /// The largest image accepted, in pixels (default [`MAX_PIXELS`]): a larger request is
    /// refused before anything is allocated.
    pub max_pixels: u64,
    /// Let the fast path interpolate colour quadratically over the triangles of faces where
    /// that passes the colour tolerance with fewer cells than linear colour (default `true`).
    /// `false` draws every face with linear colour (more triangles), for comparison.
    pub quadratic: bool,
    /// Draw quickly for an editor while a gesture is open. Through a
    /// [`RenderCache`](super::RenderCache) that prepared the same faces before, the faces an
    /// edit reaches keep the cells of that preparation (after its balancing) and are only
    /// evaluated again on the moved points: nothing is measured or balanced, and every other
    /// face keeps its plan and triangles. Otherwise (no cache, or a changed topology) the
    /// faces are planned with looser tolerances ([`DRAFT_LOOSENING`] times the colour and
    /// outline tolerances, twice the largest quad). The next render without `draft` plans the
    /// drafted faces again at the full tolerances and builds the drafted layers' triangles
    /// again: the picture after the gesture is the one a render from scratch gives.
    /// Only the fast path drafts (the uniform path and [`reference`](Self::reference) ignore it).
    pub draft: bool,
}

/// How many times looser than the options' colour and outline tolerances a
/// [`draft`](RenderOptions::draft) plans the faces it plans (a colour error under one Delta E
/// for the default tolerance).
pub const DRAFT_LOOSENING: f64 = 4.0;

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
            draft: false,
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

    /// Refuses options that cannot be rendered: an empty image, a side above
    /// [`MAX_SIDE`](super::MAX_SIDE), more pixels than [`RenderOptions::max_pixels`], a view
    /// that is empty, not finite, beyond ±[`MAX_VIEW_MAGNITUDE`](super::MAX_VIEW_MAGNITUDE) or
    /// whose pixels are smaller than its coordinates can resolve
    /// ([`MIN_PIXEL_SIZE`](super::MIN_PIXEL_SIZE),
    /// [`MIN_RELATIVE_PIXEL_SIZE`](super::MIN_RELATIVE_PIXEL_SIZE)), and tolerances or a
    /// background that are not finite. (A forced
    /// [`RenderOptions::level`] is checked against [`RenderOptions::max_quads`] for each layer,
    /// from its base mesh, before it is built.)
    ///
    /// Every render function calls it first, before allocating anything; a caller that
    /// allocates its own output buffer for [`render_document_into`](super::render_document_into) calls it before that.
    pub fn check(&self) -> Result<(), Error> {
        let invalid = |what: &str, message: String| -> Error {
            ErrorKind::Invalid {
                what: what.into(),
                message,
            }
            .into()
        };
        check_image(self.width, self.height, &self.view, self.max_pixels)?;
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
}
