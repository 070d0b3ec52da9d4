//! Multi-resolution edits: addressing, exactness, locality, following coarse edits, round trips.

use crate::common;

use gradmesh::formats::json::{read_document, write_document};
use gradmesh::render::{render_document, RenderOptions, View};
use gradmesh::VertexData;
use gradmesh::{
    ColourEdit, ColourSpace, Document, Edit, FineEdits, FirstStep, GradientMesh, OpacityEdit,
    Refinement, VertexAddress,
};
use kurbo::{Point, Vec2};
use proptest::prelude::*;

/// An `n` x `n` grid of squares of side `side`, colours from `colour(i, j)`.
fn grid(n: u32, side: f64, colour: impl Fn(u32, u32) -> [f64; 3]) -> GradientMesh {
    let mut mesh = GradientMesh::new(ColourSpace::Lab);
    for j in 0..=n {
        for i in 0..=n {
            mesh.add_point(Point::new(side * i as f64, side * j as f64), colour(i, j));
        }
    }
    let v = |i: u32, j: u32| j * (n + 1) + i;
    for j in 0..n {
        for i in 0..n {
            mesh.add_face(vec![v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)]);
        }
    }
    mesh
}

/// The sparse mesh of the paper's Figure 2 (as `examples/sparse-irregular.json`): a pentagon,
/// triangles, quads, vertices of valence 3 and 5.
fn sparse() -> GradientMesh {
    let p = [
        (60.0, 60.0),
        (200.0, 30.0),
        (340.0, 70.0),
        (380.0, 200.0),
        (320.0, 330.0),
        (190.0, 370.0),
        (60.0, 320.0),
        (30.0, 190.0),
        (150.0, 150.0),
        (260.0, 160.0),
        (210.0, 260.0),
        (120.0, 250.0),
    ];
    let mut mesh = GradientMesh::new(ColourSpace::Lab);
    for (k, &(x, y)) in p.iter().enumerate() {
        let t = k as f64;
        mesh.add_point(
            Point::new(x, y),
            [
                40.0 + 3.0 * t,
                30.0 * (0.7 * t).sin(),
                30.0 * (0.4 * t).cos(),
            ],
        );
    }
    for f in [
        vec![0, 1, 9, 8],
        vec![1, 2, 3, 9],
        vec![9, 3, 4, 10],
        vec![10, 4, 5],
        vec![11, 10, 5, 6],
        vec![7, 8, 9, 10, 11],
        vec![0, 8, 7],
        vec![7, 11, 6],
    ] {
        mesh.add_face(f);
    }
    mesh
}

fn colour_of(d: &VertexData) -> [f64; 3] {
    d.colour
}

fn set_colour(level: u32, face: u32, point: u32, at: [u32; 2], c: [f64; 3]) -> Edit {
    Edit {
        colour: Some(ColourEdit::Set(c)),
        ..Edit::new(VertexAddress::new(level, face, point, at))
    }
}

/// The vertex an address names at its level, through a refinement with that single edit.
fn vertex_named(r: &mut Refinement, address: VertexAddress) -> usize {
    r.set_edits(&[Edit::new(address)], FineEdits::default())
        .unwrap();
    r.edited_vertex(0).expect("the address names a vertex")
}

#[test]
fn addresses_name_the_vertices_the_format_documents() {
    // On a grid of squares with default handles every level is a uniform grid, so the vertex
    // at [i, j] of a sector lies i steps along the next edge and j along the previous one.
    let side = 96.0;
    let mesh = grid(3, side, |_, _| [50.0, 0.0, 0.0]);
    let (mut r, _) = Refinement::new(&mesh, 4).unwrap();
    let data = r.evaluate();
    for (f, corners) in mesh.faces.clone().iter().enumerate() {
        for (c, &p) in corners.iter().enumerate() {
            let n = corners.len();
            let here = mesh.points[p as usize].position;
            let next = mesh.points[corners[(c + 1) % n] as usize].position - here;
            let prev = mesh.points[corners[(c + n - 1) % n] as usize].position - here;
            for level in 1..=4u32 {
                let m = VertexAddress::sector_size(level);
                let step = 1.0 / (3.0 * f64::from(1u32 << (level - 1)));
                for i in 0..=m {
                    for j in 0..=m {
                        let a = VertexAddress::new(level, f as u32, p, [i, j]);
                        let v = vertex_named(&mut r, a);
                        let d = data.levels[level as usize][v];
                        let want = here + next * (step * i as f64) + prev * (step * j as f64);
                        assert!(
                            (d.position[0] - want.x).abs() < 1e-9
                                && (d.position[1] - want.y).abs() < 1e-9,
                            "{a}: vertex {v} at ({}, {}), expected {want:?}",
                            d.position[0],
                            d.position[1]
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn the_names_of_one_vertex_agree_and_may_not_both_be_edited() {
    let mesh = sparse();
    let (mut r, _) = Refinement::new(&mesh, 3).unwrap();
    // Pentagon 5 = [7, 8, 9, 10, 11]; its sector at 8 meets the sector at 9 along i = m.
    for level in 2..=3u32 {
        let m = VertexAddress::sector_size(level);
        for j in 0..=m {
            let a = vertex_named(&mut r, VertexAddress::new(level, 5, 8, [m, j]));
            let b = vertex_named(&mut r, VertexAddress::new(level, 5, 9, [j, m]));
            assert_eq!(a, b, "level {level}, j = {j}");
        }
    }
    // Edge 8-9 is shared by face 0 = [0, 1, 9, 8] (running 9 -> 8) and the pentagon (8 -> 9).
    for level in 1..=3u32 {
        for i in 0..=VertexAddress::sector_size(level) {
            let a = vertex_named(&mut r, VertexAddress::new(level, 5, 8, [i, 0]));
            let b = vertex_named(&mut r, VertexAddress::new(level, 0, 8, [0, i]));
            assert_eq!(a, b, "level {level}, i = {i}");
        }
    }
    // The face centre belongs to every sector of the face.
    let centre = vertex_named(&mut r, VertexAddress::new(2, 5, 7, [3, 3]));
    assert_eq!(
        centre,
        vertex_named(&mut r, VertexAddress::new(2, 5, 10, [3, 3]))
    );

    let mut m2 = mesh.clone();
    m2.edits = vec![
        set_colour(2, 5, 8, [3, 1], [50.0, 0.0, 0.0]),
        set_colour(2, 5, 9, [1, 3], [60.0, 0.0, 0.0]),
    ];
    let e = Refinement::new(&m2, 2).unwrap_err().to_string();
    assert!(
        e.contains("edit 1") && e.contains("same vertex as edit 0") && e.contains("one vertex"),
        "{e}"
    );
}

#[test]
fn an_absolute_colour_edit_is_interpolated_exactly() {
    let mesh = sparse();
    let targets = [
        // The vertex point of control point 8: its ring after the ternary step has its colour,
        // the edit overrides the vertex and, one step later, its new ring.
        (VertexAddress::new(1, 5, 8, [0, 0]), [90.0, -20.0, 10.0]),
        // An edge point and a face point of level 1.
        (VertexAddress::new(1, 1, 2, [1, 0]), [20.0, 40.0, -30.0]),
        (VertexAddress::new(1, 3, 4, [1, 1]), [70.0, 10.0, 60.0]),
        // A level-2 vertex on the pentagon's centre and one deeper.
        (VertexAddress::new(2, 5, 7, [3, 3]), [10.0, 0.0, 0.0]),
        (VertexAddress::new(3, 4, 6, [2, 4]), [95.0, -5.0, 5.0]),
    ];
    let mut edited = mesh.clone();
    for (a, c) in targets {
        edited.edits.push(Edit {
            colour: Some(ColourEdit::Set(c)),
            ..Edit::new(a)
        });
    }
    let (mut r, _) = Refinement::new(&edited, 3).unwrap();
    let data = r.evaluate();
    for (i, (a, c)) in targets.iter().enumerate() {
        let v = r.edited_vertex(i).unwrap();
        let limit = r.limit(&data, a.level as usize);
        let got = colour_of(&limit[v]);
        for k in 0..3 {
            assert!(
                (got[k] - c[k]).abs() < 1e-9,
                "{a}: limit {got:?}, set {c:?}"
            );
        }
    }
    // The control points whose rings no edit touches stay interpolated (Condition 1).
    let limit0 = r.limit(&data, 0);
    for p in [0, 3, 6] {
        let want = mesh.points[p].colour;
        let got = colour_of(&limit0[p]);
        assert!((0..3).all(|k| (got[k] - want[k]).abs() < 1e-9), "point {p}");
    }
}

#[test]
fn colours_stay_in_the_hull_of_the_colours_in_play() {
    // All control colours on one segment of Lab; edits along its line. The hull of the colours
    // in play is then an interval of that line, easy to test exactly.
    let (a, b) = ([30.0, 10.0, -20.0], [80.0, -30.0, 40.0]);
    let on = |t: f64| [0, 1, 2].map(|k| a[k] + t * (b[k] - a[k]));
    let mut mesh = sparse();
    for (k, p) in mesh.points.iter_mut().enumerate() {
        p.colour = on(((k * 7) % 12) as f64 / 11.0);
    }
    mesh.edits = vec![
        set_colour(1, 5, 8, [1, 0], on(1.4)),
        set_colour(2, 2, 9, [1, 2], on(-0.3)),
        Edit {
            colour: Some(ColourEdit::Offset([0, 1, 2].map(|k| 0.5 * (b[k] - a[k])))),
            ..Edit::new(VertexAddress::new(2, 0, 0, [2, 2]))
        },
        Edit {
            opacity: Some(OpacityEdit::Set(0.25)),
            ..Edit::new(VertexAddress::new(3, 6, 7, [3, 3]))
        },
    ];
    let (mut r, _) = Refinement::new(&mesh, 4).unwrap();
    let data = r.evaluate();
    let param = |c: [f64; 3]| {
        let d = [0, 1, 2].map(|k| b[k] - a[k]);
        let len2: f64 = d.iter().map(|x| x * x).sum();
        let t = (0..3).map(|k| (c[k] - a[k]) * d[k]).sum::<f64>() / len2;
        let off: f64 = (0..3)
            .map(|k| (c[k] - a[k] - t * d[k]).powi(2))
            .sum::<f64>()
            .sqrt();
        (t, off)
    };
    // The colours in play: the control colours and the edited vertices' targets.
    let mut lo: f64 = 0.0;
    let mut hi: f64 = 1.0;
    for i in 0..mesh.edits.len() {
        let level = mesh.edits[i].address.level as usize;
        let v = r.edited_vertex(i).unwrap();
        let (t, _) = param(colour_of(&data.levels[level][v]));
        lo = lo.min(t);
        hi = hi.max(t);
    }
    assert!(lo < -0.29 && hi > 1.39, "{lo} {hi}");
    let mut all: Vec<VertexData> = data.levels.concat();
    all.extend(r.limit(&data, 4));
    for d in &all {
        let (t, off) = param(colour_of(d));
        assert!(off < 1e-9, "off the line by {off}");
        assert!(
            t >= lo - 1e-9 && t <= hi + 1e-9,
            "t = {t} outside [{lo}, {hi}]"
        );
        assert!(
            (-1e-12..=1.0 + 1e-12).contains(&d.opacity),
            "opacity {}",
            d.opacity
        );
    }
}

#[test]
fn an_edit_changes_the_picture_only_inside_its_support() {
    let mesh = grid(6, 40.0, |i, j| {
        [
            40.0 + 5.0 * i as f64,
            6.0 * j as f64 - 15.0,
            10.0 - 3.0 * i as f64,
        ]
    });
    let address = VertexAddress::new(2, 14, 16, [2, 1]);
    let mut edited = mesh.clone();
    edited.edits.push(Edit {
        colour: Some(ColourEdit::Set([90.0, 40.0, -40.0])),
        opacity: Some(OpacityEdit::Set(0.5)),
        offset: Some(Vec2::new(0.4, -0.3)),
        ..Edit::new(address)
    });
    let view = View::new(-10.0, -10.0, 250.0, 250.0);
    let mut opts = RenderOptions::new(260, 260, view);
    opts.level = Some(4);
    let doc = |m: &GradientMesh| Document::new(vec![m.clone()]);
    let before = render_document(&doc(&mesh), &opts).unwrap();
    let after = render_document(&doc(&edited), &opts).unwrap();

    // The support: the faces of level 2 whose limit patch depends on the vertex lie within two
    // rings of faces of it, and their limit surface within the hull of the points one ring
    // further (before and after the move).
    let (mut r, _) = Refinement::new(&edited, 2).unwrap();
    let v = r.edited_vertex(0).unwrap();
    let t = r.topology(2).clone();
    let mut verts = vec![v as u32];
    for _ in 0..3 {
        let mut grown = verts.clone();
        for &x in &verts {
            for &f in t.vertex_faces(x as usize) {
                grown.extend_from_slice(t.face_vertices(f as usize));
            }
        }
        grown.sort_unstable();
        grown.dedup();
        verts = grown;
    }
    let (plain, _) = Refinement::new(&mesh, 2).unwrap();
    let mut bounds = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for data in [plain.evaluate(), r.evaluate()] {
        for &x in &verts {
            let d = data.levels[2][x as usize];
            bounds = [
                bounds[0].min(d.position[0]),
                bounds[1].min(d.position[1]),
                bounds[2].max(d.position[0]),
                bounds[3].max(d.position[1]),
            ];
        }
    }
    // One pixel is one unit here (view origin -10); a pixel's coverage reaches half a pixel out.
    let inside = |px: u32, py: u32| {
        let (x, y) = (px as f64 - 10.0 + 0.5, py as f64 - 10.0 + 0.5);
        x > bounds[0] - 1.0 && x < bounds[2] + 1.0 && y > bounds[1] - 1.0 && y < bounds[3] + 1.0
    };
    let (mut changed_inside, mut checked_outside) = (0, 0);
    for py in 0..260 {
        for px in 0..260 {
            let i = 4 * (py * 260 + px) as usize;
            let (a, b) = (&before.data[i..i + 4], &after.data[i..i + 4]);
            if inside(px, py) {
                changed_inside += usize::from(a != b);
            } else {
                checked_outside += 1;
                assert_eq!(
                    a, b,
                    "pixel ({px}, {py}) outside the support {bounds:?} changed"
                );
            }
        }
    }
    assert!(
        changed_inside > 100,
        "the edit shows: {changed_inside} pixels"
    );
    assert!(checked_outside > 30_000, "{checked_outside}");
}

#[test]
fn fine_edits_follow_coarse_edits() {
    let mesh = sparse();
    let mut edited = mesh.clone();
    edited.edits = vec![
        Edit {
            colour: Some(ColourEdit::Offset([-20.0, 15.0, 0.0])),
            offset: Some(Vec2::new(0.3, 0.2)),
            ..Edit::new(VertexAddress::new(2, 1, 2, [2, 1]))
        },
        Edit {
            offset: Some(Vec2::new(-0.25, 0.5)),
            ..Edit::new(VertexAddress::new(3, 5, 10, [4, 2]))
        },
        set_colour(2, 4, 6, [1, 1], [75.0, 5.0, 5.0]),
    ];
    let (mut r, _) = Refinement::new(&edited, 3).unwrap();
    let data = r.evaluate();
    let where_ = |r: &mut Refinement, data: &gradmesh::RefinedData, i: usize| {
        let level = edited.edits[i].address.level as usize;
        let v = r.edited_vertex(i).unwrap();
        (v, data.levels[level][v])
    };

    // Move, rotate and scale the whole control mesh (handles are vectors: linear part only).
    let (s, c, k) = (0.6f64.sin(), 0.6f64.cos(), 1.7);
    let map = |p: Point| {
        Point::new(
            k * (c * p.x - s * p.y) + 31.0,
            k * (s * p.x + c * p.y) - 12.0,
        )
    };
    let mut moved = edited.clone();
    for p in &mut moved.points {
        p.position = map(p.position);
        p.colour[0] += 10.0;
    }
    let (mut r2, _) = Refinement::new(&moved, 3).unwrap();
    let data2 = r2.evaluate();
    for i in 0..edited.edits.len() {
        let (v, d) = where_(&mut r, &data, i);
        let (v2, d2) = where_(&mut r2, &data2, i);
        assert_eq!(v, v2, "edit {i} stays on its vertex");
        let want = map(d.point());
        assert!(
            (d2.position[0] - want.x).abs() < 1e-9 && (d2.position[1] - want.y).abs() < 1e-9,
            "edit {i}: ({}, {}) should be {want:?}",
            d2.position[0],
            d2.position[1]
        );
        match edited.edits[i].colour {
            // A relative edit follows the recolouring; an absolute one stays.
            Some(ColourEdit::Offset(_)) => {
                assert!((d2.colour[0] - d.colour[0] - 10.0).abs() < 1e-9)
            }
            Some(ColourEdit::Set(c)) => assert!((d2.colour[0] - c[0]).abs() < 1e-12),
            None => {}
        }
    }
    // And the offset edit moved its vertex: without it the vertex is elsewhere.
    let (plain, _) = Refinement::new(&mesh, 3).unwrap();
    let p = plain.evaluate();
    let (v, d) = where_(&mut r, &data, 0);
    assert!(
        (p.levels[2][v].position[0] - d.position[0]).abs()
            + (p.levels[2][v].position[1] - d.position[1]).abs()
            > 1.0
    );
    assert!((p.levels[2][v].colour[0] - 20.0 - d.colour[0]).abs() < 1e-9);
}

#[test]
fn edits_are_applied_again_without_rebuilding_the_topology() {
    let mesh = sparse();
    let edits = vec![
        set_colour(2, 5, 8, [3, 3], [20.0, 0.0, -30.0]),
        Edit {
            opacity: Some(OpacityEdit::Offset(-0.5)),
            offset: Some(Vec2::new(0.1, 0.1)),
            ..Edit::new(VertexAddress::new(1, 0, 1, [1, 1]))
        },
    ];
    let mut edited = mesh.clone();
    edited.edits = edits.clone();
    let (fresh, _) = Refinement::new(&edited, 4).unwrap();
    let (mut reused, _) = Refinement::new(&mesh, 4).unwrap();
    let before = reused.evaluate();
    reused.set_edits(&edits, FineEdits::default()).unwrap();
    assert_eq!(reused.evaluate(), fresh.evaluate());
    assert_ne!(reused.evaluate(), before);
    reused.set_edits(&[], FineEdits::default()).unwrap();
    assert_eq!(reused.evaluate(), before);
}

#[test]
fn bad_edits_are_refused_with_their_place() {
    let cases: Vec<(Edit, FineEdits, &str)> = vec![
        (
            Edit::new(VertexAddress::new(0, 0, 0, [0, 0])),
            FineEdits::default(),
            "edit 0: expected a level in 1..=8, found 0",
        ),
        (
            Edit::new(VertexAddress::new(2, 40, 0, [0, 0])),
            FineEdits::default(),
            "edit 0: face 40 does not exist (there are 8 faces)",
        ),
        (
            Edit::new(VertexAddress::new(2, 3, 0, [0, 0])),
            FineEdits::default(),
            "edit 0: point 0 is not a corner of face 3 [10, 4, 5]",
        ),
        (
            Edit::new(VertexAddress::new(2, 3, 4, [4, 0])),
            FineEdits::default(),
            "edit 0: coordinates [4, 0] are outside the sector, whose grid at level 2 runs from 0 to 3",
        ),
        (
            Edit {
                offset: Some(Vec2::new(0.1, 0.0)),
                ..Edit::new(VertexAddress::new(2, 3, 4, [1, 0]))
            },
            FineEdits::ColourOnly,
            "edit 0: moves a refined vertex, but the mesh allows colour edits only",
        ),
        (
            Edit {
                colour: Some(ColourEdit::Offset([f64::NAN, 0.0, 0.0])),
                ..Edit::new(VertexAddress::new(2, 3, 4, [1, 0]))
            },
            FineEdits::default(),
            "edit 0: colour offset must be finite",
        ),
        (
            Edit {
                opacity: Some(OpacityEdit::Set(1.5)),
                ..Edit::new(VertexAddress::new(2, 3, 4, [1, 0]))
            },
            FineEdits::default(),
            "edit 0: opacity: expected a number in 0..1, found 1.5",
        ),
    ];
    for (edit, fine, want) in cases {
        let mut mesh = sparse();
        mesh.edits = vec![edit];
        mesh.fine_edits = fine;
        let e = Refinement::new(&mesh, 2).unwrap_err().to_string();
        assert!(e.contains(want), "{e}\nshould contain\n{want}");
    }
    let mut mesh = sparse();
    mesh.first_step = FirstStep::Binary;
    mesh.edits = vec![Edit::new(VertexAddress::new(1, 0, 0, [0, 0]))];
    let e = Refinement::new(&mesh, 2).unwrap_err().to_string();
    assert!(e.contains("edits need the ternary first step"), "{e}");
}

#[test]
fn documents_with_edits_round_trip_through_the_native_format() {
    let mut mesh = sparse();
    mesh.fine_edits = FineEdits::ColourOnly;
    mesh.edits = vec![
        set_colour(2, 5, 8, [3, 3], [21.5, 2.25, -23.125]),
        Edit {
            colour: Some(ColourEdit::Offset([-30.0, 0.1, 1e-7])),
            opacity: Some(OpacityEdit::Offset(-0.3)),
            ..Edit::new(VertexAddress::new(3, 1, 2, [5, 2]))
        },
        Edit {
            opacity: Some(OpacityEdit::Set(0.2)),
            ..Edit::new(VertexAddress::new(1, 3, 5, [1, 1]))
        },
    ];
    let mut moving = sparse();
    moving.edits = vec![Edit {
        offset: Some(Vec2::new(0.1, -1.0 / 3.0)),
        ..Edit::new(VertexAddress::new(2, 0, 0, [1, 2]))
    }];
    let doc = Document::new(vec![mesh, moving]);
    let text = write_document(&doc);
    let back = read_document(&text).unwrap();
    assert_eq!(back, doc);
    assert_eq!(write_document(&back), text);
    assert!(text.contains("\"fine_edits\": \"colour-only\""));
    assert!(text.contains(
        "{\"level\": 3, \"face\": 1, \"point\": 2, \"at\": [5, 2], \"colour_offset\": [-30.0, 0.1, 1e-7], \"opacity_offset\": -0.3}"
    ));
}

#[test]
fn edit_syntax_errors_name_the_edit_and_the_line() {
    let base = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/multires.json"
    ))
    .unwrap();
    let doc = read_document(&base).unwrap();
    assert_eq!(doc.layers[0].edits.len(), 7);
    assert_eq!(doc.layers[0].fine_edits, FineEdits::ColourOnly);
    let bad = base.replacen(
        "\"colour_offset\"",
        "\"colour\": [1, 2, 3], \"colour_offset\"",
        1,
    );
    let e = read_document(&bad).unwrap_err();
    assert!(e.location.line.is_some() && e.location.layer == Some(0));
    let e = e.to_string();
    assert!(e.contains("edit 2") && e.contains("not both"), "{e}");
    let bad = base.replacen("\"at\": [3, 3]", "\"at\": [3]", 1);
    let e = read_document(&bad).unwrap_err().to_string();
    assert!(e.contains("edit 0: at"), "{e}");
}

/// A random edit: which face, corner, level and place (as fractions, scaled to what exists),
/// and what it changes.
type RawEdit = (f64, f64, u32, f64, f64, u8, [f64; 3], f64);

fn raw_edit() -> impl Strategy<Value = RawEdit> {
    (
        0.0f64..1.0,
        0.0f64..1.0,
        1u32..=3,
        0.0f64..=1.0,
        0.0f64..=1.0,
        0u8..4,
        (0.0f64..100.0, -80.0f64..80.0, -80.0f64..80.0).prop_map(|(a, b, c)| [a, b, c]),
        0.0f64..1.0,
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, .. ProptestConfig::default() })]

    /// Whatever the edits, every value of every level and of the limit is finite, opacity stays
    /// in 0..1, and colours stay in the box of the colours in play (control colours and the
    /// edited vertices' targets): a necessary condition of the hull property.
    #[test]
    fn random_edits_keep_colours_in_the_box_of_the_colours_in_play(
        spec in common::mesh_spec(),
        raw in prop::collection::vec(raw_edit(), 1..6),
    ) {
        let mut mesh = common::build(&spec);
        for (f, c, level, i, j, kind, colour, amount) in raw {
            let face = ((f * mesh.faces.len() as f64) as usize).min(mesh.faces.len() - 1);
            let corners = &mesh.faces[face];
            let point = corners[((c * corners.len() as f64) as usize).min(corners.len() - 1)];
            let m = VertexAddress::sector_size(level) as f64;
            let at = [(i * m).round() as u32, (j * m).round() as u32];
            let mut edit = Edit::new(VertexAddress::new(level, face as u32, point, at));
            match kind {
                0 => edit.colour = Some(ColourEdit::Set(colour)),
                1 => edit.colour = Some(ColourEdit::Offset([colour[0] - 50.0, colour[1], colour[2]])),
                2 => edit.opacity = Some(OpacityEdit::Offset(amount - 0.5)),
                _ => {
                    edit.opacity = Some(OpacityEdit::Set(amount));
                    edit.offset = Some(Vec2::new(amount - 0.5, 0.25));
                }
            }
            mesh.set_edit(edit);
        }
        let (mut r, _) = match Refinement::new(&mesh, 4) {
            Ok(x) => x,
            Err(e) => {
                // Two random addresses may name one vertex: the only refusal expected.
                prop_assert!(e.to_string().contains("same vertex"), "{}", e);
                return Ok(());
            }
        };
        let data = r.evaluate();
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let mut widen = |c: [f64; 3]| {
            for k in 0..3 {
                lo[k] = lo[k].min(c[k]);
                hi[k] = hi[k].max(c[k]);
            }
        };
        for p in &mesh.points {
            widen(p.colour);
        }
        for i in 0..mesh.edits.len() {
            let level = mesh.edits[i].address.level as usize;
            let v = r.edited_vertex(i).expect("a checked edit names a vertex");
            widen(colour_of(&data.levels[level][v]));
        }
        let mut all: Vec<VertexData> = data.levels.concat();
        all.extend(r.limit(&data, 4));
        for d in &all {
            prop_assert!(d.to_array().iter().all(|x| x.is_finite()), "{:?}", d);
            prop_assert!((-1e-12..=1.0 + 1e-12).contains(&d.opacity), "opacity {}", d.opacity);
            for k in 0..3 {
                let slack = 1e-9 * (1.0 + hi[k].abs().max(lo[k].abs()));
                prop_assert!(d.to_array()[2 + k] >= lo[k] - slack && d.to_array()[2 + k] <= hi[k] + slack,
                    "channel {} = {} outside [{}, {}]", k, d.to_array()[2 + k], lo[k], hi[k]);
            }
        }
    }
}

#[test]
fn a_move_on_a_discontinuous_edge_moves_both_sides() {
    let mut mesh = grid(2, 60.0, |i, j| {
        [30.0 + 20.0 * i as f64, 10.0 * j as f64, 0.0]
    });
    mesh.set_edge(1, 4, gradmesh::EdgeKind::Discontinuous, None);
    mesh.set_edge(4, 7, gradmesh::EdgeKind::Discontinuous, None);
    // Face 0 = [0, 1, 4, 3] runs 4 -> 1 as the previous edge of its corner 4; face 1 =
    // [1, 2, 5, 4] runs it as the next edge of its corner 4. The two names are two vertices.
    let left = VertexAddress::new(2, 0, 4, [0, 2]);
    let right = VertexAddress::new(2, 1, 4, [2, 0]);
    let mut edited = mesh.clone();
    edited.edits = vec![
        Edit {
            offset: Some(Vec2::new(0.5, 0.5)),
            colour: Some(ColourEdit::Offset([0.0, 30.0, 0.0])),
            ..Edit::new(left)
        },
        Edit::new(right),
    ];
    let (mut r, _) = Refinement::new(&edited, 3).unwrap();
    let data = r.evaluate();
    let (a, b) = (r.edited_vertex(0).unwrap(), r.edited_vertex(1).unwrap());
    assert_ne!(a, b);
    let (da, db) = (data.levels[2][a], data.levels[2][b]);
    assert_eq!(
        [da.position[0], da.position[1]],
        [db.position[0], db.position[1]],
        "both sides at one place"
    );
    let (plain, _) = Refinement::new(&mesh, 3).unwrap();
    let p = plain.evaluate().levels[2][a];
    assert!(
        (p.position[0] - da.position[0]).abs() + (p.position[1] - da.position[1]).abs() > 1.0,
        "it moved"
    );
    // Colour is per side: the other side keeps its own.
    assert!((da.colour[1] - p.colour[1] - 30.0).abs() < 1e-9);
    assert!((db.colour[1] - plain.evaluate().levels[2][b].colour[1]).abs() < 1e-12);
}
