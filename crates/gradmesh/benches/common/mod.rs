//! The meshes the benchmarks share.

// Each bench uses part of this.
#![allow(dead_code)]

pub mod wavy_grid;

use gradmesh::{ColourSpace, GradientMesh};
use kurbo::Point;

/// A jittered grid of `n` x `n` cells, every third cell split into two triangles: about
/// 1.33 n^2 faces of mixed sizes.
pub fn mesh(n: u32) -> GradientMesh {
    let mut m = GradientMesh::new(ColourSpace::Lab);
    for j in 0..=n {
        for i in 0..=n {
            let jitter = ((i * 7 + j * 13) % 10) as f64 * 0.02;
            m.add_point(
                Point::new(i as f64 + jitter, j as f64 - jitter),
                [(i % 100) as f64, (j % 50) as f64, 0.0],
            );
        }
    }
    for j in 0..n {
        for i in 0..n {
            let v = j * (n + 1) + i;
            let (a, b, c, d) = (v, v + 1, v + n + 2, v + n + 1);
            if (i + j) % 3 == 0 {
                m.add_face(vec![a, b, c]);
                m.add_face(vec![a, c, d]);
            } else {
                m.add_face(vec![a, b, c, d]);
            }
        }
    }
    m
}
