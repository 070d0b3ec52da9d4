//! Limit stencils: where each vertex of an all-quad level ends up on the limit surface.
//!
//! * smooth or dart vertex of valence `n`: `(n^2 V + 4 sum(E_i) + sum(D_i)) / (n (n + 5))`, with
//!   `E_i` its edge neighbours and `D_i` the diagonal corners of its quads;
//! * crease or boundary vertex: `(A + 4 V + B) / 6` along its two sharp edges;
//! * corner: `V`.
//!
//! As in OpenSubdiv, a semi-sharp feature still present at the level counts as sharp.

use crate::catmull_clark::{Level, Stencils};
use crate::rules::{self, VertexRule};

/// The limit stencils of every vertex of `level`, or `None` if a face adjacent to a smooth
/// vertex is not a quad (refine once more first).
pub fn limit_stencils(level: &Level) -> Option<Stencils> {
    let t = &level.topology;
    let mut stencils = Stencils::new();
    let mut terms = Vec::with_capacity(32);
    for v in 0..t.vertex_count() {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{CreasingMethod, SHARPNESS_INFINITE};
    use crate::topology::Topology;

    #[test]
    fn regular_interior_limit_is_the_bspline_point() {
        // (1/36) [1 4 1; 4 16 4; 1 4 1] on a regular grid.
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
                if topology.is_boundary_edge(e) {
                    SHARPNESS_INFINITE
                } else {
                    0.0
                }
            })
            .collect();
        let level = Level {
            topology,
            edge_sharpness,
            vertex_sharpness: vec![0.0; 25],
            creasing: CreasingMethod::Uniform,
        };
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
