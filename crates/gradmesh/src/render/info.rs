//! What a render drew: per layer and in all, with the time each stage took.

use std::time::Duration;

use crate::error::Warning;

/// What was drawn for one layer.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LayerInfo {
    /// The refinement level drawn (0 for a layer without faces); on the fast path, the level
    /// whose density the finest face has (faces each have their own).
    pub level: usize,
    /// Whether [`RenderOptions::max_level`](super::RenderOptions::max_level) or [`RenderOptions::max_quads`](super::RenderOptions::max_quads) stopped the
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
    /// Whether the layer was taken from a [`RenderCache`](super::RenderCache) rather than prepared.
    pub reused: bool,
    /// Faces whose plans (grid density and samples) were taken from a [`RenderCache`](super::RenderCache) when
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
    /// How many bands of rows were drawn: all of them, unless a [`RenderCache`](super::RenderCache) held the last
    /// image and some bands draw exactly as before (they are copied from it).
    pub drawn_bands: usize,
    /// How many pixels were drawn: all of them, unless a [`RenderCache`](super::RenderCache) held the last image
    /// (the others are copied from it). Within a band drawn again, only the columns where some
    /// layer may draw differently are drawn.
    pub drawn_pixels: u64,
}
