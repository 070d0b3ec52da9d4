//! Bicubic Bézier patches of the limit surface: from uniform B-spline control grids, evaluated,
//! and cut to sub-rectangles of their parameters (exactly, by blossoming).

use crate::limit_surface::patches::ControlGrid;
use crate::validate::VertexData;

/// A bicubic Bézier patch in every coordinate of [`VertexData`] (position, colour, opacity):
/// `net[j][i]`, `i` along `u`, `j` along `v`, as in [`ControlGrid`]. Its corners are the
/// surface's values there.
pub(crate) type BezierNet = [[VertexData; 4]; 4];

/// The uniform cubic B-spline segment's Bézier points, `b = M p`.
const BSPLINE_TO_BEZIER: [[f64; 4]; 4] = [
    [1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0, 0.0],
    [0.0, 4.0 / 6.0, 2.0 / 6.0, 0.0],
    [0.0, 2.0 / 6.0, 4.0 / 6.0, 0.0],
    [0.0, 1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0],
];

/// The Bézier net of the uniform bicubic B-spline patch of `cp`: `B = M P Mᵀ` in every
/// coordinate.
pub(crate) fn bspline_to_bezier(cp: &ControlGrid) -> BezierNet {
    let mut rows = [[VertexData::ZERO; 4]; 4];
    for (j, row) in cp.iter().enumerate() {
        for (i, m) in BSPLINE_TO_BEZIER.iter().enumerate() {
            rows[j][i] = combine(m, |k| row[k]);
        }
    }
    let mut net = [[VertexData::ZERO; 4]; 4];
    for (j, m) in BSPLINE_TO_BEZIER.iter().enumerate() {
        for i in 0..4 {
            net[j][i] = combine(m, |k| rows[k][i]);
        }
    }
    net
}

/// `Σ w[k] p(k)` over four points.
fn combine(w: &[f64; 4], p: impl Fn(usize) -> VertexData) -> VertexData {
    let mut out = VertexData::ZERO;
    for (k, &wk) in w.iter().enumerate() {
        if wk != 0.0 {
            out.add_scaled(&p(k), wk);
        }
    }
    out
}

/// The cubic Bernstein polynomials at `t`.
pub(crate) fn bernstein(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t]
}

/// The patch at `(u, v)`.
pub(crate) fn evaluate(net: &BezierNet, u: f64, v: f64) -> VertexData {
    let (bu, bv) = (bernstein(u), bernstein(v));
    let rows: [VertexData; 4] = std::array::from_fn(|j| combine(&bu, |i| net[j][i]));
    combine(&bv, |j| rows[j])
}

/// The blossom of the cubic with Bézier points `p` at `(t1, t2, t3)`: de Casteljau's steps,
/// each at its own parameter.
fn blossom(p: &[VertexData; 4], t: [f64; 3]) -> VertexData {
    let mut q = *p;
    for (step, &ts) in t.iter().enumerate() {
        for k in 0..3 - step {
            q[k] = q[k].zip_with(&q[k + 1], |a, b| (1.0 - ts) * a + ts * b);
        }
    }
    q[0]
}

/// The Bézier points of the cubic `p` restricted to `a..=b`, reparametrised to `0..=1`.
fn segment(p: &[VertexData; 4], a: f64, b: f64) -> [VertexData; 4] {
    [
        blossom(p, [a, a, a]),
        blossom(p, [a, a, b]),
        blossom(p, [a, b, b]),
        blossom(p, [b, b, b]),
    ]
}

/// The patch over `u0..=u1` x `v0..=v1`, reparametrised to the unit square.
pub(crate) fn sub_net(net: &BezierNet, (u0, u1): (f64, f64), (v0, v1): (f64, f64)) -> BezierNet {
    let mut rows = [[VertexData::ZERO; 4]; 4];
    for j in 0..4 {
        rows[j] = segment(&net[j], u0, u1);
    }
    let mut out = [[VertexData::ZERO; 4]; 4];
    for i in 0..4 {
        let column = [rows[0][i], rows[1][i], rows[2][i], rows[3][i]];
        let cut = segment(&column, v0, v1);
        for j in 0..4 {
            out[j][i] = cut[j];
        }
    }
    out
}

/// The flat patch with corners `c` at `(0, 0)`, `(1, 0)`, `(1, 1)` and `(0, 1)`: bilinear in
/// every coordinate.
pub(crate) fn bilinear_net(c: [VertexData; 4]) -> BezierNet {
    let mut net = [[VertexData::ZERO; 4]; 4];
    for j in 0..4 {
        let v = j as f64 / 3.0;
        for i in 0..4 {
            let u = i as f64 / 3.0;
            let w = [(1.0 - u) * (1.0 - v), u * (1.0 - v), u * v, (1.0 - u) * v];
            net[j][i] = combine(&w, |k| c[k]);
        }
    }
    net
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::limit_surface::patches::evaluate_patch_at;

    fn uneven_grid() -> ControlGrid {
        std::array::from_fn(|j| {
            std::array::from_fn(|i| {
                let x = (4 * j + i) as f64;
                VertexData::from_array([
                    10.0 * i as f64 + (x * 0.7).sin(),
                    10.0 * j as f64 + (x * 1.3).cos(),
                    50.0 + 20.0 * (x * 0.37).sin(),
                    x * x * 0.3 - 20.0,
                    -30.0 * (x * 0.11).cos(),
                    0.5 + 0.4 * (x * 0.5).sin(),
                ])
            })
        })
    }

    fn close(a: VertexData, b: VertexData, tol: f64) -> bool {
        a.to_array()
            .iter()
            .zip(&b.to_array())
            .all(|(x, y)| (x - y).abs() <= tol)
    }

    #[test]
    fn bezier_net_is_the_bspline_patch() {
        let cp = uneven_grid();
        let net = bspline_to_bezier(&cp);
        for j in 0..=7 {
            for i in 0..=7 {
                let (u, v) = (i as f64 / 7.0, j as f64 / 7.0);
                let (a, b) = (evaluate(&net, u, v), evaluate_patch_at(&cp, u, v));
                assert!(close(a, b, 1e-12), "{u} {v}: {a:?} {b:?}");
            }
        }
    }

    #[test]
    fn corners_of_the_net_are_the_surface_there() {
        let cp = uneven_grid();
        let net = bspline_to_bezier(&cp);
        for (j, i) in [(0, 0), (0, 3), (3, 0), (3, 3)] {
            let at = evaluate_patch_at(&cp, i as f64 / 3.0, j as f64 / 3.0);
            assert!(close(net[j][i], at, 1e-12));
        }
    }

    #[test]
    fn sub_nets_reproduce_the_patch() {
        let net = bspline_to_bezier(&uneven_grid());
        let (us, vs) = ((0.2, 0.65), (0.5, 1.0));
        let sub = sub_net(&net, us, vs);
        for j in 0..=5 {
            for i in 0..=5 {
                let (s, t) = (i as f64 / 5.0, j as f64 / 5.0);
                let u = us.0 + s * (us.1 - us.0);
                let v = vs.0 + t * (vs.1 - vs.0);
                assert!(close(evaluate(&sub, s, t), evaluate(&net, u, v), 1e-12));
            }
        }
    }

    #[test]
    fn bilinear_net_is_bilinear() {
        let c = [0.0, 4.0, 10.0, 2.0].map(|x| VertexData::from_array([x; 6]));
        let net = bilinear_net(c);
        let p = evaluate(&net, 0.25, 0.5);
        let want = 0.375 * 0.0 + 0.125 * 4.0 + 0.125 * 10.0 + 0.375 * 2.0;
        assert!((p.colour[1] - want).abs() < 1e-12);
    }
}
