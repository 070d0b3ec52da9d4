//! Moving control points to cut a colour fit's error: one damped Gauss-Newton step per point.
//!
//! Moving control point `i` by `d` carries the surface near it along by about `phi_i(u) d`,
//! with `phi_i` the point's weight in the limit colour of the surface point `u` (its colour
//! basis function, which the scheme's default handles give its position too, roughly). A pixel
//! at `y` then sees what `y - phi_i d` saw, so its residual changes by `-phi_i J d`, with `J`
//! the 3 x 2 image gradient of the fitted colours there. Each point's step minimises the
//! linearised error of its own pixels with the others held: `H d = g` with
//! `H = sum_p w_p phi_ip^2 J_p^T J_p` and `g = sum_p w_p phi_ip J_p^T (fit_p - picture_p)`,
//! damped by a multiple of `H`'s trace. The caller limits, checks (folds, the error after the
//! colours are solved again) and scales the steps.

use rayon::prelude::*;

use super::image::Target;
use super::raster::{Observation, UNCOVERED};
use super::rows::SparseRows;

/// The fitted colour of every pixel (`None` where the surface does not reach).
fn predicted(
    observation: &Observation,
    vertex_colours: &[[f64; 3]],
    n: usize,
) -> Vec<Option<[f64; 3]>> {
    (0..n)
        .into_par_iter()
        .map(|i| observation.predict(vertex_colours, i))
        .collect()
}

/// The image gradient of `field` at pixel `(x, y)` per channel, by central differences where
/// both neighbours are covered and one-sided ones where one is.
fn gradient(field: &[Option<[f64; 3]>], w: usize, h: usize, x: usize, y: usize) -> [[f64; 2]; 3] {
    let at = |x: usize, y: usize| field[y * w + x];
    let centre = at(x, y).unwrap_or([0.0; 3]);
    let diff = |before: Option<[f64; 3]>, after: Option<[f64; 3]>| match (before, after) {
        (Some(a), Some(b)) => [0, 1, 2].map(|k| (b[k] - a[k]) / 2.0),
        (None, Some(b)) => [0, 1, 2].map(|k| b[k] - centre[k]),
        (Some(a), None) => [0, 1, 2].map(|k| centre[k] - a[k]),
        (None, None) => [0.0; 3],
    };
    let gx = diff(
        (x > 0).then(|| at(x - 1, y)).flatten(),
        (x + 1 < w).then(|| at(x + 1, y)).flatten(),
    );
    let gy = diff(
        (y > 0).then(|| at(x, y - 1)).flatten(),
        (y + 1 < h).then(|| at(x, y + 1)).flatten(),
    );
    [0, 1, 2].map(|k| [gx[k], gy[k]])
}

/// Per point: the normal matrix `[hxx, hxy, hyy]` and right-hand side `[gx, gy]`.
type Normal = ([f64; 3], [f64; 2]);

/// Adds one pixel's terms to the points its surface point depends on.
fn add_pixel(
    acc: &mut [Normal],
    rows: &SparseRows,
    corners: [u32; 3],
    bary: [f32; 3],
    j: &[[f64; 2]; 3],
    e: [f64; 3],
    w: f64,
) {
    let mut jtj = [0.0; 3];
    let mut jte = [0.0; 2];
    for k in 0..3 {
        let [gx, gy] = j[k];
        jtj[0] += gx * gx;
        jtj[1] += gx * gy;
        jtj[2] += gy * gy;
        jte[0] += gx * e[k];
        jte[1] += gy * e[k];
    }
    for (&corner, &b) in corners.iter().zip(&bary) {
        let (cols, vals) = rows.row(corner as usize);
        for (&c, &v) in cols.iter().zip(vals) {
            let phi = b as f64 * v;
            let (h, g) = &mut acc[c as usize];
            for m in 0..3 {
                h[m] += w * phi * phi * jtj[m];
            }
            for m in 0..2 {
                g[m] += w * phi * jte[m];
            }
        }
    }
}

/// The Gauss-Newton step of every control point (see the module's documentation), in pixels,
/// with `damping` times the trace of each point's `H` added to its diagonal.
pub(crate) fn position_steps(
    rows: &SparseRows,
    observation: &Observation,
    vertex_colours: &[[f64; 3]],
    target: &Target,
    points: usize,
    damping: f64,
) -> Vec<[f64; 2]> {
    let (w, h) = (target.width, target.height);
    let fit = predicted(observation, vertex_colours, w * h);
    let sums = (0..h)
        .into_par_iter()
        .fold(
            || vec![([0.0; 3], [0.0; 2]); points],
            |mut acc, y| {
                for x in 0..w {
                    let i = y * w + x;
                    let s = &observation.samples[i];
                    let (Some(f), true) = (fit[i], s.corners[0] != UNCOVERED) else {
                        continue;
                    };
                    let e = [0, 1, 2].map(|k| f[k] - target.colour[i][k]);
                    let j = gradient(&fit, w, h, x, y);
                    add_pixel(&mut acc, rows, s.corners, s.bary, &j, e, target.weight[i]);
                }
                acc
            },
        )
        .reduce(
            || vec![([0.0; 3], [0.0; 2]); points],
            |mut a, b| {
                for (p, q) in a.iter_mut().zip(&b) {
                    for m in 0..3 {
                        p.0[m] += q.0[m];
                    }
                    for m in 0..2 {
                        p.1[m] += q.1[m];
                    }
                }
                a
            },
        );
    sums.iter()
        .map(|([hxx, hxy, hyy], [gx, gy])| {
            let mu = damping * (hxx + hyy) + 1e-12;
            let (a, b, d) = (hxx + mu, *hxy, hyy + mu);
            let det = a * d - b * b;
            if det <= 0.0 || !det.is_finite() {
                return [0.0; 2];
            }
            [(d * gx - b * gy) / det, (a * gy - b * gx) / det]
        })
        .collect()
}
