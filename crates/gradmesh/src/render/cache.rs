//! The state kept between renders of a document being edited: prepared layers, the plans of
//! their faces, local refinements by shape, and the last image drawn.

use std::sync::Arc;

use crate::mesh::GradientMesh;

use super::options::RenderOptions;
use super::tessellate::adaptive;
use super::tessellate::layer;
use crate::colour::gamut::{BlendSpace, GamutMapping};
use crate::limit_surface::patches::ShapeCache;

/// Layers prepared for drawing (refined, tessellated and binned), kept between renders of a
/// document being edited: [`render_document_into_cached`](super::render_document_into_cached) prepares again only the layers whose
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
/// the faces within reach of what moved ([`LayerInfo::reused_faces`](super::LayerInfo::reused_faces)), and builds again only
/// the blocks of triangles next to them.
///
/// It keeps the last image drawn, too: only the pixels where some layer's triangles, outline
/// or outline colours changed are drawn, and the others are copied from it. Within a band of
/// rows ([`RenderInfo::drawn_bands`](super::RenderInfo::drawn_bands)) that is a range of columns ([`RenderInfo::drawn_pixels`](super::RenderInfo::drawn_pixels)):
/// those of the triangles that differ, those within reach of a changed boundary segment, and
/// those from the leftmost to the rightmost changed outline line (coverage is a prefix sum
/// along the row, exact in fixed point: past a change of a closed outline it is the same sum).
/// Each pixel is computed alone, so the image is the one drawing every pixel would give. The output buffer may be a fresh one each time; the copy costs one image of
/// memory.
#[derive(Default)]
pub struct RenderCache {
    /// Local refinements by shape of neighbourhood, for all layers (cleared when they pile
    /// up past [`MAX_CACHED_SHAPES`]).
    pub(super) shapes: Arc<ShapeCache>,
    /// The options the entries were prepared with, with the drawing-only fields reset.
    pub(super) key: Option<RenderOptions>,
    /// Per layer, by position: the mesh prepared and what preparing it gave.
    pub(super) layers: Vec<Option<(GradientMesh, layer::LayerPreparation)>>,
    /// Per layer, by position: the plans of its regular faces at its last preparation, once
    /// it has been prepared again (edited), which a layer prepared again after an edit takes
    /// for the faces the edit left alone.
    pub(super) plans: Vec<adaptive::TessellationCache>,
    /// The last image drawn through the cache: bands that no layer draws differently are
    /// copied from it rather than drawn again.
    pub(super) drawn: Option<LastImage>,
}

/// An image [`render_document_into_cached`](super::render_document_into_cached) drew, and the options it drew it with.
pub(super) struct LastImage {
    pub(super) opts: RenderOptions,
    /// A `Vec<P>` of the [`OutputPixel`](super::OutputPixel) type it was drawn in.
    pub(super) pixels: Box<dyn std::any::Any + Send + Sync>,
    /// Per band, then per layer: the farthest an outline pixel's colour was taken from (the
    /// nearest boundary point, see [`nearest`](super::tessellate::nearest)); negative infinity where none was.
    pub(super) reach: Vec<f64>,
}

/// The most shapes of local refinement a [`RenderCache`] keeps: a few hundred kilobytes each
/// at most, and a layer has a few dozen.
pub(super) const MAX_CACHED_SHAPES: usize = 1024;

impl RenderCache {
    /// An empty cache.
    pub fn new() -> Self {
        RenderCache::default()
    }

    /// The fields of `opts` that preparing a layer reads.
    pub(super) fn key(opts: &RenderOptions) -> RenderOptions {
        RenderOptions {
            background: None,
            dither: false,
            gamut: GamutMapping::default(),
            blend: BlendSpace::default(),
            max_pixels: 0,
            draft: false,
            ..opts.clone()
        }
    }

    /// `opts` as the last image drawn is compared with: a draft draws with the same options.
    pub(super) fn drawing_key(opts: &RenderOptions) -> RenderOptions {
        RenderOptions {
            draft: false,
            ..opts.clone()
        }
    }
}
