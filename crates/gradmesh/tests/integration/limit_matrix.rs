//! The limit colours as a sparse matrix of the control colours (`limit_matrix`): applied to the
//! points' colours and opacities it gives the limit that `refine_level` computes, on the
//! examples, the real artwork, both first steps, interpolated positions and random meshes; it
//! refuses what it cannot express.

use std::path::Path;

use gradmesh::formats::read_path;
use gradmesh::{
    limit_matrix, refine_level, Edit, ErrorKind, FirstStep, GradientMesh, LevelPoints, LimitMatrix,
    Limits, Refinement, VertexAddress, VertexData,
};
use proptest::prelude::*;

use crate::common::{build, mesh_spec};

/// The points' colours and opacity, four values a row.
fn control_values(mesh: &GradientMesh) -> Vec<f64> {
    let row = |p: &gradmesh::ControlPoint| [p.colour[0], p.colour[1], p.colour[2], p.opacity];
    mesh.points.iter().flat_map(row).collect()
}

/// Asserts that `matrix` applied to `control` gives the colour and opacity of `limit`.
fn assert_maps_to(matrix: &LimitMatrix, control: &[f64], limit: &[VertexData], what: &str) {
    assert_eq!(matrix.rows, limit.len(), "{what}: one row per vertex");
    assert_eq!(matrix.offsets.len(), matrix.rows + 1, "{what}");
    let mapped = matrix.apply(control, 4);
    for (v, (got, want)) in mapped.chunks_exact(4).zip(limit).enumerate() {
        for c in 0..4 {
            let err = (got[c] - want.attributes()[c]).abs();
            assert!(
                err <= 1e-12,
                "{what}: vertex {v} channel {c}: matrix gives {}, refinement {} (error {err:e})",
                got[c],
                want.attributes()[c]
            );
        }
    }
}

/// `limit_matrix` of `mesh` at `level` against `refine_level`'s limit points.
fn check(mesh: &GradientMesh, level: usize, what: &str) {
    let what = format!("{what}, level {level}");
    let (matrix, _) = limit_matrix(mesh, level, &Limits::DEFAULT).expect(&what);
    assert_eq!(matrix.columns, mesh.points.len(), "{what}");
    let (limit, _) = refine_level(mesh, level, LevelPoints::Limit, &Limits::DEFAULT).unwrap();
    assert_maps_to(&matrix, &control_values(mesh), &limit.data, &what);
}

/// `Refinement::limit_matrix` of `mesh` at `level` (columns: the split base vertices) against
/// `Refinement::limit`.
fn check_by_split_vertex(mesh: &GradientMesh, level: usize, what: &str) {
    let what = format!("{what}, level {level}, by split vertex");
    let (mut refinement, _) = Refinement::new(mesh, level).unwrap();
    let matrix = refinement.limit_matrix(level).expect(&what);
    let base = refinement.base().data.clone();
    assert_eq!(matrix.columns, base.len(), "{what}");
    let control: Vec<f64> = base.iter().flat_map(|d| d.attributes()).collect();
    let data = refinement.evaluate();
    let limit = refinement.limit(&data, level);
    assert_maps_to(&matrix, &control, &limit, &what);
}

fn example(name: &str) -> GradientMesh {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name);
    let mut doc = read_path(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    doc.layers.remove(0)
}

fn tucan_layer(k: usize) -> GradientMesh {
    let name = format!("Tucan_Tucan_Layer{k}.off");
    read_path(&crate::realdata::path(&name))
        .unwrap()
        .layers
        .remove(0)
}

#[test]
fn examples_match_the_refined_limit() {
    let names = [
        "annulus.json",
        "fold.json",
        "handles-long.json",
        "irregular-vertex.json",
        "non-rectangular.json",
        "rectangle.json",
        "sparse-irregular.json",
    ];
    for name in names {
        for level in 0..=3 {
            check(&example(name), level, name);
        }
    }
    // Its discontinuous edges' sides have colours of their own.
    for level in 0..=3 {
        check_by_split_vertex(&example("edge-kinds.json"), level, "edge-kinds.json");
    }
}

#[test]
fn tucan_layers_match_the_refined_limit() {
    for k in 0..6 {
        let mesh = tucan_layer(k);
        for level in [0, 1, 2, 4] {
            check(&mesh, level, &format!("Tucan layer {k}"));
        }
    }
}

/// The paper's variants: two binary steps, interpolated positions (which move positions only).
#[test]
fn variants_match_the_refined_limit() {
    for name in ["sparse-irregular.json", "edge-kinds.json"] {
        let mut binary = example(name);
        binary.first_step = FirstStep::Binary;
        let mut interpolated = example(name);
        interpolated.interpolate_positions = true;
        for level in 0..=2 {
            check_by_split_vertex(&binary, level, &format!("{name}, binary first step"));
            check_by_split_vertex(&interpolated, level, &format!("{name}, interpolated"));
            if name == "sparse-irregular.json" {
                check(&binary, level, &format!("{name}, binary first step"));
                check(&interpolated, level, &format!("{name}, interpolated"));
            }
        }
    }
}

/// A multi-resolution edit that moves a vertex leaves colours linear; one that changes colour
/// is refused, naming the edit.
#[test]
fn position_edits_are_mapped_and_colour_edits_refused() {
    let mut mesh = example("sparse-irregular.json");
    let at = VertexAddress::new(2, 0, mesh.faces[0][0], [2, 1]);
    mesh.set_edit(Edit {
        offset: Some(kurbo::Vec2::new(0.3, -0.2)),
        ..Edit::new(at)
    });
    for level in [1, 2, 3] {
        check(&mesh, level, "a position edit");
    }
    let multires = example("multires.json");
    let err = limit_matrix(&multires, 2, &Limits::DEFAULT).unwrap_err();
    assert!(
        matches!(&err.kind, ErrorKind::Invalid { what, .. } if what == "edit 0"),
        "{err}"
    );
    assert!(err.to_string().contains("changes colour"), "{err}");
}

/// A wedge with a colour of its own is refused by point; by split vertex (the refinement's own
/// matrix) it is mapped. A discontinuous edge whose sides keep the point's colour maps by point.
#[test]
fn wedges_with_their_own_colour_map_by_split_vertex_only() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/discontinuity.json");
    let mut mesh = read_path(&path).unwrap().layers.remove(1);
    let err = limit_matrix(&mesh, 2, &Limits::DEFAULT).unwrap_err();
    assert!(
        err.to_string().contains("wedge of point 1 at face 1"),
        "{err}"
    );

    let (refinement, _) = Refinement::new(&mesh, 0).unwrap();
    assert!(
        refinement.base().data.len() > mesh.points.len(),
        "the mesh is split"
    );
    for level in 0..=3 {
        check_by_split_vertex(&mesh, level, "discontinuity");
    }

    for w in &mut mesh.wedges {
        w.colour = mesh.points[w.point as usize].colour;
        w.opacity = None;
    }
    for level in 0..=3 {
        check(&mesh, level, "discontinuity with the points' colours");
    }
}

/// Rows are sorted, hold no zero, and each sums to one (limits are affine combinations).
#[test]
fn rows_are_sorted_affine_combinations() {
    let (matrix, _) = limit_matrix(&tucan_layer(0), 3, &Limits::DEFAULT).unwrap();
    for r in 0..matrix.rows {
        let span = matrix.offsets[r]..matrix.offsets[r + 1];
        assert!(!span.is_empty());
        let cols = &matrix.indices[span.clone()];
        assert!(cols.windows(2).all(|p| p[0] < p[1]), "row {r}: {cols:?}");
        assert!(matrix.values[span.clone()].iter().all(|&w| w != 0.0));
        let sum: f64 = matrix.values[span].iter().sum();
        assert!((sum - 1.0).abs() < 1e-12, "row {r} sums to {sum}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, .. ProptestConfig::default() })]

    /// Random meshes (triangles, quads, hexagons, creases, corners, handles) at levels 0 to 3.
    #[test]
    fn random_meshes_match_the_refined_limit(spec in mesh_spec(), level in 0usize..=3) {
        check(&build(&spec), level, "random mesh");
    }
}
