//! Each tool through the history: the result passes the validator, the points it does not touch
//! keep their colours, its selection is what it made, and undo gives the picture back.

use gradmesh::{ColourSpace, Document, GradientMesh};
use kurbo::Point;

use crate::editor::History;
use crate::ops::{Applied, Op, Picture};

/// A grid of `columns` x `rows` unit-10 quads with colours varying over it (Lab).
fn grid(columns: u32, rows: u32) -> GradientMesh {
    let mut mesh = GradientMesh::new(ColourSpace::Lab);
    let cell = 10.0 / f64::from(columns.max(rows));
    let rect = [0.0, 0.0, cell * f64::from(columns), cell * f64::from(rows)];
    super::add_grid(&mut mesh, rect, columns, rows).unwrap();
    mesh
}

fn picture(mesh: GradientMesh) -> Picture {
    Picture::new(Document::new(vec![mesh]))
}

/// Applies `op` to a picture of `mesh` through a history and checks what every tool promises;
/// returns the mesh after and what the tool said.
fn apply_checked(mesh: GradientMesh, op: Op) -> (GradientMesh, Applied) {
    let start = picture(mesh.clone());
    let mut history = History::new(start.clone());
    let applied = history.apply_selecting(&op, None).unwrap();
    let after = history.current().doc.layers[0].clone();
    gradmesh::validate(&after).unwrap();
    // Every point kept is where it was with its colour (the tools move no point).
    let new: Vec<Point> = (after.points.iter())
        .filter(|p| !mesh.points.iter().any(|q| q.position == p.position))
        .map(|p| p.position)
        .collect();
    for p in &after.points {
        if let Some(q) = mesh.points.iter().find(|q| q.position == p.position) {
            assert_eq!((p.colour, p.opacity), (q.colour, q.opacity));
        }
    }
    let selection = applied.selection.clone().expect("a tool selects");
    for &s in &selection.points {
        assert!(new.contains(&after.points[s as usize].position));
    }
    assert!(history.undo());
    assert_eq!(history.current(), &start);
    (after, applied)
}

fn valence(mesh: &GradientMesh, p: u32) -> usize {
    let mut neighbours = std::collections::BTreeSet::new();
    for f in &mesh.faces {
        let n = f.len();
        if let Some(i) = f.iter().position(|&c| c == p) {
            neighbours.insert(f[(i + 1) % n]);
            neighbours.insert(f[(i + n - 1) % n]);
        }
    }
    neighbours.len()
}

#[test]
fn a_grid_of_2_by_2_and_its_limits() {
    let op = Op::AddGrid {
        layer: 0,
        rect: [30.0, 20.0, 10.0, 0.0],
        columns: 2,
        rows: 2,
    };
    let (mesh, applied) = apply_checked(GradientMesh::new(ColourSpace::Lab), op);
    assert_eq!((mesh.points.len(), mesh.faces.len()), (9, 4));
    assert_eq!(
        applied.selection.unwrap().points,
        (0..9).collect::<Vec<_>>()
    );
    assert_eq!(mesh.points[4].position, Point::new(20.0, 10.0));
    let mut empty = GradientMesh::new(ColourSpace::Lab);
    for (rect, n) in [
        ([0.0, 0.0, 1.0, 1.0], 0),
        ([0.0, 0.0, 1.0, 1.0], 65),
        ([0.0, 0.0, 0.0, 1.0], 2),
    ] {
        let err = super::add_grid(&mut empty, rect, n, 2).unwrap_err();
        assert!(err.contains("1 to 64") || err.contains("no area"), "{err}");
    }
    assert!(empty.points.is_empty());
}

#[test]
fn an_ellipse_is_a_grid_ringed_by_quads_on_the_curve() {
    let op = Op::AddEllipse {
        layer: 0,
        rect: [0.0, 0.0, 40.0, 20.0],
    };
    let (mesh, _) = apply_checked(GradientMesh::new(ColourSpace::Lab), op);
    assert_eq!((mesh.points.len(), mesh.faces.len()), (17, 12));
    assert!(mesh.faces.iter().all(|f| f.len() == 4));
    // The ring's points lie on the ellipse, and so do its edges' midpoints.
    for p in 9..17u32 {
        let at = mesh.points[p as usize].position;
        let r = ((at.x - 20.0) / 20.0).powi(2) + ((at.y - 10.0) / 10.0).powi(2);
        assert!((r - 1.0).abs() < 1e-12, "{r}");
        let next = 9 + (p - 9 + 1) % 8;
        let mid = kurbo::ParamCurve::eval(&super::edge_curve(&mesh, p, next), 0.5);
        let r = ((mid.x - 20.0) / 20.0).powi(2) + ((mid.y - 10.0) / 10.0).powi(2);
        assert!((r.sqrt() - 1.0).abs() < 1e-3, "{r}");
    }
    // The grid's corners are the irregular vertices (three edges); its middle has four.
    for corner in [0, 2, 6, 8] {
        assert_eq!(valence(&mesh, corner), 3);
    }
    assert_eq!(valence(&mesh, 4), 4);
}

#[test]
fn an_outline_becomes_quads_or_is_refused_with_a_reason() {
    let pentagon: Vec<[f64; 2]> = (0..5)
        .map(|k| {
            let a = f64::from(k) * std::f64::consts::TAU / 5.0;
            [50.0 + 30.0 * a.cos(), 50.0 - 30.0 * a.sin()]
        })
        .collect();
    let op = Op::AddOutline {
        layer: 0,
        outline: pentagon,
    };
    let (mesh, _) = apply_checked(GradientMesh::new(ColourSpace::Lab), op);
    // Six outline corners (one added on the longest side), six inner, the middle; a ring of six
    // quads and three in the middle.
    assert_eq!((mesh.points.len(), mesh.faces.len()), (13, 9));
    assert!(mesh.faces.iter().all(|f| f.len() == 4));
    // The point added on the longest side makes a straight angle in the middle: the same
    // faces wherever and at whatever scale the outline is drawn.
    let corners = [
        [650.0, 460.0],
        [820.0, 470.0],
        [800.0, 600.0],
        [690.0, 620.0],
        [640.0, 540.0],
    ];
    for k in 0..40 {
        let (scale, shift) = (0.013 + 0.37 * f64::from(k), -3.7 + 11.3 * f64::from(k));
        let outline = corners.map(|[x, y]| [shift + scale * x, 0.5 * shift + scale * y]);
        let mut mesh = GradientMesh::new(ColourSpace::Lab);
        super::add_outline(&mut mesh, &outline).unwrap();
        assert_eq!((mesh.points.len(), mesh.faces.len()), (13, 9), "drawn {k}");
    }
    let mut empty = GradientMesh::new(ColourSpace::Lab);
    let bowtie = [[0.0, 0.0], [10.0, 10.0], [10.0, 0.0], [0.0, 10.0]];
    let err = super::add_outline(&mut empty, &bowtie).unwrap_err();
    assert!(err.contains("crosses itself"), "{err}");
    // A thin C: its inside is not seen whole from its centroid.
    let c_shape = [
        [0.0, 0.0],
        [100.0, 0.0],
        [100.0, 10.0],
        [10.0, 10.0],
        [10.0, 90.0],
        [100.0, 90.0],
        [100.0, 100.0],
        [0.0, 100.0],
    ];
    let err = super::add_outline(&mut empty, &c_shape).unwrap_err();
    assert!(err.contains("not seen whole"), "{err}");
    let err = super::add_outline(&mut empty, &[[0.0, 0.0], [1.0, 1.0]]).unwrap_err();
    assert!(err.contains("three or more"), "{err}");
    assert!(empty.points.is_empty() && empty.faces.is_empty());
}

#[test]
fn a_loop_cut_crosses_the_strip_and_takes_the_surface_colour() {
    let mesh = grid(3, 3);
    // The top side of the middle column's first quad: points 1 and 2.
    let op = Op::LoopCut {
        layer: 0,
        a: 1,
        b: 2,
        at: 0.5,
    };
    let (after, applied) = apply_checked(mesh.clone(), op);
    assert_eq!((after.points.len(), after.faces.len()), (20, 12));
    assert!(after.faces.iter().all(|f| f.len() == 4));
    let points = applied.selection.unwrap().points;
    assert_eq!(points.len(), 4);
    let samples = super::SurfaceSamples::of(&mesh).unwrap();
    for &p in &points {
        let point = &after.points[p as usize];
        assert!((point.position.x - 5.0).abs() < 1e-9);
        assert_eq!(samples.nearest(point.position).unwrap().0, point.colour);
    }
}

#[test]
fn a_loop_cut_stops_at_a_face_that_is_not_a_quad_and_closes_around_a_ring() {
    // A 2 x 1 grid with a triangle on its right side.
    let mut mesh = grid(2, 1);
    let tip = mesh.add_point(Point::new(15.0, 2.5), [50.0, 0.0, 0.0]);
    mesh.add_face(vec![2, tip, 5]);
    // The strip of the left side (0-3) runs along the row to the triangle.
    let op = Op::LoopCut {
        layer: 0,
        a: 0,
        b: 3,
        at: 0.25,
    };
    let (after, _) = apply_checked(mesh, op);
    // Three new points (on 0-3, 1-4, 2-5), two quads split, the triangle now a quad.
    assert_eq!(after.points.len(), 7 + 3);
    assert_eq!(after.faces.len(), 5);
    assert_eq!(after.faces[2].len(), 4);

    // A ring of 8 quads (an annulus): a cut across one closes around it.
    let mut ring = GradientMesh::new(ColourSpace::Lab);
    for k in 0..8 {
        let a = f64::from(k) * std::f64::consts::TAU / 8.0;
        for r in [10.0, 20.0] {
            ring.add_point(Point::new(r * a.cos(), r * a.sin()), [50.0, r, 0.0]);
        }
    }
    for k in 0..8u32 {
        let n = (k + 1) % 8;
        ring.add_face(vec![2 * k, 2 * n, 2 * n + 1, 2 * k + 1]);
    }
    let op = Op::LoopCut {
        layer: 0,
        a: 0,
        b: 1,
        at: 0.5,
    };
    let (after, applied) = apply_checked(ring, op);
    assert_eq!((after.points.len(), after.faces.len()), (24, 16));
    assert_eq!(applied.selection.unwrap().points.len(), 8);
}

#[test]
fn a_point_in_a_face_splits_it_into_triangles() {
    let mesh = grid(1, 1);
    let op = Op::AddPointInFace {
        layer: 0,
        face: 0,
        x: 4.0,
        y: 6.0,
    };
    let (after, applied) = apply_checked(mesh.clone(), op);
    assert_eq!((after.points.len(), after.faces.len()), (5, 4));
    assert!(after.faces.iter().all(|f| f.len() == 3 && f.contains(&4)));
    assert_eq!(applied.selection.unwrap().points, vec![4]);
    let samples = super::SurfaceSamples::of(&mesh).unwrap();
    assert_eq!(
        samples.nearest(Point::new(4.0, 6.0)).unwrap().0,
        after.points[4].colour
    );
    let mut outside = mesh.clone();
    let err = super::add_point_in_face(&mut outside, 0, Point::new(12.0, 5.0)).unwrap_err();
    assert!(err.contains("not inside face 0"), "{err}");
    assert_eq!(outside, mesh);
}

#[test]
fn dissolving_a_point_merges_its_faces() {
    // The middle of a 2 x 2 grid: one face of the eight boundary points.
    let op = Op::DissolvePoints {
        layer: 0,
        points: vec![4],
    };
    let (after, applied) = apply_checked(grid(2, 2), op);
    assert_eq!((after.points.len(), after.faces.len()), (8, 1));
    assert_eq!(after.faces[0].len(), 8);
    assert_eq!(applied.selection.unwrap().face, Some(0));
    // The middle of the top side: the two top faces become one pentagon.
    let op = Op::DissolvePoints {
        layer: 0,
        points: vec![1],
    };
    let (after, _) = apply_checked(grid(2, 2), op);
    assert_eq!(after.faces.len(), 3);
    assert_eq!(after.faces[0].len(), 5);
    // A corner of a lone triangle would leave a face of two corners.
    let mut triangle = GradientMesh::new(ColourSpace::Lab);
    for (x, y) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)] {
        triangle.add_point(Point::new(x, y), [50.0, 0.0, 0.0]);
    }
    triangle.add_face(vec![0, 1, 2]);
    let err = super::dissolve_points(&mut triangle, &[0]).unwrap_err();
    assert!(err.contains("2 corners"), "{err}");
}

#[test]
fn dissolving_an_edge_merges_its_two_faces() {
    let op = Op::DissolveEdge {
        layer: 0,
        a: 1,
        b: 4,
    };
    let (after, applied) = apply_checked(grid(2, 1), op);
    assert_eq!((after.points.len(), after.faces.len()), (6, 1));
    assert_eq!(after.faces[0].len(), 6);
    assert_eq!(applied.selection.unwrap().face, Some(0));
    let mut mesh = grid(2, 1);
    let err = super::dissolve_edge(&mut mesh, 0, 1).unwrap_err();
    assert!(err.contains("on the boundary"), "{err}");
    assert_eq!(mesh, grid(2, 1));
}

#[test]
fn tools_keep_the_sides_and_drop_edits_only_on_changed_faces() {
    let mut mesh = grid(2, 1);
    mesh.set_edit(gradmesh::Edit::new(gradmesh::VertexAddress::new(
        1,
        0,
        0,
        [1, 1],
    )));
    mesh.set_edit(gradmesh::Edit::new(gradmesh::VertexAddress::new(
        1,
        1,
        2,
        [1, 1],
    )));
    let mut picture = picture(mesh);
    let op = Op::AddPointInFace {
        layer: 0,
        face: 1,
        x: 7.0,
        y: 2.5,
    };
    let applied = op.apply_selecting(&mut picture).unwrap();
    assert!(applied.note.unwrap().contains("1 multi-resolution edit"));
    let edits = &picture.doc.layers[0].edits;
    assert_eq!((edits.len(), edits[0].address.face), (1, 0));
}
