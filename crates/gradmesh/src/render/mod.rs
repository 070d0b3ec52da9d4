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
//!      refinement would make (see `tessellate/adaptive.rs`, `plan/face_plans.rs` and
//!      `tessellate/stitch.rs`).
//!      A face whose cells fail with linear colour is also measured with *quadratic* colour
//!      (six-node triangles, see `plan/quadratic.rs`; [`RenderOptions::quadratic`]) against the
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
//! use gradmesh::render::{render_document, PngDepth, RenderOptions, View};
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
//! let opts = RenderOptions::fit(&doc, 64);
//! let image = render_document(&doc, &opts)?;
//! assert_eq!(image.width, 64);
//! let png = gradmesh::render::encode_png(&image, PngDepth::Eight { dither: true })?;
//! assert_eq!(&png[1..4], b"PNG");
//! # Ok::<(), gradmesh::Error>(())
//! ```

mod arrays;
mod cache;
mod composite;
mod info;
mod options;
mod output;
mod plan;
mod raster;
mod sources;
mod tessellate;

use std::sync::Arc;
use std::time::Instant;

use rayon::prelude::*;

use crate::colour::{srgb_decode, ColourSpace};
use crate::error::{Error, ErrorKind};
use crate::formats::svg::{scene_to_document, FillRule, MeshFill, SvgScene};
use crate::mesh::{Document, GradientMesh};

pub use crate::colour::gamut::{BlendSpace, GamutMapping};
pub use crate::folds::{find_folds, find_folds_at, Fold, FOLD_LEVEL};
pub use crate::view::{
    document_bounds, View, MAX_PIXELS, MAX_SIDE, MAX_VIEW_MAGNITUDE, MIN_PIXEL_SIZE,
    MIN_RELATIVE_PIXEL_SIZE,
};
pub use cache::RenderCache;
pub use composite::over::CanvasPixel;
pub use info::{LayerInfo, LayerTimings, RenderInfo, RenderTimings};
pub use options::{RenderOptions, DRAFT_LOOSENING};
pub use output::overlay::draw_outlines;
pub use output::pixels::{
    encode_png, encode_png_rgba16, encode_png_rgba8, write_png, write_png_rgba16, write_png_rgba8,
    write_png_rgba8_with, Image, OutputPixel, PngCompression, PngDepth,
};

use crate::limit_surface::patches::ShapeCache;
use crate::view::ToPixels;
use cache::{LastImage, MAX_CACHED_SHAPES};
use composite::band::{draw_band, Band, Scratch};
use composite::over;
#[cfg(target_arch = "x86_64")]
use composite::wide_vectors;
use sources::{classic, patches};
use tessellate::layer::{self, Columns, DrawableLayer, BAND};

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
    let doc = Document::new(vec![mesh.clone()]);
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
    check_output_buffer(opts, out.len())?;
    let (w, h) = (opts.width as usize, opts.height as usize);
    let xf = ToPixels::new(&opts.view, opts.width, opts.height);
    let start = Instant::now();
    if let Some(cache) = cache.as_deref_mut() {
        ready_cache(cache, doc, opts);
    }
    let fresh = prepare_layers(doc, opts, &xf, cache.as_deref_mut())?;
    let reused: Vec<bool> = fresh.iter().map(Option::is_none).collect();
    let kept: Vec<layer::LayerPreparation>;
    let bands = h.div_ceil(BAND);
    // Entries per band of `LastImage::reach`.
    let nl = doc.layers.len().max(1);
    // The columns of each band to draw, and the last image drawn through the cache (taken out
    // while drawing: a drawing cut short leaves none), whose other pixels are as they would be
    // drawn.
    let mut dirty = vec![Columns::all(w); bands];
    let mut last: Option<LastImage> = None;
    let mut last_slot: Option<&mut Option<LastImage>> = None;
    let prepared: Vec<&layer::LayerPreparation> = match cache {
        Some(cache) => {
            let through = draw_through_cache(cache, doc, opts, fresh, out, &mut dirty);
            last = through.last;
            last_slot = Some(through.slot);
            through.prepared
        }
        None => {
            kept = fresh
                .into_iter()
                .map(|p| p.expect("prepared: there is no cache"))
                .collect();
            kept.iter().collect()
        }
    };
    let (mut info, layers, layer_of) = describe_layers(prepared, reused);
    info.timings.prepare = start.elapsed();

    let start = Instant::now();
    let drawer = BandDrawer {
        width: w,
        layers: &layers,
        layer_of: &layer_of,
        opts,
        background: premultiplied_background(opts),
    };
    drawer.draw_bands(out, last.as_mut(), &dirty, nl);
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

/// What one layer of a picture is drawn from.
#[derive(Clone, Copy, Debug)]
pub enum LayerSource<'a> {
    /// A layer of the scheme: its limit surface.
    Scheme(&'a GradientMesh),
    /// An SVG mesh gradient painted as the SVG 2 draft and Inkscape define it: Coons patches
    /// with colour bilinear in each patch's parameters in sRGB (smoothed across patches for
    /// `type="bicubic"`).
    Classic(&'a MeshFill),
    /// A PDF patch-mesh shading (types 6 and 7) painted as the PDF specification defines it:
    /// tensor-product patches with colour bilinear in each patch's parameters in the shading's
    /// colour space.
    Patches(&'a crate::formats::pdf::ShadingFill),
}

/// One layer of a picture: what it is drawn from, and the outline that clips it.
#[derive(Clone, Copy, Debug)]
pub struct PictureLayer<'a> {
    /// What the layer is drawn from.
    pub source: LayerSource<'a>,
    /// The outline (in the plane) outside which the layer is not drawn, with the rule that
    /// tells its inside; anti-aliased with exact area coverage, as the layer's own outline is.
    pub clip: Option<(&'a kurbo::BezPath, FillRule)>,
}

/// How the mesh gradients of an SVG file are drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SvgMeshRendering {
    /// As the SVG 2 draft and Inkscape paint them (see [`LayerSource::Classic`]).
    #[default]
    Classic,
    /// Converted into layers of the scheme ([`scene_to_document`]), drawn as their limit
    /// surfaces.
    Scheme,
}

/// The layers of an SVG picture: each of `fills`, clipped to its shape, drawn classically or
/// from its layer of the scheme (`layers[i]` converted from `fills[i]`, as
/// [`scene_to_document`] makes them).
pub fn svg_picture_layers<'a>(
    fills: &'a [MeshFill],
    layers: &'a [GradientMesh],
    mode: SvgMeshRendering,
) -> Vec<PictureLayer<'a>> {
    fills
        .iter()
        .zip(layers)
        .map(|(fill, mesh)| PictureLayer {
            source: match mode {
                SvgMeshRendering::Classic => LayerSource::Classic(fill),
                SvgMeshRendering::Scheme => LayerSource::Scheme(mesh),
            },
            clip: Some((&fill.clip, fill.fill_rule)),
        })
        .collect()
}

/// The layers of a PDF picture: each of `fills` clipped to its clipping path, painted as the
/// PDF specification defines it, or drawn from its layer of the scheme (`layers[i]` converted
/// from `fills[i]`, as [`picture_to_document`](crate::formats::pdf::picture_to_document)
/// makes them) with [`SvgMeshRendering::Scheme`].
pub fn pdf_picture_layers<'a>(
    fills: &'a [crate::formats::pdf::ShadingFill],
    layers: &'a [GradientMesh],
    mode: SvgMeshRendering,
) -> Vec<PictureLayer<'a>> {
    fills
        .iter()
        .zip(layers)
        .map(|(fill, mesh)| PictureLayer {
            source: match mode {
                SvgMeshRendering::Classic => LayerSource::Patches(fill),
                SvgMeshRendering::Scheme => LayerSource::Scheme(mesh),
            },
            clip: fill.clip.as_ref().map(|(path, rule)| (path, *rule)),
        })
        .collect()
}

/// Renders the mesh-gradient fills of `scene` into a new `f32` image, each clipped to its
/// shape, drawn as `mode` says (the scheme's layers with colours in Lab).
pub fn render_svg_scene(
    scene: &SvgScene,
    mode: SvgMeshRendering,
    opts: &RenderOptions,
) -> Result<(Image, RenderInfo), Error> {
    opts.check()?;
    let (doc, _) = scene_to_document(scene, ColourSpace::Lab);
    let layers = svg_picture_layers(&scene.fills, &doc.layers, mode);
    let mut image = Image::new(opts.width, opts.height);
    let info = render_picture_into(&layers, opts, &mut image.data)?;
    Ok((image, info))
}

/// The cells an SVG mesh fill drawn classically ([`LayerSource::Classic`]) is tessellated into
/// at `opts`, before it is: a measure of the memory its drawing takes (a few hundred bytes a
/// cell with its triangles and bins), for callers that check memory ahead.
pub fn classic_cells(fill: &MeshFill, opts: &RenderOptions) -> usize {
    let xf = ToPixels::new(&opts.view, opts.width, opts.height);
    classic::cells(fill, opts, &xf)
}

/// Prepares the layers of a picture for drawing, in parallel: each from its source, with its
/// clip; the first failing layer's error, whatever the thread count.
fn prepare_picture(
    layers: &[PictureLayer<'_>],
    opts: &RenderOptions,
) -> Result<Vec<layer::LayerPreparation>, Error> {
    let xf = ToPixels::new(&opts.view, opts.width, opts.height);
    let shapes = ShapeCache::default();
    layers
        .par_iter()
        .enumerate()
        .map(|(i, picture)| {
            let (info, drawable, warnings) = match picture.source {
                LayerSource::Scheme(mesh) => layer::prepare(mesh, i, opts, &xf, &shapes, None)?,
                LayerSource::Classic(fill) => {
                    classic::prepare(fill, opts, &xf).map_err(|e| e.in_layer(i))?
                }
                LayerSource::Patches(fill) => {
                    patches::prepare(fill, opts, &xf).map_err(|e| e.in_layer(i))?
                }
            };
            let drawable = drawable.map(|mut d| {
                d.clip = picture
                    .clip
                    .map(|(path, rule)| layer::Clip::new(path, rule, &xf, opts));
                d
            });
            Ok((info, drawable, warnings))
        })
        .collect::<Vec<Result<_, Error>>>()
        .into_iter()
        .collect()
}

/// Renders the layers of a picture (bottom first) into a caller's buffer, as
/// [`render_document_into`] does: the same rasteriser and compositor for every source, each
/// layer clipped to its outline when it has one.
pub fn render_picture_into<P: OutputPixel>(
    layers: &[PictureLayer<'_>],
    opts: &RenderOptions,
    out: &mut [P],
) -> Result<RenderInfo, Error> {
    opts.check()?;
    check_output_buffer(opts, out.len())?;
    let (w, h) = (opts.width as usize, opts.height as usize);
    let start = Instant::now();
    let prepared = prepare_picture(layers, opts)?;
    let (mut info, drawn, layer_of) =
        describe_layers(prepared.iter().collect(), vec![false; layers.len()]);
    info.timings.prepare = start.elapsed();
    let start = Instant::now();
    let drawer = BandDrawer {
        width: w,
        layers: &drawn,
        layer_of: &layer_of,
        opts,
        background: premultiplied_background(opts),
    };
    let dirty = vec![Columns::all(w); h.div_ceil(BAND)];
    drawer.draw_bands(out, None, &dirty, layers.len().max(1));
    info.drawn_bands = dirty.len();
    info.drawn_pixels = (w * h) as u64;
    info.timings.draw = start.elapsed();
    Ok(info)
}

/// Composites the layers of a picture (bottom first) source-over onto `canvas`, an image of
/// `opts`'s size in premultiplied RGBA (8-bit: tiny-skia's and resvg's pixmap layout, or
/// 16-bit), on sRGB-encoded values as resvg blends; `opts.background` is not drawn (the canvas
/// is the background). Each band of rows is drawn into a band-sized buffer and composited onto
/// the canvas, so the picture costs no image-sized buffer beyond the canvas; an 8-bit canvas
/// is dithered where the layers draw, when `opts.dither` is set.
pub fn render_picture_over<P: CanvasPixel>(
    layers: &[PictureLayer<'_>],
    opts: &RenderOptions,
    canvas: &mut [P],
) -> Result<RenderInfo, Error> {
    opts.check()?;
    check_output_buffer(opts, canvas.len())?;
    let w = opts.width as usize;
    let start = Instant::now();
    let prepared = prepare_picture(layers, opts)?;
    let (mut info, drawn, layer_of) =
        describe_layers(prepared.iter().collect(), vec![false; layers.len()]);
    info.timings.prepare = start.elapsed();
    let start = Instant::now();
    let drawer = BandDrawer {
        width: w,
        layers: &drawn,
        layer_of: &layer_of,
        opts,
        background: None,
    };
    canvas
        .par_chunks_mut(4 * w * BAND)
        .enumerate()
        .for_each(|(band, chunk)| {
            let mut drawn_band = vec![0.0f32; chunk.len()];
            let mut reach = vec![0.0; layers.len().max(1)];
            drawer.draw(band, Columns::all(w), &mut drawn_band, &mut reach);
            over::composite_band_over(chunk, &drawn_band, (w, band * BAND), opts.dither);
        });
    info.drawn_bands = opts.height.div_ceil(BAND as u32) as usize;
    info.drawn_pixels = u64::from(opts.width) * u64::from(opts.height);
    info.timings.draw = start.elapsed();
    Ok(info)
}

/// Refuses an output buffer that does not hold the image `opts` describe.
fn check_output_buffer(opts: &RenderOptions, len: usize) -> Result<(), Error> {
    let (w, h) = (opts.width as usize, opts.height as usize);
    if len != 4 * w * h {
        return Err(ErrorKind::Invalid {
            what: "output buffer".into(),
            message: format!(
                "holds {len} channels, a {w}x{h} RGBA image needs {}",
                4 * w * h
            ),
        }
        .into());
    }
    Ok(())
}

/// Readies `cache` for a render of `doc` with `opts`: entries prepared with other options go,
/// and so does the last image if the layers or drawing options changed.
fn ready_cache(cache: &mut RenderCache, doc: &Document, opts: &RenderOptions) {
    let key = RenderCache::key(opts);
    if cache.key.as_ref() != Some(&key) {
        cache.key = Some(key);
        cache.layers.clear();
        cache.plans.clear();
    }
    // A document with other layers, or other drawing options, draws every band again.
    if cache.layers.len() != doc.layers.len()
        || (cache.drawn.as_ref()).is_some_and(|d| d.opts != RenderCache::drawing_key(opts))
    {
        cache.drawn = None;
    }
    cache.layers.resize_with(doc.layers.len(), || None);
    cache.plans.resize_with(doc.layers.len(), Default::default);
    if cache.shapes.len() > MAX_CACHED_SHAPES {
        cache.shapes = Arc::default();
    }
}

/// Prepares the layers of `doc` in parallel; `None` for a layer `cache` holds unchanged.
fn prepare_layers(
    doc: &Document,
    opts: &RenderOptions,
    xf: &ToPixels,
    cache: Option<&mut RenderCache>,
) -> Result<Vec<Option<layer::LayerPreparation>>, Error> {
    let shapes: Arc<ShapeCache> = cache
        .as_deref()
        .map(|c| Arc::clone(&c.shapes))
        .unwrap_or_default();
    let (cached, mut memos) = match cache {
        Some(c) => (
            Some(c.layers.as_slice()),
            c.plans.iter_mut().map(Some).collect(),
        ),
        None => (
            None,
            (0..doc.layers.len()).map(|_| None).collect::<Vec<_>>(),
        ),
    };
    doc.layers
        .par_iter()
        .zip(memos.par_iter_mut())
        .enumerate()
        .map(|(i, (mesh, memo))| {
            let entry = cached.and_then(|c| c[i].as_ref());
            // A layer drafted by an earlier render is planned again unless this is a draft.
            let drafted = !opts.draft && memo.as_deref().is_some_and(|m| m.has_drafts());
            if entry.is_some_and(|(old, _)| old == mesh) && !drafted {
                return Ok(None);
            }
            // Plans are kept from a layer's first preparation on (shared, not copied), so
            // that its first edit plans again only the faces the edit reaches.
            layer::prepare(mesh, i, opts, xf, &shapes, memo.as_deref_mut()).map(Some)
        })
        .collect::<Vec<_>>()
        // The first failing layer's error, whatever the thread count.
        .into_iter()
        .collect()
}

/// What a render through a cache draws with: the last image drawn (or a fresh one), the
/// cache's slot to put it back into, and every layer prepared.
struct ThroughCache<'c> {
    last: Option<LastImage>,
    slot: &'c mut Option<LastImage>,
    prepared: Vec<&'c layer::LayerPreparation>,
}

/// Puts the `fresh` layers into `cache` and marks in `dirty` the columns of each band that
/// they draw differently from the last image (every column if there is none to compare with).
fn draw_through_cache<'c, P: OutputPixel>(
    cache: &'c mut RenderCache,
    doc: &Document,
    opts: &RenderOptions,
    fresh: Vec<Option<layer::LayerPreparation>>,
    out: &[P],
    dirty: &mut [Columns],
) -> ThroughCache<'c> {
    let (w, bands) = (opts.width as usize, dirty.len());
    let nl = doc.layers.len().max(1);
    let mut last = cache.drawn.take();
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
                    new.mark_changed_columns(old, &reach, w, dirty)
                }
                Some((None, None)) => {}
                _ => dirty.fill(Columns::all(w)),
            }
            cache.layers[i] = Some((doc.layers[i].clone(), p));
        }
    }
    // LastImage in another pixel type or size (or never): every band is drawn.
    let same_kind = last
        .as_ref()
        .and_then(|d| d.pixels.downcast_ref::<Vec<P>>())
        .is_some_and(|p| p.len() == out.len());
    if !same_kind {
        dirty.fill(Columns::all(w));
        last = Some(LastImage {
            opts: RenderCache::drawing_key(opts),
            pixels: Box::new(out.to_vec()),
            reach: vec![f64::NEG_INFINITY; bands * nl],
        });
    }
    let RenderCache { layers, drawn, .. } = cache;
    ThroughCache {
        last,
        slot: drawn,
        // Every entry was just filled or matched.
        prepared: layers
            .iter()
            .map(|entry| &entry.as_ref().expect("filled or matched above").1)
            .collect(),
    }
}

/// The render's description of each layer, the layers with something to draw, and the
/// document's index of each of those.
fn describe_layers(
    prepared: Vec<&layer::LayerPreparation>,
    reused: Vec<bool>,
) -> (RenderInfo, Vec<&DrawableLayer>, Vec<usize>) {
    let mut info = RenderInfo::default();
    let mut layers: Vec<&DrawableLayer> = Vec::new();
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
    (info, layers, layer_of)
}

/// The background of `opts`, clamped and premultiplied in the blend space.
fn premultiplied_background(opts: &RenderOptions) -> Option<[f32; 4]> {
    opts.background.map(|bg| {
        let a = bg[3].clamp(0.0, 1.0);
        let rgb = [bg[0], bg[1], bg[2]].map(|c| c.clamp(0.0, 1.0));
        let rgb = match opts.blend {
            BlendSpace::Srgb => rgb,
            BlendSpace::Linear => rgb.map(srgb_decode),
        };
        [rgb[0] * a, rgb[1] * a, rgb[2] * a, a].map(|v| v as f32)
    })
}

/// Draws the bands of an image.
struct BandDrawer<'a> {
    width: usize,
    /// The layers with something to draw, bottom first.
    layers: &'a [&'a DrawableLayer],
    /// The document's index of each of `layers`.
    layer_of: &'a [usize],
    opts: &'a RenderOptions,
    background: Option<[f32; 4]>,
}

impl BandDrawer<'_> {
    /// Draws columns `cols` of a band, and puts in `reach` (per layer of the document) what
    /// [`Band::reach`] gets: for part of the band, the farther of that and what it held (the
    /// other columns' outline pixels keep theirs).
    fn draw<P: OutputPixel>(&self, band: usize, cols: Columns, chunk: &mut [P], reach: &mut [f64]) {
        let w = self.width;
        let mut drawn_reach = vec![f64::NEG_INFINITY; self.layers.len()];
        Scratch::with(w, |scratch| {
            let job = Band {
                wide: false,
                index: band,
                columns: cols.start..cols.end,
                out: chunk,
                layers: self.layers,
                opts: self.opts,
                background: self.background,
                reach: &mut drawn_reach,
            };
            draw_band_dispatched(job, scratch)
        });
        if cols == Columns::all(w) {
            reach.fill(f64::NEG_INFINITY);
        }
        for (&i, r) in self.layer_of.iter().zip(drawn_reach) {
            reach[i] = reach[i].max(r);
        }
    }

    /// Draws the `dirty` columns of every band of `out` in parallel. With a `last` image of
    /// the same pixel type, the other columns are copied from it, and what is drawn again is
    /// kept in it for the next render.
    fn draw_bands<P: OutputPixel>(
        &self,
        out: &mut [P],
        last: Option<&mut LastImage>,
        dirty: &[Columns],
        nl: usize,
    ) {
        let w = self.width;
        let chunks = out.par_chunks_mut(4 * w * BAND).enumerate();
        let kept = last.and_then(|LastImage { pixels, reach, .. }| {
            Some((pixels.downcast_mut::<Vec<P>>()?, reach))
        });
        match kept {
            // Pixels drawn again are kept for the next render; the others are taken from the last.
            Some((pixels, reach)) => chunks
                .zip(pixels.par_chunks_mut(4 * w * BAND))
                .zip(reach.par_chunks_mut(nl))
                .for_each(|(((band, chunk), last), reach)| {
                    let cols = dirty[band];
                    if cols == Columns::all(w) {
                        self.draw(band, cols, chunk, reach);
                        last.copy_from_slice(chunk);
                        return;
                    }
                    chunk.copy_from_slice(last);
                    if !cols.is_empty() {
                        self.draw(band, cols, chunk, reach);
                        let window = 4 * cols.start..4 * cols.end;
                        for (last, row) in
                            last.chunks_exact_mut(4 * w).zip(chunk.chunks_exact(4 * w))
                        {
                            last[window.clone()].copy_from_slice(&row[window.clone()]);
                        }
                    }
                }),
            None => chunks.for_each(|(band, chunk)| {
                self.draw(band, Columns::all(w), chunk, &mut vec![0.0; nl])
            }),
        }
    }
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

// The method that dispatches to the x86-64-v3 compilation lives beside the renderer's other
// dispatch (`wide_vectors`), the crate's one place with `unsafe` code.
impl GamutMapping {
    /// [`GamutMapping::apply`] to every colour of `colours`, in place: the same bits as one
    /// by one, in less time where many colours lie outside the gamut (the chroma search then
    /// runs on sixteen colours at once).
    ///
    /// ```
    /// use gradmesh::render::GamutMapping;
    /// let mut colours = [[1.2, 0.5, -0.1], [0.2, 0.4, 0.6]];
    /// let one_by_one = colours.map(|c| GamutMapping::Chroma.apply(c));
    /// GamutMapping::Chroma.apply_to_all(&mut colours);
    /// assert_eq!(colours, one_by_one);
    /// ```
    pub fn apply_to_all(self, colours: &mut [[f64; 3]]) {
        // Compiled for x86-64-v3 where the CPU has it (a third less time in the
        // `gamut_map_1m` bench), else for the baseline.
        #[cfg(target_arch = "x86_64")]
        if wide_vectors::available() {
            return wide_vectors::map_gamut(self, colours);
        }
        self.apply_to_all_inlined(colours)
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;
    use crate::colour::ColourSpace;
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
        let lab = Document::new(layers);
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
