//! The paper's options (section 4.5): interpolating geometry.

use crate::common::{build, mesh_spec};
use gradmesh::formats::{json, off::read_off};
use gradmesh::Refinement;
use gradmesh::{EdgeKind, GradientMesh};
use proptest::prelude::*;

/// The largest distance between a control point and the limit of its vertex, relative to the
/// size of the mesh.
fn interpolation_error(mesh: &GradientMesh, depth: usize) -> f64 {
    let (mut r, _) = Refinement::new(mesh, depth).unwrap();
    let data = r.evaluate();
    let limit = r.limit(&data, depth);
    let scale = mesh
        .points
        .iter()
        .map(|p| p.position.x.abs().max(p.position.y.abs()))
        .fold(1.0, f64::max);
    mesh.points
        .iter()
        .enumerate()
        .map(|(p, point)| {
            let l = limit[r.vertex_at_level(p as u32, depth)];
            (l.position[0] - point.position.x).hypot(l.position[1] - point.position.y) / scale
        })
        .fold(0.0, f64::max)
}

fn realdata(name: &str) -> GradientMesh {
    read_off(&std::fs::read_to_string(crate::realdata::path(name)).unwrap()).unwrap()
}

#[test]
fn interpolated_positions_pass_through_the_control_points_of_the_real_files() {
    for name in [
        "Glasses.off",
        "Paprika_Paprika_layer0.off",
        "Paprika_Paprika_layer1.off",
        "Tucan_Tucan_Layer2.off",
        "Tucan_Tucan_Layer3.off",
        "paprikaOneMesh.off",
    ] {
        let mut mesh = realdata(name);
        // Without the option the limit is only near the control point.
        let plain = interpolation_error(&mesh, 2);
        assert!(plain > 1e-4, "{name}: {plain}");
        mesh.interpolate_positions = true;
        for depth in [1, 2, 3] {
            let e = interpolation_error(&mesh, depth);
            assert!(e < 1e-9, "{name} depth {depth}: {e}");
        }
    }
}

#[test]
fn interpolation_is_exact_with_semi_sharp_creases() {
    let mut mesh = realdata("Tucan_Tucan_Layer3.off");
    let edges: Vec<(u32, u32)> = mesh
        .faces
        .iter()
        .flat_map(|f| (0..f.len()).map(move |k| (f[k], f[(k + 1) % f.len()])))
        .collect();
    for (k, &(a, b)) in edges.iter().enumerate().step_by(5) {
        mesh.set_edge(a, b, EdgeKind::Crease, Some([0.5, 1.5, 2.75][k % 3]));
    }
    mesh.interpolate_positions = true;
    // Measured where every semi-sharp crease has decayed (level 1 + 3), so that the limit
    // stencils used to measure are exact too.
    let e = interpolation_error(&mesh, 5);
    assert!(e < 1e-9, "{e}");
}

#[test]
fn the_option_round_trips_through_the_native_format() {
    let mut mesh = realdata("Tucan_Tucan_Layer0.off");
    mesh.interpolate_positions = true;
    let doc = gradmesh::Document::new(vec![mesh]);
    let text = json::write_document(&doc);
    assert!(text.contains("\"interpolate_positions\": true"));
    let back = json::read_document(&text).unwrap();
    assert_eq!(back, doc);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, .. ProptestConfig::default() })]

    /// On random meshes (creases, semi-sharp creases, corners, boundaries): the limit of every
    /// control point is the point, and colours are untouched (Conditions 1 and 2 still hold,
    /// since only positions move).
    #[test]
    fn interpolation_on_random_meshes(spec in mesh_spec()) {
        let mut mesh = build(&spec);
        let plain_colours: Vec<_> = {
            let (r, _) = Refinement::new(&mesh, 3).unwrap();
            r.evaluate().levels[3].iter().map(|d| [d.colour[0], d.colour[1], d.colour[2], d.opacity]).collect()
        };
        mesh.interpolate_positions = true;
        let e = interpolation_error(&mesh, 3);
        prop_assert!(e < 1e-9);
        let (r, _) = Refinement::new(&mesh, 3).unwrap();
        let colours: Vec<_> = r.evaluate().levels[3].iter().map(|d| [d.colour[0], d.colour[1], d.colour[2], d.opacity]).collect();
        prop_assert_eq!(colours, plain_colours);
    }
}
