//! How an SVG mesh gradient's colours vary over each patch, as the SVG 2 draft and Inkscape
//! paint them: bilinear between the patch's corners, or for `type="bicubic"` smoothed across
//! patches. The renderer's classic painting and the export of the patches as they are share it.

use super::{MeshGrid, MeshType};

/// Lattice cells per patch side of `type="bicubic"` (Inkscape splits each patch 8 x 8).
pub(crate) const BICUBIC_SPLIT: usize = 8;

/// The colour lattice of every patch of `grid`, row by row.
pub(crate) fn colour_lattices(grid: &MeshGrid) -> Vec<Lattice> {
    match grid.kind {
        MeshType::Bicubic => bicubic_lattices(grid),
        MeshType::Bilinear | MeshType::Coons => corner_lattices(grid),
    }
}

/// A patch's colours: a `(k + 1) x (k + 1)` lattice of sRGB colours over its parameters,
/// row `a` at `u = a / k` (down, from the top side), column `b` at `v = b / k` (across);
/// bilinear between.
pub(crate) struct Lattice {
    /// Cells along each side.
    pub k: usize,
    /// The colours, row by row.
    pub colours: Vec<[f64; 3]>,
}

impl Lattice {
    /// The colour at row `a`, column `b`.
    pub(crate) fn at(&self, a: usize, b: usize) -> [f64; 3] {
        self.colours[a * (self.k + 1) + b]
    }
}

/// Every patch's corner colours as a lattice of one cell (bilinear colour).
fn corner_lattices(grid: &MeshGrid) -> Vec<Lattice> {
    let mut out = Vec::with_capacity(grid.rows * grid.columns);
    for r in 0..grid.rows {
        for c in 0..grid.columns {
            let col = |i, j| grid.corner(r + i, c + j).colour;
            out.push(Lattice {
                k: 1,
                colours: vec![col(0, 0), col(0, 1), col(1, 0), col(1, 1)],
            });
        }
    }
    out
}

/// `type="bicubic"` as Inkscape computes it: per channel, slopes of the sRGB values at every
/// corner along both grid directions, per unit of chord length between neighbouring corners
/// (monotone limited, see [`chord_slopes`]); then each patch's bicubic Hermite interpolant with
/// those slopes (scaled by the patch's chords) and no twist, evaluated at 9 x 9 points and
/// clamped to 0..1. Opacity is not smoothed.
fn bicubic_lattices(grid: &MeshGrid) -> Vec<Lattice> {
    let (rows, columns) = (grid.rows, grid.columns);
    let pos = |i: usize, j: usize| grid.corner(i, j).position;
    let value = |i: usize, j: usize, ch: usize| grid.corner(i, j).colour[ch];
    // slope_down[ch][i][j]: along the grid's columns (increasing row i); slope_across along rows.
    let mut slope_down = vec![vec![vec![0.0; columns + 1]; rows + 1]; 3];
    let mut slope_across = vec![vec![vec![0.0; columns + 1]; rows + 1]; 3];
    for ch in 0..3 {
        for j in 0..=columns {
            let values: Vec<f64> = (0..=rows).map(|i| value(i, j, ch)).collect();
            let chords: Vec<f64> = (0..rows)
                .map(|i| pos(i, j).distance(pos(i + 1, j)))
                .collect();
            for (i, s) in chord_slopes(&values, &chords).into_iter().enumerate() {
                slope_down[ch][i][j] = s;
            }
        }
        for i in 0..=rows {
            let values: Vec<f64> = (0..=columns).map(|j| value(i, j, ch)).collect();
            let chords: Vec<f64> = (0..columns)
                .map(|j| pos(i, j).distance(pos(i, j + 1)))
                .collect();
            slope_across[ch][i] = chord_slopes(&values, &chords);
        }
    }
    let k = BICUBIC_SPLIT;
    let mut out = Vec::with_capacity(rows * columns);
    for r in 0..rows {
        for c in 0..columns {
            let down_chord = [
                pos(r, c).distance(pos(r + 1, c)),
                pos(r, c + 1).distance(pos(r + 1, c + 1)),
            ];
            let across_chord = [
                pos(r, c).distance(pos(r, c + 1)),
                pos(r + 1, c).distance(pos(r + 1, c + 1)),
            ];
            let mut colours = vec![[0.0; 3]; (k + 1) * (k + 1)];
            for ch in 0..3 {
                // Corner (x, y): x down (0 top, 1 bottom), y across.
                let f = |x: usize, y: usize| value(r + x, c + y, ch);
                let fx = |x: usize, y: usize| slope_down[ch][r + x][c + y] * down_chord[y];
                let fy = |x: usize, y: usize| slope_across[ch][r + x][c + y] * across_chord[x];
                for a in 0..=k {
                    for b in 0..=k {
                        let (x, y) = (a as f64 / k as f64, b as f64 / k as f64);
                        let (hx, gx) = (hermite_values(x), hermite_slopes(x));
                        let (hy, gy) = (hermite_values(y), hermite_slopes(y));
                        let mut v = 0.0;
                        for p in 0..2 {
                            for q in 0..2 {
                                v += f(p, q) * hx[p] * hy[q]
                                    + fx(p, q) * gx[p] * hy[q]
                                    + fy(p, q) * hx[p] * gy[q];
                            }
                        }
                        colours[a * (k + 1) + b][ch] = v.clamp(0.0, 1.0);
                    }
                }
            }
            out.push(Lattice { k, colours });
        }
    }
    out
}

/// The cubic Hermite basis functions that carry the values at 0 and at 1.
fn hermite_values(t: f64) -> [f64; 2] {
    let (t2, t3) = (t * t, t * t * t);
    [1.0 - 3.0 * t2 + 2.0 * t3, 3.0 * t2 - 2.0 * t3]
}

/// The cubic Hermite basis functions that carry the slopes at 0 and at 1.
fn hermite_slopes(t: f64) -> [f64; 2] {
    let (t2, t3) = (t * t, t * t * t);
    [t - 2.0 * t2 + t3, t3 - t2]
}

/// Slopes (per unit length) of `values` at points `chords[i]` apart, as Inkscape's bicubic
/// smoothing takes them. Inside: the mean of the two neighbouring secants, zero at a strict
/// extremum, and at most three times each secant in magnitude (Fritsch-Carlson limiting). At
/// the ends: the parabola through the end value with the end secant and the neighbour's slope,
/// `2 secant - neighbour`, the first end taken before the last; a chord of zero length gives 0.
/// With a single chord the first end's neighbour is not yet known (0), so the slopes are
/// `2 secant` and `0`.
fn chord_slopes(values: &[f64], chords: &[f64]) -> Vec<f64> {
    let n = values.len() - 1;
    let mut slopes = vec![0.0; n + 1];
    for i in 1..n {
        let (p0, p1, p2) = (values[i - 1], values[i], values[i + 1]);
        let (d01, d12) = (chords[i - 1], chords[i]);
        if d01 > 0.0 && d12 > 0.0 {
            let (s01, s12) = ((p1 - p0) / d01, (p2 - p1) / d12);
            let extremum = (p0 > p1 && p1 < p2) || (p0 < p1 && p1 > p2);
            let mut slope = if extremum { 0.0 } else { 0.5 * (s01 + s12) };
            if slope.abs() > (3.0 * s01).abs() {
                slope = 3.0 * s01;
            }
            if slope.abs() > (3.0 * s12).abs() {
                slope = 3.0 * s12;
            }
            slopes[i] = slope;
        }
    }
    let end = |value_from: f64, value_to: f64, chord: f64, neighbour: f64| {
        if chord > 0.0 {
            2.0 * (value_to - value_from) / chord - neighbour
        } else {
            0.0
        }
    };
    slopes[0] = end(values[0], values[1], chords[0], slopes[1]);
    slopes[n] = end(values[n - 1], values[n], chords[n - 1], slopes[n - 1]);
    slopes
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Inside, the slope is the mean secant unless limited; at an extremum it is zero; with a
    /// single chord the ends are `2 secant` and `0` (Inkscape's order of evaluation).
    #[test]
    fn chord_slopes_follow_inkscape() {
        assert_eq!(chord_slopes(&[0.0, 1.0], &[2.0]), vec![1.0, 0.0]);
        // Even steps of 0.5 over chords of 1: secants 0.5; the ends 2 * 0.5 - 0.5.
        assert_eq!(
            chord_slopes(&[0.0, 0.5, 1.0], &[1.0, 1.0]),
            vec![0.5, 0.5, 0.5]
        );
        let s = chord_slopes(&[0.0, 1.0, 0.0], &[1.0, 1.0]);
        assert_eq!(s[1], 0.0);
        // A flat secant limits the mean to zero.
        let s = chord_slopes(&[0.0, 1.0, 1.0, 2.0], &[1.0, 1.0, 1.0]);
        assert_eq!((s[1], s[2]), (0.0, 0.0));
        // A zero-length chord gives no slope.
        assert_eq!(chord_slopes(&[0.3, 0.6, 0.9], &[0.0, 1.0])[..2], [0.0, 0.0]);
    }

    /// A one-patch mesh filling an even-odd path with a hole, at half opacity: nothing shows
    /// in the hole or outside the shape, the edge at x = 10.5 covers half of its pixels, and
    /// inside, the classic colour is bilinear in sRGB between the stop colours (the first
    /// stop's corner top left, then clockwise).
    /// Hermite interpolation with slopes equal to a linear ramp's reproduces the ramp.
    #[test]
    fn hermite_basis_reproduces_a_line() {
        for t in [0.0, 0.125, 0.5, 0.875, 1.0] {
            let (h, g) = (hermite_values(t), hermite_slopes(t));
            let v = 0.2 * h[0] + 0.8 * h[1] + 0.6 * g[0] + 0.6 * g[1];
            assert!((v - (0.2 + 0.6 * t)).abs() < 1e-15, "{t}");
        }
    }
}
