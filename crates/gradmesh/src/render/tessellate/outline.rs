//! The outline of a layer flattened into line segments for coverage: the limit curves of its
//! boundary (`limit_surface::boundary`), as exact cubic Bézier segments, run through the
//! outline of the triangles.
//!
//! The two sides of a discontinuous edge are two boundaries over the same control points, run in
//! opposite directions. Every step here is made independent of the direction of travel (points
//! snapped first, Bézier points from symmetric sums, each segment flattened in a canonical
//! direction), so the two sides give the same line segments reversed, which then cancel exactly.

use crate::level::Level;
use crate::limit_surface::boundary::for_each_boundary_segment;

use crate::render::raster::coverage::Line;

/// Outline points are snapped to 2^-16 pixel, far below anything coverage can show.
const OUTLINE_GRID: f64 = 65536.0;

fn snap(p: [f64; 2]) -> [f64; 2] {
    p.map(|v| (v * OUTLINE_GRID).round() / OUTLINE_GRID)
}

/// One cubic segment of the outline from its four B-spline control points (in pixels, snapped),
/// flattened to within `tolerance` pixels. Appends the lines to `out`.
fn flatten_segment(q: [[f64; 2]; 4], tolerance: f64, out: &mut Vec<Line>) {
    // Flatten in the lexicographically smaller of the two directions.
    let reversed = [q[3], q[2], q[1], q[0]];
    let cmp = |a: &[[f64; 2]; 4], b: &[[f64; 2]; 4]| {
        a.iter()
            .flatten()
            .zip(b.iter().flatten())
            .map(|(x, y)| x.total_cmp(y))
            .find(|o| o.is_ne())
            .unwrap_or(std::cmp::Ordering::Equal)
    };
    let flip = cmp(&reversed, &q).is_lt();
    let p = if flip { reversed } else { q };
    // B-spline to Bézier with sums whose operands commute: the shared end point of neighbouring
    // segments is bitwise the same in both, and so is the reversed segment's.
    let b = [0, 1].map(|c| {
        [
            ((p[0][c] + p[2][c]) + 4.0 * p[1][c]) / 6.0,
            (2.0 * p[1][c] + p[2][c]) / 3.0,
            (p[1][c] + 2.0 * p[2][c]) / 3.0,
            ((p[1][c] + p[3][c]) + 4.0 * p[2][c]) / 6.0,
        ]
    });
    let pt = |k: usize| snap([b[0][k], b[1][k]]);
    // Wang's formula: n segments keep the chord within `tolerance` of a cubic.
    let second = |k: usize| {
        let dx = b[0][k] - 2.0 * b[0][k + 1] + b[0][k + 2];
        let dy = b[1][k] - 2.0 * b[1][k + 1] + b[1][k + 2];
        dx.hypot(dy)
    };
    let m = second(0).max(second(1));
    let n = ((0.75 * m / tolerance).sqrt().ceil() as usize).clamp(1, 4096);
    let mut pts = Vec::with_capacity(n + 1);
    pts.push(pt(0));
    for i in 1..n {
        let t = i as f64 / n as f64;
        let mt = 1.0 - t;
        let w = [mt * mt * mt, 3.0 * mt * mt * t, 3.0 * mt * t * t, t * t * t];
        let c = |c: usize| w[0] * b[c][0] + w[1] * b[c][1] + w[2] * b[c][2] + w[3] * b[c][3];
        pts.push(snap([c(0), c(1)]));
    }
    pts.push(pt(3));
    if flip {
        pts.reverse();
    }
    for w in pts.windows(2) {
        if w[0] != w[1] {
            out.push(Line { p0: w[0], p1: w[1] });
        }
    }
}

/// The flattened outline of `level`, whose control positions in pixels are `px`.
pub(crate) fn outline(
    level: &Level,
    loops: &[Vec<u32>],
    px: &[[f64; 2]],
    tolerance: f64,
) -> Vec<Line> {
    let mut lines = Vec::new();
    for lp in loops {
        let m = lp.len();
        let pos = |i: usize| snap(px[lp[i % m] as usize]);
        for_each_boundary_segment(level, lp, pos, |q| {
            flatten_segment(q, tolerance, &mut lines)
        });
    }
    cancel_opposite(lines)
}

/// Removes pairs of identical segments run in opposite directions (the two sides of a
/// discontinuous edge), keeping the order of the rest. Segments are grouped by sorting their
/// ends' bits: hashing them (SipHash) cost about 2.5 % of preparing the Tucan artwork.
fn cancel_opposite(lines: Vec<Line>) -> Vec<Line> {
    type Key = ([u64; 2], [u64; 2]);
    let bits = |p: [f64; 2]| p.map(f64::to_bits);
    // A segment's ends in a fixed order, and +1 or -1 for its direction.
    let key = |l: &Line| -> (Key, i32) {
        let (a, b) = (bits(l.p0), bits(l.p1));
        if a <= b {
            ((a, b), 1)
        } else {
            ((b, a), -1)
        }
    };
    let mut order: Vec<(Key, i32, u32)> = lines
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let (k, s) = key(l);
            (k, s, i as u32)
        })
        .collect();
    order.sort_unstable_by_key(|&(k, _, i)| (k, i));
    // In each group of the same segment, the net count's first segments of its direction (in
    // their original order) are kept: the others cancel in pairs.
    let mut keep = vec![false; lines.len()];
    for group in order.chunk_by(|a, b| a.0 == b.0) {
        let net: i32 = group.iter().map(|&(_, s, _)| s).sum();
        let kept = group.iter().filter(|&&(_, s, _)| s == net.signum());
        for &(_, _, i) in kept.take(net.unsigned_abs() as usize) {
            keep[i as usize] = true;
        }
    }
    lines
        .into_iter()
        .zip(keep)
        .filter_map(|(l, k)| k.then_some(l))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn opposite_segments_cancel() {
        let l = |a: [f64; 2], b: [f64; 2]| Line { p0: a, p1: b };
        let lines = vec![
            l([0.0, 0.0], [1.0, 0.5]),
            l([1.0, 0.5], [2.0, 2.0]),
            l([1.0, 0.5], [0.0, 0.0]),
            l([3.0, 3.0], [4.0, 4.0]),
            l([3.0, 3.0], [4.0, 4.0]),
        ];
        let kept = cancel_opposite(lines);
        assert_eq!(kept.len(), 3);
        assert_eq!(kept[0].p0, [1.0, 0.5]);
        assert_eq!(kept[1], kept[2]);
    }

    #[test]
    fn reversed_segment_flattens_to_the_same_points() {
        let q = [[0.1, 0.3], [2.7, 1.9], [5.2, 1.1], [9.9, 7.3]];
        let (mut a, mut b) = (Vec::new(), Vec::new());
        flatten_segment(q, 1e-3, &mut a);
        flatten_segment([q[3], q[2], q[1], q[0]], 1e-3, &mut b);
        assert!(a.len() > 4);
        b.reverse();
        for (x, y) in a.iter().zip(&b) {
            assert_eq!((x.p0, x.p1), (y.p1, y.p0));
        }
    }

    #[test]
    fn flattening_is_within_tolerance() {
        let q = [[0.0, 0.0], [3.0, 9.0], [6.0, -4.0], [9.0, 2.0]];
        let mut lines = Vec::new();
        let tol = 0.01;
        flatten_segment(q, tol, &mut lines);
        let b = [0, 1].map(|c| {
            [
                (q[0][c] + 4.0 * q[1][c] + q[2][c]) / 6.0,
                (2.0 * q[1][c] + q[2][c]) / 3.0,
                (q[1][c] + 2.0 * q[2][c]) / 3.0,
                (q[1][c] + 4.0 * q[2][c] + q[3][c]) / 6.0,
            ]
        });
        let curve = |t: f64| {
            let mt = 1.0 - t;
            let w = [mt * mt * mt, 3.0 * mt * mt * t, 3.0 * mt * t * t, t * t * t];
            [0, 1].map(|c| (0..4).map(|k| w[k] * b[c][k]).sum::<f64>())
        };
        for i in 0..=1000 {
            let p = curve(i as f64 / 1000.0);
            let d = lines
                .iter()
                .map(|l| {
                    let (ax, ay, bx, by) = (l.p0[0], l.p0[1], l.p1[0], l.p1[1]);
                    let (dx, dy) = (bx - ax, by - ay);
                    let t = (((p[0] - ax) * dx + (p[1] - ay) * dy) / (dx * dx + dy * dy))
                        .clamp(0.0, 1.0);
                    (p[0] - ax - t * dx).hypot(p[1] - ay - t * dy)
                })
                .fold(f64::INFINITY, f64::min);
            assert!(d <= tol * 1.01, "{d}");
        }
    }
}
