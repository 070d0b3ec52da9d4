//! Planning the faces of a layer's base level for [`adaptive`](crate::render::tessellate::adaptive): how many cells a side
//! each face takes, and whether its cells interpolate colour linearly or quadratically; then
//! the 2:1 balance between neighbouring faces.

use std::sync::{Arc, Mutex, OnceLock};

use rayon::prelude::*;

use crate::colour::{ColourSpace, Matrix3};
use crate::level::Level;
use crate::topology::Topology;
use crate::validate::VertexData;

use super::measure::{measure_quad, Measure, QuadSamples, Thresholds};
use super::quadratic::{measure_cells, Cell};
use crate::limit_surface::patches::{
    regular_corners, regular_patch_with, ControlGrid, Grid, LocalPatch, ShapeCache,
};
use crate::render::arrays::each4;
use crate::view::ToPixels;

mod frozen;

/// Quadratic colour is tried on a face only while its linear error is at most this many times
/// the tolerance: with larger errors the quarter points that check it can miss a steep colour
/// edge (Glasses.off at 160 px fails the accuracy test at twice this value), and quadratic
/// faces still take far fewer cells than linear ones.
const QUADRATIC_MAX_LINEAR_ERROR: f64 = 8.0;

/// The slowest that linear pieces' colour error is taken to fall per level for a face that
/// does not fold but may border one: where the surface folds, about 0.6 is seen (see
/// `ADAPTIVE_MIN_COUNTED_PX` in `measure.rs`); elsewhere it quarters.
const LINEAR_RATE_NEAR_FOLDS: f64 = 0.6;

/// How a face's limit surface is evaluated.
// A surface lives on the stack of one face's planning: boxing the control grid would cost an
// allocation per face.
#[allow(clippy::large_enum_variant)]
enum FaceSurface {
    Regular(ControlGrid),
    /// Face `root` of a local refinement: of the face alone, or of the faces around an
    /// extraordinary vertex refined together.
    Local {
        patch: LocalPatch,
        root: usize,
    },
}

impl FaceSurface {
    /// `regular`: whether each vertex of `level` is a regular corner ([`regular_corners`]);
    /// `shapes`: the local refinements shared by shape of neighbourhood.
    fn new(
        level: &Level,
        regular: &[bool],
        data: &[VertexData],
        f: usize,
        shapes: &ShapeCache,
    ) -> Option<FaceSurface> {
        match regular_patch_with(level, data, f, |v| regular[v]) {
            Some(cp) => Some(FaceSurface::Regular(cp)),
            None => LocalPatch::new(level, data, &[f], shapes)
                .map(|patch| FaceSurface::Local { patch, root: 0 }),
        }
    }

    fn grid(&mut self, n: usize) -> Option<Grid> {
        match self {
            FaceSurface::Regular(cp) => Some(crate::limit_surface::patches::evaluate_patch(cp, n)),
            FaceSurface::Local { patch, root } => patch.grid(*root, n),
        }
    }

    /// [`FaceSurface::grid`] into `out`, whose memory a regular patch reuses.
    fn grid_into(&mut self, n: usize, out: &mut Grid) -> Option<()> {
        match self {
            FaceSurface::Regular(cp) => {
                crate::limit_surface::patches::evaluate_patch_into(cp, n, out)
            }
            FaceSurface::Local { patch, root } => *out = patch.grid(*root, n)?,
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
            let p = xf.apply(d.position[0], d.position[1]);
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        };
        match self {
            FaceSurface::Regular(cp) => cp.iter().flatten().for_each(&mut grow),
            FaceSurface::Local { .. } => {
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

    /// The local refinement to keep for the counts balancing asks for, if this is one.
    fn into_shared_patch(self) -> Option<Arc<Mutex<LocalPatch>>> {
        match self {
            FaceSurface::Local { patch, .. } => Some(Arc::new(Mutex::new(patch))),
            FaceSurface::Regular(_) => None,
        }
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
pub(crate) struct CellOrders(Vec<OnceLock<Vec<Cell>>>);

impl CellOrders {
    fn new(n_max: usize) -> CellOrders {
        CellOrders(
            (0..=n_max.trailing_zeros())
                .map(|_| OnceLock::new())
                .collect(),
        )
    }

    #[inline]
    pub fn get(&self, n: usize) -> &[Cell] {
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
                th.space.lab_jacobian(d.colour)
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
pub(crate) enum Order {
    Linear,
    /// Six-node triangles ([`super::quadratic`]).
    Quadratic,
}

/// One face's plan: cells a side, its grid, and how it measured.
#[derive(Clone)]
pub(crate) struct Plan {
    pub n: usize,
    /// The grid of `n` cells a side; empty where it is the even points of `finer` (a regular
    /// patch's grids share their points bit for bit), which saves a quadratic face an
    /// allocation and a copy. Read through [`Plan::at`].
    grid: Grid,
    pub measured: Measure,
    pub capped: bool,
    pub estimated: bool,
    /// The face's centre, kept when a one-cell plan was measured (the measure evaluates the
    /// grid of two cells): a one-cell face fanned to finer edges needs it.
    pub centre: Option<VertexData>,
    pub order: Order,
    /// A quadratic face's grid of `2 n` cells a side: its midpoint nodes.
    pub finer: Option<Grid>,
    /// A quadratic face's colour error with linear pieces, where measured at its count.
    linear_colour: Option<f64>,
}

impl Plan {
    /// One cell a side, with its `grid` (empty when the grid of two cells holds it).
    fn one_cell(grid: Grid) -> Plan {
        Plan {
            n: 1,
            grid,
            measured: Measure::default(),
            capped: false,
            estimated: false,
            centre: None,
            order: Order::Linear,
            finer: None,
            linear_colour: None,
        }
    }

    /// Point `(i, j)` of the face's grid of `n` cells a side.
    #[inline]
    pub fn at(&self, i: usize, j: usize) -> &VertexData {
        let (g, step) = self.grid_view();
        &g[step * (j * (step * self.n + 1) + i)]
    }

    /// The grid of `n` cells a side, and the step between its points in the slice.
    #[inline]
    pub fn grid_view(&self) -> (&[VertexData], usize) {
        match &self.finer {
            Some(g2) if self.grid.is_empty() => (g2, 2),
            _ => (&self.grid, 1),
        }
    }

    /// Takes linear pieces at this count, which measured `m` against the grid `finer` of
    /// `2 n` cells a side.
    fn accept_linear(&mut self, m: Measure, finer: Grid) {
        self.measured = m;
        if self.n == 1 {
            self.centre = Some(finer[4]);
        }
        if self.grid.is_empty() {
            self.grid = even_points(&finer, self.n);
        }
    }

    /// Takes quadratic pieces at this count, which measured `mq` (and `linear_colour` with
    /// linear pieces), with their nodes from the grid `finer` of `2 n` cells a side.
    fn accept_quadratic(&mut self, mq: Measure, linear_colour: f64, finer: Grid) {
        self.measured = mq;
        self.order = Order::Quadratic;
        self.linear_colour = Some(linear_colour);
        if self.n == 1 {
            self.centre = Some(finer[4]);
        }
        self.finer = Some(finer);
    }
}

/// What the measures of the last level a face tried saw, to predict the next level's from:
/// the colour error of linear pieces and of quadratic ones.
#[derive(Default)]
struct LastColourErrors {
    linear: Option<f64>,
    quadratic: Option<f64>,
}

impl LastColourErrors {
    /// The next level's figures with linear pieces, from this level's `m`. Size halves per
    /// level and the outline's distance quarters. The colour error of linear pieces quarters
    /// where the colour is smooth, but may only halve next to an extraordinary vertex or a
    /// fold: predict the rate it fell at over the last level, between the two (a half when
    /// there is no last level).
    fn predict_linear(&mut self, m: &Measure) -> Measure {
        let ratio = match self.linear {
            Some(prev) if prev > 0.0 => (m.colour / prev).clamp(0.25, 0.5),
            _ => 0.5,
        };
        self.linear = Some(m.colour);
        Measure {
            extent: 0.5 * m.extent,
            colour: ratio * m.colour,
            outline: 0.25 * m.outline,
        }
    }

    /// The next level's figures with quadratic pieces, whose colour error at this level is
    /// `colour`, from the linear prediction `linear`. Quadratic pieces' error falls by an
    /// eighth where the colour is smooth: the same prediction from the rate it fell at,
    /// between an eighth and a half.
    fn predict_quadratic(&mut self, colour: f64, linear: Measure) -> Measure {
        let ratio = match self.quadratic {
            Some(prev) if prev > 0.0 => (colour / prev).clamp(0.125, 0.5),
            _ => 0.5,
        };
        self.quadratic = Some(colour);
        Measure {
            colour: ratio * colour,
            ..linear
        }
    }
}

/// A face's plan as its last preparation left it (before balancing), shared rather than
/// copied: with the local refinement an irregular face was planned on, and its root there.
#[derive(Clone)]
pub(crate) enum CachedPlan {
    Regular(Arc<Plan>),
    Local(Arc<Plan>, Arc<Mutex<LocalPatch>>, usize),
}

/// The plans of a layer's last preparation a planning may take: those of the faces not
/// marked in `again`.
#[derive(Clone, Copy)]
pub(crate) struct EarlierPlans<'a> {
    pub plans: &'a [CachedPlan],
    pub again: &'a [bool],
}

impl<'a> EarlierPlans<'a> {
    fn get(&self, f: usize) -> Option<&'a CachedPlan> {
        (!self.again[f]).then(|| &self.plans[f])
    }
}

/// An irregular face's local refinement, shared by the faces refined together, and the face's
/// root there.
pub(crate) type SharedPatch = (Arc<Mutex<LocalPatch>>, usize);

/// Plans of one group of irregular faces: face, plan, local refinement and root there.
type GroupPlans = Vec<(usize, Arc<Plan>, Arc<Mutex<LocalPatch>>, usize)>;

/// Every face's plan.
pub(crate) struct FacePlans {
    pub plans: Vec<Arc<Plan>>,
    /// Each irregular face's local refinement, kept for the counts balancing asks for: cutting
    /// out and refining a face's neighbourhood alone again cost Glasses a tenth of a
    /// millisecond a face.
    pub local: Vec<Option<SharedPatch>>,
    /// Whether each face took its plan from [`EarlierPlans`].
    pub reused: Vec<bool>,
}

impl FacePlans {
    /// The plans as a cache keeps them.
    pub fn to_cached(&self) -> impl Iterator<Item = CachedPlan> + '_ {
        self.plans.iter().zip(&self.local).map(|(plan, local)| {
            let plan = Arc::clone(plan);
            match local {
                Some((patch, root)) => CachedPlan::Local(plan, Arc::clone(patch), *root),
                None => CachedPlan::Regular(plan),
            }
        })
    }
}

/// What planning reads: the base level, its data, and the measures' thresholds.
pub(crate) struct FacePlanner<'a> {
    level: &'a Level,
    t: &'a Topology,
    data: &'a [VertexData],
    /// Whether each vertex of the level is a regular corner ([`regular_corners`]).
    regular: Vec<bool>,
    shapes: &'a ShapeCache,
    xf: &'a ToPixels,
    th: &'a Thresholds,
    /// The most cells a side a face may take.
    n_max: usize,
    pub orders: CellOrders,
}

impl<'a> FacePlanner<'a> {
    pub fn new(
        level: &'a Level,
        data: &'a [VertexData],
        shapes: &'a ShapeCache,
        xf: &'a ToPixels,
        th: &'a Thresholds,
        n_max: usize,
    ) -> FacePlanner<'a> {
        FacePlanner {
            level,
            t: &level.topology,
            data,
            regular: regular_corners(level),
            shapes,
            xf,
            th,
            n_max,
            orders: CellOrders::new(n_max.max(1) * 2),
        }
    }

    fn passes(&self, m: &Measure) -> bool {
        let th = self.th;
        m.extent <= th.quad && m.colour <= th.colour && m.outline <= th.outline
    }

    /// Whether each side of face `f` lies on the outline.
    fn boundary_sides(&self, f: usize) -> [bool; 4] {
        let t = self.t;
        each4(|k| t.is_boundary_edge(t.face_edges(f)[k] as usize))
    }

    /// Plans face `f` on its `surface`: doubles its cells a side until they pass the measures
    /// (or are predicted to from the last level), with linear or quadratic pieces.
    fn plan_face(
        &self,
        f: usize,
        surface: &mut FaceSurface,
        scratch: &mut PlanScratch,
    ) -> Option<Plan> {
        let off_image = surface.off_image(self.level, self.data, f, self.xf, self.th.size);
        // A regular patch's grid of two cells holds its grid of one (the same parameters and
        // arithmetic): evaluate it once and read its corners from it (the grid stays empty
        // until the face is known to need it on its own). Local refinement evaluates each
        // depth on its own, so it keeps its order of evaluation.
        let regular_surface = matches!(surface, FaceSurface::Regular(_));
        let mut next = None;
        let grid = if regular_surface && !off_image && self.n_max > 1 {
            next = Some(surface.grid(2)?);
            Vec::new()
        } else {
            surface.grid(1)?
        };
        let mut plan = Plan::one_cell(grid);
        if off_image {
            return Some(plan);
        }
        let boundary = self.boundary_sides(f);
        let mut last = LastColourErrors::default();
        loop {
            if plan.n >= self.n_max {
                plan.capped = true;
                return Some(plan);
            }
            let finer = match next.take() {
                Some(g) => g,
                None => surface.grid(2 * plan.n)?,
            };
            // The grid of `n`: the plan's, or the even points of the finer one.
            let (coarse, step) = if plan.grid.is_empty() {
                (&finer[..], 2)
            } else {
                (&plan.grid[..], 1)
            };
            let cells = self.orders.get(plan.n);
            let m = measure_grid(
                coarse,
                step,
                plan.n,
                &finer,
                cells,
                boundary,
                self.xf,
                self.th,
                &mut scratch.counted,
                &mut scratch.jacobians,
            );
            if self.passes(&m) {
                plan.accept_linear(m, finer);
                return Some(plan);
            }
            // Quadratic colour at this count, measured against the grid of `4 n` (which the
            // next level measures against its nodes anyway). Not where the face's own cells
            // fold (which sheet shows there is the linear path's business), nor where the
            // linear error says the cells are coarse for the colour's features: the quarter
            // points can then miss the error between them.
            let mut quadratic = None;
            if self.th.quadratic
                && m.colour <= QUADRATIC_MAX_LINEAR_ERROR * self.th.colour
                && turn_flags(coarse, step, plan.n) != 3
            {
                surface.grid_into(4 * plan.n, &mut scratch.quarter)?;
                let colour = self.quadratic_colour(&finer, plan.n, scratch);
                let mq = Measure { colour, ..m };
                if self.passes(&mq) {
                    plan.accept_quadratic(mq, m.colour, finer);
                    return Some(plan);
                }
                quadratic = Some(colour);
                next = Some(std::mem::take(&mut scratch.quarter));
            }
            let predicted = last.predict_linear(&m);
            plan.n *= 2;
            plan.grid = finer;
            plan.measured = predicted;
            plan.estimated = true;
            if self.passes(&predicted) {
                return Some(plan);
            }
            if let Some(colour) = quadratic {
                let predicted = last.predict_quadratic(colour, predicted);
                if self.passes(&predicted) && turn_flags(&plan.grid, 1, plan.n) != 3 {
                    plan.measured = predicted;
                    plan.order = Order::Quadratic;
                    plan.finer = next.take();
                    if regular_surface && plan.finer.is_some() {
                        plan.grid = Vec::new();
                    }
                    return Some(plan);
                }
            }
        }
    }

    /// The colour error of quadratic pieces on a face's grid of `n` cells a side, with their
    /// nodes from its grid `finer` of `2 n`, against the grid of `4 n` in `scratch.quarter`
    /// (after the linear measure of the same cells filled `scratch`'s other buffers).
    fn quadratic_colour(&self, finer: &[VertexData], n: usize, scratch: &mut PlanScratch) -> f64 {
        measure_cells(
            finer,
            &scratch.quarter,
            n,
            self.orders.get(n),
            &scratch.counted,
            self.xf,
            self.th.space,
            needs_jacobians(self.th.space).then_some(&scratch.jacobians[..]),
            &mut scratch.side_nodes,
        )
    }

    /// Plans every face: regular faces first, each on its own, then the others by local
    /// refinement; faces `earlier` has a plan for take it instead.
    pub fn plan_all(&self, earlier: Option<EarlierPlans<'_>>) -> Option<FacePlans> {
        let nf = self.t.face_count();
        let cached = |f: usize| earlier.and_then(|e| e.get(f));
        let planned: Vec<(Option<Arc<Plan>>, bool)> = each_face_with(nf, |scratch, f| {
            if let Some(CachedPlan::Regular(plan)) = cached(f) {
                return Some((Some(Arc::clone(plan)), true));
            }
            let Some(cp) = regular_patch_with(self.level, self.data, f, |v| self.regular[v]) else {
                return Some((None, false));
            };
            let plan = self.plan_face(f, &mut FaceSurface::Regular(cp), scratch)?;
            Some((Some(Arc::new(plan)), false))
        })?;
        let mut reused: Vec<bool> = planned.iter().map(|p| p.1).collect();
        let mut plans: Vec<Option<Arc<Plan>>> = planned.into_iter().map(|p| p.0).collect();
        let mut local: Vec<Option<SharedPatch>> = vec![None; nf];
        let irregular = self.irregular_groups(&plans);
        let groups: Vec<&[(usize, usize)]> = irregular.chunk_by(|a, b| a.0 == b.0).collect();
        let planned: Vec<(GroupPlans, bool)> = groups
            .par_iter()
            .map(|&group| {
                if let Some(kept) = self.cached_group(group, &cached) {
                    return Some((kept, true));
                }
                // Neighbourhoods that do not form a valid mesh together may do so one by one.
                (group.len() > 1)
                    .then(|| self.plan_together(group))
                    .flatten()
                    .or_else(|| self.plan_each_alone(group))
                    .map(|planned| (planned, false))
            })
            .collect::<Option<_>>()?;
        for (group, kept) in planned {
            for (f, plan, patch, root) in group {
                plans[f] = Some(plan);
                local[f] = Some((patch, root));
                reused[f] = kept;
            }
        }
        let plans = plans
            .into_iter()
            .map(|p| p.expect("every face is planned"))
            .collect();
        Some(FacePlans {
            plans,
            local,
            reused,
        })
    }

    /// The faces without a plan, as `(key, face)` sorted by key: their first corner that is
    /// not regular (for most, the extraordinary vertex they surround). A group of one key
    /// shares one local refinement.
    fn irregular_groups(&self, plans: &[Option<Arc<Plan>>]) -> Vec<(usize, usize)> {
        let t = self.t;
        let mut irregular: Vec<(usize, usize)> = (0..t.face_count())
            .filter(|&f| plans[f].is_none())
            .map(|f| {
                let corner = t
                    .face_vertices(f)
                    .iter()
                    .find(|&&v| !self.regular[v as usize]);
                (corner.map_or(t.vertex_count() + f, |&v| v as usize), f)
            })
            .collect();
        irregular.sort_unstable();
        irregular
    }

    /// The cached plans and local refinement of a group the edit left alone.
    fn cached_group<'e>(
        &self,
        group: &[(usize, usize)],
        cached: &impl Fn(usize) -> Option<&'e CachedPlan>,
    ) -> Option<GroupPlans> {
        group
            .iter()
            .map(|&(_, f)| match cached(f)? {
                CachedPlan::Local(plan, patch, root) => {
                    Some((f, Arc::clone(plan), Arc::clone(patch), *root))
                }
                CachedPlan::Regular(_) => None,
            })
            .collect()
    }

    /// A group's faces planned on one local refinement of them all. Faces of one group take
    /// turns at its lock; what runs under it stays on its thread (see `patches::LocalShape`).
    fn plan_together(&self, group: &[(usize, usize)]) -> Option<GroupPlans> {
        let faces: Vec<usize> = group.iter().map(|&(_, f)| f).collect();
        let mut surface = FaceSurface::Local {
            patch: LocalPatch::new(self.level, self.data, &faces, self.shapes)?,
            root: 0,
        };
        let mut planned = Vec::with_capacity(faces.len());
        let mut scratch = PlanScratch::default();
        for (k, &f) in faces.iter().enumerate() {
            if let FaceSurface::Local { root, .. } = &mut surface {
                *root = k;
            }
            planned.push((f, self.plan_face(f, &mut surface, &mut scratch)?));
        }
        let patch = surface.into_shared_patch()?;
        Some(
            planned
                .into_iter()
                .enumerate()
                .map(|(k, (f, plan))| (f, Arc::new(plan), Arc::clone(&patch), k))
                .collect(),
        )
    }

    /// A group's faces planned each on a local refinement of its own.
    fn plan_each_alone(&self, group: &[(usize, usize)]) -> Option<GroupPlans> {
        let mut scratch = PlanScratch::default();
        group
            .iter()
            .map(|&(_, f)| {
                let mut surface =
                    FaceSurface::new(self.level, &self.regular, self.data, f, self.shapes)?;
                let plan = self.plan_face(f, &mut surface, &mut scratch)?;
                Some((f, Arc::new(plan), surface.into_shared_patch()?, 0))
            })
            .collect()
    }

    /// Face `f`'s grid of `n` cells a side, from its kept local refinement if it has one.
    pub fn regrid(&self, local: &[Option<SharedPatch>], f: usize, n: usize) -> Option<Grid> {
        match &local[f] {
            Some((patch, root)) => patch
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .grid(*root, n),
            None => FaceSurface::new(self.level, &self.regular, self.data, f, self.shapes)?.grid(n),
        }
    }

    /// Counts per edge: the finer face's. A face is first refined to at least half of its
    /// finest edge (2:1 balance with the faces' own densities: the faces around a deeply
    /// refined spot, often a fold near a singular point, follow its shape closely). A coarser
    /// face then fans its boundary cells out to the edge's extra samples (see
    /// [`stitch`](crate::render::tessellate::stitch)).
    pub fn balance(&self, faces: &mut FacePlans) -> Option<()> {
        let t = self.t;
        let own_edge_cells = edge_counts(t, &faces.plans);
        let turns: Vec<u8> = faces
            .plans
            .par_iter()
            .map(|p| {
                let (g, step) = p.grid_view();
                turn_flags(g, step, p.n)
            })
            .collect();
        let local = &faces.local;
        faces
            .plans
            .par_iter_mut()
            .enumerate()
            .map(|(f, plan)| {
                let finest_edge = t
                    .face_edges(f)
                    .iter()
                    .map(|&e| own_edge_cells[e as usize])
                    .max()
                    .unwrap_or(1);
                let n = if folded(t, &turns, f) {
                    plan.n.max(finest_edge)
                } else {
                    plan.n.max(finest_edge / 2)
                };
                if n != plan.n {
                    self.refine_plan(Arc::make_mut(plan), local, f, n)?;
                }
                Some(())
            })
            .collect::<Option<Vec<()>>>()?;
        Some(())
    }

    /// Face `f`'s `plan` at `n` cells a side, more than it planned, for its neighbours' sake.
    fn refine_plan(
        &self,
        plan: &mut Plan,
        local: &[Option<SharedPatch>],
        f: usize,
        n: usize,
    ) -> Option<()> {
        // A quadratic face refined further for its neighbours' sake is often fine enough for
        // linear pieces, which need no grid of twice the count for their nodes: predicted
        // from the linear error at its own count, falling by no more than
        // LINEAR_RATE_NEAR_FOLDS a level.
        let levels = (n / plan.n).trailing_zeros() as i32;
        let linear = plan
            .linear_colour
            .map(|c| c * LINEAR_RATE_NEAR_FOLDS.powi(levels))
            .filter(|&c| c <= self.th.colour);
        if let (Order::Quadratic, Some(colour)) = (plan.order, linear) {
            plan.order = Order::Linear;
            plan.measured.colour = colour;
            plan.estimated = true;
        }
        // A regular patch's quadratic face reads its grid from the finer one.
        let quadratic = plan.order == Order::Quadratic;
        plan.grid = if quadratic && local[f].is_none() {
            Vec::new()
        } else {
            self.regrid(local, f, n)?
        };
        plan.finer = if quadratic {
            Some(self.regrid(local, f, 2 * n)?)
        } else {
            None
        };
        plan.n = n;
        Some(())
    }
}

/// Cells per edge of `t`: the most of its faces'.
pub(crate) fn edge_counts(t: &Topology, plans: &[Arc<Plan>]) -> Vec<usize> {
    let nf = t.face_count();
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
}

/// Whether face `f` takes the full count of its finest edge instead of half: where the
/// surface folds over itself, which sheet shows at a pixel depends on where the fold's crease
/// runs, which no measure checks. So faces whose cells do not all turn the same way
/// (`turns`: [`turn_flags`] per face), and faces next to them or next to a face turned the
/// other way, take the count uniform refinement would give them.
fn folded(t: &Topology, turns: &[u8], f: usize) -> bool {
    let nf = t.face_count();
    turns[f] == 3
        || t.face_edges(f).iter().any(|&e| {
            t.edge_faces(e as usize)
                .iter()
                .any(|&g| (g as usize) < nf && (turns[g as usize] | turns[f]) == 3)
        })
}

/// `f` of every face `0..nf`, on all cores, or `None` if any is `None`. The results are
/// written straight into place (an indexed collect): collected as an `Option` of a vector,
/// rayon gathered them in a list of pieces and copied them twice more, which for 90,000 faces
/// of plans was a tenth of planning.
pub(crate) fn each_face<T: Send>(
    nf: usize,
    f: impl Fn(usize) -> Option<T> + Sync + Send,
) -> Option<Vec<T>> {
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
                g[y * s + x * step].position
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
