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
    /// The boxes (`[[x0, x1], [y0, y1]]`, pixels) of the segments of `old` and of this that
    /// differ (in some bit), outside which no answer changes. With as many segments in both,
    /// the segments that differ at the same index: every other segment keeps its index, and an
    /// answer (the least distance, then the least index, whatever the grid) changes only where
    /// a differing segment, old or new, is as near. Otherwise those that lie in neither their
    /// common start nor their common end: the others keep their order in the same way. (A
    /// common start and end alone would take in the whole outline when an edit moves its
    /// first and last segments, as a point where an outline loop begins does.)
    pub fn changed_boxes(&self, old: &NearestSegments) -> Vec<[[f64; 2]; 2]> {
        let bits = |s: &Segment| {
            (
                [s.a, s.b].map(|p| p.map(f64::to_bits)),
                [s.ca, s.cb, s.bump].map(|c| c.map(f32::to_bits)),
            )
        };
        let (new, old) = (&self.segments, &old.segments);
        let same = |(a, b): (&Segment, &Segment)| bits(a) == bits(b);
        let span = |s: &Segment| [0, 1].map(|k| [s.a[k].min(s.b[k]), s.a[k].max(s.b[k])]);
        if new.len() == old.len() {
            return (new.iter().zip(old))
                .filter(|&p| !same(p))
                .flat_map(|(a, b)| [span(a), span(b)])
                .collect();
        }
        let prefix = new.iter().zip(old).take_while(|&p| same(p)).count();
        let rest = new.len().min(old.len()) - prefix;
        let suffix = (new.iter().rev().zip(old.iter().rev()))
            .take(rest)
            .take_while(|&p| same(p))
            .count();
        (new[prefix..new.len() - suffix].iter())
            .chain(&old[prefix..old.len() - suffix])
            .map(span)
            .collect()
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

    /// The attributes at the point of the boundary nearest to `p`, and the distance to that
    /// point; `None` without boundary.
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
        // The search starts from the cell nearest to `p`: outline pixels just outside the
        // segments' box (every pixel beside a rectangle's sides) used to test every segment.
        let cell_of = |x: f64, o: f64, n: usize| {
            let c = ((x - o) / self.cell).floor();
            if c.is_nan() {
                0
            } else {
                c.clamp(0.0, (n - 1) as f64) as i64
            }
        };
        let ci = cell_of(p[0], self.origin[0], self.nx);
        let cj = cell_of(p[1], self.origin[1], self.ny);
        let (nx, ny) = (self.nx as i64, self.ny as i64);
        for r in 0..=nx.max(ny) {
            for j in (cj - r).max(0)..=(cj + r).min(ny - 1) {
                for i in (ci - r).max(0)..=(ci + r).min(nx - 1) {
                    if (j - cj).abs() != r && (i - ci).abs() != r {
                        continue;
                    }
                    let c = j as usize * self.nx + i as usize;
                    for &s in &self.items[self.offsets[c] as usize..self.offsets[c + 1] as usize] {
                        consider(s as usize, &mut best);
                    }
                }
            }
            // An edge not seen yet lies in a cell of the grid beyond one of the sides of the
            // square of rings 0..=r that still has cells beyond it; none is left when no side
            // has.
            if let Some((d2, _, _)) = best {
                let edge = |k: i64, o: f64| o + k as f64 * self.cell;
                let mut margin = f64::INFINITY;
                if ci - r > 0 {
                    margin = margin.min(p[0] - edge(ci - r, self.origin[0]));
                }
                if ci + r < nx - 1 {
                    margin = margin.min(edge(ci + r + 1, self.origin[0]) - p[0]);
                }
                if cj - r > 0 {
                    margin = margin.min(p[1] - edge(cj - r, self.origin[1]));
                }
                if cj + r < ny - 1 {
                    margin = margin.min(edge(cj + r + 1, self.origin[1]) - p[1]);
                }
                // Strictly nearer (with room for rounding): an unseen edge at the same
                // distance with a lower index would win, and the answer would then depend
                // on the grid, which depends on every edge.
                if margin == f64::INFINITY || (margin > 0.0 && d2 < margin * margin * (1.0 - 1e-9))
                {
                    break;
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

    /// The answer is the brute force's, bit for bit (least distance, then least index), for
    /// points inside the segments' box and outside it (beside a rectangle's sides, where
    /// the outline pixels of a rectangular mesh lie), far and near.
    #[test]
    fn the_grid_search_gives_the_brute_force_answer_inside_and_outside_the_box() {
        // A rectangle's outline of 4 x 300 edges, 0.5 px long, colours varying along it.
        let mut corners = Vec::new();
        let n = 300;
        for k in 0..4 * n {
            let (side, t) = (k / n, (k % n) as f64 * 0.5);
            corners.push(match side {
                0 => [10.0 + t, 20.0],
                1 => [160.0, 20.0 + t],
                2 => [160.0 - t, 170.0],
                _ => [10.0, 170.0 - t],
            });
        }
        let segs: Vec<Segment> = (0..4 * n)
            .map(|k| Segment {
                a: corners[k],
                b: corners[(k + 1) % (4 * n)],
                ca: [k as f32, 0.5, 0.25, 1.0],
                cb: [(k + 1) as f32, 0.5, 0.25, 1.0],
                bump: [0.0, 0.1, 0.0, 0.0],
            })
            .collect();
        let grid = NearestSegments::new(segs.clone());
        let brute = |p: [f64; 2]| {
            let mut best: Option<(f64, usize, f64)> = None;
            for s in 0..segs.len() {
                let (d2, t) = grid.distance2(s, p);
                if best.is_none_or(|(bd, bs, _)| d2 < bd || (d2 == bd && s < bs)) {
                    best = Some((d2, s, t));
                }
            }
            best.unwrap()
        };
        let mut checked = 0;
        for j in 0..=190 {
            for i in 0..=180 {
                // Pixel centres around and inside the rectangle, and a few far away.
                let p = [i as f64 + 0.5 - 5.0, j as f64 + 0.5 - 5.0];
                let p = if (i + j) % 97 == 0 {
                    [p[0] * 7.0, p[1] * -3.0]
                } else {
                    p
                };
                let (d2, s, t) = brute(p);
                let (got, distance) = grid.attributes_and_distance_at(p).unwrap();
                let seg = &segs[s];
                let t = t as f32;
                let want: [f32; 4] = std::array::from_fn(|k| {
                    seg.ca[k] + t * (seg.cb[k] - seg.ca[k]) + seg.bump[k] * (t * (1.0 - t))
                });
                assert_eq!(got.map(f32::to_bits), want.map(f32::to_bits), "at {p:?}");
                assert_eq!(distance.to_bits(), d2.sqrt().to_bits(), "at {p:?}");
                checked += 1;
            }
        }
        assert!(checked > 30_000);
    }

    /// With as many segments as before, only those that differ count as changed, also when
    /// they are the first and the last (an outline loop beginning at a moved point); with a
    /// different number, everything between the common start and end.
    #[test]
    fn changed_boxes_are_those_of_the_segments_that_differ() {
        let segs: Vec<Segment> = (0..50)
            .map(|k| Segment {
                a: [k as f64, 0.0],
                b: [k as f64 + 1.0, 0.0],
                ca: [0.5; 4],
                cb: [0.5; 4],
                bump: [0.0; 4],
            })
            .collect();
        let old = NearestSegments::new(segs.clone());
        let mut moved = segs.clone();
        moved[0].a[1] = 2.0;
        moved[49].b[1] = -3.0;
        let boxes = NearestSegments::new(moved.clone()).changed_boxes(&old);
        assert_eq!(
            boxes,
            vec![
                [[0.0, 1.0], [0.0, 2.0]],
                [[0.0, 1.0], [0.0, 0.0]],
                [[49.0, 50.0], [-3.0, 0.0]],
                [[49.0, 50.0], [0.0, 0.0]],
            ]
        );
        moved.pop();
        let fewer = NearestSegments::new(moved).changed_boxes(&old);
        assert_eq!(fewer.len(), 49 + 50);
        assert!(NearestSegments::new(segs).changed_boxes(&old).is_empty());
    }

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
