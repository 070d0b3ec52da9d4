//! Every validation error and warning, produced by a small input, with its message checked.

use gradmesh::WedgeOverride;
use gradmesh::{validate, ColourSpace, EdgeKind, Error, GradientMesh};
use kurbo::{Point, Vec2};

/// A 2x1 strip of quads: points 0 1 2 on top, 3 4 5 below.
fn strip() -> GradientMesh {
    let mut m = GradientMesh::new(ColourSpace::Lab);
    for (x, y) in [
        (0.0, 0.0),
        (1.0, 0.0),
        (2.0, 0.0),
        (0.0, 1.0),
        (1.0, 1.0),
        (2.0, 1.0),
    ] {
        m.add_point(Point::new(x, y), [50.0, 0.0, 0.0]);
    }
    m.add_face(vec![0, 1, 4, 3]);
    m.add_face(vec![1, 2, 5, 4]);
    m
}

fn error_of(m: &GradientMesh) -> String {
    let e: Error = validate(m).expect_err("the mesh is invalid");
    e.in_file("mesh.json").in_layer(2).to_string()
}

fn assert_message(m: &GradientMesh, expected: &str) {
    let msg = error_of(m);
    assert!(
        msg.starts_with("mesh.json: layer 2: "),
        "message does not name file and layer: {msg}"
    );
    assert!(
        msg.contains(expected),
        "{msg:?} does not contain {expected:?}"
    );
}

#[test]
fn a_valid_mesh_has_no_warnings() {
    assert_eq!(validate(&strip()).unwrap(), vec![]);
}

#[test]
fn index_out_of_range() {
    let mut m = strip();
    m.faces[1][2] = 9;
    assert_message(
        &m,
        "face 1: corner 2 refers to point 9, but there are only 6 points",
    );
}

#[test]
fn too_few_corners_and_repeated_points() {
    let mut m = strip();
    m.faces.push(vec![0, 1]);
    assert_message(&m, "face 2: has 2 corners, at least 3 are needed");
    let mut m = strip();
    m.faces[0] = vec![0, 1, 4, 1];
    assert_message(&m, "face 0: visits point 1 twice");
}

#[test]
fn non_manifold_edge() {
    let mut m = strip();
    let p = m.add_point(Point::new(1.0, -1.0), [0.0; 3]);
    let q = m.add_point(Point::new(1.5, 0.5), [0.0; 3]);
    m.add_face(vec![1, 4, p]);
    m.add_face(vec![4, 1, q]);
    assert_message(
        &m,
        "edge 1-4 is non-manifold: it is shared by faces [0, 1, 2, 3]",
    );
}

#[test]
fn non_manifold_vertex() {
    // A triangle touching the strip at point 2 only.
    let mut m = strip();
    let a = m.add_point(Point::new(3.0, -1.0), [0.0; 3]);
    let b = m.add_point(Point::new(3.0, 0.0), [0.0; 3]);
    m.add_face(vec![2, a, b]);
    assert_message(
        &m,
        "point 2 is non-manifold: its faces form 2 separate fans",
    );
}

#[test]
fn inconsistent_winding() {
    let mut m = strip();
    m.faces[1] = vec![4, 5, 2, 1];
    assert_message(&m, "faces 0 and 1 are wound inconsistently");
}

#[test]
fn zero_length_edge() {
    let mut m = strip();
    m.points[4].position = m.points[1].position;
    assert_message(&m, "edge 1-4 has zero length");
}

#[test]
fn not_finite_numbers() {
    let mut m = strip();
    m.points[3].position.y = f64::NAN;
    assert_message(&m, "point 3 y is not a finite number (NaN)");
    let mut m = strip();
    m.points[5].colour[1] = f64::INFINITY;
    assert_message(&m, "point 5 colour channel 1 is not a finite number (inf)");
    let mut m = strip();
    m.set_handle(0, 1, Vec2::new(f64::NAN, 0.0));
    assert_message(&m, "handle 0->1 x is not a finite number");
}

#[test]
fn handles_and_tags_for_missing_edges() {
    let mut m = strip();
    m.set_handle(0, 5, Vec2::new(0.1, 0.1));
    assert_message(
        &m,
        "handle of point 0 names edge 0-5, which is not an edge of any face",
    );
    let mut m = strip();
    m.set_edge(0, 4, EdgeKind::Crease, None);
    assert_message(
        &m,
        "edge tag names edge 0-4, which is not an edge of any face",
    );
}

#[test]
fn values_out_of_range() {
    let mut m = strip();
    m.points[2].opacity = 1.5;
    assert_message(&m, "point 2: opacity must be in 0..1, found 1.5");
    let mut m = strip();
    m.set_edge(1, 4, EdgeKind::Crease, Some(-1.0));
    assert_message(
        &m,
        "edge 1-4: sharpness must be a finite number >= 0, found -1",
    );
}

#[test]
fn wedge_errors() {
    let mut m = strip();
    m.set_edge(1, 4, EdgeKind::Discontinuous, None);
    let wedge = |point, face| WedgeOverride {
        point,
        face,
        colour: [10.0, 0.0, 0.0],
        colour_text: None,
        opacity: None,
        handles: Default::default(),
    };
    m.wedges.push(wedge(1, 1));
    assert_eq!(validate(&m).unwrap(), vec![]);
    m.wedges.push(wedge(1, 1));
    assert_message(
        &m,
        "wedge 1 (point 1, face 1): another wedge entry already sets this side",
    );
    m.wedges.pop();
    m.wedges.push(wedge(0, 1));
    assert_message(
        &m,
        "wedge 1 (point 0, face 1): the face does not contain the point",
    );
}

#[test]
fn warnings_for_suspicious_input() {
    let mut m = strip();
    m.set_handle(0, 1, Vec2::new(0.8, 0.0));
    m.add_point(Point::new(5.0, 5.0), [50.0, 0.0, 0.0]);
    m.points[2].colour = [50.0, 150.0, 0.0];
    let warnings: Vec<String> = validate(&m)
        .unwrap()
        .iter()
        .map(|w| w.to_string())
        .collect();
    assert!(
        warnings[0].contains("handle of point 0 towards 1 is longer than half its edge"),
        "{warnings:?}"
    );
    assert!(warnings
        .iter()
        .any(|w| w == "point 6 is not used by any face"));
    assert!(
        warnings
            .iter()
            .any(|w| w
                .contains("point 2: colour [50.0, 150.0, 0.0] (lab) is outside the sRGB gamut")),
        "{warnings:?}"
    );
    assert_eq!(warnings.len(), 3, "{warnings:?}");
}

/// Thousands of colours outside the gamut give ten warnings naming points and one counting the
/// rest, not a warning each.
#[test]
fn many_colours_outside_the_gamut_are_counted() {
    let mut m = GradientMesh::new(ColourSpace::Lab);
    let n = 40u32;
    for j in 0..=n {
        for i in 0..=n {
            // Every other point far outside the sRGB gamut.
            let a = if (i + j) % 2 == 0 { 150.0 } else { 0.0 };
            m.add_point(Point::new(i as f64, j as f64), [50.0, a, 0.0]);
        }
    }
    for j in 0..n {
        for i in 0..n {
            let v = j * (n + 1) + i;
            m.add_face(vec![v, v + 1, v + n + 2, v + n + 1]);
        }
    }
    let warnings: Vec<String> = validate(&m)
        .unwrap()
        .iter()
        .map(|w| w.to_string())
        .collect();
    assert_eq!(warnings.len(), 11, "{warnings:?}");
    assert!(warnings[0].starts_with("point 0: colour [50.0, 150.0, 0.0]"));
    assert!(warnings[9].starts_with("point 18: colour"), "{warnings:?}");
    assert_eq!(
        warnings[10],
        "831 more points have colours outside the sRGB gamut"
    );
}
