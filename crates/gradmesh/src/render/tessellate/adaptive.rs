//! The fast path's tessellation: each face of a low all-quad level gets its own grid density.
//!
//! 1. **Density** ([`face_plans`](crate::render::plan::face_plans)). Each face of the base level ([`BASE_LEVEL`],
//!    shallower for meshes dense for the image: see [`base_level`]) is evaluated on grids of
//!    `1, 2, 4, ..` cells a side ([`patches`](crate::limit_surface::patches): a B-spline patch where the face
//!    is regular, local refinement elsewhere) until its cells pass the same measure as the
//!    uniform path's quads (colour at cell and side centres against the triangles, cell size,
//!    outline). A face whose control points all lie off the image stays at one cell.
//! 2. **Stitching** ([`super::stitch`]). A face is re-evaluated at half the count of its
//!    finest neighbour if it is coarser (2:1 balance), or at the full count where the surface
//!    folds (a face whose cells turn both ways, or which borders one turned the other way or
//!    folded: which sheet shows depends on where the fold runs, and no measure checks that).
//!    Each edge then takes the larger count of its two faces. Both sides read its samples from
//!    a face of that count (the first), and the samples at a vertex from the vertex's first
//!    face, so both sides share bit-identical vertices. A face coarser than an edge fans the
//!    boundary cells along it out to the edge's extra samples (from a cell corner off the
//!    edge, or from the face's centre when it is a single cell), so no T-junction is left: the
//!    snapped, top-left-rule rasteriser sees the same edges from both sides, without cracks.
//!    Each face thus keeps its own density instead of taking the count of its finest edge,
//!    which would spread a fine spot's cells over its neighbours.
//! 3. **Triangles** ([`super::stitch`]). Two per cell (fans along finer edges), faces in
//!    order, cells in the order (and with the diagonals) of the quads uniform refinement would
//!    make of the face, so folds overlap the same way.

use std::sync::Arc;

use rayon::prelude::*;

use crate::colour::ColourSpace;

use crate::refine::{RefinedData, Refinement};
use crate::topology::Topology;
use crate::validate::VertexData;

use super::nearest::Segment;
use super::stitch::{colour_bounds, Stitching};
use crate::limit_surface::patches::ShapeCache;
use crate::render::plan::face_plans::{CachedPlan, EarlierPlans, FacePlanner, FacePlans};
use crate::render::plan::measure::{Measure, Thresholds};
use crate::render::raster::triangles::{Bounds, Triangle, TriangleList};
use crate::view::ToPixels;

/// The level whose faces get their own density: all quads, extraordinary vertices isolated,
/// and faces small enough that irregular ones (refined locally) cover little of the layer.
pub(crate) const BASE_LEVEL: usize = 3;
/// The deepest base level tried when semi-sharp features still touch the outline.
const DEEPEST_BASE_LEVEL: usize = 4;
/// Dense meshes start shallower when level [`BASE_LEVEL`] would have fewer pixels than this
/// per face: building every face's patch then costs more than the pixels, and each face's own
/// grid refines it where the picture needs it anyway. With quadratic colour and the floor on
/// counted cell sizes, dense layers such as Glasses.off at 1024 px then start at level 2 and
/// take fewer triangles, though their folds take more cells (each coarse face refines to its
/// worst spot).
const MIN_BASE_FACE_PIXELS: usize = 64;

/// The base level for a layer that can cover `pixels` pixels ([`covered_pixels`]):
/// [`BASE_LEVEL`], or 2 when its faces would be too many for them, or 1 (when the ternary step
/// made only quads) when even level 2's would. A layer drawn small in a large picture (one
/// part of the artwork) starts as shallow as it would alone at its size.
fn base_level(refinement: &Refinement, pixels: usize) -> usize {
    // Each n-gon of level 1 makes n quads of level 2 (which need not be built to count them),
    // and level 3 has four times as many.
    let faces2 = refinement.topology(1).corner_count();
    let too_many = |faces: usize| faces.saturating_mul(MIN_BASE_FACE_PIXELS) > pixels;
    if too_many(faces2) && refinement.topology(1).is_all_quads() {
        1
    } else if too_many(4 * faces2) {
        2
    } else {
        BASE_LEVEL
    }
}

/// The pixels of a `size` image inside the box around `points` (whose convex hull holds the
/// layer's limit surface): what a layer can cover.
fn covered_pixels(points: &[VertexData], xf: &ToPixels, size: (i64, i64)) -> usize {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for d in points {
        let p = xf.apply(d.position[0], d.position[1]);
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let side = |k: usize, n: i64| (hi[k].min(n as f64) - lo[k].max(0.0)).max(0.0);
    (side(0, size.0) * side(1, size.1)) as usize
}

/// What the fast path produced for one layer.
pub(crate) struct Tessellation {
    /// The base level: the outline is taken from it.
    pub base_level: usize,
    /// The uniform level with the density of the finest face.
    pub level: usize,
    /// Cells drawn.
    pub quads: usize,
    /// Whether some face reached [`RenderOptions::max_level`](crate::render::RenderOptions::max_level) before passing.
    pub capped: bool,
    /// The worst figures over the faces.
    pub measured: Measure,
    /// Whether some face's figures are predicted from the coarser grid.
    pub estimated: bool,
    /// Triangles, in face order.
    pub triangles: TriangleList,
    /// The boundary of the tessellation, for outline pixels no triangle covers.
    pub segments: Vec<Segment>,
    /// The bounds of the colours in play (those of the base level, whose convex hull holds
    /// the limit surface), when some face is quadratic.
    pub bounds: Option<Bounds>,
    /// Faces whose plans were taken from the [`TessellationCache`].
    pub reused_plans: usize,
}

/// The plans of a layer's faces at its last preparation, kept by a
/// [`RenderCache`](crate::render::RenderCache) for the next. A face's plan depends only on the
/// topology and sharpness around it, the points of the faces that share a vertex with it (its
/// patch's control points, or the neighbourhood its local refinement cuts out), the working
/// space and the options (the same for every entry of a cache). So where the refinement kept
/// its topology ([`Refinement::topology_id`]), a face none of whose neighbourhood's points
/// changed bits plans the same, and keeps its plan (and local refinement) instead. After an
/// edit only the faces within reach of what it moved are planned again: a point moved at
/// level 0 changes the base level's points within a few rings of it.
#[derive(Default)]
pub(crate) struct TessellationCache {
    /// The refinement and the level the plans were made on.
    topology_id: Option<u64>,
    base_level: usize,
    /// The working space the colours are in (a layer whose space changed, and whose points
    /// are black, would have the same bits in another space).
    space: Option<ColourSpace>,
    /// The data of the base level the plans were made from.
    data: Vec<VertexData>,
    faces: Vec<CachedPlan>,
    /// The plans after balancing (empty until a preparation kept them): a draft keeps their
    /// counts and orders ([`FacePlanner::regrid_all`]).
    balanced: Vec<CachedPlan>,
    /// Whether each face's plan was made by a draft ([`RenderOptions::draft`](crate::render::RenderOptions::draft)).
    drafted: Vec<bool>,
    /// What the plans drew (empty until the triangles of the plans above are built).
    triangles: Option<TriangleBlocks>,
    /// The layer's refinement at its last preparation (the topology of its levels and the
    /// stencils between them), which an edit that keeps the topology takes again.
    pub refinement: Option<Refinement>,
}

impl TessellationCache {
    /// Whether the plans were made on the same faces as a planning of `level` of the
    /// refinement `topology_id` (`faces` faces, data `data`) in `space`.
    fn fits(
        &self,
        topology_id: u64,
        level: usize,
        space: ColourSpace,
        faces: usize,
        data: &[VertexData],
    ) -> bool {
        self.topology_id == Some(topology_id)
            && self.base_level == level
            && self.space == Some(space)
            && self.faces.len() == faces
            && self.data.len() == data.len()
    }

    /// Whether some face's plan was made by a draft: a render that is not one must plan the
    /// layer again.
    pub(crate) fn has_drafts(&self) -> bool {
        self.drafted.contains(&true)
    }

    /// Keeps the plans `faces` made on `base_level` of the refinement `topology_id`, whose
    /// data is `data`, in `space`; those planned now (not reused) by a draft if `draft`.
    fn keep_plans(
        &mut self,
        faces: &FacePlans,
        topology_id: u64,
        base_level: usize,
        space: ColourSpace,
        data: &[VertexData],
        draft: bool,
    ) {
        let drafted: Vec<bool> = (faces.reused.iter().enumerate())
            .map(|(f, &reused)| if reused { self.drafted[f] } else { draft })
            .collect();
        self.drafted = drafted;
        self.faces.clear();
        self.faces.extend(faces.to_cached());
        self.data.clear();
        self.data.extend_from_slice(data);
        self.topology_id = Some(topology_id);
        self.base_level = base_level;
        self.space = Some(space);
        self.balanced.clear();
    }

    /// Keeps the plans a draft evaluated again at the balanced counts ([`FacePlanner::regrid_all`],
    /// the faces `faces` did not reuse) as drafted, and the others' plans as they were planned,
    /// so that the next render that is not a draft plans the drafted faces again and balances
    /// the rest as a render from scratch would; `data` is the base level's data now.
    fn keep_regridded_plans(&mut self, faces: &FacePlans, data: &[VertexData]) {
        for (f, cached) in faces.to_cached().enumerate() {
            if !faces.reused[f] {
                self.faces[f] = cached;
                self.drafted[f] = true;
            }
        }
        self.data.clear();
        self.data.extend_from_slice(data);
    }
}

/// The triangles a tessellation drew: each face's count after balancing, the colour bounds
/// quadratic triangles were clamped to, the triangles of each block of [`FACES_PER_BLOCK`]
/// faces, and where each face's triangles start in its block.
struct TriangleBlocks {
    counts: Vec<usize>,
    bounds: Option<Bounds>,
    blocks: Vec<Block>,
    face_starts: Vec<u32>,
}

/// The triangles of a block of faces, shared by the preparations that keep them.
type Block = Arc<Vec<Triangle>>;

/// Faces whose triangles are kept together, in face order: a fixed number, so that the blocks
/// of two preparations of a layer match. Small, because a block an edit reaches is copied
/// (its faces the edit left alone) and compared with the last one triangle by triangle; a
/// render from scratch does not depend on the block size.
const FACES_PER_BLOCK: usize = 16;

/// Which faces must build their triangles again: those that share a vertex with a face that
/// did not keep its plan (`kept`), or whose count after balancing changed (from `last` to
/// `now`). The triangles of a face depend only on the plans of the faces sharing a vertex with
/// it (their samples along its sides and at its corners, and the counts of its edges).
fn faces_to_build(t: &Topology, kept: &[bool], now: &[usize], last: &[usize]) -> Vec<bool> {
    let mut build = vec![false; t.face_count()];
    for g in 0..t.face_count() {
        if !kept[g] || now[g] != last[g] {
            for &u in t.face_vertices(g) {
                for &h in t.vertex_faces(u as usize) {
                    build[h as usize] = true;
                }
            }
        }
    }
    build
}

/// Which faces must be planned again after the base level's data went from `old` to `new`
/// (same topology `t`): those sharing a vertex with a face around a point that changed bits.
fn faces_to_plan_again(t: &Topology, old: &[VertexData], new: &[VertexData]) -> Vec<bool> {
    let mut again = vec![false; t.face_count()];
    let changed = |v: &usize| {
        let (a, b) = (old[*v].to_array(), new[*v].to_array());
        a.iter().zip(b).any(|(x, y)| x.to_bits() != y.to_bits())
    };
    for v in (0..new.len()).filter(changed) {
        for &g in t.vertex_faces(v) {
            for &u in t.face_vertices(g as usize) {
                for &h in t.vertex_faces(u as usize) {
                    again[h as usize] = true;
                }
            }
        }
    }
    again
}

/// What earlier preparations left that a layer's tessellation may take: the local refinements
/// by shape (of all layers), and this layer's [`TessellationCache`] (with a
/// [`RenderCache`](crate::render::RenderCache); this tessellation's plans and triangles are then left
/// in their place).
pub(crate) struct Caches<'a> {
    pub shapes: &'a ShapeCache,
    pub tessellation: Option<&'a mut TessellationCache>,
}

/// Tessellates the layer adaptively, taking what earlier preparations left ([`Caches`]), or
/// `None` where the fast path does not apply (a face that is not a quad at the base level, a
/// neighbourhood that is not a valid mesh on its own, semi-sharpness on the outline down to
/// [`DEEPEST_BASE_LEVEL`]): the caller then refines uniformly.
pub(crate) fn tessellate(
    refinement: &mut Refinement,
    data: &mut RefinedData,
    xf: &ToPixels,
    th: &Thresholds,
    max_level: usize,
    size: (i64, i64),
    caches: Caches<'_>,
) -> Option<Tessellation> {
    let Caches {
        shapes,
        tessellation: mut cache,
    } = caches;
    let topology_id = refinement.topology_id();
    let k0 = build_base_level(refinement, data, xf, size)?;
    let level = refinement.level(k0);
    let t = &level.topology;
    if !t.is_all_quads() {
        return None;
    }
    let d = &data.levels[k0];
    let nf = t.face_count();
    let n_max = 1usize << (max_level.max(k0) - k0).min(12);
    let planner = FacePlanner::new(level, d, shapes, xf, th, n_max);

    // 1. The density of each face, or the plan the cache has for it.
    let fitting_cache = cache
        .as_deref()
        .filter(|c| c.fits(topology_id, k0, th.space, nf, d));
    let again = fitting_cache.map(|c| {
        let mut again = faces_to_plan_again(t, &c.data, d);
        if !th.draft {
            again.iter_mut().zip(&c.drafted).for_each(|(a, &d)| *a |= d);
        }
        again
    });
    let earlier = fitting_cache
        .zip(again.as_deref())
        .map(|(c, again)| EarlierPlans {
            plans: &c.faces,
            again,
        });
    // A draft through a cache keeps the last balanced counts and orders.
    let regridded = (fitting_cache.zip(again.as_deref()))
        .filter(|(c, _)| th.draft && c.balanced.len() == nf)
        .and_then(|(c, again)| planner.regrid_all(&c.balanced, again));
    let is_regridded = regridded.is_some();
    let mut faces = match regridded {
        Some(faces) => faces,
        None => planner.plan_all(earlier)?,
    };
    // Cached as planned: balancing below copies a plan it changes. What the last plans drew
    // is taken out (it fits these plans only where they were kept).
    let mut last_triangles = None;
    if let Some(cache) = cache.as_deref_mut() {
        // After a draft, every face builds its triangles again.
        let after_draft = !th.draft && cache.has_drafts();
        last_triangles = (cache.triangles.take()).filter(|_| again.is_some() && !after_draft);
        if is_regridded {
            cache.keep_regridded_plans(&faces, d);
        } else {
            cache.keep_plans(&faces, topology_id, k0, th.space, d, th.draft);
        }
    }

    // 2. Counts per edge, and the samples faces share.
    if !is_regridded {
        planner.balance(&mut faces)?;
    }
    let bounds = colour_bounds(&faces.plans, d);
    let stitching = Stitching::new(&planner, t, &faces, xf, size, bounds.as_ref())?;

    // 3. Triangles.
    // Each face's count after balancing, for a cache only.
    let counts: Option<Vec<usize>> = cache
        .is_some()
        .then(|| faces.plans.iter().map(|p| p.n).collect());
    let last_blocks = last_triangles
        .zip(counts.as_ref())
        .filter(|(last, _)| last.fits(nf, bounds.as_ref()))
        .map(|(last, counts)| {
            let build = faces_to_build(t, &faces.reused, counts, &last.counts);
            (last, build)
        });
    let (triangle_blocks, face_starts) = build_blocks(&stitching, nf, last_blocks);
    if let (Some(cache), Some(counts)) = (cache, counts) {
        cache.balanced.clear();
        cache.balanced.extend(faces.to_cached());
        cache.triangles = Some(TriangleBlocks {
            counts,
            bounds,
            blocks: triangle_blocks.clone(),
            face_starts,
        });
    }
    let segments = stitching.boundary_segments();
    let figures = figures(k0, &faces);
    Some(Tessellation {
        base_level: k0,
        level: figures.level,
        quads: figures.quads,
        capped: figures.capped,
        measured: figures.measured,
        estimated: figures.estimated,
        triangles: TriangleList::from_shared(triangle_blocks),
        segments,
        bounds,
        reused_plans: faces.reused.iter().filter(|&&k| k).count(),
    })
}

/// Builds the levels of `data` down to the base level and returns it: the one for the pixels
/// the layer covers, or deeper for the edits or for semi-sharpness on the outline; `None`
/// when semi-sharpness still touches the outline at [`DEEPEST_BASE_LEVEL`].
fn build_base_level(
    refinement: &mut Refinement,
    data: &mut RefinedData,
    xf: &ToPixels,
    size: (i64, i64),
) -> Option<usize> {
    // Faces refine on their own from the base level with bare stencils: it must lie below the
    // rings of the deepest multi-resolution edit.
    build_levels_to(refinement, data, 1);
    let pixels = covered_pixels(&data.levels[1], xf, size);
    let mut k0 = base_level(refinement, pixels).max(refinement.base().edits.deepest_level() + 1);
    loop {
        build_levels_to(refinement, data, k0);
        if !refinement.level(k0).semi_sharp_on_boundary() {
            return Some(k0);
        }
        if k0 >= DEEPEST_BASE_LEVEL {
            return None;
        }
        k0 += 1;
    }
}

/// Refines and evaluates `data` down to level `k`.
fn build_levels_to(refinement: &mut Refinement, data: &mut RefinedData, k: usize) {
    while data.levels.len() <= k {
        let j = data.levels.len() - 1;
        refinement.extend_to(j + 1);
        let next = refinement.next_level_data(j, &data.levels[j]);
        data.levels.push(next);
    }
}

impl TriangleBlocks {
    /// Whether these blocks are of `nf` faces drawn under the colour `bounds`.
    fn fits(&self, nf: usize, bounds: Option<&Bounds>) -> bool {
        let bits = |b: Option<&Bounds>| b.map(|b| b.map(|row| row.map(f32::to_bits)));
        self.counts.len() == nf
            && self.blocks.len() == nf.div_ceil(FACES_PER_BLOCK)
            && bits(self.bounds.as_ref()) == bits(bounds)
    }
}

/// The triangles of `nf` faces, a list per block of [`FACES_PER_BLOCK`] (a list per face,
/// sized for all its cells' triangles, cost a fresh allocation per face, and most of a dense
/// layer's triangles are culled), and where each face's triangles start in its block. A face
/// draws as last time if every face sharing a vertex with it kept its plan and its count (its
/// grid and nodes then come out the same), under the same colour bounds: `last` has the
/// triangles of faces that all do, and which faces to build again. A block none of whose
/// faces is built again is shared whole; in another, the faces not built again copy their
/// triangles from the last block.
fn build_blocks(
    stitching: &Stitching<'_>,
    nf: usize,
    last: Option<(TriangleBlocks, Vec<bool>)>,
) -> (Vec<Block>, Vec<u32>) {
    let built: Vec<(Block, Vec<u32>)> = (0..nf.div_ceil(FACES_PER_BLOCK))
        .into_par_iter()
        .map(|b| {
            let faces = b * FACES_PER_BLOCK..((b + 1) * FACES_PER_BLOCK).min(nf);
            if let Some((last, build)) = &last {
                if !build[faces.clone()].contains(&true) {
                    let starts = last.face_starts[faces].to_vec();
                    return (Arc::clone(&last.blocks[b]), starts);
                }
            }
            let mut out = Vec::new();
            let mut starts = Vec::with_capacity(faces.len());
            for f in faces {
                starts.push(out.len() as u32);
                match &last {
                    Some((last, build)) if !build[f] => {
                        out.extend_from_slice(last.face_triangles(b, f))
                    }
                    _ => stitching.face_triangles(&mut out, f),
                }
            }
            (Arc::new(out), starts)
        })
        .collect();
    let mut face_starts = Vec::with_capacity(nf);
    let blocks = built
        .into_iter()
        .map(|(block, starts)| {
            face_starts.extend(starts);
            block
        })
        .collect();
    (blocks, face_starts)
}

impl TriangleBlocks {
    /// The triangles face `f` drew, in its block `b`.
    fn face_triangles(&self, b: usize, f: usize) -> &[Triangle] {
        let block = &self.blocks[b];
        let start = self.face_starts[f] as usize;
        let end = match f + 1 {
            next if next < self.face_starts.len() && next % FACES_PER_BLOCK != 0 => {
                self.face_starts[next] as usize
            }
            _ => block.len(),
        };
        &block[start..end]
    }
}

/// The figures of a tessellation over its faces.
struct Figures {
    /// The uniform level with the density of the finest face.
    level: usize,
    quads: usize,
    capped: bool,
    measured: Measure,
    estimated: bool,
}

/// The figures over the faces of base level `k0`, in one pass (each plan is a pointer to
/// follow).
fn figures(k0: usize, faces: &FacePlans) -> Figures {
    let (mut finest, mut quads, mut capped, mut estimated) = (1, 0, false, false);
    let mut measured = Measure::default();
    for p in &faces.plans {
        finest = finest.max(p.n);
        quads += p.n * p.n;
        capped |= p.capped;
        estimated |= p.estimated;
        measured = measured.max(p.measured);
    }
    Figures {
        level: k0 + finest.trailing_zeros() as usize,
        quads,
        capped,
        measured,
        estimated,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::tessellate::stitch::between_pixel_centres;
    use crate::render::{RenderOptions, View};
    use crate::GradientMesh;
    use kurbo::Point;

    /// [`tessellate`] down to level 12, with local refinements of its own.
    fn tessellate_alone(
        refinement: &mut Refinement,
        data: &mut RefinedData,
        xf: &ToPixels,
        th: &Thresholds,
        size: (i64, i64),
    ) -> Option<Tessellation> {
        tessellate(
            refinement,
            data,
            xf,
            th,
            12,
            size,
            Caches {
                shapes: &ShapeCache::default(),
                tessellation: None,
            },
        )
    }

    /// What a layer can cover: the box around its points, clipped to the image.
    #[test]
    fn covered_pixels_are_the_points_box_clipped_to_the_image() {
        let xf = ToPixels::new(&View::new(0.0, 0.0, 100.0, 50.0), 100, 50);
        let at = |x: f64, y: f64| VertexData::from_array([x, y, 50.0, 0.0, 0.0, 1.0]);
        let inside = [at(10.0, 5.0), at(30.0, 25.0), at(20.0, 10.0)];
        assert_eq!(covered_pixels(&inside, &xf, (100, 50)), 400);
        let across = [at(-10.0, -10.0), at(20.0, 10.0)];
        assert_eq!(covered_pixels(&across, &xf, (100, 50)), 200);
        let beyond = [at(-10.0, 60.0), at(300.0, 70.0)];
        assert_eq!(covered_pixels(&beyond, &xf, (100, 50)), 0);
    }

    /// The cheap test skips only cells whose triangles the exact one (on snapped corners)
    /// culls too, also for corners a snapping step from a column or a row of pixel centres;
    /// and it does skip cells between two columns or two rows.
    #[test]
    fn cells_skipped_between_pixel_centres_are_culled() {
        let step = 1.0 / 256.0;
        let mut skipped = 0;
        for base in [0.0, 7.0, -3.0, 1023.0] {
            // Corners from a third of a step before a column (row) to past the next one.
            for a in -1..=780 {
                for width in [0, 1, 2, 3, 5, 8, 40, 200] {
                    let x0 = base + 0.5 + f64::from(a) * step / 3.0;
                    let xs = [x0, x0 + f64::from(width) * step / 2.0, x0 + 0.3 * step];
                    let tall = [[xs[0], 1.0], [xs[1], 2.0], [xs[2], 8.0], [xs[0], 9.0]];
                    // The same cell on its side: between two rows.
                    let flat = tall.map(|[x, y]| [y, x]);
                    for quad in [tall, flat] {
                        if !between_pixel_centres(quad) {
                            continue;
                        }
                        skipped += 1;
                        for tri in [[0, 1, 2], [0, 2, 3]] {
                            let corners = tri.map(|k| quad[k]);
                            let size = (2048, 2048);
                            assert!(
                                crate::render::raster::triangles::snapped_if_visible(corners, size)
                                    .is_none(),
                                "{corners:?} was skipped but may cover a pixel centre"
                            );
                        }
                    }
                }
            }
        }
        assert!(skipped > 2000, "only {skipped} cells skipped");
    }

    /// A flat grid whose colour has one sharp spot: the faces around it are refined deeply and
    /// the rest stay at one or two cells, so edges join faces of very different counts (fans,
    /// fans from a face's centre). Every pixel centre well inside is covered exactly once.
    #[test]
    fn faces_of_different_counts_leave_no_gap_and_no_overlap() {
        // Linear colour, and quadratic with a tolerance low enough for several counts.
        for (quadratic, tolerance) in [(false, 0.2), (true, 0.005)] {
            faces_of_different_counts(quadratic, tolerance);
        }
    }

    fn faces_of_different_counts(quadratic: bool, tolerance: f64) {
        let n = 4;
        let mut mesh = GradientMesh::new(ColourSpace::Lab);
        for j in 0..=n {
            for i in 0..=n {
                let spot = (i, j) == (1, 2);
                let colour = if spot {
                    [90.0, -60.0, 70.0]
                } else {
                    [40.0, 10.0, -20.0]
                };
                // Curved rows and columns, so that a missing fan would leave gaps.
                let (x, y) = (100.0 * i as f64, 100.0 * j as f64);
                let warp = |a: f64, b: f64| a + 12.0 * (b / 45.0).sin();
                mesh.add_point(Point::new(warp(x, y), warp(y, x)), colour);
            }
        }
        let v = |i: u32, j: u32| j * (n + 1) + i;
        for j in 0..n {
            for i in 0..n {
                mesh.add_face(vec![v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)]);
            }
        }
        let (mut refinement, _) = Refinement::new(&mesh, 2).unwrap();
        let mut data = refinement.evaluate();
        let mut opts = RenderOptions::new(400, 400, View::new(0.0, 0.0, 400.0, 400.0));
        opts.quadratic = quadratic;
        opts.colour_tolerance = tolerance;
        let xf = ToPixels::new(&opts.view, 400, 400);
        let th = Thresholds::new(&opts, ColourSpace::Lab);
        let tess = tessellate_alone(&mut refinement, &mut data, &xf, &th, (400, 400)).unwrap();
        if quadratic {
            assert!(tess.triangles.iter().any(|t| t.is_quadratic()));
        }
        // Faces of many counts: more levels than one, far fewer cells than uniform.
        let base_faces = refinement.topology(tess.base_level).face_count();
        let uniform = (1usize << (2 * (tess.level - tess.base_level))) * base_faces;
        assert!(tess.level >= tess.base_level + 2, "{}", tess.level);
        assert!(tess.quads * 4 < uniform, "{} of {uniform}", tess.quads);

        let hits = coverage(&tess, 400, 400);
        for y in 30..370 {
            for x in 30..370 {
                assert_eq!(hits[y * 400 + x], 1, "pixel ({x}, {y})");
            }
        }
    }

    /// Real artwork with linear and quadratic faces, fans between faces of different counts
    /// and folds: wherever two triangles share a side, they show the same colours along it
    /// (up to single precision, and to the 1/512 pixel between the exact and the snapped side).
    #[test]
    fn shared_sides_agree_in_colour() {
        for name in ["Glasses.off", "Tucan_Tucan_Layer2.off"] {
            let (_, _, tess) = real_tessellation(name);
            let tris: Vec<&Triangle> = tess.triangles.iter().collect();
            let mut sides: std::collections::HashMap<([i64; 2], [i64; 2]), Vec<usize>> =
                std::collections::HashMap::new();
            for (i, t) in tris.iter().enumerate() {
                let v = t.vertices();
                for k in 0..3 {
                    let (a, b) = (v[k], v[(k + 1) % 3]);
                    sides.entry((a.min(b), a.max(b))).or_default().push(i);
                }
            }
            let (mut shared, mut quadratic, mut worst) = (0, 0, 0.0f32);
            for ((a, b), ts) in &sides {
                let [i, j] = ts[..] else { continue };
                shared += 1;
                quadratic += usize::from(tris[i].is_quadratic() || tris[j].is_quadratic());
                for s in [0.25, 0.5, 0.75] {
                    let at = |k: usize| (a[k] as f64 + s * (b[k] - a[k]) as f64) / 256.0;
                    let (x, y) = (at(0), at(1));
                    let (ci, cj) = (tris[i].eval(x, y), tris[j].eval(x, y));
                    // How far the colours move over a pixel: the two sides agree exactly on
                    // the exact side, and this is at most 1/512 pixel off it.
                    let slope = |t: &Triangle, k: usize| {
                        let c = t.eval(x, y)[k];
                        (t.eval(x + 1.0, y)[k] - c).abs() + (t.eval(x, y + 1.0)[k] - c).abs()
                    };
                    for k in 0..4 {
                        let allowed = 0.01 + (slope(tris[i], k) + slope(tris[j], k)) / 256.0;
                        let scale = if k == 3 { 100.0 } else { 1.0 };
                        worst = worst.max(scale * (ci[k] - cj[k]).abs() / allowed);
                    }
                }
            }
            assert!(
                shared > 10_000 && quadratic > 1_000,
                "{name}: {shared} {quadratic}"
            );
            assert!(worst < 1.0, "{name}: {worst}");
        }
    }

    /// A real file's first layer, its options at 700 px, and its tessellation.
    fn real_tessellation(name: &str) -> (crate::Document, RenderOptions, Tessellation) {
        let dir = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../../shared/realdata/gradientmeshimproved-off/"
        );
        let doc = crate::formats::read_path(&std::path::PathBuf::from(dir).join(name)).unwrap();
        let opts = RenderOptions::fit(&doc, 700);
        let (w, h) = (opts.width as i64, opts.height as i64);
        let xf = ToPixels::new(&opts.view, opts.width, opts.height);
        let th = Thresholds::new(&opts, ColourSpace::Lab);
        let (mut refinement, _) = Refinement::new(&doc.layers[0], 2).unwrap();
        let mut data = refinement.evaluate();
        let tess = tessellate_alone(&mut refinement, &mut data, &xf, &th, (w, h)).unwrap();
        (doc, opts, tess)
    }

    /// A memo of plans gives the same tessellation as planning afresh; after a point moved,
    /// only the faces around it plan again (regular and irregular); a refinement of another
    /// topology plans everything again.
    #[test]
    fn remembered_plans_are_taken_for_faces_an_edit_left_alone() {
        let dir = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../../shared/realdata/gradientmeshimproved-off/"
        );
        let mut doc =
            crate::formats::read_path(&std::path::PathBuf::from(dir).join("Glasses.off")).unwrap();
        let opts = RenderOptions::fit(&doc, 500);
        let (w, h) = (opts.width as i64, opts.height as i64);
        let xf = ToPixels::new(&opts.view, opts.width, opts.height);
        let th = Thresholds::new(&opts, ColourSpace::Lab);
        let shapes = ShapeCache::default();
        // As `layer::prepare` does: the memo's refinement takes the new data if it can.
        let run = |mesh: &crate::GradientMesh, mut memo: Option<&mut TessellationCache>| {
            let (base, _) = crate::validate::BaseMesh::new(mesh).unwrap();
            let kept = memo.as_deref_mut().and_then(|m| m.refinement.take());
            let mut refinement = Refinement::rebased_or_new(kept, base, 1);
            let mut data = refinement.evaluate_to(refinement.base(), 1);
            let kept = Caches {
                shapes: &shapes,
                tessellation: memo.as_deref_mut(),
            };
            let tess = tessellate(&mut refinement, &mut data, &xf, &th, 12, (w, h), kept).unwrap();
            if let Some(memo) = memo {
                memo.refinement = Some(refinement);
            }
            tess
        };
        let same = |a: &Tessellation, b: &Tessellation| {
            assert_eq!(a.triangles.len(), b.triangles.len());
            for (x, y) in a.triangles.iter().zip(b.triangles.iter()) {
                assert_eq!(format!("{x:?}"), format!("{y:?}"));
            }
        };
        let mut memo = TessellationCache::default();
        let first = run(&doc.layers[0], Some(&mut memo));
        assert_eq!(first.reused_plans, 0);
        same(&first, &run(&doc.layers[0], None));
        // Unchanged: every face keeps its plan.
        let again = run(&doc.layers[0], Some(&mut memo));
        let faces = memo.faces.len();
        let local = |m: &TessellationCache| {
            let local = m
                .faces
                .iter()
                .filter(|p| matches!(p, CachedPlan::Local(..)));
            local.count()
        };
        assert!(faces > 1000 && local(&memo) > 100, "{faces} faces");
        assert_eq!(again.reused_plans, faces);
        same(&again, &first);
        // A point moved: the faces within its reach plan again, and the result is a fresh one's.
        doc.layers[0].points[40].position.x += 2.0;
        let moved = run(&doc.layers[0], Some(&mut memo));
        let reused = moved.reused_plans;
        assert!(reused > faces / 2 && reused < faces, "{reused} of {faces}");
        same(&moved, &run(&doc.layers[0], None));
        // Points moved next to extraordinary vertices: irregular faces plan again too.
        let before = memo.faces.clone();
        for p in doc.layers[0].points.iter_mut().step_by(7) {
            p.position.y += 1.0;
        }
        let moved = run(&doc.layers[0], Some(&mut memo));
        same(&moved, &run(&doc.layers[0], None));
        let replanned = |local: bool| {
            let pairs = before.iter().zip(&memo.faces);
            pairs
                .filter(|(a, b)| match (a, b) {
                    (CachedPlan::Regular(a), CachedPlan::Regular(b)) => {
                        !local && !Arc::ptr_eq(a, b)
                    }
                    (CachedPlan::Local(a, ..), CachedPlan::Local(b, ..)) => {
                        local && !Arc::ptr_eq(a, b)
                    }
                    _ => false,
                })
                .count()
        };
        assert!(replanned(true) > 0 && replanned(false) > 0);
        assert!(moved.reused_plans > 0 && moved.reused_plans < faces);
        // A colour far from its neighbours', at a point moved far: the faces around it take
        // other grids, and the triangles kept around them still fit.
        doc.layers[0].points[60].colour = [100.0, 90.0, -90.0];
        doc.layers[0].points[60].colour_text = None;
        doc.layers[0].points[60].position.x += 30.0;
        let moved = run(&doc.layers[0], Some(&mut memo));
        same(&moved, &run(&doc.layers[0], None));
        // Another refinement of the same mesh: nothing is kept.
        memo.refinement = None;
        assert_eq!(run(&doc.layers[0], Some(&mut memo)).reused_plans, 0);
        // The same bits in another working space are other colours: nothing is kept (capped
        // at level 4: read as Oklab, these colours would take deep grids).
        let th = Thresholds::new(&opts, ColourSpace::Oklab);
        let mut refinement = memo.refinement.take().unwrap();
        let mut data = refinement.evaluate_to(refinement.base(), 1);
        let kept = Caches {
            shapes: &shapes,
            tessellation: Some(&mut memo),
        };
        let other = tessellate(&mut refinement, &mut data, &xf, &th, 4, (w, h), kept).unwrap();
        assert_eq!(other.reused_plans, 0);
    }

    /// A face builds its triangles again when a face sharing a vertex with it planned again or
    /// changed its count, and not otherwise.
    #[test]
    fn faces_build_again_around_faces_whose_plans_or_counts_changed() {
        // A strip of three quads: the first and the last share no vertex.
        let t = Topology::build(
            8,
            vec![0, 4, 8, 12],
            vec![0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6],
            |_, _| false,
        )
        .unwrap();
        let build = |kept: [bool; 3], now: [usize; 3]| faces_to_build(&t, &kept, &now, &[2, 2, 2]);
        assert_eq!(build([true; 3], [2; 3]), [false; 3]);
        assert_eq!(build([true; 3], [2, 4, 2]), [true; 3]);
        assert_eq!(build([true; 3], [4, 2, 2]), [true, true, false]);
        assert_eq!(build([true, true, false], [2; 3]), [false, true, true]);
        assert_eq!(build([true; 3], [2, 2, 1]), [false, true, true]);
    }

    /// Pixel coverage counts of a tessellation.
    fn coverage(tess: &Tessellation, w: i64, h: i64) -> Vec<u32> {
        let mut hits = vec![0u32; (w * h) as usize];
        let mut cursor = tess.triangles.cursor();
        for i in 0..tess.triangles.len() {
            let t = cursor.get(i);
            t.for_each_span(t.rows().0.max(0)..t.rows().1.min(h), w, |j, a, b| {
                for x in a..b {
                    hits[(j * w + x) as usize] += 1;
                }
            });
        }
        hits
    }

    /// Real artwork (degenerate handles, folds, faces from one cell to many a side, one-cell
    /// faces fanned from their centre): every pixel centre inside the outline is covered.
    #[test]
    fn real_artwork_has_no_cracks() {
        for name in [
            "Glasses.off",
            "Tucan_Tucan_Layer3.off",
            "Tucan_Tucan_Layer0.off",
        ] {
            let (doc, opts, tess) = real_tessellation(name);
            let (w, h) = (opts.width as i64, opts.height as i64);
            let hits = coverage(&tess, w, h);
            // Inside: the pixel and its neighbours lie wholly within the outline, which is
            // drawn exactly, apart from the triangles.
            let img = crate::render::render_document(&doc, &opts).unwrap();
            let opaque = |x: i64, y: i64| img.pixel(x as u32, y as u32)[3] == 1.0;
            let mut inside = 0;
            for y in 1..h - 1 {
                for x in 1..w - 1 {
                    if (-1..=1).all(|dy| (-1..=1).all(|dx| opaque(x + dx, y + dy))) {
                        inside += 1;
                        assert!(
                            hits[(y * w + x) as usize] > 0,
                            "{name}: crack at ({x}, {y})"
                        );
                    }
                }
            }
            assert!(inside > 10_000, "{name}: {inside}");
        }
    }
}
