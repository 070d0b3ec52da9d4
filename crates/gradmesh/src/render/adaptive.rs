//! The fast path's tessellation: each face of a low all-quad level gets its own grid density.
//!
//! 1. **Density.** Each face of the base level ([`BASE_LEVEL`], shallower for meshes dense for
//!    the image: see [`base_level`]) is evaluated on grids of `1, 2, 4, ..`
//!    cells a side ([`patches`](super::patches): a B-spline patch where the face is regular,
//!    local refinement elsewhere) until its cells pass the same measure as the uniform path's
//!    quads (colour at cell and side centres against the triangles, cell size, outline). A face
//!    whose control points all lie off the image stays at one cell.
//! 2. **Stitching.** A face is re-evaluated at half the count of its finest neighbour if it
//!    is coarser (2:1 balance), or at the full count where the surface folds (a face whose
//!    cells turn both ways, or which borders one turned the other way or folded: which sheet
//!    shows depends on where the fold runs, and no measure checks that). Each edge then takes
//!    the larger count of its two faces. Both sides read its samples from a face of that count
//!    (the first), and the samples at a vertex from the vertex's first face, so both sides
//!    share bit-identical vertices. A face coarser than an edge fans the boundary cells
//!    along it out to the edge's extra samples (from a cell corner off the edge, or from the
//!    face's centre when it is a single cell), so no T-junction is left: the snapped,
//!    top-left-rule rasteriser sees the same edges from both sides, without cracks. Each face
//!    thus keeps its own density instead of taking the count of its finest edge, which would
//!    spread a fine spot's cells over its neighbours.
//! 3. **Triangles.** Two per cell (fans along finer edges), faces in order, cells in the order
//!    (and with the diagonals) of the quads uniform refinement would make of the face, so
//!    folds overlap the same way.

use std::sync::{Arc, Mutex, OnceLock};

use rayon::prelude::*;

use crate::colour::{ColourSpace, Matrix3};
use crate::level::Level;
use crate::refine::{RefinedData, Refinement};
use crate::rules;
use crate::topology::Topology;
use crate::validate::VertexData;

use super::measure::{measure_quad, Measure, QuadSamples, Thresholds};
use super::nearest::Segment;
use super::patches::{
    regular_corners, regular_patch_with, ControlGrid, Grid, LocalPatch, ShapeCache,
};
use super::quadratic::{chord_node, measure_cells, screen_gradient, Cell, Quadratic};
use super::triangles::{snap, Bounds, Triangle, TriangleList, UNBOUNDED};
use super::view::ToPixels;
use super::{each3, each4};

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

/// Quadratic colour is tried on a face only while its linear error is at most this many times
/// the tolerance: with larger errors the quarter points that check it can miss a steep colour
/// edge (Glasses.off at 160 px fails the accuracy test at twice this value), and quadratic
/// faces still take far fewer cells than linear ones.
const QUADRATIC_MAX_LINEAR_ERROR: f64 = 8.0;

/// The slowest that linear pieces' colour error is taken to fall per level for a face that
/// does not fold but may border one: where the surface folds, about 0.6 is seen (see
/// `ADAPTIVE_MIN_COUNTED_PX` in `measure.rs`); elsewhere it quarters.
const LINEAR_RATE_NEAR_FOLDS: f64 = 0.6;

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
        let p = xf.apply(d[0], d[1]);
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let side = |k: usize, n: i64| (hi[k].min(n as f64) - lo[k].max(0.0)).max(0.0);
    (side(0, size.0) * side(1, size.1)) as usize
}

/// What the fast path produced for one layer.
pub(super) struct Tessellation {
    /// The base level: the outline is taken from it.
    pub base_level: usize,
    /// The uniform level with the density of the finest face.
    pub level: usize,
    /// Cells drawn.
    pub quads: usize,
    /// Whether some face reached [`super::RenderOptions::max_level`] before passing.
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
    /// Faces whose plans were taken from the [`PlanMemo`].
    pub reused_plans: usize,
}

/// How a face's limit surface is evaluated.
// A source lives on the stack of one face's planning: boxing the control grid would cost an
// allocation per face.
#[allow(clippy::large_enum_variant)]
enum Source {
    Regular(ControlGrid),
    /// Face `root` of a local refinement: of the face alone, or of the faces around an
    /// extraordinary vertex refined together.
    Local {
        patch: LocalPatch,
        root: usize,
    },
}

impl Source {
    /// `regular`: whether each vertex of `level` is a regular corner ([`regular_corners`]);
    /// `shapes`: the local refinements shared by shape of neighbourhood.
    fn new(
        level: &Level,
        regular: &[bool],
        data: &[VertexData],
        f: usize,
        shapes: &ShapeCache,
    ) -> Option<Source> {
        match regular_patch_with(level, data, f, |v| regular[v]) {
            Some(cp) => Some(Source::Regular(cp)),
            None => LocalPatch::new(level, data, &[f], shapes)
                .map(|patch| Source::Local { patch, root: 0 }),
        }
    }

    fn grid(&mut self, n: usize) -> Option<Grid> {
        match self {
            Source::Regular(cp) => Some(super::patches::evaluate_patch(cp, n)),
            Source::Local { patch, root } => patch.grid(*root, n),
        }
    }

    /// [`Source::grid`] into `out`, whose memory a regular patch reuses.
    fn grid_into(&mut self, n: usize, out: &mut Grid) -> Option<()> {
        match self {
            Source::Regular(cp) => super::patches::evaluate_patch_into(cp, n, out),
            Source::Local { patch, root } => *out = patch.grid(*root, n)?,
        }
        Some(())
    }

    /// Whether the convex hull of the points face `f`'s surface is made of misses the image:
    /// a patch's control points, or the points of the faces around it in `level`.
    fn off_image(
        &self,
        level: &Level,
        data: &[VertexData],
        f: usize,
        xf: &ToPixels,
        size: (f64, f64),
    ) -> bool {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        let mut grow = |d: &VertexData| {
            let p = xf.apply(d[0], d[1]);
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        };
        match self {
            Source::Regular(cp) => cp.iter().flatten().for_each(&mut grow),
            Source::Local { .. } => {
                let t = &level.topology;
                for &v in t.face_vertices(f) {
                    for &g in t.vertex_faces(v as usize) {
                        for &w in t.face_vertices(g as usize) {
                            grow(&data[w as usize]);
                        }
                    }
                }
            }
        }
        hi[0] < -1.0 || hi[1] < -1.0 || lo[0] > size.0 + 1.0 || lo[1] > size.1 + 1.0
    }
}

/// Whether semi-sharpness still touches the boundary at `level`: the outline is only a uniform
/// B-spline of the boundary vertices once it has decayed there.
fn semi_sharp_on_boundary(level: &Level) -> bool {
    let t = &level.topology;
    let semi = |s: f64| rules::is_sharp(s) && !rules::is_infinite(s);
    (0..t.vertex_count()).any(|v| {
        t.is_boundary_vertex(v)
            && (semi(level.vertex_sharpness[v])
                || t.vertex_edges(v)
                    .iter()
                    .any(|&e| semi(level.edge_sharpness[e as usize])))
    })
}

/// The grid position of parameter `s` (`0..=m`) along side `k` of a face, from its corner `k`
/// to its corner `k + 1`.
fn side_position(k: usize, s: usize, m: usize) -> (usize, usize) {
    match k {
        0 => (s, 0),
        1 => (m, s),
        2 => (m - s, m),
        _ => (0, m - s),
    }
}

/// The cells of a grid of `n` cells a side (`n` a power of two) in the order, and with the
/// first corner, of the quads that `log2 n` Catmull-Clark steps make of the face: child `c` of
/// a quad sits at its corner `c`, starts there and runs along the parent's side `c` (see
/// [`crate::catmull_clark::refine`]). Drawing in this order keeps the uniform path's order
/// where the surface folds over itself, and the same diagonals.
fn cell_order(n: usize) -> Vec<Cell> {
    fn visit(o: [i64; 2], u: [i64; 2], v: [i64; 2], size: i64, out: &mut Vec<Cell>) {
        let corners = [
            o,
            [o[0] + size * u[0], o[1] + size * u[1]],
            [o[0] + size * (u[0] + v[0]), o[1] + size * (u[1] + v[1])],
            [o[0] + size * v[0], o[1] + size * v[1]],
        ];
        if size == 1 {
            out.push(corners.map(|p| (p[0] as usize, p[1] as usize)));
            return;
        }
        for c in 0..4 {
            let p = corners[c];
            let towards = |q: [i64; 2]| [(q[0] - p[0]) / size, (q[1] - p[1]) / size];
            visit(
                p,
                towards(corners[(c + 1) % 4]),
                towards(corners[(c + 3) % 4]),
                size / 2,
                out,
            );
        }
    }
    let mut out = Vec::with_capacity(n * n);
    visit([0, 0], [1, 0], [0, 1], n as i64, &mut out);
    out
}

/// [`cell_order`] for every power of two up to a limit, each built on first use.
struct CellOrders(Vec<OnceLock<Vec<Cell>>>);

impl CellOrders {
    fn new(n_max: usize) -> CellOrders {
        CellOrders(
            (0..=n_max.trailing_zeros())
                .map(|_| OnceLock::new())
                .collect(),
        )
    }

    fn get(&self, n: usize) -> &[Cell] {
        self.0[n.trailing_zeros() as usize].get_or_init(|| cell_order(n))
    }
}

/// Measures a face's grid of `n` cells a side (every `step`-th point of `g`, row and column)
/// against its grid of `2 n` (whose even samples are the same points). `boundary[k]`: whether
/// side `k` of the face lies on the outline. `counted` receives, per cell, whether its colour
/// counted (it reaches the image and is not too small to matter, see [`measure_quad`]);
/// `jacobians`, in spaces whose distances are not Lab's, the derivative to Lab at each cell's
/// centre (the points of the finer grid with both coordinates odd; the others are never asked
/// for), which the quadratic measure reads too.
#[allow(clippy::too_many_arguments)]
fn measure_grid(
    g: &[VertexData],
    step: usize,
    n: usize,
    g2: &[VertexData],
    cells: &[Cell],
    boundary: [bool; 4],
    xf: &ToPixels,
    th: &Thresholds,
    counted: &mut Vec<bool>,
    jacobians: &mut Vec<Matrix3>,
) -> Measure {
    let (s1, s2) = (step * (step * n + 1), 2 * n + 1);
    let at = |(i, j): (usize, usize)| &g[j * s1 + i * step];
    // The point halfway between two grid points, from the finer grid.
    let mid = |a: (usize, usize), b: (usize, usize)| &g2[(a.1 + b.1) * s2 + a.0 + b.0];
    // Which face side, if any, both ends of a cell side lie on.
    let on_side = |a: (usize, usize), b: (usize, usize)| -> bool {
        (a.1 == 0 && b.1 == 0 && boundary[0])
            || (a.0 == n && b.0 == n && boundary[1])
            || (a.1 == n && b.1 == n && boundary[2])
            || (a.0 == 0 && b.0 == 0 && boundary[3])
    };
    // Spaces whose distances are not Lab's measure through the derivative at each cell's
    // centre (as the quadratic measure does): one conversion per cell instead of two per
    // comparison.
    jacobians.clear();
    let jacobians = needs_jacobians(th.space).then(|| {
        jacobians.extend(g2.iter().enumerate().map(|(k, d)| {
            if (k % s2) % 2 == 1 && (k / s2) % 2 == 1 {
                th.space.lab_jacobian([d[2], d[3], d[4]])
            } else {
                Matrix3::default()
            }
        }));
        &jacobians[..]
    });
    let mut m = Measure::default();
    counted.clear();
    for c in cells {
        let sides = each4(|k| (c[k], c[(k + 1) % 4]));
        let q = QuadSamples {
            corners: each4(|k| at(c[k])),
            centre: mid(c[0], c[2]),
            mids: each4(|k| mid(sides[k].0, sides[k].1)),
            boundary: each4(|k| on_side(sides[k].0, sides[k].1)),
            jacobians: jacobians.as_ref().map(|j| {
                let (a, b) = (c[0], c[2]);
                [&j[(a.1 + b.1) * s2 + a.0 + b.0]; 5]
            }),
        };
        let cell = measure_quad(&q, xf, th.size, th.space, th.min_quad, true);
        // A cell off the image measures nothing; one whose colour did not count measures no
        // colour, and a smaller one than `min_quad` only then.
        counted.push(cell.extent > 0.0 && (cell.colour > 0.0 || cell.extent >= th.min_quad));
        m = m.max(cell);
    }
    m
}

/// Buffers one thread's planning reuses from face to face (most faces of a dense layer stop at
/// a cell or two a side, and each measure allocating its own cost a dense layer several
/// allocations a face).
#[derive(Default)]
struct PlanScratch {
    counted: Vec<bool>,
    jacobians: Vec<Matrix3>,
    side_nodes: Vec<Option<[f64; 4]>>,
    /// The grid of `4 n` cells a side a quadratic measure reads.
    quarter: Grid,
}

/// Whether colour errors in `space` are measured through the derivative to Lab.
fn needs_jacobians(space: ColourSpace) -> bool {
    matches!(
        space,
        ColourSpace::Srgb | ColourSpace::SrgbLinear | ColourSpace::Oklab
    )
}

/// How a face's cells interpolate colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Order {
    Linear,
    /// Six-node triangles ([`super::quadratic`]).
    Quadratic,
}

/// One face's choice: cells a side, its grid, and how it measured.
#[derive(Clone)]
struct Plan {
    n: usize,
    /// The grid of `n` cells a side; empty where it is the even points of `finer` (a regular
    /// patch's grids share their points bit for bit), which saves a quadratic face an
    /// allocation and a copy. Read through [`Plan::at`].
    grid: Grid,
    measured: Measure,
    capped: bool,
    estimated: bool,
    /// The face's centre, kept when a one-cell plan was measured (the measure evaluates the
    /// grid of two cells): a one-cell face fanned to finer edges needs it.
    centre: Option<VertexData>,
    order: Order,
    /// A quadratic face's grid of `2 n` cells a side: its midpoint nodes.
    finer: Option<Grid>,
    /// A quadratic face's colour error with linear pieces, where measured at its count.
    linear_colour: Option<f64>,
}

impl Plan {
    /// Point `(i, j)` of the face's grid of `n` cells a side.
    fn at(&self, i: usize, j: usize) -> &VertexData {
        let (g, step) = self.grid_view();
        &g[step * (j * (step * self.n + 1) + i)]
    }

    /// The grid of `n` cells a side, and the step between its points in the slice.
    fn grid_view(&self) -> (&[VertexData], usize) {
        match &self.finer {
            Some(g2) if self.grid.is_empty() => (g2, 2),
            _ => (&self.grid, 1),
        }
    }
}

/// The plans of a layer's faces at its last preparation, kept by a
/// [`RenderCache`](super::RenderCache) for the next. A face's plan depends only on the
/// topology and sharpness around it, the points of the faces that share a vertex with it (its
/// patch's control points, or the neighbourhood its local refinement cuts out), the working
/// space and the options (the same for every entry of a cache). So where the refinement kept
/// its topology ([`Refinement::topology_id`]), a face none of whose neighbourhood's points
/// changed bits plans the same, and keeps its plan (and local refinement) instead. After an
/// edit only the faces within reach of what it moved are planned again: a point moved at
/// level 0 changes the base level's points within a few rings of it.
#[derive(Default)]
pub(crate) struct PlanMemo {
    /// The refinement and the level the plans were made on.
    topology_id: Option<u64>,
    base_level: usize,
    /// The working space the colours are in (a layer whose space changed, and whose points
    /// are black, would have the same bits in another space).
    space: Option<ColourSpace>,
    /// The data of the base level the plans were made from.
    data: Vec<VertexData>,
    faces: Vec<KeptPlan>,
    /// What the plans drew: each face's count after balancing, the colour bounds quadratic
    /// triangles were clamped to, and the triangles of each block of [`FACES_PER_BLOCK`]
    /// faces (empty until the triangles of the plans above are built).
    drawn: Option<DrawnFaces>,
    /// The layer's refinement at its last preparation (the topology of its levels and the
    /// stencils between them), which an edit that keeps the topology takes again.
    pub refinement: Option<Refinement>,
}

/// See [`PlanMemo::drawn`].
struct DrawnFaces {
    counts: Vec<usize>,
    bounds: Option<Bounds>,
    blocks: Vec<Arc<Vec<Triangle>>>,
}

/// Faces whose triangles are built (and kept) together, in face order: a fixed number, so
/// that the blocks of two preparations of a layer match. Small, because an edit builds every
/// block it reaches again; a render from scratch does not depend on the block size.
const FACES_PER_BLOCK: usize = 16;

/// Which blocks of `per_block` faces (in face order) must build their triangles again: those
/// with a face that shares a vertex with a face that did not keep its plan (`kept`), or whose
/// count after balancing changed (from `last` to `now`). The triangles of a face depend only
/// on the plans of the faces sharing a vertex with it (their samples along its sides and at
/// its corners, and the counts of its edges).
fn blocks_to_build(
    t: &Topology,
    kept: &[bool],
    now: &[usize],
    last: &[usize],
    per_block: usize,
) -> Vec<bool> {
    let mut build = vec![false; t.face_count().div_ceil(per_block)];
    for g in 0..t.face_count() {
        if !kept[g] || now[g] != last[g] {
            for &u in t.face_vertices(g) {
                for &h in t.vertex_faces(u as usize) {
                    build[h as usize / per_block] = true;
                }
            }
        }
    }
    build
}

/// A face's plan as its last preparation left it (before balancing), shared rather than
/// copied: with the local refinement an irregular face was planned on, and its root there.
#[derive(Clone)]
enum KeptPlan {
    Regular(Arc<Plan>),
    Local(Arc<Plan>, Arc<Mutex<LocalPatch>>, usize),
}

/// Which faces must be planned again after the base level's data went from `old` to `new`
/// (same topology `t`): those sharing a vertex with a face around a point that changed bits.
fn faces_to_plan_again(t: &Topology, old: &[VertexData], new: &[VertexData]) -> Vec<bool> {
    let mut again = vec![false; t.face_count()];
    let changed = |v: &usize| {
        let (a, b) = (&old[*v], &new[*v]);
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
/// by shape (of all layers), and the plans of this layer's regular faces (with a
/// [`RenderCache`](super::RenderCache); this tessellation's are then left in their place).
pub(crate) struct Kept<'a> {
    pub shapes: &'a ShapeCache,
    pub plans: Option<&'a mut PlanMemo>,
}

/// Tessellates the layer adaptively, taking what earlier preparations left ([`Kept`]), or
/// `None` where the fast path does not apply (a face that is not a quad at the base level, a
/// neighbourhood that is not a valid mesh on its own, semi-sharpness on the outline down to
/// [`DEEPEST_BASE_LEVEL`]): the caller then refines uniformly.
pub(super) fn tessellate(
    refinement: &mut Refinement,
    data: &mut RefinedData,
    xf: &ToPixels,
    th: &Thresholds,
    max_level: usize,
    size: (i64, i64),
    kept: Kept<'_>,
) -> Option<Tessellation> {
    let Kept {
        shapes,
        plans: mut memo,
    } = kept;
    let topology_id = refinement.topology_id();
    // Faces refine on their own from the base level with bare stencils: it must lie below the
    // rings of the deepest multi-resolution edit.
    while data.levels.len() <= 1 {
        let j = data.levels.len() - 1;
        refinement.extend_to(j + 1);
        let next = refinement.next_level_data(j, &data.levels[j]);
        data.levels.push(next);
    }
    let pixels = covered_pixels(&data.levels[1], xf, size);
    let mut k0 = base_level(refinement, pixels).max(refinement.base().edits.deepest_level() + 1);
    loop {
        while data.levels.len() <= k0 {
            let j = data.levels.len() - 1;
            refinement.extend_to(j + 1);
            let next = refinement.next_level_data(j, &data.levels[j]);
            data.levels.push(next);
        }
        if !semi_sharp_on_boundary(refinement.level(k0)) {
            break;
        }
        if k0 >= DEEPEST_BASE_LEVEL {
            return None;
        }
        k0 += 1;
    }
    let level = refinement.level(k0);
    let t = &level.topology;
    if !t.is_all_quads() {
        return None;
    }
    let d = &data.levels[k0];
    let nf = t.face_count();
    let n_max = 1usize << (max_level.max(k0) - k0).min(12);
    let passes =
        |m: &Measure| m.extent <= th.quad && m.colour <= th.colour && m.outline <= th.outline;
    let boundary_sides =
        |f: usize| -> [bool; 4] { each4(|k| t.is_boundary_edge(t.face_edges(f)[k] as usize)) };

    let regular = regular_corners(level);

    // 1. The density of each face.
    let orders = CellOrders::new(n_max.max(1) * 2);
    let plan_face = |f: usize, src: &mut Source, scratch: &mut PlanScratch| -> Option<Plan> {
        let off_image = src.off_image(level, d, f, xf, th.size);
        // A regular patch's grid of two cells holds its grid of one (the same parameters and
        // arithmetic): evaluate it once and read its corners from it (the grid stays empty
        // until the face is known to need it on its own). Local refinement evaluates each
        // depth on its own, so it keeps its order of evaluation.
        let regular_source = matches!(src, Source::Regular(_));
        let mut next = None;
        let grid = if regular_source && !off_image && n_max > 1 {
            next = Some(src.grid(2)?);
            Vec::new()
        } else {
            src.grid(1)?
        };
        let mut plan = Plan {
            n: 1,
            grid,
            measured: Measure::default(),
            capped: false,
            estimated: false,
            centre: None,
            order: Order::Linear,
            finer: None,
            linear_colour: None,
        };
        if off_image {
            return Some(plan);
        }
        let boundary = boundary_sides(f);
        let (mut last_colour, mut last_quadratic): (Option<f64>, Option<f64>) = (None, None);
        loop {
            if plan.n >= n_max {
                plan.capped = true;
                return Some(plan);
            }
            let finer = match next.take() {
                Some(g) => g,
                None => src.grid(2 * plan.n)?,
            };
            // The grid of `n`: the plan's, or the even points of the finer one.
            let (coarse, step) = if plan.grid.is_empty() {
                (&finer[..], 2)
            } else {
                (&plan.grid[..], 1)
            };
            let m = measure_grid(
                coarse,
                step,
                plan.n,
                &finer,
                orders.get(plan.n),
                boundary,
                xf,
                th,
                &mut scratch.counted,
                &mut scratch.jacobians,
            );
            if passes(&m) {
                plan.measured = m;
                if plan.n == 1 {
                    plan.centre = Some(finer[4]);
                }
                if plan.grid.is_empty() {
                    plan.grid = even_points(&finer, plan.n);
                }
                return Some(plan);
            }
            // Quadratic colour at this count, measured against the grid of `4 n` (which the
            // next level measures against its nodes anyway). Not where the face's own cells
            // fold (which sheet shows there is the linear path's business), nor where the
            // linear error says the cells are coarse for the colour's features: the quarter
            // points can then miss the error between them.
            let mut quadratic = None;
            if th.quadratic
                && m.colour <= QUADRATIC_MAX_LINEAR_ERROR * th.colour
                && turn_flags(coarse, step, plan.n) != 3
            {
                src.grid_into(4 * plan.n, &mut scratch.quarter)?;
                let colour = measure_cells(
                    &finer,
                    &scratch.quarter,
                    plan.n,
                    orders.get(plan.n),
                    &scratch.counted,
                    xf,
                    th.space,
                    needs_jacobians(th.space).then_some(&scratch.jacobians[..]),
                    &mut scratch.side_nodes,
                );
                let mq = Measure { colour, ..m };
                if passes(&mq) {
                    plan.measured = mq;
                    plan.order = Order::Quadratic;
                    plan.linear_colour = Some(m.colour);
                    if plan.n == 1 {
                        plan.centre = Some(finer[4]);
                    }
                    plan.finer = Some(finer);
                    return Some(plan);
                }
                quadratic = Some(colour);
                next = Some(std::mem::take(&mut scratch.quarter));
            }
            // Size halves per level and the outline's distance quarters. The colour error of
            // linear pieces quarters where the colour is smooth, but may only halve next to an
            // extraordinary vertex or a fold: predict the rate it fell at over the last level,
            // between the two (a half when there is no last level).
            let ratio = match last_colour {
                Some(prev) if prev > 0.0 => (m.colour / prev).clamp(0.25, 0.5),
                _ => 0.5,
            };
            last_colour = Some(m.colour);
            let predicted = Measure {
                extent: 0.5 * m.extent,
                colour: ratio * m.colour,
                outline: 0.25 * m.outline,
            };
            plan.n *= 2;
            plan.grid = finer;
            plan.measured = predicted;
            plan.estimated = true;
            if passes(&predicted) {
                return Some(plan);
            }
            // Quadratic pieces' error falls by an eighth where the colour is smooth: the same
            // prediction from the rate it fell at, between an eighth and a half.
            if let Some(colour) = quadratic {
                let ratio = match last_quadratic {
                    Some(prev) if prev > 0.0 => (colour / prev).clamp(0.125, 0.5),
                    _ => 0.5,
                };
                last_quadratic = Some(colour);
                let predicted = Measure {
                    colour: ratio * colour,
                    ..predicted
                };
                if passes(&predicted) && turn_flags(&plan.grid, 1, plan.n) != 3 {
                    plan.measured = predicted;
                    plan.order = Order::Quadratic;
                    plan.finer = next.take();
                    if regular_source && plan.finer.is_some() {
                        plan.grid = Vec::new();
                    }
                    return Some(plan);
                }
            }
        }
    };
    // Regular faces first, each on its own, or as the memo of the last preparation has them.
    let old_memo = memo.as_deref().filter(|m| {
        m.topology_id == Some(topology_id)
            && m.base_level == k0
            && m.space == Some(th.space)
            && m.faces.len() == nf
            && m.data.len() == d.len()
    });
    let again = old_memo.map(|m| faces_to_plan_again(t, &m.data, d));
    let kept_plan = |f: usize| -> Option<&KeptPlan> {
        let (m, again) = (old_memo?, again.as_ref()?);
        (!again[f]).then(|| &m.faces[f])
    };
    let planned: Vec<(Option<Arc<Plan>>, bool)> = each_face_with(nf, |scratch, f| {
        if let Some(KeptPlan::Regular(plan)) = kept_plan(f) {
            return Some((Some(Arc::clone(plan)), true));
        }
        let Some(cp) = regular_patch_with(level, d, f, |v| regular[v]) else {
            return Some((None, false));
        };
        let plan = plan_face(f, &mut Source::Regular(cp), scratch)?;
        Some((Some(Arc::new(plan)), false))
    })?;
    // Which faces kept their plans.
    let mut kept_faces: Vec<bool> = planned.iter().map(|p| p.1).collect();
    let mut plans: Vec<Option<Arc<Plan>>> = planned.into_iter().map(|p| p.0).collect();
    // The others refine locally, grouped by their first corner that is not regular (for
    // most, the extraordinary vertex they surround): a group shares one local refinement.
    let mut irregular: Vec<(usize, usize)> = (0..nf)
        .filter(|&f| plans[f].is_none())
        .map(|f| {
            let corner = t.face_vertices(f).iter().find(|&&v| !regular[v as usize]);
            (corner.map_or(t.vertex_count() + f, |&v| v as usize), f)
        })
        .collect();
    irregular.sort_unstable();
    let groups: Vec<&[(usize, usize)]> = irregular.chunk_by(|a, b| a.0 == b.0).collect();
    // Each face planned with its local refinement and its root there, kept for the counts
    // step 2 asks for: cutting out and refining a face's neighbourhood alone again cost
    // Glasses a tenth of a millisecond a face. Faces of one group take turns at its lock;
    // what runs under it stays on its thread (see `patches::LocalShape`).
    type Planned = Vec<(usize, Arc<Plan>, Arc<Mutex<LocalPatch>>, usize)>;
    let kept = |src: Source| -> Option<Arc<Mutex<LocalPatch>>> {
        match src {
            Source::Local { patch, .. } => Some(Arc::new(Mutex::new(patch))),
            Source::Regular(_) => None,
        }
    };
    let each_alone = |group: &[(usize, usize)]| -> Option<Planned> {
        let mut scratch = PlanScratch::default();
        group
            .iter()
            .map(|&(_, f)| {
                let mut src = Source::new(level, &regular, d, f, shapes)?;
                let plan = plan_face(f, &mut src, &mut scratch)?;
                Some((f, Arc::new(plan), kept(src)?, 0))
            })
            .collect()
    };
    let together = |group: &[(usize, usize)]| -> Option<Planned> {
        let faces: Vec<usize> = group.iter().map(|&(_, f)| f).collect();
        let mut src = Source::Local {
            patch: LocalPatch::new(level, d, &faces, shapes)?,
            root: 0,
        };
        let mut planned = Vec::with_capacity(faces.len());
        let mut scratch = PlanScratch::default();
        for (k, &f) in faces.iter().enumerate() {
            if let Source::Local { root, .. } = &mut src {
                *root = k;
            }
            planned.push((f, plan_face(f, &mut src, &mut scratch)?));
        }
        let patch = kept(src)?;
        Some(
            planned
                .into_iter()
                .enumerate()
                .map(|(k, (f, plan))| (f, Arc::new(plan), Arc::clone(&patch), k))
                .collect(),
        )
    };
    // A group the edit left alone keeps its plans and local refinement.
    let kept_group = |group: &[(usize, usize)]| -> Option<Planned> {
        group
            .iter()
            .map(|&(_, f)| match kept_plan(f)? {
                KeptPlan::Local(plan, patch, root) => {
                    Some((f, Arc::clone(plan), Arc::clone(patch), *root))
                }
                KeptPlan::Regular(_) => None,
            })
            .collect()
    };
    let planned: Vec<(Planned, bool)> = groups
        .par_iter()
        .map(|&group| {
            if let Some(kept) = kept_group(group) {
                return Some((kept, true));
            }
            // Neighbourhoods that do not form a valid mesh together may do so one by one.
            (group.len() > 1)
                .then(|| together(group))
                .flatten()
                .or_else(|| each_alone(group))
                .map(|planned| (planned, false))
        })
        .collect::<Option<_>>()?;
    let mut local_of: Vec<Option<(Arc<Mutex<LocalPatch>>, usize)>> = vec![None; nf];
    for (group, kept) in planned {
        for (f, plan, patch, root) in group {
            plans[f] = Some(plan);
            local_of[f] = Some((patch, root));
            kept_faces[f] = kept;
        }
    }
    let reused_plans = kept_faces.iter().filter(|&&k| k).count();
    // Face `f`'s grid of `n` cells a side, from its kept local refinement if it has one.
    let regrid = |f: usize, n: usize| -> Option<Grid> {
        match &local_of[f] {
            Some((patch, root)) => patch
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .grid(*root, n),
            None => Source::new(level, &regular, d, f, shapes)?.grid(n),
        }
    };
    let mut plans: Vec<Arc<Plan>> = plans
        .into_iter()
        .map(|p| p.expect("every face is planned"))
        .collect();
    // Remembered as planned: balancing below copies a plan it changes. What the last plans
    // drew is taken out (it fits these plans only where they were kept).
    let mut last_drawn = None;
    if let Some(memo) = memo.as_deref_mut() {
        last_drawn = memo.drawn.take().filter(|_| again.is_some());
        memo.faces.clear();
        memo.faces
            .extend(plans.iter().zip(&local_of).map(|(plan, local)| {
                let plan = Arc::clone(plan);
                match local {
                    Some((patch, root)) => KeptPlan::Local(plan, Arc::clone(patch), *root),
                    None => KeptPlan::Regular(plan),
                }
            }));
        memo.data.clear();
        memo.data.extend_from_slice(d);
        memo.topology_id = Some(topology_id);
        memo.base_level = k0;
        memo.space = Some(th.space);
    }
    // 2. Counts per edge: the finer face's. A face is first refined to at least half of its
    // finest edge (2:1 balance with the faces' own densities: the faces around a deeply
    // refined spot, often a fold near a singular point, follow its shape closely). A coarser
    // face then fans its boundary cells out to the edge's extra samples (step 3).
    let edge_counts = |plans: &[Arc<Plan>]| -> Vec<usize> {
        // The counts side by side first: read through each plan's pointer, edge by edge, they
        // would be a cache miss each.
        let counts: Vec<usize> = plans.par_iter().map(|p| p.n).collect();
        (0..t.edge_count())
            .into_par_iter()
            .map(|e| {
                t.edge_faces(e)
                    .iter()
                    .filter(|&&g| (g as usize) < nf)
                    .map(|&g| counts[g as usize])
                    .max()
                    .unwrap_or(1)
            })
            .collect()
    };
    let own_edge_cells = edge_counts(&plans);
    // Where the surface folds over itself, which sheet shows at a pixel depends on where the
    // fold's crease runs, which no measure checks: faces whose cells do not all turn the same
    // way, and faces next to them or next to a face turned the other way, take the full count
    // of their finest edge (as uniform refinement would give them) instead of half.
    let turns: Vec<u8> = plans
        .par_iter()
        .map(|p| {
            let (g, step) = p.grid_view();
            turn_flags(g, step, p.n)
        })
        .collect();
    let folded = |f: usize| -> bool {
        turns[f] == 3
            || t.face_edges(f).iter().any(|&e| {
                t.edge_faces(e as usize)
                    .iter()
                    .any(|&g| (g as usize) < nf && (turns[g as usize] | turns[f]) == 3)
            })
    };
    plans
        .par_iter_mut()
        .enumerate()
        .map(|(f, plan)| {
            let finest_edge = t
                .face_edges(f)
                .iter()
                .map(|&e| own_edge_cells[e as usize])
                .max()
                .unwrap_or(1);
            let n = if folded(f) {
                plan.n.max(finest_edge)
            } else {
                plan.n.max(finest_edge / 2)
            };
            if n != plan.n {
                let plan = Arc::make_mut(plan);
                // A quadratic face refined further for its neighbours' sake is often fine
                // enough for linear pieces, which need no grid of twice the count for their
                // nodes: predicted from the linear error at its own count, falling by no
                // more than LINEAR_RATE_NEAR_FOLDS a level.
                let levels = (n / plan.n).trailing_zeros() as i32;
                let linear = plan
                    .linear_colour
                    .map(|c| c * LINEAR_RATE_NEAR_FOLDS.powi(levels))
                    .filter(|&c| c <= th.colour);
                if let (Order::Quadratic, Some(colour)) = (plan.order, linear) {
                    plan.order = Order::Linear;
                    plan.measured.colour = colour;
                    plan.estimated = true;
                }
                // A regular patch's quadratic face reads its grid from the finer one.
                let quadratic = plan.order == Order::Quadratic;
                plan.grid = if quadratic && local_of[f].is_none() {
                    Vec::new()
                } else {
                    regrid(f, n)?
                };
                plan.finer = if quadratic {
                    Some(regrid(f, 2 * n)?)
                } else {
                    None
                };
                plan.n = n;
            }
            Some(())
        })
        .collect::<Option<Vec<()>>>()?;
    let edge_cells = edge_counts(&plans);
    // A face of one cell with a finer edge is fanned from its centre.
    let centres: Vec<Option<VertexData>> = each_face(nf, |f| {
        let finer = t
            .face_edges(f)
            .iter()
            .any(|&e| edge_cells[e as usize] > plans[f].n);
        if plans[f].n == 1 && finer {
            match plans[f].centre {
                Some(c) => Some(Some(c)),
                None => regrid(f, 2).map(|g| Some(g[4])),
            }
        } else {
            Some(None)
        }
    })?;

    // The shared samples: each edge's from its first face of the edge's count (which runs it
    // from its first vertex to its second), each vertex's from its first face. They are read
    // from those faces' grids where needed rather than copied (fresh memory costs page faults).
    let edge_sources: Vec<(u32, u8, bool)> = (0..t.edge_count())
        .into_par_iter()
        .map(|e| {
            let ne = edge_cells[e];
            let owner = t
                .edge_faces(e)
                .into_iter()
                .find(|&g| (g as usize) < nf && plans[g as usize].n >= ne)
                .expect("an edge has a face of its count");
            let k = t
                .face_edges(owner as usize)
                .iter()
                .position(|&x| x as usize == e)
                .expect("an edge is a side of its face");
            let forward = t.face_vertices(owner as usize)[k] == t.edge_vertices(e)[0];
            (owner, k as u8, forward)
        })
        .collect();
    // Sample `s` (`0..=ne`) of edge `e`, from its first vertex.
    let edge_sample = |e: usize, s: usize| -> &VertexData {
        let (owner, k, forward) = edge_sources[e];
        let plan = &plans[owner as usize];
        let (m, ne) = (plan.n, edge_cells[e]);
        let q = if forward { s } else { ne - s };
        let (i, j) = side_position(k as usize, q * (m / ne), m);
        plan.at(i, j)
    };
    // Copied, unlike the edges': every face reads four, and one read here is one cache miss
    // instead of a chain of them.
    let vertex_samples: Vec<VertexData> = (0..t.vertex_count())
        .into_par_iter()
        .map(|v| {
            let (Some(&f), Some(&c)) =
                (t.vertex_faces(v).first(), t.vertex_face_corners(v).first())
            else {
                return [0.0; 6];
            };
            let m = plans[f as usize].n;
            let (i, j) = side_position(c as usize, 0, m);
            *plans[f as usize].at(i, j)
        })
        .collect();
    let vertex_sample = |v: usize| &vertex_samples[v];
    // The sample at position `s` (`0..=ne`) of edge `fe[k]`, counted from the face's corner `k`.
    let side_sample = |fv: &[u32], fe: &[u32], k: usize, s: usize| -> &VertexData {
        let e = fe[k] as usize;
        let ne = edge_cells[e];
        let forward = fv[k] == t.edge_vertices(e)[0];
        edge_sample(e, if forward { s } else { ne - s })
    };
    // Grid point `(i, j)` of face `f` as drawn: its corners are the vertices' samples, its
    // sides the edges' (at the face's own count), the rest its own.
    let face_sample = |f: usize, (i, j): (usize, usize)| -> &VertexData {
        let m = plans[f].n;
        let side = if j == 0 {
            Some((0, i))
        } else if i == m {
            Some((1, j))
        } else if j == m {
            Some((2, m - i))
        } else if i == 0 {
            Some((3, m - j))
        } else {
            None
        };
        match side {
            None => plans[f].at(i, j),
            Some((k, 0)) => vertex_sample(t.face_vertices(f)[k] as usize),
            Some((k, q)) if q == m => vertex_sample(t.face_vertices(f)[(k + 1) % 4] as usize),
            Some((k, q)) => {
                let (fv, fe) = (t.face_vertices(f), t.face_edges(f));
                let r = edge_cells[fe[k] as usize] / m;
                side_sample(fv, fe, k, q * r)
            }
        }
    };

    // Quadratic faces' midpoint nodes. An edge is quadratic where every face on it is: its
    // nodes are then the owner's finer samples moved to the chords' midpoints (see
    // [`super::quadratic`]), which both sides compute alike; elsewhere they are the mean of
    // the segment's ends, the colour a linear face (or its fan) draws along it.
    let edge_quadratic: Vec<bool> = (0..t.edge_count())
        .into_par_iter()
        .map(|e| {
            t.edge_faces(e)
                .iter()
                .filter(|&&g| (g as usize) < nf)
                .all(|&g| plans[g as usize].order == Order::Quadratic)
        })
        .collect();
    let px = |d: &VertexData| xf.apply(d[0], d[1]);
    let mean = |a: &VertexData, b: &VertexData| each4(|k| 0.5 * (a[2 + k] + b[2 + k]));
    // The node of segment `s` (from sample `s` to `s + 1`, counted from the edge's first
    // vertex) of edge `e`.
    let edge_node = |e: usize, s: usize| -> [f64; 4] {
        let (a, b) = (edge_sample(e, s), edge_sample(e, s + 1));
        let (owner, k, forward) = edge_sources[e];
        let plan = &plans[owner as usize];
        match (&plan.finer, edge_quadratic[e]) {
            (Some(g2), true) => {
                let (m, ne) = (plan.n, edge_cells[e]);
                let q = if forward { s } else { ne - 1 - s };
                let (i, j) = side_position(k as usize, 2 * q + 1, 2 * m);
                let gradient = screen_gradient(g2, 2 * m + 1, (i, j), xf);
                chord_node(px(a), px(b), &g2[j * (2 * m + 1) + i], &gradient, xf)
            }
            _ => mean(a, b),
        }
    };
    // The node of the segment of face side `k` between its positions `sa` and `sb` (adjacent,
    // at the edge's count, counted from the face's corner `k`).
    let side_node = |fv: &[u32], fe: &[u32], k: usize, sa: usize, sb: usize| -> [f64; 4] {
        let e = fe[k] as usize;
        let lo = sa.min(sb);
        let forward = fv[k] == t.edge_vertices(e)[0];
        edge_node(e, if forward { lo } else { edge_cells[e] - 1 - lo })
    };

    // 3. Triangles.
    let bounds = plans.iter().any(|p| p.order == Order::Quadratic).then(|| {
        let mut b = [[f32::INFINITY; 4], [f32::NEG_INFINITY; 4]];
        for p in d {
            for k in 0..4 {
                // Widened by a millionth: the f32 of a value may lie on either side of it.
                let v = p[2 + k] as f32;
                let margin = 1e-6 * (1.0 + v.abs());
                b[0][k] = b[0][k].min(v - margin);
                b[1][k] = b[1][k].max(v + margin);
            }
        }
        b
    });
    let clamp_to = bounds.as_ref().unwrap_or(&UNBOUNDED);
    // Appends face `f`'s triangles to `out`.
    let face_triangles = |out: &mut Vec<Triangle>, f: usize| {
        let plan = &plans[f];
        let m = plan.n;
        let (fv, fe) = (t.face_vertices(f), t.face_edges(f));
        // Extra samples per cell side along each face side.
        let ratio = each4(|k| edge_cells[fe[k] as usize] / m);
        // The face side, and the position along it, of grid point (i, j), if it has one.
        let on_side = |k: usize, (i, j): (usize, usize)| -> Option<usize> {
            match k {
                0 => (j == 0).then_some(i),
                1 => (i == m).then_some(j),
                2 => (j == m).then_some(m - i),
                _ => (i == 0).then_some(m - j),
            }
        };
        let sample = |p: (usize, usize)| face_sample(f, p);
        let g2 = plan
            .finer
            .as_ref()
            .filter(|_| plan.order == Order::Quadratic);
        // The face's own node between adjacent grid points `a` and `b` (quadratic faces).
        let own_node = |g2: &Grid, a: (usize, usize), b: (usize, usize)| -> [f64; 4] {
            let mid = (a.0 + b.0, a.1 + b.1);
            let gradient = screen_gradient(g2, 2 * m + 1, mid, xf);
            let d = &g2[mid.1 * (2 * m + 1) + mid.0];
            chord_node(px(sample(a)), px(sample(b)), d, &gradient, xf)
        };
        // The node drawn between adjacent grid points `a` and `b` not on a refined side: the
        // edge's along a face side, the face's own inside.
        let cell_node = |g2: &Grid, a: (usize, usize), b: (usize, usize)| -> [f64; 4] {
            for k in 0..4 {
                if let (Some(sa), Some(sb)) = (on_side(k, a), on_side(k, b)) {
                    return side_node(fv, fe, k, sa, sb);
                }
            }
            own_node(g2, a, b)
        };
        let mut push = |d: [&VertexData; 3], mids: Option<[[f64; 4]; 3]>| {
            if let Some(x) = screen_triangle(d, mids, clamp_to, xf, size) {
                out.push(x);
            }
        };
        let mut polygon: Vec<&VertexData> = Vec::new();
        // Quadratic faces: the node of each polygon side, from vertex `i` to `i + 1`.
        let mut nodes: Vec<[f64; 4]> = Vec::new();
        for cell in orders.get(m) {
            // Which cell sides lie along a face side with extra samples.
            let refined = each4(|c| {
                let (a, b) = (cell[c], cell[(c + 1) % 4]);
                (0..4).find(|&k| ratio[k] > 1 && on_side(k, a).is_some() && on_side(k, b).is_some())
            });
            if refined.iter().all(Option::is_none) {
                let q = each4(|k| sample(cell[k]));
                // Most cells of a dense face cover no pixel centre: skip their nodes.
                if between_pixel_centres(q.map(px)) {
                    continue;
                }
                match g2 {
                    None => {
                        push([q[0], q[1], q[2]], None);
                        push([q[0], q[2], q[3]], None);
                    }
                    Some(g2) => {
                        let s = each4(|k| cell_node(g2, cell[k], cell[(k + 1) % 4]));
                        let diagonal = own_node(g2, cell[0], cell[2]);
                        push([q[0], q[1], q[2]], Some([s[0], s[1], diagonal]));
                        push([q[0], q[2], q[3]], Some([diagonal, s[2], s[3]]));
                    }
                }
                continue;
            }
            // The cell with the edge's samples on its refined sides, fanned from a corner on
            // none of them (with two or more cells a side, a cell touches at most two adjacent
            // face sides), or else from the face's centre.
            let apex = (0..4).find(|&c| refined[c].is_none() && refined[(c + 3) % 4].is_none());
            polygon.clear();
            nodes.clear();
            for n in 0..4 {
                let c = (apex.unwrap_or(0) + n) % 4;
                polygon.push(sample(cell[c]));
                if let Some(k) = refined[c] {
                    let sa = on_side(k, cell[c]).expect("on the side") * ratio[k];
                    let sb = on_side(k, cell[(c + 1) % 4]).expect("on the side") * ratio[k];
                    let mut last = sa;
                    for x in 1..=ratio[k] {
                        let s = if sb > sa { sa + x } else { sa - x };
                        if x < ratio[k] {
                            polygon.push(side_sample(fv, fe, k, s));
                        }
                        if g2.is_some() {
                            nodes.push(side_node(fv, fe, k, last, s));
                        }
                        last = s;
                    }
                } else if let Some(g2) = g2 {
                    nodes.push(cell_node(g2, cell[c], cell[(c + 1) % 4]));
                }
            }
            let Some(g2) = g2 else {
                match (apex, &centres[f]) {
                    (None, Some(centre)) => {
                        for i in 0..polygon.len() {
                            push([centre, polygon[i], polygon[(i + 1) % polygon.len()]], None);
                        }
                    }
                    // From the apex corner; (None, None) is not reached (a one-cell face with
                    // a finer edge has a centre), and a fan from a corner is its graceful
                    // fallback.
                    _ => {
                        for w in polygon[1..].windows(2) {
                            push([polygon[0], w[0], w[1]], None);
                        }
                    }
                }
                continue;
            };
            // A quadratic fan: the spokes' nodes come from the cell's own quadratic triangles
            // (its own nodes on every side), at the spokes' midpoints.
            let q = each4(|k| sample(cell[k]));
            let own = each4(|k| own_node(g2, cell[k], cell[(k + 1) % 4]));
            let diagonal = own_node(g2, cell[0], cell[2]);
            let triangle = |v: [usize; 3], mids: [[f64; 4]; 3]| Quadratic {
                p: v.map(|k| px(q[k])),
                c: v.map(|k| [q[k][2], q[k][3], q[k][4], q[k][5]]),
                m: mids,
            };
            let halves = [
                triangle([0, 1, 2], [own[0], own[1], diagonal]),
                triangle([0, 2, 3], [diagonal, own[2], own[3]]),
            ];
            let (p0, p1, p2) = (px(q[0]), px(q[1]), px(q[2]));
            let cross = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
                (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
            };
            let spoke = |a: &VertexData, b: &VertexData| -> [f64; 4] {
                let (pa, pb) = (px(a), px(b));
                let x = [0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1])];
                // The half on the same side of the diagonal as the point.
                let first = (cross(p0, p2, x) > 0.0) == (cross(p0, p2, p1) > 0.0);
                halves[usize::from(!first)]
                    .eval(x)
                    .unwrap_or_else(|| mean(a, b))
            };
            let len = polygon.len();
            match (apex, &centres[f]) {
                (None, Some(centre)) => {
                    for i in 0..len {
                        let (a, b) = (polygon[i], polygon[(i + 1) % len]);
                        push(
                            [centre, a, b],
                            Some([spoke(centre, a), nodes[i], spoke(b, centre)]),
                        );
                    }
                }
                _ => {
                    for i in 1..len - 1 {
                        let (a, b) = (polygon[i], polygon[i + 1]);
                        let first = if i == 1 {
                            nodes[0]
                        } else {
                            spoke(polygon[0], a)
                        };
                        let last = if i + 1 == len - 1 {
                            nodes[len - 1]
                        } else {
                            spoke(b, polygon[0])
                        };
                        push([polygon[0], a, b], Some([first, nodes[i], last]));
                    }
                }
            }
        }
    };
    // A face draws as last time if every face sharing a vertex with it kept its plan and its
    // count (its grid and nodes then come out the same), under the same colour bounds: the
    // blocks of faces that all do are taken as they were.
    let blocks = nf.div_ceil(FACES_PER_BLOCK);
    let same_bounds = |a: &Option<Bounds>| {
        let bits = |b: &Option<Bounds>| b.map(|b| b.map(|row| row.map(f32::to_bits)));
        bits(a) == bits(&bounds)
    };
    // Each face's count after balancing, for a memo only.
    let counts: Option<Vec<usize>> = memo.is_some().then(|| plans.iter().map(|p| p.n).collect());
    let last_blocks = last_drawn
        .zip(counts.as_ref())
        .filter(|(last, _)| {
            last.counts.len() == nf && last.blocks.len() == blocks && same_bounds(&last.bounds)
        })
        .map(|(last, counts)| {
            let build = blocks_to_build(t, &kept_faces, counts, &last.counts, FACES_PER_BLOCK);
            (last.blocks, build)
        });
    // A list per block (a list per face, sized for all its cells' triangles, cost a fresh
    // allocation per face, and most of a dense layer's triangles are culled).
    let triangle_blocks: Vec<Arc<Vec<Triangle>>> = (0..blocks)
        .into_par_iter()
        .map(|b| match &last_blocks {
            Some((last, build)) if !build[b] => Arc::clone(&last[b]),
            _ => {
                let mut out = Vec::new();
                for f in b * FACES_PER_BLOCK..((b + 1) * FACES_PER_BLOCK).min(nf) {
                    face_triangles(&mut out, f);
                }
                Arc::new(out)
            }
        })
        .collect();
    if let (Some(memo), Some(counts)) = (memo, counts) {
        memo.drawn = Some(DrawnFaces {
            counts,
            bounds,
            blocks: triangle_blocks.clone(),
        });
    }
    let triangles = TriangleList::from_shared(triangle_blocks);

    // The boundary of the tessellation, loop by loop.
    let mut segments = Vec::new();
    for lp in super::outline::boundary_loops(t) {
        for i in 0..lp.len() {
            let (a, b) = (lp[i], lp[(i + 1) % lp.len()]);
            let Some(&e) = t
                .vertex_edges(a as usize)
                .iter()
                .find(|&&e| t.is_boundary_edge(e as usize) && t.other_vertex(e as usize, a) == b)
            else {
                continue;
            };
            let ne = edge_cells[e as usize];
            let mut s: Vec<VertexData> = (0..=ne).map(|q| *edge_sample(e as usize, q)).collect();
            let mut nodes: Vec<[f64; 4]> = (0..ne).map(|q| edge_node(e as usize, q)).collect();
            if t.edge_vertices(e as usize)[0] != a {
                s.reverse();
                nodes.reverse();
            }
            for (w, node) in s.windows(2).zip(&nodes) {
                let (pa, pb) = (xf.apply(w[0][0], w[0][1]), xf.apply(w[1][0], w[1][1]));
                let snappable = |p: [f64; 2]| snap(p[0]).is_some() && snap(p[1]).is_some();
                if snappable(pa) && snappable(pb) {
                    let c = |d: &VertexData| [d[2], d[3], d[4], d[5]].map(|x| x as f32);
                    segments.push(Segment {
                        a: pa,
                        b: pb,
                        ca: c(&w[0]),
                        cb: c(&w[1]),
                        // Zero where the edge is linear (its node is then this same mean).
                        bump: each4(|k| (4.0 * (node[k] - mean(&w[0], &w[1])[k])) as f32),
                    });
                }
            }
        }
    }

    // The figures over the faces, in one pass (each plan is a pointer to follow).
    let (mut finest, mut quads, mut capped, mut estimated) = (1, 0, false, false);
    let mut measured = Measure::default();
    for p in &plans {
        finest = finest.max(p.n);
        quads += p.n * p.n;
        capped |= p.capped;
        estimated |= p.estimated;
        measured = measured.max(p.measured);
    }
    Some(Tessellation {
        base_level: k0,
        level: k0 + finest.trailing_zeros() as usize,
        quads,
        capped,
        measured,
        estimated,
        triangles,
        segments,
        bounds,
        reused_plans,
    })
}

/// `f` of every face `0..nf`, on all cores, or `None` if any is `None`. The results are
/// written straight into place (an indexed collect): collected as an `Option` of a vector,
/// rayon gathered them in a list of pieces and copied them twice more, which for 90,000 faces
/// of plans was a tenth of planning.
fn each_face<T: Send>(nf: usize, f: impl Fn(usize) -> Option<T> + Sync + Send) -> Option<Vec<T>> {
    let mut all: Vec<Option<T>> = Vec::with_capacity(nf);
    (0..nf).into_par_iter().map(f).collect_into_vec(&mut all);
    all.into_iter().collect()
}

/// [`each_face`] with a [`PlanScratch`] per piece of the work.
fn each_face_with<T: Send>(
    nf: usize,
    f: impl Fn(&mut PlanScratch, usize) -> Option<T> + Sync + Send,
) -> Option<Vec<T>> {
    let mut all: Vec<Option<T>> = Vec::with_capacity(nf);
    (0..nf)
        .into_par_iter()
        .map_init(PlanScratch::default, f)
        .collect_into_vec(&mut all);
    all.into_iter().collect()
}

/// The grid of `n` cells a side among the points of the grid of `2 n`.
fn even_points(g2: &[VertexData], n: usize) -> Grid {
    let s2 = 2 * n + 1;
    (0..=n)
        .flat_map(|j| (0..=n).map(move |i| g2[2 * (j * s2 + i)]))
        .collect()
}

/// Which ways the cells of a grid of `n` cells a side turn in the plane: bit 0 for
/// counter-clockwise, bit 1 for clockwise (3: the face folds over itself). The grid's points
/// are every `step`-th of `g`'s, row and column.
fn turn_flags(g: &[VertexData], step: usize, n: usize) -> u8 {
    let s = step * (step * n + 1);
    let mut flags = 0;
    for j in 0..n {
        for i in 0..n {
            let [a, b, c, d] = each4(|k| {
                let (x, y) = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)][k];
                &g[y * s + x * step]
            });
            // Twice the signed area of the quad: the cross product of its diagonals.
            let cross = (c[0] - a[0]) * (d[1] - b[1]) - (c[1] - a[1]) * (d[0] - b[0]);
            if cross > 0.0 {
                flags |= 1;
            } else if cross < 0.0 {
                flags |= 2;
            }
        }
    }
    flags
}

/// Whether points (pixels) surely lie between two adjacent columns, or two adjacent rows, of
/// pixel centres, so that no triangle through them covers a centre. Cheap, and sure: the
/// margin covers the snapping that the exact test (in [`super::triangles::screen_triangle_px`])
/// works on.
fn between_pixel_centres<const N: usize>(p: [[f64; 2]; N]) -> bool {
    // A sixty-fourth of a pixel: far more than the snapping moves a point.
    const MARGIN: f64 = 1.0 / 64.0;
    // Floors without the library call.
    let floor = |v: f64| {
        let t = v as i64;
        t - i64::from(v < t as f64)
    };
    let between = |axis: usize| {
        let (lo, hi) = p
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), q| {
                (lo.min(q[axis]), hi.max(q[axis]))
            });
        let (lo, hi) = (lo - 0.5 - MARGIN, hi - 0.5 + MARGIN);
        // Far outside i64 (or NaN) they are not between; the exact test decides. Else: no
        // integer (centre) in [lo, hi].
        lo.abs() < 1e15 && hi.abs() < 1e15 && floor(lo) == floor(hi) && (floor(lo) as f64) < lo
    };
    between(0) || between(1)
}

/// The triangle through three limit samples, in pixels, quadratic with the side nodes `mids`
/// (within the colour `bounds`), if it may cover a pixel centre of the image (see [`super::triangles::screen_triangle_px`]).
fn screen_triangle(
    d: [&VertexData; 3],
    mids: Option<[[f64; 4]; 3]>,
    bounds: &Bounds,
    xf: &ToPixels,
    size: (i64, i64),
) -> Option<Triangle> {
    let exact = each3(|k| xf.apply(d[k][0], d[k][1]));
    let attr = each3(|k| [d[k][2], d[k][3], d[k][4], d[k][5]]);
    super::triangles::screen_triangle_px(exact, attr, mids, bounds, size)
}

#[cfg(test)]
mod tests {
    use super::*;
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
            Kept {
                shapes: &ShapeCache::default(),
                plans: None,
            },
        )
    }

    /// What a layer can cover: the box around its points, clipped to the image.
    #[test]
    fn covered_pixels_are_the_points_box_clipped_to_the_image() {
        let xf = ToPixels::new(&View::new(0.0, 0.0, 100.0, 50.0), 100, 50);
        let at = |x: f64, y: f64| [x, y, 50.0, 0.0, 0.0, 1.0];
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
                    let wide = tall.map(|[x, y]| [y, x]);
                    for quad in [tall, wide] {
                        if !between_pixel_centres(quad) {
                            continue;
                        }
                        skipped += 1;
                        for tri in [[0, 1, 2], [0, 2, 3]] {
                            let corners = tri.map(|k| quad[k]);
                            let size = (2048, 2048);
                            assert!(
                                crate::render::triangles::snapped_if_visible(corners, size)
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
        let run = |mesh: &crate::GradientMesh, mut memo: Option<&mut PlanMemo>| {
            let (base, _) = crate::validate::BaseMesh::new(mesh).unwrap();
            let kept = memo.as_deref_mut().and_then(|m| m.refinement.take());
            let mut refinement = Refinement::rebased_or_new(kept, base, 1);
            let mut data = refinement.evaluate_to(refinement.base(), 1);
            let kept = Kept {
                shapes: &shapes,
                plans: memo.as_deref_mut(),
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
        let mut memo = PlanMemo::default();
        let first = run(&doc.layers[0], Some(&mut memo));
        assert_eq!(first.reused_plans, 0);
        same(&first, &run(&doc.layers[0], None));
        // Unchanged: every face keeps its plan.
        let again = run(&doc.layers[0], Some(&mut memo));
        let faces = memo.faces.len();
        let local = |m: &PlanMemo| {
            let local = m.faces.iter().filter(|p| matches!(p, KeptPlan::Local(..)));
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
                    (KeptPlan::Regular(a), KeptPlan::Regular(b)) => !local && !Arc::ptr_eq(a, b),
                    (KeptPlan::Local(a, ..), KeptPlan::Local(b, ..)) => local && !Arc::ptr_eq(a, b),
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
        let kept = Kept {
            shapes: &shapes,
            plans: Some(&mut memo),
        };
        let other = tessellate(&mut refinement, &mut data, &xf, &th, 4, (w, h), kept).unwrap();
        assert_eq!(other.reused_plans, 0);
    }

    /// A block builds its triangles again when a face sharing a vertex with one of its faces
    /// planned again or changed its count, and not otherwise.
    #[test]
    fn blocks_build_again_around_faces_whose_plans_or_counts_changed() {
        // A strip of three quads: the first and the last share no vertex.
        let t = Topology::build(
            8,
            vec![0, 4, 8, 12],
            vec![0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6],
            |_, _| false,
        )
        .unwrap();
        let build = |kept: [bool; 3], now: [usize; 3], per_block: usize| {
            blocks_to_build(&t, &kept, &now, &[2, 2, 2], per_block)
        };
        assert_eq!(build([true; 3], [2; 3], 1), [false; 3]);
        assert_eq!(build([true; 3], [2, 4, 2], 1), [true; 3]);
        assert_eq!(build([true; 3], [4, 2, 2], 1), [true, true, false]);
        assert_eq!(build([true, true, false], [2; 3], 1), [false, true, true]);
        assert_eq!(build([true; 3], [4, 2, 2], 2), [true, false]);
        assert_eq!(build([true; 3], [2, 2, 1], 2), [true, true]);
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
