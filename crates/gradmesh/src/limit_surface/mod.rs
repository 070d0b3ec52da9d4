//! Evaluating the limit surface: limit stencils (here), where each vertex of an all-quad level
//! ends up, and [`patches`], the surface face by face as bicubic patches or local refinement.
//!
//! Limit stencils:
//!
//! * smooth vertex of valence `n`: `(n^2 V + 4 sum(E_i) + sum(D_i)) / (n (n + 5))`, with `E_i`
//!   its edge neighbours and `D_i` the diagonal corners of its quads;
//! * dart (one sharp edge ending at an interior vertex): the smooth mask is not its limit,
//!   because the sharp edge's points follow the midpoint rule at every level; the exact mask is
//!   the dominant left eigenvector of the local subdivision matrix, computed per valence;
//! * crease or boundary vertex: `(A + 4 V + B) / 6` along its two sharp edges;
//! * corner: `V`.
//!
//! As in OpenSubdiv, a semi-sharp feature still present at the level counts as sharp.

pub(crate) mod boundary;
pub(crate) mod patches;

use std::collections::HashMap;

use crate::catmull_clark::{Level, Stencils};
use crate::rules::{self, VertexRule};

/// The limit stencils of every vertex of `level`, or `None` if a face adjacent to a smooth
/// vertex is not a quad (refine once more first).
pub fn limit_stencils(level: &Level) -> Option<Stencils> {
    use rayon::prelude::*;
    // Built in parallel by ranges of vertices, concatenated in order: the same table whatever
    // the thread count.
    const CHUNK: usize = 1 << 14;
    let n = level.topology.vertex_count();
    if n <= CHUNK {
        return limit_stencils_of(level, 0..n);
    }
    let parts: Vec<Stencils> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|k| limit_stencils_of(level, k * CHUNK..((k + 1) * CHUNK).min(n)))
        .collect::<Option<_>>()?;
    Some(Stencils::concat(&parts))
}

/// The limit stencils of the given vertices of `level`, in their order (see
/// [`limit_stencils`]; `None` if a face next to one of them that needs it is not a quad).
/// For a few vertices of a level: a locally refined face needs only its own grid's points.
pub fn limit_stencils_for(level: &Level, vertices: &[u32]) -> Option<Stencils> {
    limit_stencils_of(level, vertices.iter().map(|&v| v as usize))
}

/// The limit stencils of `vertices` of `level` (see [`limit_stencils`]).
fn limit_stencils_of(
    level: &Level,
    vertices: impl ExactSizeIterator<Item = usize>,
) -> Option<Stencils> {
    let t = &level.topology;
    let count = vertices.len();
    let mut stencils = Stencils::with_capacity(count, 10 * count);
    let mut terms = Vec::with_capacity(32);
    let mut dart_masks: HashMap<usize, Vec<f64>> = HashMap::new();
    for v in vertices {
        let edges = t.vertex_edges(v);
        match level.vertex_rule(v) {
            VertexRule::Corner => terms.push((v as u32, 1.0)),
            VertexRule::Crease => {
                terms.push((v as u32, 4.0 / 6.0));
                for &e in edges {
                    if rules::is_sharp(level.edge_sharpness[e as usize]) {
                        terms.push((t.other_vertex(e as usize, v as u32), 1.0 / 6.0));
                    }
                }
            }
            VertexRule::Dart if t.vertex_faces(v).len() == edges.len() => {
                let n = edges.len();
                let sharp = edges
                    .iter()
                    .position(|&e| rules::is_sharp(level.edge_sharpness[e as usize]))
                    .expect("a dart has one sharp edge");
                let mask = dart_masks.entry(n).or_insert_with(|| dart_mask(n));
                terms.push((v as u32, mask[0]));
                for k in 0..n {
                    // The mask has the sharp edge at ring position 0.
                    let r = (k + n - sharp) % n;
                    let e = edges[k] as usize;
                    terms.push((t.other_vertex(e, v as u32), mask[1 + r]));
                    let f = t.vertex_faces(v)[k] as usize;
                    let c = t.vertex_face_corners(v)[k] as usize;
                    let fv = t.face_vertices(f);
                    if fv.len() != 4 {
                        return None;
                    }
                    terms.push((fv[(c + 2) % 4], mask[1 + n + r]));
                }
            }
            VertexRule::Smooth | VertexRule::Dart => {
                if t.vertex_faces(v).is_empty() {
                    // An isolated vertex stays where it is.
                    terms.push((v as u32, 1.0));
                } else {
                    let n = edges.len() as f64;
                    let scale = 1.0 / (n * (n + 5.0));
                    terms.push((v as u32, n * n * scale));
                    for &e in edges {
                        terms.push((t.other_vertex(e as usize, v as u32), 4.0 * scale));
                    }
                    for (&f, &c) in t.vertex_faces(v).iter().zip(t.vertex_face_corners(v)) {
                        let fv = t.face_vertices(f as usize);
                        if fv.len() != 4 {
                            return None;
                        }
                        terms.push((fv[(c as usize + 2) % 4], scale));
                    }
                }
            }
        }
        stencils.push(&mut terms);
    }
    Some(stencils)
}

/// The limit mask of a dart of valence `n` whose sharp edge is ring edge 0: weights of
/// `[V, E_0 .. E_(n-1), D_0 .. D_(n-1)]`, with `D_k` the diagonal of the quad between ring edges
/// `k` and `k + 1`.
///
/// The one-ring of a vertex refines into the one-ring of its vertex point by a fixed matrix
/// `S` (smooth vertex rule, smooth edge rule except the midpoint rule on edge 0, face
/// centroids). The limit mask is the left eigenvector of `S` for eigenvalue 1, normalised to
/// sum 1; power iteration converges because every other eigenvalue is below 1 in magnitude.
fn dart_mask(n: usize) -> Vec<f64> {
    let size = 1 + 2 * n;
    let (e, d) = (|k: usize| 1 + k % n, |k: usize| 1 + n + k % n);
    let nf = n as f64;
    // Rows of S: new point = sum of weights times old points.
    let mut s = vec![vec![0.0; size]; size];
    let centroid = |row: &mut Vec<f64>, k: usize, w: f64| {
        // Quad k: V, E_k, D_k, E_(k+1).
        for i in [0, e(k), d(k), e(k + 1)] {
            row[i] += w / 4.0;
        }
    };
    s[0][0] = (nf - 2.0) / nf;
    for k in 0..n {
        s[0][e(k)] += 1.0 / (nf * nf);
        centroid(&mut s[0], k, 1.0 / (nf * nf));
    }
    for k in 0..n {
        let row = &mut s[e(k)];
        if k == 0 {
            row[0] += 0.5;
            row[e(0)] += 0.5;
        } else {
            row[0] += 0.25;
            row[e(k)] += 0.25;
            centroid(row, k, 0.25);
            centroid(row, k + n - 1, 0.25);
        }
        centroid(&mut s[d(k)], k, 1.0);
    }
    let mut l = vec![1.0 / size as f64; size];
    for _ in 0..10_000 {
        let mut next = vec![0.0; size];
        for (i, row) in s.iter().enumerate() {
            for (j, &w) in row.iter().enumerate() {
                next[j] += l[i] * w;
            }
        }
        let sum: f64 = next.iter().sum();
        next.iter_mut().for_each(|x| *x /= sum);
        let change = next
            .iter()
            .zip(&l)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        l = next;
        if change < 1e-17 {
            break;
        }
    }
    l
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{CreasingMethod, SHARPNESS_INFINITE};
    use crate::topology::Topology;
    use crate::validate::VertexData;

    /// The dart mask equals the position of the vertex after many levels of refinement.
    #[test]
    fn dart_mask_is_the_limit_of_refinement() {
        use crate::catmull_clark::refine;
        for n in 3..=6u32 {
            // A closed fan of n quads around vertex 0, spoke 0-1 infinitely sharp.
            let faces: Vec<Vec<u32>> = (0..n)
                .map(|i| vec![0, 1 + i, n + 1 + i, 1 + (i + 1) % n])
                .collect();
            let nv = 1 + 2 * n as usize;
            let topology = Topology::from_faces(nv, &faces).unwrap();
            let edge_sharpness = (0..topology.edge_count())
                .map(|e| {
                    let [a, b] = topology.edge_vertices(e);
                    if topology.is_boundary_edge(e) || (a.min(b), a.max(b)) == (0, 1) {
                        SHARPNESS_INFINITE
                    } else {
                        0.0
                    }
                })
                .collect();
            let mut level = Level {
                topology,
                edge_sharpness,
                vertex_sharpness: vec![0.0; nv],
                creasing: CreasingMethod::Uniform,
            };
            assert_eq!(level.vertex_rule(0), VertexRule::Dart);
            let data: Vec<VertexData> = (0..nv)
                .map(|i| {
                    let x = (i as f64 * 1.7).sin() * 3.0 + i as f64;
                    VertexData::from_array([x, (i as f64 * 0.9).cos() * 5.0, x * x, 0.0, 0.0, 1.0])
                })
                .collect();
            // The limit of the vertex is the same whichever level it is computed from, and the
            // vertex point approaches it level by level.
            let mask = limit_stencils(&level).unwrap().apply(&data)[0];
            let mut d = data.clone();
            let mut index = 0usize;
            let first_gap =
                (d[0].position[0] - mask.position[0]).hypot(d[0].position[1] - mask.position[1]);
            let mut gap = first_gap;
            for _ in 0..6 {
                let (child, st) = refine(&level);
                index += level.topology.face_count() + level.topology.edge_count();
                d = st.apply(&d);
                level = child;
                let again = limit_stencils(&level).unwrap().apply(&d)[index];
                for c in 0..3 {
                    assert!(
                        (mask.to_array()[c] - again.to_array()[c]).abs()
                            < 1e-12 * (1.0 + mask.to_array()[c].abs()),
                        "n {n}: {mask:?} vs {again:?}"
                    );
                }
                gap = (d[index].position[0] - mask.position[0])
                    .hypot(d[index].position[1] - mask.position[1]);
            }
            assert!(gap < 0.2 * first_gap, "n {n}: {gap} after {first_gap}");
        }
    }

    /// A 4x4 grid of quads (vertex `5 j + i`), its boundary and the edges `(a, b)` for which
    /// `sharp(a, b)` holds infinitely sharp.
    fn grid_4x4(sharp: impl Fn(u32, u32) -> bool) -> Level {
        let n = 4u32;
        let mut faces = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let v = j * (n + 1) + i;
                faces.push(vec![v, v + 1, v + n + 2, v + n + 1]);
            }
        }
        let topology = Topology::from_faces(25, &faces).unwrap();
        let edge_sharpness = (0..topology.edge_count())
            .map(|e| {
                let [a, b] = topology.edge_vertices(e);
                if topology.is_boundary_edge(e) || sharp(a, b) {
                    SHARPNESS_INFINITE
                } else {
                    0.0
                }
            })
            .collect();
        Level {
            topology,
            edge_sharpness,
            vertex_sharpness: vec![0.0; 25],
            creasing: CreasingMethod::Uniform,
        }
    }

    /// The stencils of a few vertices, in any order, are those of the whole level, bit for bit
    /// (smooth, boundary and corner vertices of a grid with a dart in it).
    #[test]
    fn stencils_of_some_vertices_match_the_whole_level() {
        // Boundary, and one spoke from the centre: the centre is a dart.
        let level = grid_4x4(|a, b| (a.min(b), a.max(b)) == (7, 12));
        assert_eq!(level.vertex_rule(12), VertexRule::Dart);
        let all = limit_stencils(&level).unwrap();
        let some = [12u32, 0, 7, 24, 6, 2];
        let part = limit_stencils_for(&level, &some).unwrap();
        for (k, &v) in some.iter().enumerate() {
            let (s, w) = all.stencil(v as usize);
            let (ps, pw) = part.stencil(k);
            assert_eq!(s, ps, "vertex {v}");
            assert_eq!(
                w.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                pw.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                "vertex {v}"
            );
        }
    }

    #[test]
    fn regular_interior_limit_is_the_bspline_point() {
        // (1/36) [1 4 1; 4 16 4; 1 4 1] on a regular grid.
        let level = grid_4x4(|_, _| false);
        let st = limit_stencils(&level).unwrap();
        let (s, w) = st.stencil(12);
        for (&s, &w) in s.iter().zip(w) {
            let (dx, dy) = ((s as i32 % 5 - 2).abs(), (s as i32 / 5 - 2).abs());
            let f = |d: i32| [4.0, 1.0, 0.0][d as usize];
            assert!((w - f(dx) * f(dy) / 36.0).abs() < 1e-12);
        }
        // Boundary vertex 2 (middle of the top row): (1 4 1) / 6.
        let (s, w) = st.stencil(2);
        assert_eq!(s, &[1, 2, 3]);
        for (w, e) in w.iter().zip([1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0]) {
            assert!((w - e).abs() < 1e-15);
        }
    }
}
