//! Quadratic colour over a face's cells: the six-node (P2) triangles of the fast path.
//!
//! Linear colour over triangles converges as the square of the cell size, so the colour
//! tolerance, not the pixels, sets the cell count where colour is smooth. A quadratic triangle
//! through its corners and its sides' midpoints converges as the cube, and needs far fewer
//! cells (the `vs_cairo` scene: 1.5k cells instead of 26.6k at 0.2 Delta E).
//!
//! The midpoint nodes sit at the midpoints of the drawn (straight) sides, but the surface's
//! sample at the parameter midpoint lies off that chord, by about the square of the side's
//! length times the curvature. Each node's colour is therefore that sample's colour moved
//! along the local screen gradient by the offset to the chord's midpoint: the error left is of
//! fourth order, and two triangles that share a side, given its ends and the same sample,
//! compute the same three nodes bit for bit, so the colour is continuous across every side.
//!
//! Near extraordinary vertices and folds the colour is not smooth enough for the cube: there
//! the faces stay linear (each face takes whichever passes first, see
//! [`face_plans`](super::face_plans)).

use crate::validate::VertexData;

use super::measure::sample_error;
use crate::colour::{ColourSpace, Matrix3};
use crate::render::arrays::each4;
use crate::view::ToPixels;

/// The screen gradient of the four attributes: `grad[k] = [d/dx, d/dy]`.
pub(crate) type Gradient = [[f64; 2]; 4];

/// A quadratic triangle in screen coordinates (pixels, double precision): corners `p` with
/// attributes `c`, and the attributes `m[k]` at the midpoint of the side from `p[k]` to
/// `p[k + 1]`.
pub(crate) struct Quadratic {
    pub p: [[f64; 2]; 3],
    pub c: [[f64; 4]; 3],
    pub m: [[f64; 4]; 3],
}

impl Quadratic {
    /// The attributes at `x` (extrapolated outside), or `None` for a triangle without area.
    pub fn eval(&self, x: [f64; 2]) -> Option<[f64; 4]> {
        Some(self.evaluator()?.eval(x))
    }

    /// The triangle ready to evaluate at many points: its map from the plane to barycentric
    /// coordinates, found once; `None` for a triangle without area.
    pub fn evaluator(&self) -> Option<QuadraticEvaluator<'_>> {
        let [a, b, c] = self.p;
        let (e1, e2) = ([b[0] - a[0], b[1] - a[1]], [c[0] - a[0], c[1] - a[1]]);
        let det = e1[0] * e2[1] - e1[1] * e2[0];
        let scale = (e1[0] * e1[0] + e1[1] * e1[1]).max(e2[0] * e2[0] + e2[1] * e2[1]);
        if !well_conditioned(det, scale) {
            return None;
        }
        Some(QuadraticEvaluator {
            q: self,
            l1: [e2[1] / det, -e2[0] / det],
            l2: [-e1[1] / det, e1[0] / det],
        })
    }
}

/// See [`Quadratic::evaluator`].
pub(crate) struct QuadraticEvaluator<'a> {
    q: &'a Quadratic,
    l1: [f64; 2],
    l2: [f64; 2],
}

impl QuadraticEvaluator<'_> {
    pub fn eval(&self, x: [f64; 2]) -> [f64; 4] {
        let q = self.q;
        let (dx, dy) = (x[0] - q.p[0][0], x[1] - q.p[0][1]);
        let l1 = self.l1[0] * dx + self.l1[1] * dy;
        let l2 = self.l2[0] * dx + self.l2[1] * dy;
        let l = [1.0 - l1 - l2, l1, l2];
        // Corner weights l (2 l - 1) and side weights 4 l_i l_j.
        let wc = [0, 1, 2].map(|i| l[i] * (2.0 * l[i] - 1.0));
        let wm = [0, 1, 2].map(|i| 4.0 * l[i] * l[(i + 1) % 3]);
        each4(|k| {
            wc[0] * q.c[0][k]
                + wc[1] * q.c[1][k]
                + wc[2] * q.c[2][k]
                + wm[0] * q.m[0][k]
                + wm[1] * q.m[1][k]
                + wm[2] * q.m[2][k]
        })
    }
}

/// Whether a determinant `det` is clearly non-zero for vectors whose squared length is about
/// `scale` (false for NaN).
fn well_conditioned(det: f64, scale: f64) -> bool {
    matches!(
        det.abs().partial_cmp(&(1e-9 * scale)),
        Some(std::cmp::Ordering::Greater)
    )
}

/// The attributes at the midpoint of the chord from `a` to `b` (pixels), from the surface's
/// sample `mid` there in parameter and the screen gradient `grad` at it.
pub(crate) fn chord_node(
    a: [f64; 2],
    b: [f64; 2],
    mid: &VertexData,
    grad: &Gradient,
    xf: &ToPixels,
) -> [f64; 4] {
    let at = xf.apply(mid.position[0], mid.position[1]);
    let (ox, oy) = (0.5 * (a[0] + b[0]) - at[0], 0.5 * (a[1] + b[1]) - at[1]);
    let attr = mid.attributes();
    each4(|k| attr[k] + grad[k][0] * ox + grad[k][1] * oy)
}

/// The screen gradient of the attributes at point `(i, j)` of a face's grid `g` of `side`
/// points a side (at least three), by differences of second order (one-sided on the face's
/// border); zero where the map to the screen is singular there.
pub(crate) fn screen_gradient(
    g: &[VertexData],
    side: usize,
    (i, j): (usize, usize),
    xf: &ToPixels,
) -> Gradient {
    // The points and weights of the difference at position `t` (a central one has a zero
    // third weight: one loop for all three cases).
    let stencil = |t: usize| -> ([usize; 3], [f64; 3]) {
        if t == 0 {
            ([0, 1, 2], [-1.5, 2.0, -0.5])
        } else if t == side - 1 {
            ([t, t - 1, t - 2], [1.5, -2.0, 0.5])
        } else {
            ([t + 1, t - 1, t], [0.5, -0.5, 0.0])
        }
    };
    let ((pi, wi), (pj, wj)) = (stencil(i), stencil(j));
    let (mut di, mut dj) = (VertexData::ZERO, VertexData::ZERO);
    for n in 0..3 {
        di.add_scaled(&g[j * side + pi[n]], wi[n]);
        dj.add_scaled(&g[pj[n] * side + i], wj[n]);
    }
    // The map to pixels is a scaling (and a shift, which differences drop).
    let (a, b) = (di.position[0] * xf.sx, di.position[1] * xf.sy);
    let (c, d) = (dj.position[0] * xf.sx, dj.position[1] * xf.sy);
    // Solve [dx/di dy/di; dx/dj dy/dj] [gx; gy] = [dC/di; dC/dj].
    let det = a * d - b * c;
    let scale = (a * a + b * b).max(c * c + d * d);
    if !well_conditioned(det, scale) {
        return [[0.0; 2]; 4];
    }
    let (di, dj) = (di.attributes(), dj.attributes());
    each4(|k| {
        let (ci, cj) = (di[k], dj[k]);
        [(ci * d - b * cj) / det, (a * cj - c * ci) / det]
    })
}

/// The corners of a cell (grid coordinates, wound like the face).
pub(crate) type Cell = [(usize, usize); 4];

/// The largest colour error of the quadratic triangles `(0, 1, 2)` and `(0, 2, 3)` of the
/// `cells` of a face's grid of `n` cells a side, whose nodes come from its grid `g2` of `2 n`
/// (the same points at even positions), against the samples of its grid `g4` of `4 n` at the
/// nine quarter points of each triangle (at their true screen positions). `counted[c]`: whether
/// cell `c`'s colour counts (see [`super::measure::measure_quad`]). `jacobians`: in spaces whose
/// distances are not Lab's, the derivative to Lab at the points of `g2` (those at the cells'
/// centres are read), from [`super::face_plans`]'s linear measure. Infinite where a counted
/// triangle has no area on the screen.
#[allow(clippy::too_many_arguments)]
pub(crate) fn measure_cells(
    g2: &[VertexData],
    g4: &[VertexData],
    n: usize,
    cells: &[Cell],
    counted: &[bool],
    xf: &ToPixels,
    space: ColourSpace,
    jacobians: Option<&[Matrix3]>,
    side_nodes: &mut Vec<Option<[f64; 4]>>,
) -> f64 {
    let (s2, s4) = (2 * n + 1, 4 * n + 1);
    let at2 = |(i, j): (usize, usize)| &g2[j * s2 + i];
    let at4 = |i: usize, j: usize| &g4[j * s4 + i];
    let px = |d: &VertexData| xf.apply(d.position[0], d.position[1]);
    let attr = |d: &VertexData| d.attributes();
    let node_at = |a: (usize, usize), b: (usize, usize)| {
        let m = (a.0 + b.0, a.1 + b.1);
        let (pa, pb) = (at2((2 * a.0, 2 * a.1)), at2((2 * b.0, 2 * b.1)));
        chord_node(px(pa), px(pb), at2(m), &screen_gradient(g2, s2, m, xf), xf)
    };
    // The nodes of the cells' sides, each found once (a side is shared by two cells): at
    // points of the finer grid with one odd coordinate, wanted where a counted cell is.
    side_nodes.clear();
    side_nodes.resize(s2 * s2, None);
    let mut worst = 0.0f64;
    for (cell, _) in cells.iter().zip(counted).filter(|(_, &c)| c) {
        let corner = |k: usize| at2((2 * cell[k].0, 2 * cell[k].1));
        let mut side = |k: usize| {
            let (a, b) = (cell[k], cell[(k + 1) % 4]);
            *side_nodes[(a.1 + b.1) * s2 + a.0 + b.0].get_or_insert_with(|| node_at(a, b))
        };
        let sides = [side(0), side(1), side(2), side(3)];
        let diagonal = node_at(cell[0], cell[2]);
        // Spaces whose distances are not Lab's are measured through the derivative to Lab at
        // the cell's centre (as the linear measure does at each sample): two conversions per
        // test would cost more than the rest of the measure.
        let centre = (cell[0].0 + cell[2].0, cell[0].1 + cell[2].1);
        let jacobian = jacobians.map(|j| &j[centre.1 * s2 + centre.0]);
        let p = each4(|k| px(corner(k)));
        let c = each4(|k| attr(corner(k)));
        let triangles = [
            ([0, 1, 2], [sides[0], sides[1], diagonal]),
            ([0, 2, 3], [diagonal, sides[2], sides[3]]),
        ];
        for (t, m) in triangles {
            let q = Quadratic {
                p: [p[t[0]], p[t[1]], p[t[2]]],
                c: [c[t[0]], c[t[1]], c[t[2]]],
                m,
            };
            let Some(q) = q.evaluator() else {
                return f64::INFINITY;
            };
            let v = [cell[t[0]], cell[t[1]], cell[t[2]]];
            let mut check = |(i, j): (usize, usize)| {
                let d = at4(i, j);
                let shown = q.eval(px(d));
                worst = worst.max(sample_error(space, attr(d), shown, jacobian));
            };
            for e in 0..3 {
                let (a, b, r) = (v[e], v[(e + 1) % 3], v[(e + 2) % 3]);
                check((3 * a.0 + b.0, 3 * a.1 + b.1));
                check((a.0 + 3 * b.0, a.1 + 3 * b.1));
                check((2 * a.0 + b.0 + r.0, 2 * a.1 + b.1 + r.1));
            }
        }
    }
    worst
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::View;

    /// On a quadratic field mapped affinely to the screen, the nodes are exact and so is the
    /// triangle; the gradient is exact for any quadratic field, on the border too.
    #[test]
    fn quadratic_fields_are_exact() {
        let xf = ToPixels::new(&View::new(-10.0, -10.0, 30.0, 30.0), 400, 400);
        let field = |x: f64, y: f64| -> [f64; 4] {
            [
                50.0 + 2.0 * x - y + 0.3 * x * x - 0.2 * x * y + 0.1 * y * y,
                -4.0 + x * y * 0.05,
                7.0 - 0.4 * y * y,
                1.0,
            ]
        };
        // A sheared grid of 5 x 5 points over (0, 0)..(8, 8) in the plane.
        let side = 5;
        let g: Vec<VertexData> = (0..side * side)
            .map(|k| {
                let (i, j) = ((k % side) as f64, (k / side) as f64);
                let (x, y) = (2.0 * i + 0.5 * j, 2.0 * j);
                let c = field(x, y);
                VertexData::from_array([x, y, c[0], c[1], c[2], c[3]])
            })
            .collect();
        for (i, j) in [(0, 0), (2, 1), (4, 4), (0, 3), (4, 2)] {
            let grad = screen_gradient(&g, side, (i, j), &xf);
            let d = &g[j * side + i];
            let (x, y) = (d.position[0], d.position[1]);
            // Screen pixels per plane unit: 10.
            let want = [
                [
                    (2.0 + 0.6 * x - 0.2 * y) / 10.0,
                    (-1.0 - 0.2 * x + 0.2 * y) / 10.0,
                ],
                [0.05 * y / 10.0, 0.05 * x / 10.0],
                [0.0, -0.8 * y / 10.0],
                [0.0, 0.0],
            ];
            for k in 0..4 {
                for a in 0..2 {
                    assert!((grad[k][a] - want[k][a]).abs() < 1e-9, "({i}, {j}) {k} {a}");
                }
            }
        }
        // A triangle of three grid points with its midpoints' nodes reproduces the field.
        let px = |k: usize| xf.apply(g[k].position[0], g[k].position[1]);
        let corners = [0, 2, 12];
        let mids = [(1, 0), (2, 1), (1, 1)];
        let m = side_nodes(&g, side, &xf, corners, mids);
        let q = Quadratic {
            p: corners.map(px),
            c: corners.map(|k| g[k].attributes()),
            m,
        };
        for (x, y) in [(1.0, 0.5), (2.5, 1.5), (3.0, 0.25)] {
            let got = q.eval(xf.apply(x, y)).unwrap();
            let want = field(x, y);
            for k in 0..4 {
                assert!(
                    (got[k] - want[k]).abs() < 1e-9,
                    "{k}: {} {}",
                    got[k],
                    want[k]
                );
            }
        }
    }

    /// The nodes of the sides of the triangle through grid points `corners` (flat indices),
    /// from the samples at grid positions `mids` (side `k` runs from corner `k` to `k + 1`).
    fn side_nodes(
        g: &[VertexData],
        side: usize,
        xf: &ToPixels,
        corners: [usize; 3],
        mids: [(usize, usize); 3],
    ) -> [[f64; 4]; 3] {
        std::array::from_fn(|e| {
            let (a, b) = (corners[e], corners[(e + 1) % 3]);
            let (i, j) = mids[e];
            chord_node(
                xf.apply(g[a].position[0], g[a].position[1]),
                xf.apply(g[b].position[0], g[b].position[1]),
                &g[j * side + i],
                &screen_gradient(g, side, (i, j), xf),
                xf,
            )
        })
    }
}
