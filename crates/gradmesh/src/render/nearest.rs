//! Colours for outline pixels whose centre no triangle covers: the colour of the nearest point
//! of the tessellation's boundary (a boundary edge between two limit points, colours varying
//! linearly along it).
//!
//! Such pixels lie within about a pixel of the boundary polygon (the outline curve is within the
//! geometric tolerance of it), so this extends the surface's boundary colours outward by at most
//! that much. A uniform grid of cells finds the nearest edge; the search grows ring by ring
//! until no unseen edge can be closer, so the answer is exact and deterministic (ties go to the
//! lower edge index).

/// A boundary edge in pixel coordinates with the attributes at its ends.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Segment {
    pub a: [f64; 2],
    pub b: [f64; 2],
    pub ca: [f32; 4],
    pub cb: [f32; 4],
    /// The quadratic part: `bump t (1 - t)` is added at `t` along the segment (zero on a
    /// linear one, four times the midpoint's distance from the mean of the ends otherwise).
    pub bump: [f32; 4],
}

/// Boundary edges bucketed in a uniform grid.
#[derive(Clone, Debug, Default)]
pub(crate) struct NearestSegments {
    segments: Vec<Segment>,
    origin: [f64; 2],
    cell: f64,
    nx: usize,
    ny: usize,
    offsets: Vec<u32>,
    items: Vec<u32>,
}

impl NearestSegments {
    /// The boxes (`[[x0, x1], [y0, y1]]`, pixels) of the segments that differ in any bit
    /// between `old` and this, in either, when both hold as many: the others keep their
    /// indices, and an answer (the least distance, then the least index, whatever the grid)
    /// changes only where a changed segment is as near. `None` for another count.
    pub fn changed_boxes(&self, old: &NearestSegments) -> Option<Vec<[[f64; 2]; 2]>> {
        if self.segments.len() != old.segments.len() {
            return None;
        }
        let bits = |s: &Segment| {
            (
                [s.a, s.b].map(|p| p.map(f64::to_bits)),
                [s.ca, s.cb, s.bump].map(|c| c.map(f32::to_bits)),
            )
        };
        let span = |s: &Segment| [0, 1].map(|k| [s.a[k].min(s.b[k]), s.a[k].max(s.b[k])]);
        Some(
            self.segments
                .iter()
                .zip(&old.segments)
                .filter(|(a, b)| bits(a) != bits(b))
                .flat_map(|(a, b)| [span(a), span(b)])
                .collect(),
        )
    }

    pub fn new(segments: Vec<Segment>) -> Self {
        if segments.is_empty() {
            return NearestSegments::default();
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for s in &segments {
            for p in [s.a, s.b] {
                for c in 0..2 {
                    lo[c] = lo[c].min(p[c]);
                    hi[c] = hi[c].max(p[c]);
                }
            }
        }
        let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1.0);
        // About 8-pixel cells, at most 512 per side.
        let cell = 8.0f64.max(extent / 512.0);
        let nx = ((hi[0] - lo[0]) / cell).floor() as usize + 1;
        let ny = ((hi[1] - lo[1]) / cell).floor() as usize + 1;
        let cell_range = |a: f64, b: f64, o: f64, n: usize| {
            let i0 = (((a.min(b) - o) / cell).floor().max(0.0) as usize).min(n - 1);
            let i1 = (((a.max(b) - o) / cell).floor().max(0.0) as usize).min(n - 1);
            (i0, i1)
        };
        let mut counts = vec![0u32; nx * ny + 1];
        let ranges: Vec<_> = segments
            .iter()
            .map(|s| {
                (
                    cell_range(s.a[0], s.b[0], lo[0], nx),
                    cell_range(s.a[1], s.b[1], lo[1], ny),
                )
            })
            .collect();
        for &((x0, x1), (y0, y1)) in &ranges {
            for j in y0..=y1 {
                for i in x0..=x1 {
                    counts[j * nx + i + 1] += 1;
                }
            }
        }
        for k in 0..nx * ny {
            counts[k + 1] += counts[k];
        }
        let mut fill = counts.clone();
        let mut items = vec![0u32; counts[nx * ny] as usize];
        for (s, &((x0, x1), (y0, y1))) in ranges.iter().enumerate() {
            for j in y0..=y1 {
                for i in x0..=x1 {
                    let c = j * nx + i;
                    items[fill[c] as usize] = s as u32;
                    fill[c] += 1;
                }
            }
        }
        NearestSegments {
            segments,
            origin: lo,
            cell,
            nx,
            ny,
            offsets: counts,
            items,
        }
    }

    fn distance2(&self, s: usize, p: [f64; 2]) -> (f64, f64) {
        let seg = &self.segments[s];
        let (dx, dy) = (seg.b[0] - seg.a[0], seg.b[1] - seg.a[1]);
        let len2 = dx * dx + dy * dy;
        let t = if len2 > 0.0 {
            (((p[0] - seg.a[0]) * dx + (p[1] - seg.a[1]) * dy) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let (ex, ey) = (p[0] - seg.a[0] - t * dx, p[1] - seg.a[1] - t * dy);
        (ex * ex + ey * ey, t)
    }

    /// The attributes at the point of the boundary nearest to `p`, or `None` without boundary.
    #[cfg(test)]
    pub fn attributes_at(&self, p: [f64; 2]) -> Option<[f32; 4]> {
        self.attributes_and_distance_at(p).map(|(a, _)| a)
    }

    /// [`NearestSegments::attributes_at`], and the distance to that point.
    pub fn attributes_and_distance_at(&self, p: [f64; 2]) -> Option<([f32; 4], f64)> {
        if self.segments.is_empty() {
            return None;
        }
        let mut best: Option<(f64, usize, f64)> = None;
        let consider = |s: usize, best: &mut Option<(f64, usize, f64)>| {
            let (d2, t) = self.distance2(s, p);
            let better = match *best {
                None => true,
                Some((bd, bs, _)) => d2 < bd || (d2 == bd && s < bs),
            };
            if better {
                *best = Some((d2, s, t));
            }
        };
        let ci = ((p[0] - self.origin[0]) / self.cell).floor();
        let cj = ((p[1] - self.origin[1]) / self.cell).floor();
        let inside = ci >= 0.0 && cj >= 0.0 && (ci as usize) < self.nx && (cj as usize) < self.ny;
        if !inside {
            for s in 0..self.segments.len() {
                consider(s, &mut best);
            }
        } else {
            let (ci, cj) = (ci as i64, cj as i64);
            let max_r = self.nx.max(self.ny) as i64;
            for r in 0..=max_r {
                for j in (cj - r)..=(cj + r) {
                    for i in (ci - r)..=(ci + r) {
                        let on_ring = (j - cj).abs() == r || (i - ci).abs() == r;
                        if !on_ring || i < 0 || j < 0 || i >= self.nx as i64 || j >= self.ny as i64
                        {
                            continue;
                        }
                        let c = j as usize * self.nx + i as usize;
                        for &s in
                            &self.items[self.offsets[c] as usize..self.offsets[c + 1] as usize]
                        {
                            consider(s as usize, &mut best);
                        }
                    }
                }
                // Any edge not seen yet lies outside the square of rings 0..=r.
                if let Some((d2, _, _)) = best {
                    let left = self.origin[0] + (ci - r) as f64 * self.cell;
                    let top = self.origin[1] + (cj - r) as f64 * self.cell;
                    let right = self.origin[0] + (ci + r + 1) as f64 * self.cell;
                    let bottom = self.origin[1] + (cj + r + 1) as f64 * self.cell;
                    let margin = (p[0] - left)
                        .min(right - p[0])
                        .min(p[1] - top)
                        .min(bottom - p[1]);
                    // Strictly nearer (with room for rounding): an unseen edge at the same
                    // distance with a lower index would win, and the answer would then depend
                    // on the grid, which depends on every edge.
                    if d2 < margin * margin * (1.0 - 1e-9) {
                        break;
                    }
                }
            }
        }
        let (d2, s, t) = best?;
        let seg = &self.segments[s];
        let t = t as f32;
        let mut out = [0.0f32; 4];
        for k in 0..4 {
            out[k] = seg.ca[k] + t * (seg.cb[k] - seg.ca[k]) + seg.bump[k] * (t * (1.0 - t));
        }
        Some((out, d2.sqrt()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_nearest_edge_and_interpolates() {
        let mut segs = Vec::new();
        // A polyline of 200 edges along a circle of radius 100 around (150, 150).
        let n = 200;
        let pt = |k: usize| {
            let a = k as f64 / n as f64 * std::f64::consts::TAU;
            [150.0 + 100.0 * a.cos(), 150.0 + 100.0 * a.sin()]
        };
        for k in 0..n {
            segs.push(Segment {
                a: pt(k),
                b: pt(k + 1),
                ca: [k as f32, 0.0, 0.0, 1.0],
                cb: [(k + 1) as f32, 0.0, 0.0, 1.0],
                bump: [0.0; 4],
            });
        }
        let grid = NearestSegments::new(segs.clone());
        for (x, y) in [
            (251.0, 150.0),
            (150.0, 40.0),
            (163.0, 141.0),
            (400.0, 400.0),
        ] {
            let p = [x, y];
            let got = grid.attributes_at(p).unwrap();
            // Brute force.
            let mut best = (f64::INFINITY, 0.0f32);
            for s in &segs {
                let (dx, dy) = (s.b[0] - s.a[0], s.b[1] - s.a[1]);
                let t = (((p[0] - s.a[0]) * dx + (p[1] - s.a[1]) * dy) / (dx * dx + dy * dy))
                    .clamp(0.0, 1.0);
                let d = (p[0] - s.a[0] - t * dx).hypot(p[1] - s.a[1] - t * dy);
                if d < best.0 {
                    best = (d, s.ca[0] + t as f32 * (s.cb[0] - s.ca[0]));
                }
            }
            assert!((got[0] - best.1).abs() < 1e-3, "{p:?}: {got:?} vs {best:?}");
        }
    }
}
