//! Degenerate but legal geometry gets a defined result: zero-area faces, collinear corners,
//! handles of length zero or longer than their edge, coincident points on different faces, tiny
//! and huge coordinates, and a mesh outside the view. Each case validates, refines to depth 3
//! and to the limit with finite numbers only, and keeps Condition 1: the limit colour and
//! opacity at each control point's vertex are the point's own.

use gradmesh::render::{render_document, RenderOptions, View};
use gradmesh::Refinement;
use gradmesh::{validate, ColourSpace, Document, EdgeKind, GradientMesh};
use kurbo::{Point, Vec2};

const DEPTH: usize = 3;

/// Validates, refines to [`DEPTH`] and to the limit; asserts finite data and Condition 1.
fn check(mesh: &GradientMesh, what: &str) {
    validate(mesh).unwrap_or_else(|e| panic!("{what}: {e}"));
    let (mut r, _) = Refinement::new(mesh, DEPTH).unwrap_or_else(|e| panic!("{what}: {e}"));
    let data = r.evaluate();
    for (k, level) in data.levels.iter().enumerate() {
        for (i, d) in level.iter().enumerate() {
            assert!(
                d.to_array().iter().all(|x| x.is_finite()),
                "{what}: level {k} vertex {i}: {d:?}"
            );
        }
    }
    let limit = r.limit(&data, DEPTH);
    for (i, d) in limit.iter().enumerate() {
        assert!(
            d.to_array().iter().all(|x| x.is_finite()),
            "{what}: limit of vertex {i}: {d:?}"
        );
    }
    for (p, point) in mesh.points.iter().enumerate() {
        let at = r.vertex_at_level(p as u32, DEPTH);
        let want = [
            point.colour[0],
            point.colour[1],
            point.colour[2],
            point.opacity,
        ];
        for c in 0..4 {
            let got = limit[at].to_array()[2 + c];
            assert!(
                (got - want[c]).abs() <= 1e-9 * want[c].abs().max(1.0),
                "{what}: Condition 1 fails at point {p} channel {c}: {got} != {}",
                want[c]
            );
        }
    }
}

fn mesh_of(points: &[(f64, f64)], faces: &[&[u32]]) -> GradientMesh {
    let mut mesh = GradientMesh::new(ColourSpace::Lab);
    for (k, &(x, y)) in points.iter().enumerate() {
        let k = k as f64;
        mesh.add_point(
            Point::new(x, y),
            [20.0 + 7.0 * k, 30.0 - 11.0 * k, -40.0 + 13.0 * k],
        );
        mesh.points.last_mut().unwrap().opacity = 1.0 - 0.05 * k;
    }
    for f in faces {
        mesh.add_face(f.to_vec());
    }
    mesh
}

/// Two quads side by side with a triangle on top: boundary, interior edges, mixed sizes.
fn sample() -> GradientMesh {
    mesh_of(
        &[
            (0.0, 0.0),
            (1.0, 0.0),
            (2.0, 0.0),
            (0.0, 1.0),
            (1.0, 1.0),
            (2.0, 1.0),
            (1.0, 2.0),
        ],
        &[&[0, 3, 4, 1], &[1, 4, 5, 2], &[3, 6, 4]],
    )
}

#[test]
fn the_sample_itself() {
    check(&sample(), "sample");
}

#[test]
fn zero_area_faces() {
    // A triangle whose corners are collinear, next to a proper one.
    let flat = mesh_of(
        &[(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (1.0, 1.0)],
        &[&[0, 1, 2], &[0, 2, 3]],
    );
    check(&flat, "collinear triangle");
    // A quad folded flat: all four corners on a line.
    let line = mesh_of(
        &[(0.0, 0.0), (1.0, 0.0), (3.0, 0.0), (2.0, 0.0)],
        &[&[0, 1, 2, 3]],
    );
    check(&line, "quad on a line");
    // A whole mesh on a line, several faces.
    let mut squashed = sample();
    for p in &mut squashed.points {
        p.position.y = 0.0;
        p.position.x += 0.1 * p.colour[0];
    }
    check(&squashed, "squashed sample");
}

#[test]
fn collinear_corners() {
    // A quad with three collinear corners (a triangle with a point on one side), and a
    // pentagon with a straight angle.
    let quad = mesh_of(
        &[(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (1.0, 1.0)],
        &[&[0, 1, 2, 3]],
    );
    check(&quad, "quad with collinear corners");
    let pentagon = mesh_of(
        &[(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (2.0, 1.0), (0.0, 1.0)],
        &[&[0, 1, 2, 3, 4]],
    );
    check(&pentagon, "pentagon with a straight angle");
    // A reflex (non-convex) quad.
    let dart = mesh_of(
        &[(0.0, 0.0), (2.0, 1.0), (0.0, 2.0), (0.5, 1.0)],
        &[&[0, 1, 2, 3]],
    );
    check(&dart, "reflex quad");
}

#[test]
fn handles_of_length_zero() {
    let mut mesh = sample();
    let faces = mesh.faces.clone();
    for f in &faces {
        for k in 0..f.len() {
            let (a, b) = (f[k], f[(k + 1) % f.len()]);
            mesh.set_handle(a, b, Vec2::ZERO);
            mesh.set_handle(b, a, Vec2::ZERO);
        }
    }
    check(&mesh, "zero handles");
    // Zero handles at one point only, and a zero handle with a long one opposite.
    let mut mesh = sample();
    mesh.set_handle(4, 1, Vec2::ZERO);
    mesh.set_handle(4, 3, Vec2::ZERO);
    mesh.set_handle(1, 4, Vec2::new(0.0, 5.0));
    check(&mesh, "mixed zero handles");
}

#[test]
fn handles_longer_than_the_edge() {
    for factor in [1.0, 2.0, 10.0, 1e3, 1e6] {
        let mut mesh = sample();
        let faces = mesh.faces.clone();
        for f in &faces {
            for k in 0..f.len() {
                let (a, b) = (f[k], f[(k + 1) % f.len()]);
                let d = mesh.points[b as usize].position - mesh.points[a as usize].position;
                mesh.set_handle(a, b, d * factor);
                // Pointing backwards too.
                mesh.set_handle(b, a, Vec2::new(d.y, -d.x) * factor);
            }
        }
        check(&mesh, &format!("handles {factor} times their edge"));
    }
}

#[test]
fn coincident_points_on_different_faces() {
    // Two triangles touching at a point that is two control points (not shared).
    let mesh = mesh_of(
        &[
            (0.0, 0.0),
            (1.0, 0.0),
            (0.0, 1.0),
            (1.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
        ],
        &[&[0, 1, 2], &[3, 4, 5]],
    );
    check(&mesh, "touching triangles");
    // Two overlapping copies of one quad (a second layer inside one mesh).
    let mesh = mesh_of(
        &[
            (0.0, 0.0),
            (1.0, 0.0),
            (1.0, 1.0),
            (0.0, 1.0),
            (0.0, 0.0),
            (1.0, 0.0),
            (1.0, 1.0),
            (0.0, 1.0),
        ],
        &[&[0, 1, 2, 3], &[4, 5, 6, 7]],
    );
    check(&mesh, "stacked quads");
    // A strip whose far end comes back onto its start (coincident but not joined).
    let mesh = mesh_of(
        &[
            (0.0, 0.0),
            (1.0, 0.0),
            (1.0, 1.0),
            (0.0, 1.0),
            (0.5, 0.5),
            (0.0, 0.0),
        ],
        &[&[0, 1, 2, 3], &[3, 2, 4], &[4, 2, 5]],
    );
    check(&mesh, "strip folding back");
}

#[test]
fn tiny_and_huge_coordinates() {
    for (scale, offset) in [
        (1e-9, 0.0),
        (1e9, 0.0),
        (1e-9, 1e-9),
        (1e9, -1e9),
        (1e-3, 1e9),
        (1.0, 1e9),
        (1e9, 1e9),
    ] {
        let mut mesh = sample();
        for p in &mut mesh.points {
            p.position = Point::new(offset + scale * p.position.x, offset + scale * p.position.y);
        }
        check(&mesh, &format!("scale {scale}, offset {offset}"));
        // With explicit handles at the same scale, creases, corners and a discontinuity.
        mesh.set_handle(4, 1, Vec2::new(0.1 * scale, -0.2 * scale));
        mesh.set_edge(1, 4, EdgeKind::Crease, Some(1.5));
        mesh.set_edge(3, 4, EdgeKind::Discontinuous, None);
        mesh.points[0].corner = true;
        mesh.interpolate_positions = true;
        check(&mesh, &format!("tagged, scale {scale}, offset {offset}"));
    }
}

#[test]
fn colours_far_outside_the_gamut() {
    let mut mesh = sample();
    for (k, p) in mesh.points.iter_mut().enumerate() {
        p.colour = [1e6 * k as f64, -1e6, 1e-9];
    }
    check(&mesh, "huge colours");
}

#[test]
fn a_mesh_outside_the_view_renders_transparent() {
    let doc = Document::new(vec![sample()]);
    for view in [
        View::new(100.0, 100.0, 110.0, 110.0),
        View::new(-1e9, -1e9, -1e9 + 10.0, -1e9 + 10.0),
        View::new(0.0, 5.0, 2.0, 6.0),
    ] {
        let opts = RenderOptions::new(16, 8, view);
        let image = render_document(&doc, &opts).unwrap_or_else(|e| panic!("{view:?}: {e}"));
        assert!(image.data.iter().all(|&x| x == 0.0), "{view:?}");
    }
    // A tiny mesh far away in a huge view, and a view inside one face.
    let mut tiny = sample();
    for p in &mut tiny.points {
        p.position = Point::new(1e6 + 1e-9 * p.position.x, 1e-9 * p.position.y);
    }
    let doc = Document::new(vec![tiny]);
    let image = render_document(
        &doc,
        &RenderOptions::new(8, 8, View::new(0.0, 0.0, 1e3, 1e3)),
    )
    .unwrap();
    assert!(image.data.iter().all(|x| x.is_finite()));
}

/// A view that lies inside one face shows the face everywhere.
#[test]
fn a_view_inside_a_face_is_covered() {
    let doc = Document::new(vec![sample()]);
    let image = render_document(
        &doc,
        &RenderOptions::new(8, 8, View::new(0.4, 0.4, 0.6, 0.6)),
    )
    .unwrap();
    assert!(image.data.iter().all(|x| x.is_finite()));
    assert!(
        image.data.chunks(4).all(|px| px[3] > 0.5),
        "inside is not covered: {:?}",
        &image.data[..16]
    );
}

/// A point used by no face is legal (a warning): it has no ring, so every level keeps it where
/// it is, with its colour (the Catmull-Clark vertex rule would divide by its valence, 0).
#[test]
fn isolated_points_stay_finite() {
    let mut mesh = sample();
    mesh.add_point(Point::new(5.0, 5.0), [50.0, 0.0, 0.0]);
    let (r, warnings) = Refinement::new(&mesh, 2).unwrap();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    let data = r.evaluate();
    let v = r.vertex_at_level(7, 2);
    assert!(
        data.levels[2][v].to_array().iter().all(|x| x.is_finite()),
        "{:?}",
        data.levels[2][v]
    );
}
