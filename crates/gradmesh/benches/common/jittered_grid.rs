//! The meshes of the scaling example and of the `mesh_size_1024` bench: jittered grids of
//! quads with smoothly varying colours, which leave the sRGB gamut over about half the image.

use gradmesh::{ColourSpace, Document, GradientMesh};
use kurbo::Point;

/// The grids' sizes: 10, 100, 1,000 and 10,000 faces.
pub const SIZES: [(u32, u32); 4] = [(5, 2), (10, 10), (40, 25), (100, 100)];

/// A jittered grid of `w` x `h` quads over a 1000-unit square, with smoothly varying colours.
pub fn grid(w: u32, h: u32) -> Document {
    let mut m = GradientMesh::new(ColourSpace::Lab);
    for j in 0..=h {
        for i in 0..=w {
            let (u, v) = (i as f64 / w as f64, j as f64 / h as f64);
            // Jitter inner points by up to a fifth of a cell, deterministically.
            let inner = i > 0 && i < w && j > 0 && j < h;
            let jitter = if inner { 0.2 } else { 0.0 };
            let (dx, dy) = (
                jitter * ((i * 7 + j * 13) % 11) as f64 / 10.0 - jitter / 2.0,
                jitter * ((i * 5 + j * 3) % 7) as f64 / 6.0 - jitter / 2.0,
            );
            m.add_point(
                Point::new(1000.0 * (u + dx / w as f64), 1000.0 * (v + dy / h as f64)),
                [
                    40.0 + 50.0 * u,
                    60.0 * (6.0 * v).sin(),
                    60.0 * (5.0 * u + 1.0).cos(),
                ],
            );
        }
    }
    for j in 0..h {
        for i in 0..w {
            let a = j * (w + 1) + i;
            m.add_face(vec![a, a + 1, a + w + 2, a + w + 1]);
        }
    }
    Document::new(vec![m])
}
