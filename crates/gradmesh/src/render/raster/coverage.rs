//! Exact area coverage of a closed outline, by signed-area accumulation (the method of font
//! rasterisers such as font-rs and stb_truetype).
//!
//! Every line segment adds, to each pixel of each row it crosses, the signed area of the part of
//! that pixel lying to its right, stored as a difference from the pixel on its left; a prefix sum
//! along the row then gives the winding-weighted area of every pixel. Loops of opposite
//! orientation (an outer boundary and a hole) subtract, a segment run once in each direction
//! (the two sides of a discontinuous edge) cancels, and the magnitude is clamped to 1.
//!
//! Rows are independent: a band of rows is accumulated from the segments that cross it alone,
//! with the same arithmetic whichever band or thread does it.
//!
//! Areas are summed in fixed point ([`ONE`] per pixel), and each piece of a segment within a
//! row adds exactly the difference of its ends' fixed-point heights over its cells. Integer
//! sums do not depend on the order of the additions, and a closed outline's pieces in a row
//! add up to exactly zero; so two outlines that differ only between the same two points give
//! bit-identical sums to the right of every line that differs. A cached render relies on it
//! to draw again only the columns an outline's change reaches.

/// Fixed-point units per pixel of area: fine beyond the precision of an `f32` coverage, and
/// far from overflowing an `i64` at any winding number.
pub(crate) const ONE: f64 = (1u64 << 32) as f64;

/// `v` pixels of area (or of height) in fixed point.
#[inline]
fn fixed(v: f64) -> i64 {
    (v * ONE).round() as i64
}

/// A fixed-point sum in pixels of area.
#[inline]
fn area(sum: i64) -> f64 {
    sum as f64 * (1.0 / ONE)
}

/// A directed line segment in pixel coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Line {
    pub p0: [f64; 2],
    pub p1: [f64; 2],
}

impl Line {
    /// The rows `[first, last)` whose interior the segment may touch.
    pub fn rows(&self) -> (i64, i64) {
        let (lo, hi) = if self.p0[1] < self.p1[1] {
            (self.p0[1], self.p1[1])
        } else {
            (self.p1[1], self.p0[1])
        };
        (lo.floor() as i64, hi.ceil() as i64)
    }
}

/// Accumulation rows of a band, each with the runs of cells its segments touched.
///
/// A layer's outline crosses a row in a few places and touches a few cells there; only those
/// are summed and cleared again, and between them the coverage is constant. Every row is left
/// cleared by [`Accumulator::resolve`], so one accumulator serves band after band.
#[derive(Clone, Debug)]
pub(crate) struct Accumulator {
    width: usize,
    /// `width + 2` cells a row, in fixed point: a segment's contribution may spill one cell
    /// past the image.
    cells: Vec<i64>,
    /// Runs of cells `[first, end)` of each row that may be non-zero, in the order added.
    touched: Vec<Vec<[usize; 2]>>,
}

impl Accumulator {
    /// Cleared rows of `width` pixels, at most `rows` of them.
    pub fn new(width: usize, rows: usize) -> Accumulator {
        Accumulator {
            width,
            cells: vec![0; (width + 2) * rows],
            touched: vec![Vec::new(); rows],
        }
    }

    /// The widest rows this accumulator holds.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Adds the contribution of `line` to image rows `row0 .. row0 + rows` (accumulator rows
    /// `0 .. rows`).
    pub fn add(&mut self, row0: i64, rows: usize, line: &Line) {
        let ([x0, y0], [x1, y1], dir) = if line.p0[1] < line.p1[1] {
            (line.p0, line.p1, 1)
        } else if line.p0[1] > line.p1[1] {
            (line.p1, line.p0, -1)
        } else {
            return;
        };
        let stride = self.width + 2;
        let dxdy = (x1 - x0) / (y1 - y0);
        let first = (y0.floor() as i64).max(row0);
        let last = (y1.ceil() as i64).min(row0 + rows as i64);
        for j in first..last {
            let ya = y0.max(j as f64);
            let yb = y1.min((j + 1) as f64);
            if yb <= ya {
                continue;
            }
            // Ends computed from the segment, not incrementally: the same in every band.
            let xa = if ya == y0 { x0 } else { x0 + (ya - y0) * dxdy };
            let xb = if yb == y1 { x1 } else { x0 + (yb - y0) * dxdy };
            let r = (j - row0) as usize;
            let row = &mut self.cells[r * stride..(r + 1) * stride];
            // The heights of the ends in fixed point: the pieces of a chain of segments
            // share their ends, so their heights add up to the chain's exactly.
            let height = dir * (fixed(yb) - fixed(ya));
            add_piece(row, self.width as f64, xa, xb, height, &mut self.touched[r]);
        }
    }

    /// Writes the coverage of columns `c0..c1` of row `r` into `out[c0..c1]` and clears the
    /// row. Returns the columns `[a, b)` outside which that coverage is zero.
    ///
    /// The same sums as a prefix sum over every cell from `c0`: the cells skipped are zero.
    /// Coverage follows the non-zero rule.
    pub fn resolve(&mut self, r: usize, c0: usize, c1: usize, out: &mut [f32]) -> (usize, usize) {
        self.resolve_with::<false>(r, c0, c1, out)
    }

    /// [`Accumulator::resolve`] with the even-odd rule when `EVEN_ODD`, else the non-zero rule.
    #[inline(always)]
    pub fn resolve_with<const EVEN_ODD: bool>(
        &mut self,
        r: usize,
        c0: usize,
        c1: usize,
        out: &mut [f32],
    ) -> (usize, usize) {
        let coverage_of = if EVEN_ODD {
            coverage_even_odd
        } else {
            coverage_of
        };
        let stride = self.width + 2;
        let row = &mut self.cells[r * stride..(r + 1) * stride];
        let runs = &mut self.touched[r];
        runs.sort_unstable_by_key(|run| run[0]);
        let mut sum = 0i64;
        // Columns before `next` are written.
        let mut next = c0;
        let (mut a, mut b) = (c1, c0);
        let mut k = 0;
        while k < runs.len() {
            // Overlapping or adjacent runs merge, so each cell is summed once.
            let [first, mut end] = runs[k];
            k += 1;
            while k < runs.len() && runs[k][0] <= end {
                end = end.max(runs[k][1]);
                k += 1;
            }
            let (s, e) = (first.clamp(next, c1), end.clamp(next, c1));
            out[next..s].fill(coverage_of(area(sum)));
            for (o, &v) in out[s..e].iter_mut().zip(&row[s..e]) {
                sum += v;
                *o = coverage_of(area(sum));
            }
            if s < e {
                a = a.min(s);
                b = e;
            }
            next = e;
            row[first..end].fill(0);
        }
        runs.clear();
        let tail = coverage_of(area(sum));
        out[next..c1].fill(tail);
        if tail != 0.0 {
            (a.min(next), c1)
        } else {
            (a, b.max(a))
        }
    }
}

/// Adds one piece of a segment within one row: from `xa` to `xb`, spanning `d` (signed, fixed
/// point) of the row's height. Parts left of the image count fully for every pixel; parts right
/// of it for none. The cells it changes add up to `d` exactly; it records them in `touched`.
fn add_piece(row: &mut [i64], width: f64, xa: f64, xb: f64, d: i64, touched: &mut Vec<[usize; 2]>) {
    let (lo, hi) = if xa <= xb { (xa, xb) } else { (xb, xa) };
    if hi <= 0.0 || lo >= width || hi - lo < 1e-9 {
        let x = (0.5 * (xa + xb)).clamp(0.0, width);
        touched.push(add_span(row, x, x, d));
        return;
    }
    // Split at the image's left and right edges, sharing `d` in proportion to length (the
    // shares rounded as running totals, so that they add up to `d`).
    let len = hi - lo;
    let mut cuts = [lo, lo.max(0.0), hi.min(width), hi];
    cuts.iter_mut().for_each(|c| *c = c.clamp(lo, hi));
    let share_to = |k: usize| {
        if k == 3 {
            d
        } else {
            (d as f64 * ((cuts[k] - lo) / len)).round() as i64
        }
    };
    for k in 0..3 {
        let (a, b) = (cuts[k], cuts[k + 1]);
        if b <= a {
            continue;
        }
        let part = share_to(k + 1) - share_to(k);
        let (a, b) = (a.clamp(0.0, width), b.clamp(0.0, width));
        touched.push(add_span(row, a, b, part));
    }
}

/// Adds a monotone piece from `x0` to `x1` (`x0 <= x1`, both in `0..=width`) spanning `d`
/// (fixed point), whose cells add up to `d` exactly. Returns the cells `[first, end)` it changed.
fn add_span(row: &mut [i64], x0: f64, x1: f64, d: i64) -> [usize; 2] {
    let c0 = x0.floor() as usize;
    if x1 - x0 < 1e-9 {
        // Vertical: the area right of x in cell c0 is c0 + 1 - x.
        let f = (c0 as f64 + 1.0 - x0).clamp(0.0, 1.0);
        let first = (d as f64 * f).round() as i64;
        row[c0] += first;
        row[c0 + 1] += d - first;
        return [c0, c0 + 2];
    }
    let c1 = x1.ceil() as usize;
    let s = d as f64 / (x1 - x0);
    // A(c) = s * integral over [x0, x1] of clamp(c + 1 - x, 0, 1), by the antiderivative
    // H(u) of clamp(1 - u, 0, 1) with u = x - c, taken relative to each cell to keep precision.
    let h = |u: f64| -> f64 {
        if u <= 0.0 {
            u
        } else if u >= 1.0 {
            0.5
        } else {
            u - 0.5 * u * u
        }
    };
    let mut prev = 0;
    let last = c1.min(row.len() - 1);
    for c in c0..=last {
        let cf = c as f64;
        let a = if c == c1 {
            d
        } else {
            (s * (h(x1 - cf) - h(x0 - cf))).round() as i64
        };
        row[c] += a - prev;
        prev = a;
    }
    [c0, last + 1]
}

/// The coverage in `0..=1` of a winding-weighted area (non-zero rule).
#[inline]
fn coverage_of(sum: f64) -> f32 {
    clean(sum.abs().min(1.0))
}

/// The coverage in `0..=1` of a winding-weighted area under the even-odd rule: winding 2
/// counts as outside, so the area folds back every other unit.
#[inline]
fn coverage_even_odd(sum: f64) -> f32 {
    let v = sum.abs() % 2.0;
    clean(if v > 1.0 { 2.0 - v } else { v })
}

/// A coverage in `0..=1`, with round-off next to 0 and 1 removed.
#[inline]
fn clean(c: f64) -> f32 {
    // Round-off of cancelled contributions is not coverage.
    if c < 1e-9 {
        0.0
    } else if c > 1.0 - 1e-9 {
        1.0
    } else {
        c as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn render(lines: &[Line], w: usize, h: usize) -> Vec<f32> {
        let mut acc = Accumulator::new(w, h);
        for l in lines {
            acc.add(0, h, l);
        }
        let mut out = vec![0.0; w * h];
        for j in 0..h {
            acc.resolve(j, 0, w, &mut out[j * w..(j + 1) * w]);
        }
        assert!(acc.cells.iter().all(|&c| c == 0), "left cleared");
        out
    }

    fn polygon(pts: &[[f64; 2]]) -> Vec<Line> {
        (0..pts.len())
            .map(|i| Line {
                p0: pts[i],
                p1: pts[(i + 1) % pts.len()],
            })
            .collect()
    }

    /// Area of the intersection of a convex polygon with the pixel square (Sutherland-Hodgman).
    fn exact(pts: &[[f64; 2]], i: usize, j: usize) -> f64 {
        let mut poly: Vec<[f64; 2]> = pts.to_vec();
        let (x0, y0) = (i as f64, j as f64);
        let planes: [(usize, f64, f64); 4] = [
            (0, x0, 1.0),
            (0, x0 + 1.0, -1.0),
            (1, y0, 1.0),
            (1, y0 + 1.0, -1.0),
        ];
        for (axis, v, sign) in planes {
            let inside = |p: &[f64; 2]| (p[axis] - v) * sign >= 0.0;
            let mut out = Vec::new();
            for k in 0..poly.len() {
                let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
                if inside(&a) {
                    out.push(a);
                }
                if inside(&a) != inside(&b) {
                    let t = (v - a[axis]) / (b[axis] - a[axis]);
                    out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
                }
            }
            poly = out;
            if poly.is_empty() {
                return 0.0;
            }
        }
        let mut area = 0.0;
        for k in 0..poly.len() {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            area += a[0] * b[1] - b[0] * a[1];
        }
        0.5 * area.abs()
    }

    /// Resolving only the touched runs gives the same bits as a prefix sum over every cell
    /// from the first column, and nothing outside the range it returns is covered.
    #[test]
    fn sparse_resolve_matches_the_dense_prefix_sum() {
        let outer = [[1.25, 0.5], [37.5, 2.0], [35.0, 11.75], [0.5, 9.5]];
        let hole = [[8.0, 3.0], [9.0, 8.0], [20.5, 7.5], [21.0, 3.5]];
        let right = [[26.0, 1.0], [31.0, 1.0], [31.0, 10.0], [26.0, 10.0]];
        let mut lines = polygon(&outer);
        lines.extend(polygon(&hole));
        // A square run the other way: cancels part of the outer loop.
        lines.extend(
            polygon(&right)
                .into_iter()
                .rev()
                .map(|l| Line { p0: l.p1, p1: l.p0 }),
        );
        let (w, h) = (40, 12);
        let mut acc = Accumulator::new(w, h);
        for l in &lines {
            acc.add(0, h, l);
        }
        for (c0, c1) in [(0, w), (3, 33), (10, 12), (39, 40), (5, 5)] {
            let mut copy = acc.clone();
            for j in 0..h {
                let cells = copy.cells[j * (w + 2)..(j + 1) * (w + 2)].to_vec();
                let mut out = vec![-1.0; w];
                let (a, b) = copy.resolve(j, c0, c1, &mut out);
                let mut sum = 0;
                for i in c0..c1 {
                    sum += cells[i];
                    assert_eq!(
                        out[i],
                        coverage_of(area(sum)),
                        "row {j} column {i} of {c0}..{c1}"
                    );
                    if !(a..b).contains(&i) {
                        assert_eq!(out[i], 0.0, "row {j} column {i} outside {a}..{b}");
                    }
                }
                assert!(out[..c0].iter().chain(&out[c1..]).all(|&v| v == -1.0));
            }
            assert!(copy.cells.iter().all(|&c| c == 0), "left cleared");
            assert!(copy.touched.iter().all(Vec::is_empty));
        }
    }

    /// The running sums of a row's cells, from column 0.
    fn prefix_sums(acc: &Accumulator, j: usize) -> Vec<i64> {
        let stride = acc.width + 2;
        acc.cells[j * stride..(j + 1) * stride]
            .iter()
            .scan(0i64, |sum, &c| {
                *sum += c;
                Some(*sum)
            })
            .collect()
    }

    /// Two outlines that differ only in the lines around one moved point have the same sums,
    /// to the unit, in every column right of the lines that differ, whatever the order the
    /// lines were added in; and each row of a closed outline sums to exactly zero.
    #[test]
    fn outlines_differing_between_the_same_points_match_right_of_the_difference() {
        let base = [
            [3.37, 1.21],
            [17.93, 0.47],
            [31.11, 2.83],
            [38.71, 13.39],
            [29.53, 19.61],
            [12.29, 18.07],
            [1.13, 11.73],
        ];
        let mut moved = base;
        moved[5] = [14.81, 16.33];
        let (w, h) = (48, 21);
        let accumulate = |lines: &[Line]| {
            let mut acc = Accumulator::new(w, h);
            lines.iter().for_each(|l| acc.add(0, h, l));
            acc
        };
        let old = accumulate(&polygon(&base));
        let mut reversed = polygon(&moved);
        reversed.reverse();
        let new = accumulate(&reversed);
        // The lines that differ: those on each side of point 5.
        let right = [base[4], base[5], base[6], moved[5]]
            .iter()
            .map(|p| p[0])
            .fold(f64::NEG_INFINITY, f64::max);
        let first_same = right.ceil() as usize + 1;
        let mut differ = false;
        for j in 0..h {
            let (o, n) = (prefix_sums(&old, j), prefix_sums(&new, j));
            assert_eq!(o[first_same..], n[first_same..], "row {j}");
            assert_eq!(*o.last().unwrap(), 0, "row {j} of the first outline");
            assert_eq!(*n.last().unwrap(), 0, "row {j} of the second");
            differ |= o != n;
        }
        assert!(differ, "the point moved");
    }

    #[test]
    fn triangle_coverage_is_exact() {
        let pts = [[1.3, 0.7], [13.9, 4.2], [4.1, 11.6]];
        let (w, h) = (16, 14);
        let cov = render(&polygon(&pts), w, h);
        for j in 0..h {
            for i in 0..w {
                let e = exact(&pts, i, j);
                assert!((cov[j * w + i] as f64 - e).abs() < 1e-6, "{i} {j}");
            }
        }
        // Reversed orientation: the same magnitude.
        let mut rev = pts;
        rev.reverse();
        assert_eq!(render(&polygon(&rev), w, h), cov);
    }

    /// Under the even-odd rule a loop inside another loop of the same orientation is a hole,
    /// with exact coverage on its edges; under the non-zero rule it is filled.
    #[test]
    fn even_odd_makes_holes_of_nested_loops() {
        let outer = [[0.5, 0.5], [9.5, 0.5], [9.5, 9.5], [0.5, 9.5]];
        let inner = [[3.0, 3.5], [7.0, 3.5], [7.0, 7.0], [3.0, 7.0]];
        let mut lines = polygon(&outer);
        lines.extend(polygon(&inner));
        let (w, h) = (10, 10);
        let mut acc = Accumulator::new(w, h);
        for l in &lines {
            acc.add(0, h, l);
        }
        let mut even_odd = vec![0.0; w * h];
        for j in 0..h {
            acc.resolve_with::<true>(j, 0, w, &mut even_odd[j * w..(j + 1) * w]);
        }
        let non_zero = render(&lines, w, h);
        assert_eq!(non_zero[5 * w + 5], 1.0);
        assert_eq!(even_odd[5 * w + 5], 0.0);
        assert_eq!(even_odd[2 * w + 2], 1.0);
        // Row 3 is half inside the hole (from y 3.5): coverage one half.
        assert_eq!(even_odd[3 * w + 5], 0.5);
        assert_eq!(even_odd[0], 0.25);
    }

    #[test]
    fn clipped_at_image_edges() {
        // A square sticking out on every side of a 6x5 image.
        let pts = [[-3.5, -2.25], [8.5, -2.25], [8.5, 7.5], [-3.5, 7.5]];
        let cov = render(&polygon(&pts), 6, 5);
        assert!(cov.iter().all(|&c| c == 1.0), "{cov:?}");
        let pts = [[-3.0, 1.5], [2.5, 1.5], [2.5, 3.0], [-3.0, 3.0]];
        let cov = render(&polygon(&pts), 6, 5);
        assert_eq!(&cov[6..12], &[0.5, 0.5, 0.25, 0.0, 0.0, 0.0]);
        assert_eq!(&cov[12..18], &[1.0, 1.0, 0.5, 0.0, 0.0, 0.0]);
    }

    #[test]
    fn holes_and_cancelled_edges() {
        let outer = [[0.5, 0.5], [9.5, 0.5], [9.5, 9.5], [0.5, 9.5]];
        let hole = [[3.0, 3.0], [3.0, 7.0], [7.0, 7.0], [7.0, 3.0]];
        let mut lines = polygon(&outer);
        lines.extend(polygon(&hole));
        let cov = render(&lines, 10, 10);
        assert_eq!(cov[5 * 10 + 5], 0.0);
        assert_eq!(cov[2 * 10 + 2], 1.0);
        // Two halves sharing a slanted edge, run once each way: no seam.
        let left = [[0.0, 0.0], [6.3, 0.0], [3.7, 10.0], [0.0, 10.0]];
        let right = [[6.3, 0.0], [10.0, 0.0], [10.0, 10.0], [3.7, 10.0]];
        let mut lines = polygon(&left);
        lines.extend(polygon(&right));
        let cov = render(&lines, 10, 10);
        assert!(cov.iter().all(|&c| c == 1.0), "{cov:?}");
    }
}
