//! The fast path's tessellation: each face of a low all-quad level gets its own grid density.
//!
//! 1. **Density.** Each face of the base level ([`BASE_LEVEL`], shallower for meshes dense for
//!    the image: see [`base_level`]) is evaluated on grids of `1, 2, 4, ..`
//!    cells a side ([`patches`](super::patches): a B-spline patch where the face is regular,
//!    local refinement elsewhere) until its cells pass the same measure as the uniform path's
//!    quads (colour at cell and side centres against the triangles, cell size, outline). A face
//!    whose control points all lie off the image stays at one cell.
//! 2. **Stitching.** Each edge takes the larger count of its two faces, and each face is
//!    re-evaluated at the largest count of itself and its edges. The samples on an edge are
//!    copied from one face (the edge's first) to the other, and the samples at a vertex from the
//!    vertex's first face, so the two sides share bit-identical vertices. A face finer than one
//!    of its edges collapses its extra boundary samples onto the nearest shared one (those
//!    triangles vanish and their neighbours fan), so no T-junction is left: the snapped,
//!    top-left-rule rasteriser sees the same edges from both sides, without cracks.
//! 3. **Triangles.** Two per cell, faces in order, cells in the order (and with the diagonals) of
//!    the quads uniform refinement would make of the face, so folds overlap the same way.

use std::sync::OnceLock;

use rayon::prelude::*;

use crate::catmull_clark::Level;
use crate::colour::{ColourSpace, Matrix3};
use crate::refine::{RefinedMesh, Refinement};
use crate::rules;
use crate::validate::VertexData;

use super::layer::{measure_quad, Measure, QuadSamples, Thresholds};
use super::nearest::Segment;
use super::patches::{regular_patch, ControlGrid, Grid, LocalPatch};
use super::triangles::{snap, Triangle, TriangleList};
use super::view::ToPixels;

/// The level whose faces get their own density: all quads, extraordinary vertices isolated,
/// and faces small enough that irregular ones (refined locally) cover little of the layer.
pub(crate) const BASE_LEVEL: usize = 3;
/// The deepest base level tried when semi-sharp features still touch the outline.
const DEEPEST_BASE_LEVEL: usize = 4;
/// Dense meshes start shallower when level [`BASE_LEVEL`] would have fewer pixels than this
/// per face: building every face's patch then costs more than the pixels, and each face's own
/// grid refines it where the picture needs it anyway.
const MIN_BASE_FACE_PIXELS: usize = 16;

/// The base level for a layer drawn into `size` pixels: [`BASE_LEVEL`], or 2 when its faces
/// would be too many for the image, or 1 (when the ternary step made only quads) when even
/// level 2's would.
fn base_level(refinement: &Refinement, size: (i64, i64)) -> usize {
    let pixels = (size.0.max(0) as usize).saturating_mul(size.1.max(0) as usize);
    // Level 2 is all quads, so level 3 has four times its faces.
    let faces2 = refinement.topology(2).face_count();
    let too_many = |faces: usize| faces.saturating_mul(MIN_BASE_FACE_PIXELS) > pixels;
    if too_many(faces2) && refinement.topology(1).is_all_quads() {
        1
    } else if too_many(4 * faces2) {
        2
    } else {
        BASE_LEVEL
    }
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
}

/// How a face's limit surface is evaluated.
enum Source {
    Regular(Box<ControlGrid>),
    Local(LocalPatch),
}

impl Source {
    fn new(level: &Level, data: &[VertexData], f: usize) -> Option<Source> {
        match regular_patch(level, data, f) {
            Some(cp) => Some(Source::Regular(Box::new(cp))),
            None => LocalPatch::new(level, data, f).map(Source::Local),
        }
    }

    fn grid(&mut self, n: usize) -> Option<Grid> {
        match self {
            Source::Regular(cp) => Some(super::patches::evaluate_patch(cp, n)),
            Source::Local(p) => p.grid(n),
        }
    }

    /// Whether the convex hull of the points the surface is made of misses the image.
    fn off_image(&self, xf: &ToPixels, size: (f64, f64)) -> bool {
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
            Source::Local(p) => p.control_points().iter().for_each(&mut grow),
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

/// A cell of a face's grid: its corners `(i, j)`, wound like the face.
type Cell = [(usize, usize); 4];

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

/// Measures a face's grid of `n` cells a side against its grid of `2 n` (whose even samples
/// are the same points). `boundary[k]`: whether side `k` of the face lies on the outline.
fn measure_grid(
    g: &[VertexData],
    n: usize,
    g2: &[VertexData],
    cells: &[Cell],
    boundary: [bool; 4],
    xf: &ToPixels,
    th: &Thresholds,
) -> Measure {
    let (s1, s2) = (n + 1, 2 * n + 1);
    let at = |(i, j): (usize, usize)| &g[j * s1 + i];
    // The point halfway between two grid points, from the finer grid.
    let mid = |a: (usize, usize), b: (usize, usize)| &g2[(a.1 + b.1) * s2 + a.0 + b.0];
    // Which face side, if any, both ends of a cell side lie on.
    let on_side = |a: (usize, usize), b: (usize, usize)| -> bool {
        (a.1 == 0 && b.1 == 0 && boundary[0])
            || (a.0 == n && b.0 == n && boundary[1])
            || (a.1 == n && b.1 == n && boundary[2])
            || (a.0 == 0 && b.0 == 0 && boundary[3])
    };
    // Spaces whose distances are not (a multiple of) Lab's measure through the derivative at
    // each sample: one conversion per sample instead of two per comparison. The samples are
    // the points of the finer grid with an odd coordinate; the others are never asked for.
    let jacobians: Option<Vec<Matrix3>> =
        matches!(th.space, ColourSpace::Srgb | ColourSpace::SrgbLinear).then(|| {
            g2.iter()
                .enumerate()
                .map(|(k, d)| {
                    if (k % s2) % 2 == 0 && (k / s2) % 2 == 0 {
                        Matrix3::default()
                    } else {
                        th.space.lab_jacobian([d[2], d[3], d[4]])
                    }
                })
                .collect()
        });
    let jac = |a: (usize, usize), b: (usize, usize)| {
        jacobians.as_ref().map(|j| &j[(a.1 + b.1) * s2 + a.0 + b.0])
    };
    let mut m = Measure::default();
    for c in cells {
        let sides = [0, 1, 2, 3].map(|k| (c[k], c[(k + 1) % 4]));
        let q = QuadSamples {
            corners: c.map(at),
            centre: mid(c[0], c[2]),
            mids: sides.map(|(a, b)| mid(a, b)),
            boundary: sides.map(|(a, b)| on_side(a, b)),
            jacobians: jacobians.as_ref().map(|_| {
                let centre = jac(c[0], c[2]).expect("jacobians present");
                let mids = sides.map(|(a, b)| jac(a, b).expect("jacobians present"));
                [centre, mids[0], mids[1], mids[2], mids[3]]
            }),
        };
        m = m.max(measure_quad(&q, xf, th.size, th.space, th.min_quad, true));
    }
    m
}

/// One face's choice: cells a side, its grid, and how it measured.
struct Plan {
    n: usize,
    grid: Grid,
    measured: Measure,
    capped: bool,
    estimated: bool,
}

/// Tessellates the layer adaptively, or `None` where the fast path does not apply (a face
/// that is not a quad at the base level, a neighbourhood that is not a valid mesh on its own,
/// semi-sharpness on the outline down to [`DEEPEST_BASE_LEVEL`]): the caller then refines
/// uniformly.
pub(super) fn tessellate(
    refinement: &mut Refinement,
    data: &mut RefinedMesh,
    xf: &ToPixels,
    th: &Thresholds,
    max_level: usize,
    size: (i64, i64),
) -> Option<Tessellation> {
    // Faces refine on their own from the base level with bare stencils: it must lie below the
    // rings of the deepest multi-resolution edit.
    let mut k0 = base_level(refinement, size).max(refinement.base().edits.deepest_level() + 1);
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
    let boundary_sides = |f: usize| -> [bool; 4] {
        [0, 1, 2, 3].map(|k| t.is_boundary_edge(t.face_edges(f)[k] as usize))
    };

    // 1. The density of each face.
    let orders = CellOrders::new(n_max.max(1) * 2);
    let plan_face = |f: usize| -> Option<Plan> {
        let mut src = Source::new(level, d, f)?;
        let mut plan = Plan {
            n: 1,
            grid: src.grid(1)?,
            measured: Measure::default(),
            capped: false,
            estimated: false,
        };
        if src.off_image(xf, th.size) {
            return Some(plan);
        }
        let boundary = boundary_sides(f);
        loop {
            if plan.n >= n_max {
                plan.capped = true;
                return Some(plan);
            }
            let finer = src.grid(2 * plan.n)?;
            let m = measure_grid(
                &plan.grid,
                plan.n,
                &finer,
                orders.get(plan.n),
                boundary,
                xf,
                th,
            );
            if passes(&m) {
                plan.measured = m;
                return Some(plan);
            }
            // Colour and size halve at least per level; the outline's distance quarters.
            let predicted = Measure {
                extent: 0.5 * m.extent,
                colour: 0.5 * m.colour,
                outline: 0.25 * m.outline,
            };
            plan.n *= 2;
            plan.grid = finer;
            plan.measured = predicted;
            plan.estimated = true;
            if passes(&predicted) {
                return Some(plan);
            }
        }
    };
    let mut plans: Vec<Plan> = (0..nf)
        .into_par_iter()
        .map(plan_face)
        .collect::<Option<_>>()?;
    // 2. Counts per edge (the finer face's), per face the finest of itself and its edges.
    let edge_cells: Vec<usize> = (0..t.edge_count())
        .map(|e| {
            t.edge_faces(e)
                .iter()
                .filter(|&&g| (g as usize) < nf)
                .map(|&g| plans[g as usize].n)
                .max()
                .unwrap_or(1)
        })
        .collect();
    let cells: Vec<usize> = (0..nf)
        .map(|f| {
            t.face_edges(f)
                .iter()
                .map(|&e| edge_cells[e as usize])
                .fold(plans[f].n, usize::max)
        })
        .collect();
    plans
        .par_iter_mut()
        .enumerate()
        .map(|(f, plan)| {
            if cells[f] != plan.n {
                plan.grid = Source::new(level, d, f)?.grid(cells[f])?;
                plan.n = cells[f];
            }
            Some(())
        })
        .collect::<Option<Vec<()>>>()?;

    // The shared samples: each edge's from its first face (which runs it from its first
    // vertex to its second), each vertex's from its first face.
    let edge_samples: Vec<Vec<VertexData>> = (0..t.edge_count())
        .map(|e| {
            let owner = t
                .edge_faces(e)
                .into_iter()
                .find(|&g| (g as usize) < nf)
                .expect("an edge has a face") as usize;
            let k = t
                .face_edges(owner)
                .iter()
                .position(|&x| x as usize == e)
                .expect("an edge is a side of its face");
            let (m, ne) = (plans[owner].n, edge_cells[e]);
            let step = m / ne;
            let mut samples: Vec<VertexData> = (0..=ne)
                .map(|q| {
                    let (i, j) = side_position(k, q * step, m);
                    plans[owner].grid[j * (m + 1) + i]
                })
                .collect();
            if t.face_vertices(owner)[k] != t.edge_vertices(e)[0] {
                samples.reverse();
            }
            samples
        })
        .collect();
    let vertex_samples: Vec<VertexData> = (0..t.vertex_count())
        .map(|v| {
            let (Some(&f), Some(&c)) =
                (t.vertex_faces(v).first(), t.vertex_face_corners(v).first())
            else {
                return [0.0; 6];
            };
            let m = plans[f as usize].n;
            let (i, j) = side_position(c as usize, 0, m);
            plans[f as usize].grid[j * (m + 1) + i]
        })
        .collect();
    plans.par_iter_mut().enumerate().for_each(|(f, plan)| {
        let m = plan.n;
        let (fv, fe) = (t.face_vertices(f), t.face_edges(f));
        for k in 0..4 {
            let e = fe[k] as usize;
            let ne = edge_cells[e];
            let forward = fv[k] == t.edge_vertices(e)[0];
            for q in 0..=ne {
                let (i, j) = side_position(k, q * (m / ne), m);
                let s = if forward { q } else { ne - q };
                plan.grid[j * (m + 1) + i] = edge_samples[e][s];
            }
        }
        for k in 0..4 {
            let (i, j) = side_position(k, 0, m);
            plan.grid[j * (m + 1) + i] = vertex_samples[fv[k] as usize];
        }
    });

    // 3. Triangles.
    let face_triangles = |f: usize| -> Vec<Triangle> {
        let plan = &plans[f];
        let m = plan.n;
        let fe = t.face_edges(f);
        let steps = [0, 1, 2, 3].map(|k| m / edge_cells[fe[k] as usize]);
        // A boundary sample of the face's grid moves to the nearest sample its edge shares.
        let round = |s: usize, step: usize| (s + step / 2) / step * step;
        let canonical = |i: usize, j: usize| -> (usize, usize) {
            if j == 0 {
                (round(i, steps[0]), 0)
            } else if i == m {
                (m, round(j, steps[1]))
            } else if j == m {
                (m - round(m - i, steps[2]), m)
            } else if i == 0 {
                (0, m - round(m - j, steps[3]))
            } else {
                (i, j)
            }
        };
        let sample = |(i, j): (usize, usize)| &plan.grid[j * (m + 1) + i];
        let mut out = Vec::with_capacity(2 * m * m);
        for cell in orders.get(m) {
            let q = cell.map(|(i, j)| canonical(i, j));
            for tri in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
                if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
                    continue;
                }
                let d = tri.map(sample);
                if let Some(x) = screen_triangle(d, xf, size) {
                    out.push(x);
                }
            }
        }
        out
    };
    let triangles =
        TriangleList::from_chunks((0..nf).into_par_iter().map(face_triangles).collect());

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
            let mut s = edge_samples[e as usize].clone();
            if t.edge_vertices(e as usize)[0] != a {
                s.reverse();
            }
            for w in s.windows(2) {
                let (pa, pb) = (xf.apply(w[0][0], w[0][1]), xf.apply(w[1][0], w[1][1]));
                let snappable = |p: [f64; 2]| snap(p[0]).is_some() && snap(p[1]).is_some();
                if snappable(pa) && snappable(pb) {
                    let c = |d: &VertexData| [d[2], d[3], d[4], d[5]].map(|x| x as f32);
                    segments.push(Segment {
                        a: pa,
                        b: pb,
                        ca: c(&w[0]),
                        cb: c(&w[1]),
                    });
                }
            }
        }
    }

    let finest = plans.iter().map(|p| p.n).max().unwrap_or(1);
    Some(Tessellation {
        base_level: k0,
        level: k0 + finest.trailing_zeros() as usize,
        quads: plans.iter().map(|p| p.n * p.n).sum(),
        capped: plans.iter().any(|p| p.capped),
        measured: plans
            .iter()
            .map(|p| p.measured)
            .fold(Measure::default(), Measure::max),
        estimated: plans.iter().any(|p| p.estimated),
        triangles,
        segments,
    })
}

/// The triangle through three limit samples, in pixels, if it may cover a pixel centre of the
/// image (see [`super::layer::screen_triangle_px`]).
fn screen_triangle(d: [&VertexData; 3], xf: &ToPixels, size: (i64, i64)) -> Option<Triangle> {
    let exact = d.map(|d| xf.apply(d[0], d[1]));
    let attr = d.map(|d| [d[2], d[3], d[4], d[5]]);
    super::layer::screen_triangle_px(exact, attr, size)
}
