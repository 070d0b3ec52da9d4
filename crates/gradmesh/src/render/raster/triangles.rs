//! Triangles with linearly or quadratically interpolated attributes, rasterised at pixel
//! centres with an exact fill rule.
//!
//! Vertices are snapped to 1/256 pixel and edge functions are evaluated in integers, so two
//! triangles that share an edge (the same two snapped vertices) decide every pixel centre on it
//! consistently: a centre belongs to exactly one of them (top-left rule, which is a symbolic
//! perturbation of the sample point and so also settles centres on shared vertices). Interior
//! edges have no gaps and no double coverage.

use std::sync::Arc;

use crate::render::arrays::each4;

/// Sub-pixel steps per pixel.
pub(crate) const SUBPIXEL: i64 = 256;
/// Snapped coordinates beyond this magnitude (2^32 pixels) are not rasterised.
const LIMIT: i64 = 1 << 40;
/// Vertices within this magnitude (2^18 pixels, in sub-pixel units)...
const SMALL: i64 = 1 << 26;
/// ...and rows within this one (2^16, twice the largest image side) take 64-bit arithmetic.
const SMALL_ROWS: i64 = 1 << 16;
/// Rows whose spans [`Triangle::for_each_span`] finds together.
const SPAN_ROWS: usize = 16;
/// Integers below this magnitude, and the sums of two of them, are exact in `f64`.
const EXACT_F64: i64 = 1 << 51;

/// Snaps a pixel coordinate to the sub-pixel grid; `None` if it is not finite or too large.
pub(crate) fn snap(v: f64) -> Option<i64> {
    let s = v * SUBPIXEL as f64;
    // `f64::round` without its library call (baseline x86-64 has no rounding instruction):
    // below 2^40 the fraction `s - trunc(s)` is exact, so this rounds half away from zero
    // exactly as `round` does.
    if s.is_nan() || s.abs() >= LIMIT as f64 {
        return None;
    }
    let t = s as i64;
    let frac = s - t as f64;
    let rounded = t + (frac >= 0.5) as i64 - (frac <= -0.5) as i64;
    (rounded.abs() < LIMIT).then_some(rounded)
}

/// One edge of a triangle: start point and direction in sub-pixel units, and whether pixel
/// centres exactly on it belong to the triangle. Computed from the vertices when needed, so
/// that triangles stay small (they are written once and read once per band).
#[derive(Clone, Copy, Debug)]
struct Edge {
    p: [i64; 2],
    d: [i64; 2],
    include: bool,
    /// `1 / |dy SUBPIXEL|` (infinite for a horizontal edge): each row's span then divides
    /// by multiplying ([`floor_div_small`]), and the division is made once a band.
    inv: f64,
}

impl Edge {
    #[inline(always)]
    fn new(p: [i64; 2], q: [i64; 2]) -> Edge {
        let d = [q[0] - p[0], q[1] - p[1]];
        Edge {
            p,
            d,
            // The interior is where dx (y - py) - dy (x - px) > 0; of the two triangles
            // sharing an edge (run in opposite directions) exactly one takes this side.
            include: d[1] > 0 || (d[1] == 0 && d[0] < 0),
            inv: 1.0 / (d[1] * SUBPIXEL).abs() as f64,
        }
    }
}

/// A positively oriented triangle with four attributes varying over it as polynomials of degree
/// two (a linear triangle's quadratic terms are zero).
///
/// Kept small (152 bytes): a dense layer has tens of thousands of triangles, written once and
/// read once per band, and the fresh pages they take cost more than building them.
#[derive(Clone, Debug)]
pub(crate) struct Triangle {
    /// Snapped vertices, positively oriented.
    v: [[i64; 2]; 3],
    /// First row and one past the last row whose centres may lie inside, clamped to
    /// [`ROW_CLAMP`] (far beyond any image).
    rows: [i32; 2],
    /// Attribute values are `at_origin + gx * (x - ox) + gy * (y - oy)` at pixel coordinates
    /// (x, y), where the origin (ox, oy) is the pixel corner at or below the first vertex (see
    /// [`Triangle::origin`]). Relative to a nearby integer origin, single precision keeps
    /// about 7 digits of the colour even far from the image's origin, and a row is filled in
    /// single precision.
    at_origin: [f32; 4],
    gx: [f32; 4],
    gy: [f32; 4],
    /// The quadratic terms: `+ qxx (x - ox)^2 + qxy (x - ox) (y - oy) + qyy (y - oy)^2`, all
    /// zero on a linear triangle (adding them then changes no bit of its attributes).
    qxx: [f32; 4],
    qxy: [f32; 4],
    qyy: [f32; 4],
    /// Whether there are quadratic terms.
    #[cfg(test)]
    quadratic: bool,
    /// Whether the values are clamped to the layer's colour bounds: a quadratic triangle may
    /// overshoot them slightly between its nodes (a linear one cannot), unless its Bernstein
    /// coefficients, which bound it, lie inside.
    clamped: bool,
}

/// Per attribute, the smallest and the largest value of a layer's colours in play: quadratic
/// pixels are clamped to them, so that no pixel leaves the box around the control colours.
pub(crate) type Bounds = [[f32; 4]; 2];

/// Whether the quadratic triangle with corner values `attr` and side nodes `mids` stays
/// within `bounds`: its Bernstein coefficients (the corners, and `2 m - (a + b) / 2` per side),
/// whose hull holds it, lie inside with a margin for single-precision evaluation (a few steps
/// of the values' size, and a small fraction of their spread, which bounds the terms).
fn within_bounds(attr: &[[f64; 4]; 3], mids: &[[f64; 4]; 3], bounds: &Bounds) -> bool {
    (0..4).all(|k| {
        let coefficients: [f64; 6] = std::array::from_fn(|n| {
            let i = n % 3;
            let (a, b) = (attr[i][k], attr[(i + 1) % 3][k]);
            if n < 3 {
                a
            } else {
                2.0 * mids[i][k] - 0.5 * (a + b)
            }
        });
        let min = coefficients.iter().fold(f64::INFINITY, |m, &c| m.min(c));
        let max = coefficients
            .iter()
            .fold(f64::NEG_INFINITY, |m, &c| m.max(c));
        let (lo, hi) = (bounds[0][k] as f64, bounds[1][k] as f64);
        let margin = 2.5e-7 * (1.0 + lo.abs().max(hi.abs())) + 1e-4 * (max - min);
        coefficients.iter().all(|c| c.is_finite()) && min >= lo + margin && max <= hi - margin
    })
}

/// Bounds that clamp nothing.
pub(crate) const UNBOUNDED: Bounds = [[f32::NEG_INFINITY; 4], [f32::INFINITY; 4]];

/// Rows are kept within this magnitude: images are at most 2^16 rows tall.
const ROW_CLAMP: i64 = 1 << 30;

/// Triangles in drawing order, kept in the chunks they were built in (one per block of faces
/// on the fast path): concatenating them would write every triangle to fresh memory a second
/// time, and first touches of pages cost more than building the triangles. Chunks are shared:
/// a layer prepared again after an edit takes the blocks the edit left alone.
#[derive(Clone, Debug, Default)]
pub(crate) struct TriangleList {
    chunks: Vec<Arc<Vec<Triangle>>>,
    /// The index of each chunk's first triangle, and the total at the end.
    starts: Vec<usize>,
}

impl TriangleList {
    pub fn from_chunks(chunks: Vec<Vec<Triangle>>) -> TriangleList {
        TriangleList::from_shared(chunks.into_iter().map(Arc::new).collect())
    }

    /// The list of the triangles of `chunks`, in order (without copying them). Empty chunks
    /// are kept: a chunk's place is that of its block (see [`TriangleList::for_each_moved`]).
    pub fn from_shared(chunks: Vec<Arc<Vec<Triangle>>>) -> TriangleList {
        let mut starts = Vec::with_capacity(chunks.len() + 1);
        let mut total = 0;
        starts.push(0);
        for c in &chunks {
            total += c.len();
            starts.push(total);
        }
        TriangleList { chunks, starts }
    }

    pub fn len(&self) -> usize {
        *self.starts.last().unwrap_or(&0)
    }

    /// Every triangle, in order.
    pub fn iter(&self) -> impl Iterator<Item = &Triangle> {
        self.chunks.iter().flat_map(|c| c.iter())
    }

    /// Calls `f` with each triangle that `other` does not hold, bit for bit, at the same place
    /// (the same offset in the same chunk). Triangles are drawn in the order of their places,
    /// so a pixel that no such triangle of either list covers shows the same triangle in both.
    /// Chunks both lists share (a block of faces an edit left alone) are skipped whole.
    pub fn for_each_moved(&self, other: &TriangleList, mut f: impl FnMut(&Triangle)) {
        for (k, chunk) in self.chunks.iter().enumerate() {
            let theirs = other.chunks.get(k);
            if theirs.is_some_and(|c| Arc::ptr_eq(c, chunk)) {
                continue;
            }
            for (i, t) in chunk.iter().enumerate() {
                if !theirs
                    .and_then(|c| c.get(i))
                    .is_some_and(|u| t.same_bits(u))
                {
                    f(t);
                }
            }
        }
    }

    /// A reader for increasing indices (a band's bin), each found in amortised constant time.
    pub fn cursor(&self) -> TriangleCursor<'_> {
        TriangleCursor {
            list: self,
            chunk: 0,
        }
    }
}

/// See [`TriangleList::cursor`].
pub(crate) struct TriangleCursor<'a> {
    list: &'a TriangleList,
    chunk: usize,
}

impl<'a> TriangleCursor<'a> {
    /// Triangle `i`; indices must not decrease between calls.
    pub fn get(&mut self, i: usize) -> &'a Triangle {
        let starts = &self.list.starts;
        // Skip ahead by galloping, then step: bins jump over many chunks at once.
        let mut step = 1;
        while self.chunk + step < starts.len() - 1 && starts[self.chunk + step] <= i {
            self.chunk += step;
            step *= 2;
        }
        while starts[self.chunk + 1] <= i {
            self.chunk += 1;
        }
        &self.list.chunks[self.chunk][i - starts[self.chunk]]
    }
}

fn floor_div(a: i128, b: i128) -> i128 {
    a.div_euclid(b)
}

fn ceil_div(a: i128, b: i128) -> i128 {
    -((-a).div_euclid(b))
}

/// `floor(a / b)` for `b > 0` and `|a|, |b| < 2^55` (the range of [`Triangle::span_small`]),
/// given `inv`, `1 / b` rounded: a floating-point quotient, which is within one of the answer,
/// corrected with exact integer products. Several times faster than a 64-bit integer division
/// (and than a floating-point one), and exact.
#[inline]
fn floor_div_small(a: i64, b: i64, inv: f64) -> i64 {
    // Truncation, not `floor` (a library call on baseline x86-64): one more step at most.
    let mut q = (a as f64 * inv) as i64;
    // Rounding a, b, 1 / b and the product to 53 bits errs by under 2^-51 relatively, so by
    // under 1/16 on quotients below 2^47 (|a| < 2^55, b >= 256): q is off by at most two,
    // and |q b| <= |a| + 3 b stays far below 2^63.
    while q * b > a {
        q -= 1;
    }
    while (q + 1) * b <= a {
        q += 1;
    }
    q
}

/// `floor(a / b)` for integers `|a| < EXACT_F64` and `b` in `256..EXACT_F64` held in `f64`,
/// given `inv`, `1 / b` rounded: the rounded quotient is within one of the answer, and one
/// exact test each way settles it (the products are integers below 2^53). Without branches
/// or integer conversions, so that rows vectorise.
#[inline(always)]
fn floor_div_f64(a: f64, b: f64, inv: f64) -> f64 {
    // Round to the nearest integer by adding and removing 1.5 * 2^52 (|a / b| < 2^43), then
    // down.
    const ROUND: f64 = 6_755_399_441_055_744.0;
    let t = a * inv;
    let r = (t + ROUND) - ROUND;
    let mut q = r - if r > t { 1.0 } else { 0.0 };
    q -= if q * b > a { 1.0 } else { 0.0 };
    q += if (q + 1.0) * b <= a { 1.0 } else { 0.0 };
    q
}

impl Triangle {
    /// The triangle through snapped vertices `v` with attributes `attr` at them; `None` if it
    /// has no area. The attributes' planes go through the exact vertex positions `exact` (pixel
    /// units): snapping decides which pixel centres are inside, but moving the colours with the
    /// vertices would shift the colour field by up to 1/512 pixel, which the gradient of a
    /// gradient mesh turns into visible 16-bit noise.
    #[cfg(test)]
    pub fn new(v: [[i64; 2]; 3], exact: [[f64; 2]; 3], attr: [[f64; 4]; 3]) -> Option<Triangle> {
        Self::new_quadratic(v, exact, attr, None, &UNBOUNDED)
    }

    /// As `Triangle::new` (the tests' constructor), and with `mids` quadratic: `mids[k]` are the attributes at the
    /// midpoint of the exact side from vertex `k` to vertex `k + 1` (the six nodes of a
    /// quadratic Lagrange triangle). Two triangles that share a side and its three nodes agree
    /// all along it.
    /// `bounds` are the layer's colour bounds, which [`Triangle::fill_row`] is given.
    pub fn new_quadratic(
        v: [[i64; 2]; 3],
        exact: [[f64; 2]; 3],
        attr: [[f64; 4]; 3],
        mids: Option<[[f64; 4]; 3]>,
        bounds: &Bounds,
    ) -> Option<Triangle> {
        let cross = |a: [i64; 2], b: [i64; 2], c: [i64; 2]| -> i128 {
            (b[0] - a[0]) as i128 * (c[1] - a[1]) as i128
                - (b[1] - a[1]) as i128 * (c[0] - a[0]) as i128
        };
        let mut v = v;
        let area2 = cross(v[0], v[1], v[2]);
        if area2 == 0 {
            return None;
        }
        if area2 < 0 {
            v.swap(1, 2);
        }
        let ymin = v.iter().map(|p| p[1]).min().expect("three vertices");
        let ymax = v.iter().map(|p| p[1]).max().expect("three vertices");
        let half = SUBPIXEL / 2;
        // Snapped coordinates are under 2^40: 64 bits hold this.
        let clamp = |r: i64| r.clamp(-ROW_CLAMP, ROW_CLAMP) as i32;
        let rows = [
            clamp(-((half - ymin).div_euclid(SUBPIXEL))),
            clamp((ymax - half).div_euclid(SUBPIXEL) + 1),
        ];
        let origin = Self::origin_of(&v);

        // Plane of each attribute, in pixel units, through the exact positions (a triangle
        // that snapping left with area may have none exactly: then keep the mean value).
        let [a, b, c] = exact;
        let (e1, e2) = ([b[0] - a[0], b[1] - a[1]], [c[0] - a[0], c[1] - a[1]]);
        let det = e1[0] * e2[1] - e1[1] * e2[0];
        // Coefficients of 1, x, y, x^2, x y, y^2 (offsets from the origin) per attribute.
        let mut poly = [[0.0f64; 4]; 6];
        if det == 0.0 || !det.is_finite() {
            for k in 0..4 {
                poly[0][k] = (attr[0][k] + attr[1][k] + attr[2][k]) / 3.0;
            }
        } else {
            // From the first vertex, which lies within a pixel of the origin.
            let (dx, dy) = (origin[0] - a[0], origin[1] - a[1]);
            for k in 0..4 {
                let (d1, d2) = (attr[1][k] - attr[0][k], attr[2][k] - attr[0][k]);
                let (sx, sy) = (
                    (d1 * e2[1] - d2 * e1[1]) / det,
                    (d2 * e1[0] - d1 * e2[0]) / det,
                );
                poly[0][k] = attr[0][k] + sx * dx + sy * dy;
                poly[1][k] = sx;
                poly[2][k] = sy;
            }
            if let Some(mids) = mids {
                // Barycentric coordinates as affine functions of the offset from the origin:
                // (constant, d/dx, d/dy).
                let l1 = [(dx * e2[1] - dy * e2[0]) / det, e2[1] / det, -e2[0] / det];
                let l2 = [(e1[0] * dy - e1[1] * dx) / det, -e1[1] / det, e1[0] / det];
                let l0 = [1.0 - l1[0] - l2[0], -l1[1] - l2[1], -l1[2] - l2[2]];
                let l = [l0, l1, l2];
                // The quadratic triangle is the linear one plus a bump `4 l_i l_j` per side,
                // weighted by how far the side's midpoint value lies off the mean of its ends.
                for side in 0..3 {
                    let (p, q) = (l[side], l[(side + 1) % 3]);
                    let bump = [
                        p[0] * q[0],
                        p[0] * q[1] + p[1] * q[0],
                        p[0] * q[2] + p[2] * q[0],
                        p[1] * q[1],
                        p[1] * q[2] + p[2] * q[1],
                        p[2] * q[2],
                    ];
                    let (ci, cj) = (attr[side], attr[(side + 1) % 3]);
                    for k in 0..4 {
                        let w = 4.0 * (mids[side][k] - 0.5 * (ci[k] + cj[k]));
                        for (n, t) in bump.iter().enumerate() {
                            poly[n][k] += w * t;
                        }
                    }
                }
            }
        }
        let single = |n: usize| each4(|k| poly[n][k] as f32);
        Some(Triangle {
            v,
            rows,
            at_origin: single(0),
            gx: single(1),
            gy: single(2),
            qxx: single(3),
            qxy: single(4),
            qyy: single(5),
            #[cfg(test)]
            quadratic: mids.is_some(),
            clamped: mids.is_some_and(|m| !within_bounds(&attr, &m, bounds)),
        })
    }

    /// Whether `other` is this triangle bit for bit: it then draws the same pixels.
    pub fn same_bits(&self, other: &Triangle) -> bool {
        let bits = |t: &Triangle| {
            [t.at_origin, t.gx, t.gy, t.qxx, t.qxy, t.qyy].map(|a| a.map(f32::to_bits))
        };
        self.v == other.v
            && self.rows == other.rows
            && self.clamped == other.clamped
            && bits(self) == bits(other)
    }

    /// The snapped vertices, in sub-pixel units.
    #[cfg(test)]
    pub fn vertices(&self) -> [[i64; 2]; 3] {
        self.v
    }

    /// Whether the attributes have quadratic terms.
    #[cfg(test)]
    pub fn is_quadratic(&self) -> bool {
        self.quadratic
    }

    /// Columns `[start, end)` of a `width`-pixel image holding every pixel centre inside
    /// (with a pixel to spare on each side).
    pub fn columns(&self, width: usize) -> (usize, usize) {
        let xs = self.v.map(|v| v[0]);
        let lo = xs[0].min(xs[1]).min(xs[2]).div_euclid(SUBPIXEL) - 1;
        let hi = xs[0].max(xs[1]).max(xs[2]).div_euclid(SUBPIXEL) + 2;
        let clamp = |x: i64| x.clamp(0, width as i64) as usize;
        (clamp(lo), clamp(hi))
    }

    /// The first row and one past the last whose pixel centres may lie inside.
    #[inline]
    pub fn rows(&self) -> (i64, i64) {
        (self.rows[0] as i64, self.rows[1] as i64)
    }

    /// The pixel corner at or below (in both coordinates) the first vertex.
    #[inline]
    fn origin(&self) -> [f64; 2] {
        Self::origin_of(&self.v)
    }

    #[inline]
    fn origin_of(v: &[[i64; 2]; 3]) -> [f64; 2] {
        [
            v[0][0].div_euclid(SUBPIXEL) as f64,
            v[0][1].div_euclid(SUBPIXEL) as f64,
        ]
    }

    /// Whether every vertex lies within [`SMALL`] of the origin.
    #[inline]
    fn small(&self) -> bool {
        self.v.iter().flatten().all(|c| c.abs() < SMALL)
    }

    #[inline(always)]
    fn edges(&self) -> [Edge; 3] {
        let v = &self.v;
        [
            Edge::new(v[0], v[1]),
            Edge::new(v[1], v[2]),
            Edge::new(v[2], v[0]),
        ]
    }

    /// The columns `[start, end)` of row `j` whose pixel centres lie inside, clipped to
    /// `0..width`.
    #[cfg(test)]
    pub fn span(&self, j: i64, width: i64) -> (i64, i64) {
        let mut span = (0, 0);
        self.for_each_span(j..j + 1, width, |_, a, b| span = (a, b));
        span
    }

    /// Calls `f(j, start, end)` with the columns inside for each row `j` in `rows`, finding
    /// the edges once. Rows go in groups of up to [`SPAN_ROWS`], whose spans are found
    /// together ([`Triangle::spans_f64`]) where the edge functions are small enough, one by
    /// one in integers elsewhere and in groups of one or two rows (a small triangle's share of
    /// a band, for which the groups' set-up cost more than they saved). `f` is called from one
    /// place: a second call site kept the attribute fill it inlines from being compiled with
    /// wide vectors.
    #[inline(always)]
    pub fn for_each_span(
        &self,
        rows: std::ops::Range<i64>,
        width: i64,
        mut f: impl FnMut(i64, i64, i64),
    ) {
        let edges = self.edges();
        let small = self.small();
        let mut spans = [(0i64, 0i64); SPAN_ROWS];
        let mut j0 = rows.start;
        while j0 < rows.end {
            let j1 = rows.end.min(j0 + SPAN_ROWS as i64);
            if j1 - j0 < 3 || !Self::spans_f64(&edges, j0, j1, width, &mut spans) {
                for (span, j) in spans.iter_mut().zip(j0..j1) {
                    *span = if small && j.abs() < SMALL_ROWS {
                        Self::span_small(&edges, j, width)
                    } else {
                        Self::span_i128(&edges, j, width)
                    };
                }
            }
            for (&(a, b), j) in spans.iter().zip(j0..j1) {
                f(j, a, b);
            }
            j0 = j1;
        }
    }

    /// The spans of rows `j0..j1` (at most [`SPAN_ROWS`]) into `out`, in double precision:
    /// every row's edge function values, quotients and their products are integers below
    /// [`EXACT_F64`], so each step is exact, and the rows are independent lanes without
    /// branches, computed four at a time (vectorised). `false`, leaving `out` alone, where
    /// some value is too large.
    #[inline(always)]
    fn spans_f64(
        edges: &[Edge; 3],
        j0: i64,
        j1: i64,
        width: i64,
        out: &mut [(i64, i64); SPAN_ROWS],
    ) -> bool {
        let half = SUBPIXEL / 2;
        let mut lo = [0.0f64; SPAN_ROWS];
        let mut hi = [width as f64; SPAN_ROWS];
        // Row `j0 + r` as a lane number; whole vectors of four lanes are computed.
        let lane: [f64; SPAN_ROWS] = std::array::from_fn(|r| r as f64);
        let lanes = ((j1 - j0) as usize).next_multiple_of(4).min(SPAN_ROWS);
        for e in edges {
            let (px, py) = (e.p[0], e.p[1]);
            let (dx, dy) = (e.d[0], e.d[1]);
            // E(i) = dx (ry - py) - dy (256 i + 128 - px) = k - m i, with k linear in the
            // row: its largest magnitude over the rows is at the first or the last.
            let k_at = |j: i64| {
                dx.checked_mul(j.checked_mul(SUBPIXEL)?.checked_add(half - py)?)?
                    .checked_sub(dy.checked_mul(half - px)?)
            };
            let (Some(k_first), Some(k_last)) = (k_at(j0), k_at(j1 - 1)) else {
                return false;
            };
            let Some(m) = dy.checked_mul(SUBPIXEL) else {
                return false;
            };
            let step = dx.saturating_mul(SUBPIXEL);
            if [k_first, k_last, m, step]
                .iter()
                .any(|v| v.unsigned_abs() >= EXACT_F64 as u64)
            {
                return false;
            }
            let (k0, step, b) = (k_first as f64, step as f64, m.abs() as f64);
            let k = |r: usize| k0 + step * lane[r];
            if m == 0 {
                // A horizontal edge: the whole row is inside or outside.
                for r in 0..lanes {
                    let kr = k(r);
                    let inside = kr > 0.0 || (kr == 0.0 && e.include);
                    hi[r] = if inside { hi[r] } else { f64::NEG_INFINITY };
                }
            } else if m > 0 {
                for r in 0..lanes {
                    let kr = k(r);
                    let stop = if e.include {
                        floor_div_f64(kr, b, e.inv) + 1.0
                    } else {
                        -floor_div_f64(-kr, b, e.inv)
                    };
                    hi[r] = hi[r].min(stop);
                }
            } else {
                for r in 0..lanes {
                    let kr = k(r);
                    let first = if e.include {
                        -floor_div_f64(kr, b, e.inv)
                    } else {
                        floor_div_f64(-kr, b, e.inv) + 1.0
                    };
                    lo[r] = lo[r].max(first);
                }
            }
        }
        for r in 0..(j1 - j0) as usize {
            out[r] = if lo[r] < hi[r] {
                (lo[r] as i64, hi[r] as i64)
            } else {
                (0, 0)
            };
        }
        true
    }

    /// A row's span in 64-bit integers: exact when the vertices lie within [`SMALL`] and
    /// the row within [`SMALL_ROWS`] (every product stays under 2^55), and several times faster
    /// than 128-bit division. Same arithmetic, same answers.
    // Always inlined, as are the other functions of the drawing loop: they are then compiled
    // with the wide vector instructions of `render::wide_vectors` where the CPU has them.
    #[inline(always)]
    fn span_small(edges: &[Edge; 3], j: i64, width: i64) -> (i64, i64) {
        let half = SUBPIXEL / 2;
        let ry = j * SUBPIXEL + half;
        let (mut start, mut end) = (0i64, width);
        for e in edges {
            let (px, py) = (e.p[0], e.p[1]);
            let (dx, dy) = (e.d[0], e.d[1]);
            let k = dx * (ry - py) - dy * (half - px);
            let m = dy * SUBPIXEL;
            if m == 0 {
                if !(k > 0 || (k == 0 && e.include)) {
                    return (0, 0);
                }
            } else if m > 0 {
                let stop = if e.include {
                    floor_div_small(k, m, e.inv) + 1
                } else {
                    -floor_div_small(-k, m, e.inv)
                };
                end = end.min(stop);
            } else {
                let n = -m;
                let first = if e.include {
                    -floor_div_small(k, n, e.inv)
                } else {
                    floor_div_small(-k, n, e.inv) + 1
                };
                start = start.max(first);
            }
        }
        if start >= end {
            (0, 0)
        } else {
            (start, end)
        }
    }

    /// A row's span in 128-bit integers, for any snapped coordinates.
    fn span_i128(edges: &[Edge; 3], j: i64, width: i64) -> (i64, i64) {
        let half = (SUBPIXEL / 2) as i128;
        let ry = j as i128 * SUBPIXEL as i128 + half;
        let (mut start, mut end) = (0i128, width as i128);
        for e in edges {
            let (px, py) = (e.p[0] as i128, e.p[1] as i128);
            let (dx, dy) = (e.d[0] as i128, e.d[1] as i128);
            // E(i) = dx (ry - py) - dy (256 i + 128 - px) = k - m i.
            let k = dx * (ry - py) - dy * (half - px);
            let m = dy * SUBPIXEL as i128;
            if m == 0 {
                if !(k > 0 || (k == 0 && e.include)) {
                    return (0, 0);
                }
            } else if m > 0 {
                let stop = if e.include {
                    floor_div(k, m) + 1
                } else {
                    ceil_div(k, m)
                };
                end = end.min(stop);
            } else {
                let n = -m;
                let first = if e.include {
                    ceil_div(-k, n)
                } else {
                    floor_div(-k, n) + 1
                };
                start = start.max(first);
            }
        }
        if start >= end {
            (0, 0)
        } else {
            (start as i64, end as i64)
        }
    }

    /// The attributes at pixel coordinates `(x, y)`.
    #[cfg(test)]
    pub fn eval(&self, x: f64, y: f64) -> [f32; 4] {
        self.fill_row(y, x, &mut [[0.0; 4]], &UNBOUNDED)[0]
    }

    /// Writes the attributes at the pixel centres `x0, x0 + 1, ..` of row `y` (pixel
    /// coordinates of the centres) into `out`: the row's polynomial in `x` once, then two
    /// multiply-adds per attribute and pixel, in single precision. On a linear triangle the
    /// quadratic terms are zero and the values are the plane's, bit for bit; a quadratic one's
    /// are clamped to `bounds`.
    #[inline(always)]
    pub fn fill_row<'a>(
        &self,
        y: f64,
        x0: f64,
        out: &'a mut [[f32; 4]],
        bounds: &Bounds,
    ) -> &'a [[f32; 4]] {
        let o = self.origin();
        // Exact while the row lies within 2^23 pixels of the origin (a triangle with a vertex
        // near the image); farther, the rounding is a fraction of the gradient's change over
        // the triangle.
        let (dy, dx0) = ((y - o[1]) as f32, (x0 - o[0]) as f32);
        let row: [f32; 4] = each4(|k| self.at_origin[k] + self.gy[k] * dy + self.qyy[k] * dy * dy);
        let slope: [f32; 4] = each4(|k| self.gx[k] + self.qxy[k] * dy);
        // An `i32` count: converting it to `f32` is one vector instruction, a `usize` one is
        // one scalar instruction per lane. The same values (spans are far below 2^31).
        for (n, out) in (0i32..).zip(out.iter_mut()) {
            let dx = dx0 + n as f32;
            *out = each4(|k| row[k] + (slope[k] + self.qxx[k] * dx) * dx);
        }
        if self.clamped {
            for v in out.iter_mut() {
                *v = each4(|k| v[k].clamp(bounds[0][k], bounds[1][k]));
            }
        }
        out
    }
}

/// The triangle through three points (pixels) with attributes `attr` (and quadratic, with the
/// side nodes `mids`, and the layer's colour `bounds`), snapped, if it may cover a pixel centre
/// of a `size` image.
pub(crate) fn screen_triangle_px(
    exact: [[f64; 2]; 3],
    attr: [[f64; 4]; 3],
    mids: Option<[[f64; 4]; 3]>,
    bounds: &Bounds,
    size: (i64, i64),
) -> Option<Triangle> {
    let v = snapped_if_visible(exact, size)?;
    let tri = Triangle::new_quadratic(v, exact, attr, mids, bounds)?;
    let rows = tri.rows();
    (rows.1 > 0 && rows.0 < size.1 && rows.0 < rows.1).then_some(tri)
}

/// The snapped corners of the triangle through three points (pixels), unless it surely covers
/// no pixel centre of a `size` image: it lies beside the image, or no column of pixel centres
/// runs between its leftmost and rightmost corner, or no row between its lowest and highest
/// (at deep levels most cells are under a pixel).
pub(crate) fn snapped_if_visible(exact: [[f64; 2]; 3], size: (i64, i64)) -> Option<[[i64; 2]; 3]> {
    let (w, h) = size;
    let (xmax, ymax) = (w * SUBPIXEL, h * SUBPIXEL);
    let snapped = |p: [f64; 2]| Some([snap(p[0])?, snap(p[1])?]);
    let v = [snapped(exact[0])?, snapped(exact[1])?, snapped(exact[2])?];
    let outside = v.iter().all(|p| p[0] < 0)
        || v.iter().all(|p| p[0] > xmax)
        || v.iter().all(|p| p[1] < 0)
        || v.iter().all(|p| p[1] > ymax);
    // No column (row) of pixel centres runs between the least and the greatest x (y): the
    // row test is the triangle's own (`Triangle::rows`), made before building it.
    let half = SUBPIXEL / 2;
    let none_between = |axis: usize| {
        let lo = v.iter().map(|p| p[axis]).min().expect("three vertices");
        let hi = v.iter().map(|p| p[axis]).max().expect("three vertices");
        (lo - half).div_euclid(SUBPIXEL) == (hi - half).div_euclid(SUBPIXEL)
            && (lo - half).rem_euclid(SUBPIXEL) != 0
    };
    (!outside && !none_between(0) && !none_between(1)).then_some(v)
}

#[cfg(test)]
mod tests {
    /// `snap` rounds exactly as `f64::round` does, halves and limits included.
    #[test]
    fn snap_matches_round() {
        let by_round = |v: f64| {
            let s = (v * SUBPIXEL as f64).round();
            (s.is_finite() && s.abs() < LIMIT as f64).then_some(s as i64)
        };
        let limit_px = LIMIT as f64 / SUBPIXEL as f64;
        let mut values = vec![
            0.0,
            -0.0,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            limit_px,
            -limit_px,
            limit_px - 0.5 / SUBPIXEL as f64,
            limit_px - 1e-9,
            1e300,
        ];
        for k in 1..2000 {
            // Exact halves and quarters of a sub-pixel step, and values next to them.
            let v = k as f64 / (4.0 * SUBPIXEL as f64);
            let (up, down) = (
                f64::from_bits(v.to_bits() + 1),
                f64::from_bits(v.to_bits() - 1),
            );
            values.extend([v, up, down, -v, -up, -down, v * 1e6 + 0.123]);
        }
        for v in values {
            assert_eq!(snap(v), by_round(v), "{v:e}");
        }
    }

    use super::*;

    fn p(x: f64, y: f64) -> [i64; 2] {
        [snap(x).unwrap(), snap(y).unwrap()]
    }

    fn count(tris: &[Triangle], w: i64, h: i64) -> Vec<u32> {
        let mut hits = vec![0u32; (w * h) as usize];
        for t in tris {
            for j in t.rows().0.max(0)..t.rows().1.min(h) {
                let (a, b) = t.span(j, w);
                for i in a..b {
                    hits[(j * w + i) as usize] += 1;
                }
            }
        }
        hits
    }

    #[test]
    fn fan_through_pixel_centres_covers_each_once() {
        // A fan of triangles around a vertex at a pixel centre, with edges through other centres.
        let c = p(8.5, 8.5);
        let ring = [
            p(2.5, 2.5),
            p(8.5, 1.5),
            p(14.5, 2.5),
            p(15.5, 8.5),
            p(14.5, 14.5),
            p(8.5, 15.5),
            p(2.5, 14.5),
            p(1.5, 8.5),
        ];
        let tris: Vec<Triangle> = (0..8)
            .map(|k| {
                Triangle::new(
                    [c, ring[k], ring[(k + 1) % 8]],
                    [[0.0; 2]; 3],
                    [[0.0; 4]; 3],
                )
                .unwrap()
            })
            .collect();
        let hits = count(&tris, 17, 17);
        assert!(hits.iter().all(|&h| h <= 1), "double coverage");
        assert_eq!(hits[8 * 17 + 8], 1);
        // Every centre strictly inside the octagon is covered.
        for j in 3..14 {
            for i in 3..14 {
                assert_eq!(hits[j * 17 + i], 1, "{i} {j}");
            }
        }
    }

    #[test]
    fn grid_of_quads_has_no_gaps() {
        // A sheared grid of quads split in two triangles, vertices on awkward positions.
        let n = 7;
        let vert = |i: usize, j: usize| {
            p(
                1.0 + i as f64 * 2.25 + j as f64 * 0.375,
                0.5 + j as f64 * 2.0 + (i * i) as f64 * 0.0625,
            )
        };
        let mut tris = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let (a, b, c, d) = (
                    vert(i, j),
                    vert(i + 1, j),
                    vert(i + 1, j + 1),
                    vert(i, j + 1),
                );
                tris.extend(Triangle::new([a, b, c], [[0.0; 2]; 3], [[0.0; 4]; 3]));
                tris.extend(Triangle::new([a, c, d], [[0.0; 2]; 3], [[0.0; 4]; 3]));
            }
        }
        let hits = count(&tris, 24, 24);
        assert!(hits.iter().all(|&h| h <= 1));
        // Inside the grid, away from its outline, every centre is hit.
        assert_eq!(hits[8 * 24 + 8], 1);
        let covered = hits.iter().filter(|&&h| h == 1).count();
        assert!(covered > 200);
    }

    #[test]
    fn triangle_list_cursor_finds_every_index() {
        let tri = |x: f64| {
            Triangle::new(
                [p(x, 0.0), p(x + 1.0, 0.0), p(x, 1.0)],
                [[x, 0.0], [x + 1.0, 0.0], [x, 1.0]],
                [[x, 0.0, 0.0, 1.0]; 3],
            )
            .unwrap()
        };
        let sizes = [3, 0, 1, 7, 0, 0, 2, 5, 1, 1, 4];
        let mut x = 0.0;
        let chunks: Vec<Vec<Triangle>> = sizes
            .iter()
            .map(|&n| {
                (0..n)
                    .map(|_| {
                        x += 1.0;
                        tri(x)
                    })
                    .collect()
            })
            .collect();
        let list = TriangleList::from_chunks(chunks);
        assert_eq!(list.len(), sizes.iter().sum::<usize>());
        assert_eq!(list.iter().count(), list.len());
        // Every index, and sparse increasing subsets of them.
        for stride in [1, 2, 3, 5, 11] {
            let mut cursor = list.cursor();
            for i in (0..list.len()).step_by(stride) {
                assert_eq!(cursor.get(i).at_origin[0], (i + 1) as f32);
            }
        }
    }

    #[test]
    fn fast_floor_division_is_exact() {
        let mut next = crate::render::test_random(0x9e37_79b9_7f4a_7c15);
        for _ in 0..200_000 {
            let r = next();
            // Numerators of every size up to 2^55, both signs; denominators 256 .. 2^35.
            let a = ((r >> 9) as i64 >> (r % 50)) * if r & 1 == 0 { 1 } else { -1 };
            let b = 256 * (1 + (next() >> (29 + next() % 35)) as i64);
            let inv = 1.0 / b as f64;
            assert_eq!(floor_div_small(a, b, inv), a.div_euclid(b), "{a} / {b}");
            // Exact multiples and their neighbours.
            for a in [a / b * b - 1, a / b * b, a / b * b + 1] {
                assert_eq!(floor_div_small(a, b, inv), a.div_euclid(b), "{a} / {b}");
            }
        }
    }

    #[test]
    fn small_and_i128_spans_agree() {
        // Awkward vertices, both orientations, rows through and beside them.
        let mut bits = crate::render::test_random(0x2545_f491);
        let mut next = || (bits() % 20_000) as f64 / 37.0 - 20.0;
        for _ in 0..2000 {
            let v = [0, 1, 2].map(|_| p(next(), next()));
            let Some(t) = Triangle::new(v, [[0.0; 2]; 3], [[0.0; 4]; 3]) else {
                continue;
            };
            assert!(t.small());
            for j in t.rows().0 - 1..=t.rows().1 {
                let e = t.edges();
                assert_eq!(
                    Triangle::span_small(&e, j, 600),
                    Triangle::span_i128(&e, j, 600)
                );
            }
        }
    }

    #[test]
    fn spans_found_together_match_i128_spans() {
        // Triangles of every size from a pixel to far beyond the double-precision path's
        // range, near and far from the origin, with rows through, beside and far from them.
        let mut bits = crate::render::test_random(0x9e37_79b9);
        let (mut checked_f64, mut checked_integers) = (0, 0);
        for n in 0..3000 {
            let scale = [1.0, 50.0, 3000.0, 1e6, 3e9][n % 5];
            let centre = [
                (bits() % 4000) as f64 - 1000.0,
                (bits() % 4000) as f64 - 1000.0,
            ];
            let mut next = || (bits() % 1_000_000) as f64 / 1e6 - 0.5;
            let v = [0, 1, 2].map(|_| p(centre[0] + scale * next(), centre[1] + scale * next()));
            let Some(t) = Triangle::new(v, [[0.0; 2]; 3], [[0.0; 4]; 3]) else {
                continue;
            };
            let e = t.edges();
            let (r0, r1) = t.rows();
            let first = r0.max(-70_000) - 3;
            let rows = first..r1.min(first + 60) + 3;
            for width in [1, 600, 40_000] {
                let mut got = Vec::new();
                t.for_each_span(rows.clone(), width, |j, a, b| got.push((j, a, b)));
                let want: Vec<_> = rows
                    .clone()
                    .map(|j| {
                        let (a, b) = Triangle::span_i128(&e, j, width);
                        (j, a, b)
                    })
                    .collect();
                assert_eq!(got, want, "{v:?} width {width}");
                let mut spans = [(0, 0); SPAN_ROWS];
                if Triangle::spans_f64(&e, first, first + 16, width, &mut spans) {
                    checked_f64 += 1;
                } else {
                    checked_integers += 1;
                }
            }
        }
        // Both paths were taken, the double-precision one by most groups of rows.
        assert!(
            checked_f64 > 3000 && checked_integers > 100,
            "{checked_f64} {checked_integers}"
        );
    }

    /// Far from the image's origin and on a steep gradient, the single-precision attributes
    /// (relative to an integer origin by the first vertex) stay within a millionth of the
    /// attributes' range of the exact plane.
    #[test]
    fn attributes_stay_exact_far_from_the_origin() {
        for (x0, y0) in [(0.0, 0.0), (3000.37, 2047.9), (-1234.5, 60_000.25)] {
            let exact = [[x0, y0], [x0 + 7.3, y0 + 0.4], [x0 + 1.1, y0 + 5.9]];
            let attr = [
                [20.0, -40.0, 60.0, 1.0],
                [90.0, 35.0, -70.0, 0.5],
                [55.0, 120.0, 10.0, 0.0],
            ];
            let t = Triangle::new(exact.map(|q| p(q[0], q[1])), exact, attr).unwrap();
            for (u, v) in [(0.2, 0.3), (0.5, 0.1), (0.05, 0.9)] {
                let x = exact[0][0] + u * 7.3 + v * 1.1;
                let y = exact[0][1] + u * 0.4 + v * 5.9;
                let got = t.eval(x, y);
                for k in 0..4 {
                    let want =
                        attr[0][k] + u * (attr[1][k] - attr[0][k]) + v * (attr[2][k] - attr[0][k]);
                    assert!(
                        (got[k] as f64 - want).abs() < 2e-4,
                        "{x0} {k}: {} {want}",
                        got[k]
                    );
                }
            }
        }
    }

    /// A quadratic triangle reproduces any quadratic field from its six nodes, near the
    /// image's origin and far from it, whichever way round its vertices are given.
    #[test]
    fn quadratic_triangles_reproduce_quadratic_fields() {
        let field = |x: f64, y: f64, k: usize| -> f64 {
            let (x, y) = (x * 0.05, y * 0.05);
            [
                40.0 + 3.0 * x - 2.0 * y + 0.7 * x * x - 1.1 * x * y + 0.4 * y * y,
                -20.0 + x * y - 0.3 * y * y,
                10.0 - 0.9 * x * x + 2.0 * y,
                1.0 - 0.01 * x * y,
            ][k]
        };
        for (x0, y0) in [(0.0, 0.0), (2000.25, -731.6)] {
            let mut exact = [
                [x0 + 0.3, y0 + 0.1],
                [x0 + 17.9, y0 + 3.2],
                [x0 + 5.2, y0 + 14.7],
            ];
            for flip in [false, true] {
                if flip {
                    exact.swap(1, 2);
                }
                let attr = exact.map(|p| each4(|k| field(p[0], p[1], k)));
                let mids = [0, 1, 2].map(|i| {
                    let (a, b) = (exact[i], exact[(i + 1) % 3]);
                    each4(|k| field(0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), k))
                });
                let v = exact.map(|q| p(q[0], q[1]));
                let t = Triangle::new_quadratic(v, exact, attr, Some(mids), &UNBOUNDED).unwrap();
                let linear = Triangle::new(v, exact, attr).unwrap();
                let mut off_plane = 0.0f64;
                for (u, w) in [(0.2, 0.3), (0.5, 0.25), (0.1, 0.8), (0.33, 0.33)] {
                    let x = exact[0][0]
                        + u * (exact[1][0] - exact[0][0])
                        + w * (exact[2][0] - exact[0][0]);
                    let y = exact[0][1]
                        + u * (exact[1][1] - exact[0][1])
                        + w * (exact[2][1] - exact[0][1]);
                    let (got, plane) = (t.eval(x, y), linear.eval(x, y));
                    for k in 0..4 {
                        let want = field(x, y, k);
                        assert!(
                            (got[k] as f64 - want).abs() < 2e-3,
                            "{x0} {k}: {} {want}",
                            got[k]
                        );
                        off_plane = off_plane.max((plane[k] as f64 - want).abs());
                    }
                }
                // The field is far from linear over the triangle: the test sees the bumps.
                assert!(off_plane > 0.05, "{off_plane}");
            }
        }
    }

    /// A quadratic triangle is clamped to the layer's bounds unless it provably stays inside:
    /// every pixel lies within the bounds either way, and an unclamped triangle's pixels are
    /// its polynomial's.
    #[test]
    fn quadratic_triangles_stay_within_bounds() {
        let bounds: Bounds = [
            [0.0, -10.0, -10.0, 0.999_998],
            [100.0, 10.0, 10.0, 1.000_002],
        ];
        let exact = [[3.3, 2.1], [40.9, 7.2], [12.2, 35.7]];
        let v = exact.map(|q| p(q[0], q[1]));
        let (mut clamped, mut free) = (0, 0);
        // Side nodes from the mean of their ends outwards: inside, then overshooting.
        for bulge in [0.0, 2.0, 4.0, 6.0, 9.9, 10.5, 20.0] {
            for top in [50.0, 95.0, 99.999] {
                let attr = [
                    [top, 8.0, -9.0, 1.0],
                    [20.0, -9.5, 0.0, 1.0],
                    [top - 10.0, 0.0, 9.0, 0.999_999_999_999_999_8],
                ];
                let mids = [0, 1, 2].map(|i| {
                    each4(|k| {
                        let mean = 0.5 * (attr[i][k] + attr[(i + 1) % 3][k]);
                        if k == 3 {
                            mean
                        } else {
                            mean + [bulge, -bulge, bulge][i] * if k == 0 { 0.5 } else { 0.1 }
                        }
                    })
                });
                let t = Triangle::new_quadratic(v, exact, attr, Some(mids), &bounds).unwrap();
                let raw = Triangle::new_quadratic(v, exact, attr, Some(mids), &UNBOUNDED).unwrap();
                let (r0, r1) = t.rows();
                t.for_each_span(r0..r1, 64, |j, a, b| {
                    let n = (b - a) as usize;
                    let (mut got, mut poly) = (vec![[0.0; 4]; n], vec![[0.0; 4]; n]);
                    t.fill_row(j as f64 + 0.5, a as f64 + 0.5, &mut got, &bounds);
                    raw.fill_row(j as f64 + 0.5, a as f64 + 0.5, &mut poly, &bounds);
                    for (g, q) in got.iter().zip(&poly) {
                        for k in 0..4 {
                            assert!(g[k] >= bounds[0][k] && g[k] <= bounds[1][k], "{g:?}");
                            if !t.clamped {
                                assert_eq!(g[k], q[k]);
                            }
                        }
                    }
                });
                if t.clamped {
                    clamped += 1;
                } else {
                    free += 1;
                }
            }
        }
        // Both kinds were seen.
        assert!(clamped > 3 && free > 3, "{clamped} {free}");
    }

    #[test]
    fn attributes_are_linear() {
        let t = Triangle::new(
            [p(0.0, 0.0), p(10.0, 0.0), p(0.0, 10.0)],
            [[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]],
            [
                [0.0, 1.0, 2.0, 3.0],
                [10.0, 1.0, 2.0, 3.0],
                [0.0, 11.0, 2.0, 3.0],
            ],
        )
        .unwrap();
        let v = t.eval(2.5, 4.0);
        assert!((v[0] - 2.5).abs() < 1e-6 && (v[1] - 5.0).abs() < 1e-6 && v[3] == 3.0);
    }
}
