//! Property tests of the paper's conditions on random valid meshes of mixed face sizes.

use crate::common::{build, mesh_spec};
use gradmesh::GradientMesh;
use gradmesh::{RefinedData, Refinement};
use kurbo::{Affine, Point, Vec2};
use proptest::prelude::*;

/// Index of control point `p`'s vertex at every level `0..=depth`.
fn vertex_chain(r: &Refinement, p: u32, depth: usize) -> Vec<usize> {
    (0..=depth).map(|k| r.vertex_at_level(p, k)).collect()
}

fn colour_bounds(mesh: &GradientMesh) -> ([f64; 4], [f64; 4]) {
    let mut lo = [f64::INFINITY; 4];
    let mut hi = [f64::NEG_INFINITY; 4];
    for p in &mesh.points {
        for c in 0..3 {
            lo[c] = lo[c].min(p.colour[c]);
            hi[c] = hi[c].max(p.colour[c]);
        }
        lo[3] = lo[3].min(p.opacity);
        hi[3] = hi[3].max(p.opacity);
    }
    (lo, hi)
}

fn refine(mesh: &GradientMesh, depth: usize) -> (Refinement, RefinedData) {
    let (r, _) = Refinement::new(mesh, depth).expect("a valid mesh");
    let data = r.evaluate();
    (r, data)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, .. ProptestConfig::default() })]

    /// Condition 1: the colour of every control point is the colour of its vertex at every
    /// level and in the limit.
    #[test]
    fn condition_1_colours_are_interpolated(spec in mesh_spec()) {
        let mesh = build(&spec);
        let depth = 3;
        let (mut r, data) = refine(&mesh, depth);
        let limit = r.limit(&data, depth);
        for (p, point) in mesh.points.iter().enumerate() {
            let chain = vertex_chain(&r, p as u32, depth);
            for (k, &v) in chain.iter().enumerate() {
                for c in 0..3 {
                    let got = data.levels[k][v].to_array()[2 + c];
                    prop_assert!((got - point.colour[c]).abs() < 1e-9,
                        "point {p} level {k} channel {c}: {got} vs {}", point.colour[c]);
                }
            }
            let v = chain[depth];
            for c in 0..3 {
                prop_assert!((limit[v].to_array()[2 + c] - point.colour[c]).abs() < 1e-9);
            }
            prop_assert!((limit[v].opacity - point.opacity).abs() < 1e-9);
        }
    }

    /// Condition 2: every refined and limit colour lies within the per-channel bounds of the
    /// control colours (Catmull-Clark weights are a convex combination).
    #[test]
    fn condition_2_colours_stay_in_the_hull(spec in mesh_spec()) {
        let mesh = build(&spec);
        let (lo, hi) = colour_bounds(&mesh);
        let (mut r, data) = refine(&mesh, 3);
        let limit = r.limit(&data, 3);
        for (k, level) in data.levels.iter().chain(std::iter::once(&limit)).enumerate() {
            for d in level {
                for c in 0..4 {
                    let x = d.to_array()[2 + c];
                    prop_assert!(x >= lo[c] - 1e-9 && x <= hi[c] + 1e-9,
                        "level {k} channel {c}: {x} outside {}..{}", lo[c], hi[c]);
                }
            }
        }
    }

    /// Positions commute with similarity transforms of the whole mesh (handles included), and
    /// with any affine map when the handles lie along their edges.
    #[test]
    fn positions_are_affine_invariant(
        spec in mesh_spec(),
        angle in -3.0f64..3.0,
        scale in 0.1f64..10.0,
        shear in -0.8f64..0.8,
        tx in -100.0f64..100.0,
    ) {
        let mesh = build(&spec);
        let check = |mesh: &GradientMesh, a: Affine| -> Result<(), TestCaseError> {
            let mut moved = mesh.clone();
            for p in &mut moved.points {
                p.position = a * p.position;
            }
            let linear = Affine::new({
                let c = a.as_coeffs();
                [c[0], c[1], c[2], c[3], 0.0, 0.0]
            });
            for h in moved.handles.values_mut() {
                *h = (linear * h.to_point()).to_vec2();
            }
            let (_, d0) = refine(mesh, 3);
            let (_, d1) = refine(&moved, 3);
            for k in 0..=3 {
                for (p, q) in d0.levels[k].iter().zip(&d1.levels[k]) {
                    let expect = a * Point::new(p.position[0], p.position[1]);
                    let err = (expect - Point::new(q.position[0], q.position[1])).hypot();
                    prop_assert!(err < 1e-7 * (1.0 + expect.to_vec2().hypot()),
                        "level {k}: {expect:?} vs {q:?}");
                }
            }
            Ok(())
        };
        check(&mesh, Affine::translate(Vec2::new(tx, -tx)) * Affine::rotate(angle) * Affine::scale(scale))?;
        let mut along = mesh.clone();
        along.handles.clear();
        check(&along, Affine::new([scale, shear, 0.3, 1.0, tx, 2.0]))?;
    }
}
