//! Which surface point each pixel sees: the quads of a refined level, placed at their limit
//! positions, are split into triangles and rasterised; each pixel centre inside a triangle
//! takes the barycentric combination of its corners' limit colours. What the colour fit needs
//! of the pixels is summed per triangle and per vertex here.

use crate::refine::Refinement;
use crate::ternary_step;

use super::image::Target;

/// No triangle covers the pixel.
pub(crate) const UNCOVERED: u32 = u32::MAX;

/// The triangle a pixel falls in: its three level vertices and barycentric weights.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PixelSample {
    pub corners: [u32; 3],
    pub bary: [f32; 3],
}

/// The pixels of a target seen through the limit surface of one refined level.
#[derive(Clone, Debug)]
pub(crate) struct Observation {
    /// Per pixel, its triangle (`corners[0] == UNCOVERED` when none covers it).
    pub samples: Vec<PixelSample>,
    /// Per pixel, the base face whose surface it sees (`UNCOVERED` when none).
    pub base_face: Vec<u32>,
    /// Per triangle: its corners and the weighted sums of products of its pixels' barycentric
    /// weights, `[m00, m11, m22, m01, m02, m12]`.
    pub triangles: Vec<([u32; 3], [f64; 6])>,
    /// Per level vertex: the weighted sum of the target colours times its barycentric weight.
    pub rhs: Vec<[f64; 3]>,
    /// Per level vertex: the weighted sum of its barycentric weights (its share of the pixels).
    pub mass: Vec<f64>,
}

/// The base face each face of level `depth` lies in.
pub(crate) fn base_faces(refinement: &Refinement, depth: usize) -> Vec<u32> {
    let base = refinement.topology(0);
    let mut of = vec![0u32; refinement.topology(1).face_count()];
    for f in 0..base.face_count() {
        let first = ternary_step::first_child_face(base, f);
        let n = base.face_vertices(f).len();
        of[first..first + 2 * n + 1].fill(f as u32);
    }
    for k in 1..depth {
        let t = refinement.topology(k);
        let mut child = vec![0u32; t.corner_count()];
        for f in 0..t.face_count() {
            let (s, e) = (
                t.face_offset(f),
                t.face_offset(f) + t.face_vertices(f).len(),
            );
            child[s..e].fill(of[f]);
        }
        of = child;
    }
    of
}

impl Observation {
    /// Rasterises the quads of level `depth` (all quads: `depth >= 2`) with their corners at
    /// `positions` (the level's limit positions, in pixels) over `target`. Where the surface
    /// folds over itself, a pixel sees the last triangle over it, as the renderer draws it (and
    /// as a later patch paints over an earlier one).
    pub fn new(
        refinement: &Refinement,
        depth: usize,
        positions: &[[f64; 2]],
        target: &Target,
    ) -> Observation {
        let t = refinement.topology(depth);
        let faces = base_faces(refinement, depth);
        let pixels = target.width * target.height;
        let mut obs = Observation {
            samples: vec![
                PixelSample {
                    corners: [UNCOVERED; 3],
                    bary: [0.0; 3],
                };
                pixels
            ],
            base_face: vec![UNCOVERED; pixels],
            triangles: Vec::with_capacity(2 * t.face_count()),
            rhs: vec![[0.0; 3]; t.vertex_count()],
            mass: vec![0.0; t.vertex_count()],
        };
        let mut triangles = Vec::with_capacity(2 * t.face_count());
        let mut triangle_of = vec![UNCOVERED; pixels];
        for f in 0..t.face_count() {
            let v = t.face_vertices(f);
            for tri in [[v[0], v[1], v[2]], [v[0], v[2], v[3]]] {
                let index = triangles.len() as u32;
                triangles.push(tri);
                obs.rasterise(tri, positions, target, (faces[f], index), &mut triangle_of);
            }
        }
        obs.sum_pixels(&triangles, &triangle_of, target);
        obs
    }

    /// Rasterises one triangle, number `index` of base face `face`: the pixel centres inside
    /// it take it (over any earlier triangle).
    fn rasterise(
        &mut self,
        tri: [u32; 3],
        positions: &[[f64; 2]],
        target: &Target,
        (face, index): (u32, u32),
        triangle_of: &mut [u32],
    ) {
        let p = tri.map(|v| positions[v as usize]);
        let area =
            (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
        if area.abs() < 1e-12 || !area.is_finite() {
            return;
        }
        let (w, h) = (target.width as f64, target.height as f64);
        let lo = |k: usize, size: f64| {
            let m = p.iter().map(|q| q[k]).fold(f64::INFINITY, f64::min);
            (m - 0.5).ceil().clamp(0.0, size) as usize
        };
        let hi = |k: usize, size: f64| {
            let m = p.iter().map(|q| q[k]).fold(f64::NEG_INFINITY, f64::max);
            ((m - 0.5).floor() + 1.0).clamp(0.0, size) as usize
        };
        let (x0, x1, y0, y1) = (lo(0, w), hi(0, w), lo(1, h), hi(1, h));
        for y in y0..y1 {
            let cy = y as f64 + 0.5;
            for x in x0..x1 {
                let i = y * target.width + x;
                let cx = x as f64 + 0.5;
                // Barycentric weights from the signed areas of the sub-triangles.
                let edge = |a: [f64; 2], b: [f64; 2]| {
                    ((b[0] - a[0]) * (cy - a[1]) - (cx - a[0]) * (b[1] - a[1])) / area
                };
                let b = [edge(p[1], p[2]), edge(p[2], p[0]), edge(p[0], p[1])];
                if b.iter().any(|&l| l < -1e-9) {
                    continue;
                }
                self.samples[i] = PixelSample {
                    corners: tri,
                    bary: b.map(|l| l as f32),
                };
                self.base_face[i] = face;
                triangle_of[i] = index;
            }
        }
    }

    /// Sums what the colour fit needs of the pixels: per triangle (`triangles[k]`, the one
    /// `triangle_of` gives a pixel) the products of its pixels' weights, per vertex its share
    /// of the pixels and of their target colours.
    fn sum_pixels(&mut self, triangles: &[[u32; 3]], triangle_of: &[u32], target: &Target) {
        let mut moments = vec![[0.0; 6]; triangles.len()];
        let mut seen = vec![false; triangles.len()];
        for (i, &k) in triangle_of.iter().enumerate() {
            let wt = target.weight[i];
            if k == UNCOVERED || wt == 0.0 {
                continue;
            }
            let (tri, m) = (triangles[k as usize], &mut moments[k as usize]);
            seen[k as usize] = true;
            let b = self.samples[i].bary.map(f64::from);
            m[0] += wt * b[0] * b[0];
            m[1] += wt * b[1] * b[1];
            m[2] += wt * b[2] * b[2];
            m[3] += wt * b[0] * b[1];
            m[4] += wt * b[0] * b[2];
            m[5] += wt * b[1] * b[2];
            for c in 0..3 {
                let v = tri[c] as usize;
                self.mass[v] += wt * b[c];
                for (r, t) in self.rhs[v].iter_mut().zip(&target.colour[i]) {
                    *r += wt * b[c] * t;
                }
            }
        }
        for (k, &tri) in triangles.iter().enumerate() {
            if seen[k] {
                self.triangles.push((tri, moments[k]));
            }
        }
    }

    /// `K z`, with `K` the matrix of the summed products of barycentric weights between level
    /// vertices: the data term of the normal equations before the rows are applied.
    pub fn apply_gram(&self, z: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let mut out = vec![[0.0; 3]; z.len()];
        for (tri, m) in &self.triangles {
            let [a, b, c] = tri.map(|v| v as usize);
            for k in 0..3 {
                let (za, zb, zc) = (z[a][k], z[b][k], z[c][k]);
                out[a][k] += m[0] * za + m[3] * zb + m[4] * zc;
                out[b][k] += m[3] * za + m[1] * zb + m[5] * zc;
                out[c][k] += m[4] * za + m[5] * zb + m[2] * zc;
            }
        }
        out
    }

    /// The colour each pixel sees, given the colours `z` of the level's vertices (`None` for
    /// an uncovered pixel).
    pub fn predict(&self, z: &[[f64; 3]], i: usize) -> Option<[f64; 3]> {
        let s = &self.samples[i];
        if s.corners[0] == UNCOVERED {
            return None;
        }
        let mut out = [0.0; 3];
        for k in 0..3 {
            let zc = &z[s.corners[k] as usize];
            for c in 0..3 {
                out[c] += s.bary[k] as f64 * zc[c];
            }
        }
        Some(out)
    }
}
