//! The triangles of [`super::adaptive`]'s planned faces, stitched along their edges: each edge
//! takes the larger count of its two faces and both read its samples from the same face, and
//! a face coarser than an edge fans its cells along it out to the edge's extra samples, so
//! that no T-junction and no crack is left.

use std::sync::Arc;

use rayon::prelude::*;

use crate::topology::Topology;
use crate::validate::VertexData;

use super::nearest::Segment;
use crate::limit_surface::patches::Grid;
use crate::render::arrays::{each3, each4};
use crate::render::plan::face_plans::{
    each_face, edge_counts, CellOrders, FacePlanner, FacePlans, Order, Plan,
};
use crate::render::plan::quadratic::{chord_node, screen_gradient, Cell, Quadratic};
use crate::render::raster::triangles::{snap, Bounds, Triangle, UNBOUNDED};
use crate::view::ToPixels;

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

/// The mean of two samples' attributes.
#[inline]
fn mean(a: &VertexData, b: &VertexData) -> [f64; 4] {
    let (a, b) = (a.attributes(), b.attributes());
    each4(|k| 0.5 * (a[k] + b[k]))
}

/// The bounds of the colours of the base level's points `data` (whose convex hull holds the
/// limit surface), when some face is quadratic: quadratic triangles are clamped to them.
pub(crate) fn colour_bounds(plans: &[Arc<Plan>], data: &[VertexData]) -> Option<Bounds> {
    plans.iter().any(|p| p.order == Order::Quadratic).then(|| {
        let mut b = [[f32::INFINITY; 4], [f32::NEG_INFINITY; 4]];
        for p in data {
            let attr = p.attributes();
            for k in 0..4 {
                // Widened by a millionth: the f32 of a value may lie on either side of it.
                let v = attr[k] as f32;
                let margin = 1e-6 * (1.0 + v.abs());
                b[0][k] = b[0][k].min(v - margin);
                b[1][k] = b[1][k].max(v + margin);
            }
        }
        b
    })
}

/// Where an edge's samples are read: the side `side` of face `face`, which runs it from its
/// first vertex to its second if `forward`.
#[derive(Clone, Copy)]
struct EdgeOwner {
    face: u32,
    side: u8,
    forward: bool,
}

/// The balanced plans of a layer's faces and the samples their edges and vertices share.
pub(crate) struct Stitching<'a> {
    t: &'a Topology,
    plans: &'a [Arc<Plan>],
    orders: &'a CellOrders,
    xf: &'a ToPixels,
    size: (i64, i64),
    /// The colour bounds quadratic triangles are clamped to.
    clamp_to: Bounds,
    /// Cells per edge.
    edge_cells: Vec<usize>,
    /// Each edge's samples from its first face of the edge's count. They are read from those
    /// faces' grids where needed rather than copied (fresh memory costs page faults).
    edge_owners: Vec<EdgeOwner>,
    /// Each vertex's sample, from its first face. Copied, unlike the edges': every face reads
    /// four, and one read here is one cache miss instead of a chain of them.
    vertex_samples: Vec<VertexData>,
    /// Whether every face on each edge is quadratic.
    edge_quadratic: Vec<bool>,
    /// The centre of each face of one cell with a finer edge, which is fanned from it.
    centres: Vec<Option<VertexData>>,
}

impl<'a> Stitching<'a> {
    /// The stitching of `faces` (balanced), whose one-cell faces without a centre take it
    /// from `planner`; `bounds`: see [`colour_bounds`].
    pub fn new(
        planner: &'a FacePlanner<'a>,
        t: &'a Topology,
        faces: &'a FacePlans,
        xf: &'a ToPixels,
        size: (i64, i64),
        bounds: Option<&Bounds>,
    ) -> Option<Stitching<'a>> {
        let plans = &faces.plans[..];
        let nf = t.face_count();
        let edge_cells = edge_counts(t, plans);
        let centres: Vec<Option<VertexData>> = each_face(nf, |f| {
            let finer = t
                .face_edges(f)
                .iter()
                .any(|&e| edge_cells[e as usize] > plans[f].n);
            if plans[f].n == 1 && finer {
                match plans[f].centre {
                    Some(c) => Some(Some(c)),
                    None => planner.regrid(&faces.local, f, 2).map(|g| Some(g[4])),
                }
            } else {
                Some(None)
            }
        })?;
        let edge_owners = edge_owners(t, plans, &edge_cells);
        let vertex_samples = vertex_samples(t, plans);
        // An edge is quadratic where every face on it is: its nodes are then the owner's finer
        // samples moved to the chords' midpoints (see `plan::quadratic`), which both sides
        // compute alike; elsewhere they are the mean of the segment's ends, the colour a
        // linear face (or its fan) draws along it.
        let edge_quadratic: Vec<bool> = (0..t.edge_count())
            .into_par_iter()
            .map(|e| {
                t.edge_faces(e)
                    .iter()
                    .filter(|&&g| (g as usize) < nf)
                    .all(|&g| plans[g as usize].order == Order::Quadratic)
            })
            .collect();
        Some(Stitching {
            t,
            plans,
            orders: &planner.orders,
            xf,
            size,
            clamp_to: *bounds.unwrap_or(&UNBOUNDED),
            edge_cells,
            edge_owners,
            vertex_samples,
            edge_quadratic,
            centres,
        })
    }

    #[inline]
    fn px(&self, d: &VertexData) -> [f64; 2] {
        self.xf.apply(d.position[0], d.position[1])
    }

    /// Sample `s` (`0..=ne`) of edge `e`, from its first vertex.
    #[inline]
    fn edge_sample(&self, e: usize, s: usize) -> &'a VertexData {
        let EdgeOwner {
            face,
            side,
            forward,
        } = self.edge_owners[e];
        let plan: &'a Plan = &self.plans[face as usize];
        let (m, ne) = (plan.n, self.edge_cells[e]);
        let q = if forward { s } else { ne - s };
        let (i, j) = side_position(side as usize, q * (m / ne), m);
        plan.at(i, j)
    }

    /// The sample at position `s` (`0..=ne`) of edge `fe[k]`, counted from the face's corner
    /// `k` (`fv`, `fe`: the face's vertices and edges).
    #[inline]
    fn side_sample(&self, fv: &[u32], fe: &[u32], k: usize, s: usize) -> &'a VertexData {
        let e = fe[k] as usize;
        let ne = self.edge_cells[e];
        let forward = fv[k] == self.t.edge_vertices(e)[0];
        self.edge_sample(e, if forward { s } else { ne - s })
    }

    /// Grid point `(i, j)` of face `f` as drawn: its corners are the vertices' samples, its
    /// sides the edges' (at the face's own count), the rest its own.
    #[inline]
    fn face_sample(&self, f: usize, (i, j): (usize, usize)) -> &VertexData {
        let t = self.t;
        let plan: &'a Plan = &self.plans[f];
        let m = plan.n;
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
            None => plan.at(i, j),
            Some((k, 0)) => &self.vertex_samples[t.face_vertices(f)[k] as usize],
            Some((k, q)) if q == m => {
                &self.vertex_samples[t.face_vertices(f)[(k + 1) % 4] as usize]
            }
            Some((k, q)) => {
                let (fv, fe) = (t.face_vertices(f), t.face_edges(f));
                let r = self.edge_cells[fe[k] as usize] / m;
                self.side_sample(fv, fe, k, q * r)
            }
        }
    }

    /// The node of segment `s` (from sample `s` to `s + 1`, counted from the edge's first
    /// vertex) of edge `e`.
    #[inline]
    fn edge_node(&self, e: usize, s: usize) -> [f64; 4] {
        let (a, b) = (self.edge_sample(e, s), self.edge_sample(e, s + 1));
        let EdgeOwner {
            face,
            side,
            forward,
        } = self.edge_owners[e];
        let plan = &self.plans[face as usize];
        match (&plan.finer, self.edge_quadratic[e]) {
            (Some(g2), true) => {
                let (m, ne) = (plan.n, self.edge_cells[e]);
                let q = if forward { s } else { ne - 1 - s };
                let (i, j) = side_position(side as usize, 2 * q + 1, 2 * m);
                let gradient = screen_gradient(g2, 2 * m + 1, (i, j), self.xf);
                let mid = &g2[j * (2 * m + 1) + i];
                chord_node(self.px(a), self.px(b), mid, &gradient, self.xf)
            }
            _ => mean(a, b),
        }
    }

    /// The node of the segment of face side `k` between its positions `sa` and `sb`
    /// (adjacent, at the edge's count, counted from the face's corner `k`).
    #[inline]
    fn side_node(&self, fv: &[u32], fe: &[u32], k: usize, sa: usize, sb: usize) -> [f64; 4] {
        let e = fe[k] as usize;
        let lo = sa.min(sb);
        let forward = fv[k] == self.t.edge_vertices(e)[0];
        self.edge_node(
            e,
            if forward {
                lo
            } else {
                self.edge_cells[e] - 1 - lo
            },
        )
    }

    /// Appends face `f`'s triangles to `out`: two per cell, cells along a finer edge fanned
    /// out to its samples.
    pub fn face_triangles(&self, out: &mut Vec<Triangle>, f: usize) {
        let t = self.t;
        let plan = &self.plans[f];
        let m = plan.n;
        let (fv, fe) = (t.face_vertices(f), t.face_edges(f));
        let face = FaceDrawing {
            st: self,
            f,
            m,
            fv,
            fe,
            ratio: each4(|k| self.edge_cells[fe[k] as usize] / m),
            g2: plan
                .finer
                .as_ref()
                .filter(|_| plan.order == Order::Quadratic),
        };
        let mut polygon: Vec<&VertexData> = Vec::new();
        // Quadratic faces: the node of each polygon side, from vertex `i` to `i + 1`.
        let mut nodes: Vec<[f64; 4]> = Vec::new();
        for cell in self.orders.get(m) {
            let refined = face.refined_sides(cell);
            if refined.iter().all(Option::is_none) {
                face.whole_cell(out, cell);
                continue;
            }
            // The cell with the edge's samples on its refined sides, fanned from a corner on
            // none of them (with two or more cells a side, a cell touches at most two adjacent
            // face sides), or else from the face's centre.
            let apex = (0..4).find(|&c| refined[c].is_none() && refined[(c + 3) % 4].is_none());
            face.fan_polygon(cell, refined, apex, &mut polygon, &mut nodes);
            match face.g2 {
                None => face.linear_fan(out, apex, &polygon),
                Some(g2) => face.quadratic_fan(out, g2, cell, apex, &polygon, &nodes),
            }
        }
    }

    /// The boundary of the tessellation, loop by loop: the segments between the samples of
    /// boundary edges that snap to the pixel grid, for outline pixels no triangle covers.
    pub fn boundary_segments(&self) -> Vec<Segment> {
        let t = self.t;
        let mut segments = Vec::new();
        for lp in crate::limit_surface::boundary::boundary_loops(t) {
            for i in 0..lp.len() {
                let (a, b) = (lp[i], lp[(i + 1) % lp.len()]);
                let Some(&e) = t.vertex_edges(a as usize).iter().find(|&&e| {
                    t.is_boundary_edge(e as usize) && t.other_vertex(e as usize, a) == b
                }) else {
                    continue;
                };
                let reversed = t.edge_vertices(e as usize)[0] != a;
                self.edge_segments(e as usize, reversed, &mut segments);
            }
        }
        segments
    }

    /// Appends boundary edge `e`'s segments to `segments`, from its second vertex if
    /// `reversed`.
    fn edge_segments(&self, e: usize, reversed: bool, segments: &mut Vec<Segment>) {
        let ne = self.edge_cells[e];
        let mut s: Vec<VertexData> = (0..=ne).map(|q| *self.edge_sample(e, q)).collect();
        let mut nodes: Vec<[f64; 4]> = (0..ne).map(|q| self.edge_node(e, q)).collect();
        if reversed {
            s.reverse();
            nodes.reverse();
        }
        let xf = self.xf;
        for (w, node) in s.windows(2).zip(&nodes) {
            let (pa, pb) = (
                xf.apply(w[0].position[0], w[0].position[1]),
                xf.apply(w[1].position[0], w[1].position[1]),
            );
            let snappable = |p: [f64; 2]| snap(p[0]).is_some() && snap(p[1]).is_some();
            if snappable(pa) && snappable(pb) {
                let c = |d: &VertexData| d.attributes().map(|x| x as f32);
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

/// Each edge's [`EdgeOwner`]: its first face of the edge's count.
fn edge_owners(t: &Topology, plans: &[Arc<Plan>], edge_cells: &[usize]) -> Vec<EdgeOwner> {
    let nf = t.face_count();
    (0..t.edge_count())
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
            EdgeOwner {
                face: owner,
                side: k as u8,
                forward,
            }
        })
        .collect()
}

/// Each vertex's sample, from its first face.
fn vertex_samples(t: &Topology, plans: &[Arc<Plan>]) -> Vec<VertexData> {
    (0..t.vertex_count())
        .into_par_iter()
        .map(|v| {
            let (Some(&f), Some(&c)) =
                (t.vertex_faces(v).first(), t.vertex_face_corners(v).first())
            else {
                return VertexData::ZERO;
            };
            let m = plans[f as usize].n;
            let (i, j) = side_position(c as usize, 0, m);
            *plans[f as usize].at(i, j)
        })
        .collect()
}

/// One face being drawn: what its cells read.
struct FaceDrawing<'s, 'a> {
    st: &'s Stitching<'a>,
    f: usize,
    /// Cells a side.
    m: usize,
    fv: &'a [u32],
    fe: &'a [u32],
    /// Extra samples per cell side along each face side.
    ratio: [usize; 4],
    /// A quadratic face's grid of `2 m` cells a side.
    g2: Option<&'a Grid>,
}

impl<'s, 'a> FaceDrawing<'s, 'a> {
    /// The position along face side `k` of grid point `(i, j)`, if it lies on that side.
    #[inline]
    fn on_side(&self, k: usize, (i, j): (usize, usize)) -> Option<usize> {
        let m = self.m;
        match k {
            0 => (j == 0).then_some(i),
            1 => (i == m).then_some(j),
            2 => (j == m).then_some(m - i),
            _ => (i == 0).then_some(m - j),
        }
    }

    #[inline]
    fn sample(&self, p: (usize, usize)) -> &'s VertexData {
        self.st.face_sample(self.f, p)
    }

    /// Which sides of `cell` lie along a face side with extra samples: that side.
    #[inline]
    fn refined_sides(&self, cell: &Cell) -> [Option<usize>; 4] {
        each4(|c| {
            let (a, b) = (cell[c], cell[(c + 1) % 4]);
            (0..4).find(|&k| {
                self.ratio[k] > 1 && self.on_side(k, a).is_some() && self.on_side(k, b).is_some()
            })
        })
    }

    /// The face's own node between adjacent grid points `a` and `b` (quadratic faces).
    #[inline]
    fn own_node(&self, g2: &Grid, a: (usize, usize), b: (usize, usize)) -> [f64; 4] {
        let (m, xf) = (self.m, self.st.xf);
        let mid = (a.0 + b.0, a.1 + b.1);
        let gradient = screen_gradient(g2, 2 * m + 1, mid, xf);
        let d = &g2[mid.1 * (2 * m + 1) + mid.0];
        let (pa, pb) = (self.st.px(self.sample(a)), self.st.px(self.sample(b)));
        chord_node(pa, pb, d, &gradient, xf)
    }

    /// The node drawn between adjacent grid points `a` and `b` not on a refined side: the
    /// edge's along a face side, the face's own inside.
    #[inline]
    fn cell_node(&self, g2: &Grid, a: (usize, usize), b: (usize, usize)) -> [f64; 4] {
        for k in 0..4 {
            if let (Some(sa), Some(sb)) = (self.on_side(k, a), self.on_side(k, b)) {
                return self.st.side_node(self.fv, self.fe, k, sa, sb);
            }
        }
        self.own_node(g2, a, b)
    }

    /// Appends the triangle through `d` (quadratic with the side nodes `mids`) to `out`, if
    /// it may cover a pixel centre of the image.
    #[inline]
    fn push(&self, out: &mut Vec<Triangle>, d: [&VertexData; 3], mids: Option<[[f64; 4]; 3]>) {
        let st = self.st;
        if let Some(x) = screen_triangle(d, mids, &st.clamp_to, st.xf, st.size) {
            out.push(x);
        }
    }

    /// A cell with no refined side: its two triangles.
    #[inline]
    fn whole_cell(&self, out: &mut Vec<Triangle>, cell: &Cell) {
        let q = each4(|k| self.sample(cell[k]));
        // Most cells of a dense face cover no pixel centre: skip their nodes.
        if between_pixel_centres(q.map(|d| self.st.px(d))) {
            return;
        }
        match self.g2 {
            None => {
                self.push(out, [q[0], q[1], q[2]], None);
                self.push(out, [q[0], q[2], q[3]], None);
            }
            Some(g2) => {
                let s = each4(|k| self.cell_node(g2, cell[k], cell[(k + 1) % 4]));
                let diagonal = self.own_node(g2, cell[0], cell[2]);
                self.push(out, [q[0], q[1], q[2]], Some([s[0], s[1], diagonal]));
                self.push(out, [q[0], q[2], q[3]], Some([diagonal, s[2], s[3]]));
            }
        }
    }

    /// The polygon of a cell with the edge's samples on its `refined` sides, from corner
    /// `apex` (or 0), into `polygon`; for a quadratic face, the node of each polygon side
    /// into `nodes`.
    fn fan_polygon(
        &self,
        cell: &Cell,
        refined: [Option<usize>; 4],
        apex: Option<usize>,
        polygon: &mut Vec<&'s VertexData>,
        nodes: &mut Vec<[f64; 4]>,
    ) {
        polygon.clear();
        nodes.clear();
        let (fv, fe) = (self.fv, self.fe);
        for n in 0..4 {
            let c = (apex.unwrap_or(0) + n) % 4;
            polygon.push(self.sample(cell[c]));
            if let Some(k) = refined[c] {
                let ratio = self.ratio[k];
                let sa = self.on_side(k, cell[c]).expect("on the side") * ratio;
                let sb = self.on_side(k, cell[(c + 1) % 4]).expect("on the side") * ratio;
                let mut last = sa;
                for x in 1..=ratio {
                    let s = if sb > sa { sa + x } else { sa - x };
                    if x < ratio {
                        polygon.push(self.st.side_sample(fv, fe, k, s));
                    }
                    if self.g2.is_some() {
                        nodes.push(self.st.side_node(fv, fe, k, last, s));
                    }
                    last = s;
                }
            } else if let Some(g2) = self.g2 {
                nodes.push(self.cell_node(g2, cell[c], cell[(c + 1) % 4]));
            }
        }
    }

    /// A linear face's fan of `polygon`: from the face's centre when no corner is an `apex`.
    fn linear_fan(&self, out: &mut Vec<Triangle>, apex: Option<usize>, polygon: &[&VertexData]) {
        match (apex, &self.st.centres[self.f]) {
            (None, Some(centre)) => {
                for i in 0..polygon.len() {
                    let (a, b) = (polygon[i], polygon[(i + 1) % polygon.len()]);
                    self.push(out, [centre, a, b], None);
                }
            }
            // From the apex corner; (None, None) is not reached (a one-cell face with a finer
            // edge has a centre), and a fan from a corner is its graceful fallback.
            _ => {
                for w in polygon[1..].windows(2) {
                    self.push(out, [polygon[0], w[0], w[1]], None);
                }
            }
        }
    }

    /// A quadratic face's fan of `polygon` (with the `nodes` of its sides). The spokes' nodes
    /// come from the cell's own quadratic triangles (its own nodes on every side), at the
    /// spokes' midpoints.
    fn quadratic_fan(
        &self,
        out: &mut Vec<Triangle>,
        g2: &Grid,
        cell: &Cell,
        apex: Option<usize>,
        polygon: &[&VertexData],
        nodes: &[[f64; 4]],
    ) {
        let px = |d: &VertexData| self.st.px(d);
        let q = each4(|k| self.sample(cell[k]));
        let own = each4(|k| self.own_node(g2, cell[k], cell[(k + 1) % 4]));
        let diagonal = self.own_node(g2, cell[0], cell[2]);
        let triangle = |v: [usize; 3], mids: [[f64; 4]; 3]| Quadratic {
            p: v.map(|k| px(q[k])),
            c: v.map(|k| q[k].attributes()),
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
        match (apex, &self.st.centres[self.f]) {
            (None, Some(centre)) => {
                for i in 0..len {
                    let (a, b) = (polygon[i], polygon[(i + 1) % len]);
                    let mids = [spoke(centre, a), nodes[i], spoke(b, centre)];
                    self.push(out, [centre, a, b], Some(mids));
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
                    self.push(out, [polygon[0], a, b], Some([first, nodes[i], last]));
                }
            }
        }
    }
}

/// Whether points (pixels) surely lie between two adjacent columns, or two adjacent rows, of
/// pixel centres, so that no triangle through them covers a centre. Cheap, and sure: the
/// margin covers the snapping that the exact test (in [`screen_triangle_px`](crate::render::raster::triangles::screen_triangle_px))
/// works on.
pub(crate) fn between_pixel_centres<const N: usize>(p: [[f64; 2]; N]) -> bool {
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
/// (within the colour `bounds`), if it may cover a pixel centre of the image (see
/// [`screen_triangle_px`](crate::render::raster::triangles::screen_triangle_px)).
#[inline]
fn screen_triangle(
    d: [&VertexData; 3],
    mids: Option<[[f64; 4]; 3]>,
    bounds: &Bounds,
    xf: &ToPixels,
    size: (i64, i64),
) -> Option<Triangle> {
    let exact = each3(|k| xf.apply(d[k].position[0], d[k].position[1]));
    let attr = each3(|k| d[k].attributes());
    crate::render::raster::triangles::screen_triangle_px(exact, attr, mids, bounds, size)
}
