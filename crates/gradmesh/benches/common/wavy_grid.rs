//! The scene of the `vs_cairo` bench: a rectangular 4x4-point mesh with curved edges (9
//! patches) in a 1024-unit square, in sRGB. The `vs_cairo_scene` example renders it once, for
//! instruction counts.

use gradmesh::{ColourSpace, Document, GradientMesh};
use kurbo::{Point, Vec2};

/// Points a side.
pub const N: usize = 4;

/// Control points of the 4x4 grid, with wavy positions, in a 1024-unit square.
pub fn grid() -> Vec<Point> {
    let mut p = Vec::new();
    for j in 0..N {
        for i in 0..N {
            let (x, y) = (40.0 + 944.0 * i as f64 / 3.0, 40.0 + 944.0 * j as f64 / 3.0);
            p.push(Point::new(
                x + 30.0 * (y / 160.0).sin(),
                y + 25.0 * (x / 190.0).sin(),
            ));
        }
    }
    p
}

/// The sRGB colour of grid point `(i, j)`.
pub fn colour(i: usize, j: usize) -> [f64; 3] {
    let t = (i * 7 + j * 3) as f64;
    [
        0.5 + 0.5 * (t * 0.9).sin(),
        0.5 + 0.5 * (t * 1.3 + 1.0).sin(),
        0.5 + 0.5 * (t * 0.7 + 2.0).sin(),
    ]
}

/// The handle of grid point `a` towards `b`, bent a little so that edges are curved.
pub fn handle(p: &[Point], a: usize, b: usize) -> Vec2 {
    let d = (p[b] - p[a]) / 3.0;
    Vec2::new(d.x - 0.15 * d.y, d.y + 0.15 * d.x)
}

/// The scene as a one-layer document.
pub fn document() -> Document {
    let p = grid();
    let mut m = GradientMesh::new(ColourSpace::Srgb);
    for j in 0..N {
        for i in 0..N {
            m.add_point(p[j * N + i], colour(i, j));
        }
    }
    for j in 0..N - 1 {
        for i in 0..N - 1 {
            let v = (j * N + i) as u32;
            m.add_face(vec![v, v + 1, v + 1 + N as u32, v + N as u32]);
        }
    }
    let faces = m.faces.clone();
    for f in &faces {
        for k in 0..4 {
            let (a, b) = (f[k] as usize, f[(k + 1) % 4] as usize);
            m.set_handle(a as u32, b as u32, handle(&p, a, b));
            m.set_handle(b as u32, a as u32, handle(&p, b, a));
        }
    }
    Document::new(vec![m])
}
