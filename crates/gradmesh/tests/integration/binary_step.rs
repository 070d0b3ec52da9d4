//! The paper's alternative first refinement (section 4.5): two binary splits instead of the
//! ternary step. Conditions 1 and 2, topology, the regular split of a grid, the file option,
//! interpolated positions, and how close the result is to the ternary step's.

use crate::common::{build, mesh_spec};
use gradmesh::formats::{json, off::read_off};
use gradmesh::internals::binary_step::{edge_midpoint, face_centre, inner_point, HANDLE_SCALE};
use gradmesh::internals::ternary_step::{edge_point, face_point};
use gradmesh::VertexData;
use gradmesh::{ColourSpace, Document, EdgeKind, FirstStep, GradientMesh};
use gradmesh::{RefinedData, Refinement};
use kurbo::{Point, Vec2};
use proptest::prelude::*;

fn binary(mut mesh: GradientMesh) -> GradientMesh {
    mesh.first_step = FirstStep::Binary;
    mesh
}

fn refine(mesh: &GradientMesh, depth: usize) -> (Refinement, RefinedData) {
    let (r, _) = Refinement::new(mesh, depth).expect("a valid mesh");
    let data = r.evaluate();
    (r, data)
}

/// Per-channel bounds of the control colours and opacities (channels 2..6 of the data).
fn colour_bounds(mesh: &GradientMesh) -> ([f64; 4], [f64; 4]) {
    let mut lo = [f64::INFINITY; 4];
    let mut hi = [f64::NEG_INFINITY; 4];
    let wedges = mesh.wedges.iter().map(|w| (w.colour, w.opacity));
    let points = mesh.points.iter().map(|p| (p.colour, Some(p.opacity)));
    for (colour, opacity) in points.chain(wedges) {
        for c in 0..3 {
            lo[c] = lo[c].min(colour[c]);
            hi[c] = hi[c].max(colour[c]);
        }
        if let Some(o) = opacity {
            lo[3] = lo[3].min(o);
            hi[3] = hi[3].max(o);
        }
    }
    (lo, hi)
}

fn realdata(name: &str) -> GradientMesh {
    read_off(&std::fs::read_to_string(crate::realdata::path(name)).unwrap()).unwrap()
}

const REAL_FILES: [&str; 6] = [
    "Glasses.off",
    "Paprika_Paprika_layer1.off",
    "Tucan_Tucan_Layer0.off",
    "Tucan_Tucan_Layer2.off",
    "Tucan_Tucan_Layer3.off",
    "paprikaOneMesh.off",
];

/// Condition 1 on the split base: the vertex of every split vertex (every wedge of a control
/// point) keeps its colour and opacity at every level and in the limit.
fn check_condition_1(mesh: &GradientMesh, depth: usize) -> Result<(), TestCaseError> {
    let (mut r, data) = refine(mesh, depth);
    let limit = r.limit(&data, depth);
    let base = r.base().clone();
    for (v, d) in base.data.iter().enumerate() {
        if base.topology.vertex_faces(v).is_empty() {
            continue;
        }
        for k in 0..=depth {
            let got = data.levels[k][r.vertex_at_level(v as u32, k)];
            for c in 2..6 {
                prop_assert!(
                    (got.to_array()[c] - d.to_array()[c]).abs() < 1e-9,
                    "vertex {v} level {k} channel {c}: {} vs {}",
                    got.to_array()[c],
                    d.to_array()[c]
                );
            }
        }
        let got = limit[r.vertex_at_level(v as u32, depth)];
        for c in 2..6 {
            prop_assert!(
                (got.to_array()[c] - d.to_array()[c]).abs() < 1e-9,
                "vertex {v} limit channel {c}: {} vs {}",
                got.to_array()[c],
                d.to_array()[c]
            );
        }
    }
    Ok(())
}

/// Condition 2: every refined and limit colour and opacity within the control bounds.
fn check_condition_2(mesh: &GradientMesh, depth: usize) -> Result<(), TestCaseError> {
    let (lo, hi) = colour_bounds(mesh);
    let (mut r, data) = refine(mesh, depth);
    let limit = r.limit(&data, depth);
    for (k, level) in data.levels.iter().chain([&limit]).enumerate() {
        for d in level {
            for c in 0..4 {
                let x = d.to_array()[2 + c];
                prop_assert!(
                    x >= lo[c] - 1e-9 && x <= hi[c] + 1e-9,
                    "level {k} channel {c}: {x} outside {}..{}",
                    lo[c],
                    hi[c]
                );
            }
        }
    }
    Ok(())
}

/// The 1-ring of every control point at level 1 has exactly its colour and opacity.
fn check_rings(mesh: &GradientMesh) -> Result<(), TestCaseError> {
    let (r, data) = refine(mesh, 1);
    let (base, t1) = (r.base(), r.topology(1));
    for v in 0..base.topology.vertex_count() {
        for &f in t1.vertex_faces(v) {
            for &u in t1.face_vertices(f as usize) {
                prop_assert_eq!(
                    &data.levels[1][u as usize].to_array()[2..],
                    &base.data[v].to_array()[2..],
                    "point {} of the ring of {}",
                    u,
                    v
                );
            }
        }
        // The ring holds no other control point.
        let ring_has_other = t1.vertex_faces(v).iter().any(|&f| {
            t1.face_vertices(f as usize)
                .iter()
                .any(|&u| (u as usize) < base.topology.vertex_count() && u as usize != v)
        });
        prop_assert!(
            !ring_has_other,
            "the ring of {} touches another control point",
            v
        );
    }
    Ok(())
}

/// The largest distance between a control point and the limit of its vertex, relative to the
/// size of the mesh.
fn interpolation_error(mesh: &GradientMesh, depth: usize) -> f64 {
    let (mut r, data) = refine(mesh, depth);
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

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, .. ProptestConfig::default() })]

    /// Condition 1: every control point's colour and opacity at every level and in the limit.
    #[test]
    fn condition_1_colours_are_interpolated(spec in mesh_spec()) {
        check_condition_1(&binary(build(&spec)), 3)?;
    }

    /// Condition 2: every colour and opacity within the per-channel bounds of the control
    /// points, at every level and in the limit.
    #[test]
    fn condition_2_colours_stay_in_the_hull(spec in mesh_spec()) {
        check_condition_2(&binary(build(&spec)), 3)?;
    }

    /// Level 1 is all quads, keeps the Euler characteristic, and gives every control point a
    /// ring of its own colour that touches no other control point.
    #[test]
    fn level_1_is_quads_with_a_ring_per_control_point(spec in mesh_spec()) {
        let mesh = binary(build(&spec));
        let (r, _) = refine(&mesh, 2);
        let t0 = r.topology(0);
        let t1 = r.topology(1);
        prop_assert!(t1.is_all_quads());
        prop_assert_eq!(t1.face_count(), 4 * t0.corner_count());
        prop_assert_eq!(t1.corner_count(), 16 * t0.corner_count());
        prop_assert_eq!(t1.edge_count(), 4 * t0.edge_count() + 6 * t0.corner_count());
        prop_assert_eq!(
            t1.vertex_count(),
            t0.vertex_count() + 3 * t0.edge_count() + t0.face_count() + 2 * t0.corner_count()
        );
        for k in 1..=2 {
            prop_assert_eq!(r.topology(k).euler_characteristic(), t0.euler_characteristic());
        }
        check_rings(&mesh)?;
    }

    /// The four level-1 edges along each base edge carry its sharpness; the others are smooth
    /// unless on the boundary.
    #[test]
    fn creases_are_kept_along_the_four_refined_edges(spec in mesh_spec()) {
        let mesh = binary(build(&spec));
        let (r, _) = refine(&mesh, 1);
        let (base, level) = (r.base(), r.level(1));
        let t0 = &base.topology;
        let t1 = &level.topology;
        let mut along = vec![None; t1.edge_count()];
        for e in 0..t0.edge_count() {
            let [a, b] = t0.edge_vertices(e);
            let chain = [
                a,
                edge_point(t0, e as u32, 0),
                edge_midpoint(t0, e as u32),
                edge_point(t0, e as u32, 1),
                b,
            ];
            for w in chain.windows(2) {
                let e1 = t1
                    .vertex_edges(w[0] as usize)
                    .iter()
                    .copied()
                    .find(|&e1| t1.other_vertex(e1 as usize, w[0]) == w[1])
                    .expect("consecutive points along a base edge are joined");
                along[e1 as usize] = Some(e);
            }
        }
        for e1 in 0..t1.edge_count() {
            let s = level.edge_sharpness[e1];
            match along[e1] {
                _ if t1.is_boundary_edge(e1) => prop_assert_eq!(s, 10.0),
                Some(e) => prop_assert_eq!(s, base.edge_sharpness[e]),
                None => prop_assert_eq!(s, 0.0),
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, .. ProptestConfig::default() })]

    /// Interpolated positions work with the binary step: every control point is its limit, and
    /// colours are those of the binary step without the option.
    #[test]
    fn interpolated_positions_on_random_meshes(spec in mesh_spec()) {
        let mut mesh = binary(build(&spec));
        let plain: Vec<_> = refine(&mesh, 3).1.levels[3]
            .iter()
            .map(|d| d.attributes())
            .collect();
        mesh.interpolate_positions = true;
        let e = interpolation_error(&mesh, 3);
        prop_assert!(e < 1e-9, "{e}");
        let colours: Vec<_> = refine(&mesh, 3).1.levels[3]
            .iter()
            .map(|d| d.attributes())
            .collect();
        prop_assert_eq!(colours, plain);
    }
}

#[test]
fn interpolated_positions_on_the_real_files() {
    for name in REAL_FILES {
        let mut mesh = binary(realdata(name));
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
fn conditions_hold_on_the_real_files() {
    for name in REAL_FILES {
        let mesh = binary(realdata(name));
        check_condition_1(&mesh, 2).unwrap_or_else(|e| panic!("{name}: {e}"));
        check_condition_2(&mesh, 2).unwrap_or_else(|e| panic!("{name}: {e}"));
        check_rings(&mesh).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

/// An `n` by `n` grid of squares of side 12 with four colours; `handle` scales every handle
/// along its edge (`None`: the default third).
fn grid(n: u32, handle: Option<f64>) -> GradientMesh {
    let mut mesh = GradientMesh::new(ColourSpace::Lab);
    let colours = [
        [30.0, 60.0, 40.0],
        [90.0, -20.0, 80.0],
        [50.0, 10.0, -60.0],
        [70.0, -50.0, 20.0],
    ];
    for j in 0..=n {
        for i in 0..=n {
            let p = Point::new(12.0 * i as f64, 12.0 * j as f64);
            mesh.add_point(p, colours[((i + 2 * j) % 4) as usize]);
        }
    }
    for j in 0..n {
        for i in 0..n {
            let v = j * (n + 1) + i;
            mesh.add_face([v, v + 1, v + n + 2, v + n + 1]);
        }
    }
    if let Some(s) = handle {
        for f in mesh.faces.clone() {
            for k in 0..4 {
                let (a, b) = (f[k], f[(k + 1) % 4]);
                let d = mesh.points[b as usize].position - mesh.points[a as usize].position;
                mesh.set_handle(a, b, d * s);
            }
        }
    }
    mesh
}

/// With the default handles a regular grid is split regularly: level 1 is the tensor grid of
/// the five points `0, 5/18, 1/2, 13/18, 1` of each cell side (the ternary step's thirds drawn
/// to 5/6 of the handles), so every level-1 face is an axis-aligned rectangle, the same in
/// every cell and symmetric about the cell's centre lines.
#[test]
fn default_handles_split_a_grid_regularly() {
    let n = 3;
    let mesh = binary(grid(n, None));
    let (r, data) = refine(&mesh, 1);
    let t0 = r.topology(0);
    let d = &data.levels[1];
    let at = |i: u32| Point::new(d[i as usize].position[0], d[i as usize].position[1]);
    let close = |i: u32, p: Point| {
        assert!((at(i) - p).hypot() < 1e-12, "{i}: {:?} vs {p:?}", at(i));
    };
    let pos = |v: u32| mesh.points[v as usize].position;
    let (near, far) = (5.0 / 18.0, 13.0 / 18.0);
    for e in 0..t0.edge_count() as u32 {
        let [a, b] = t0.edge_vertices(e as usize).map(pos);
        close(edge_point(t0, e, 0), a.lerp(b, near));
        close(edge_midpoint(t0, e), a.lerp(b, 0.5));
        close(edge_point(t0, e, 1), a.lerp(b, far));
    }
    for f in 0..t0.face_count() {
        let fv = t0.face_vertices(f);
        let o = t0.face_offset(f);
        let centre = pos(fv[0]).midpoint(pos(fv[2]));
        close(face_centre(t0, f), centre);
        for i in 0..4 {
            let (v, next, prev) = (pos(fv[i]), pos(fv[(i + 1) % 4]), pos(fv[(i + 3) % 4]));
            let ring = v + (next - v) * near + (prev - v) * near;
            close(face_point(t0, o + i), ring);
            close(inner_point(t0, o + i), v.midpoint(next) + (prev - v) * near);
        }
    }
    // Every level-1 face is an axis-aligned rectangle with sides from the five points.
    let t1 = r.topology(1);
    assert_eq!(t1.face_count(), (16 * n * n) as usize);
    let sides = [near, 0.5 - near].map(|s| 12.0 * s);
    for f in 0..t1.face_count() {
        let fv = t1.face_vertices(f);
        for k in 0..4 {
            let side = at(fv[(k + 1) % 4]) - at(fv[k]);
            let length = side.hypot();
            assert!(
                side.x.abs() < 1e-12 || side.y.abs() < 1e-12,
                "face {f}: {side:?}"
            );
            assert!(
                sides.iter().any(|s| (s - length).abs() < 1e-12),
                "face {f}: {length}"
            );
        }
    }
}

/// The quarter point lies on the handle, at [`HANDLE_SCALE`] of it; the midpoint is the
/// midpoint of the ternary step's edge points (the handle tips).
#[test]
fn the_quarter_points_lie_on_the_handles() {
    let mut mesh = binary(grid(1, None));
    let (h0, h1) = (Vec2::new(5.0, 1.0), Vec2::new(-2.0, 0.5));
    mesh.set_handle(0, 1, h0);
    mesh.set_handle(1, 0, h1);
    let (r, data) = refine(&mesh, 1);
    let t0 = r.topology(0);
    let e = (0..t0.edge_count())
        .find(|&e| {
            let [a, b] = t0.edge_vertices(e);
            a.min(b) == 0 && a.max(b) == 1
        })
        .unwrap() as u32;
    let end0 = usize::from(t0.edge_vertices(e as usize)[0] != 0);
    let d = &data.levels[1];
    let p = |i: u32| Point::new(d[i as usize].position[0], d[i as usize].position[1]);
    let (v0, v1) = (Point::new(0.0, 0.0), Point::new(12.0, 0.0));
    assert!((p(edge_point(t0, e, end0)) - (v0 + h0 * HANDLE_SCALE)).hypot() < 1e-12);
    assert!((p(edge_point(t0, e, 1 - end0)) - (v1 + h1 * HANDLE_SCALE)).hypot() < 1e-12);
    assert!((p(edge_midpoint(t0, e)) - (v0 + h0).midpoint(v1 + h1)).hypot() < 1e-12);
}

/// A discontinuous edge with different colours on its two sides: each side keeps its own
/// colour (both wedges of each end point are control points of the split base).
#[test]
fn discontinuous_edges_keep_both_colours() {
    let mut mesh = binary(grid(2, None));
    // The interior vertical edge 1-4-7 is discontinuous.
    mesh.set_edge(1, 4, EdgeKind::Discontinuous, None);
    mesh.set_edge(4, 7, EdgeKind::Discontinuous, None);
    for (point, face) in [(1, 1), (4, 1), (7, 3)] {
        mesh.wedges.push(gradmesh::WedgeOverride {
            point,
            face,
            colour: [95.0, 0.0, 0.0],
            colour_text: None,
            opacity: Some(0.5),
            handles: Default::default(),
        });
    }
    check_condition_1(&mesh, 3).unwrap();
    check_condition_2(&mesh, 3).unwrap();
    check_rings(&mesh).unwrap();
}

#[test]
fn the_option_round_trips_through_the_native_format() {
    let mut mesh = binary(realdata("Tucan_Tucan_Layer0.off"));
    mesh.interpolate_positions = true;
    let doc = Document::new(vec![mesh.clone(), grid(2, None)]);
    let text = json::write_document(&doc);
    assert_eq!(text.matches("\"first_step\": \"binary\"").count(), 1);
    let back = json::read_document(&text).unwrap();
    assert_eq!(back, doc);
    assert_eq!(back.layers[0].first_step, FirstStep::Binary);
    assert_eq!(back.layers[1].first_step, FirstStep::Ternary);

    let with = |value: &str| {
        text.replacen(
            "\"first_step\": \"binary\"",
            &format!("\"first_step\": {value}"),
            1,
        )
    };
    let ternary = json::read_document(&with("\"ternary\"")).unwrap();
    assert_eq!(ternary.layers[0].first_step, FirstStep::Ternary);
    let e = json::read_document(&with("\"quaternary\"")).unwrap_err();
    let message = e.to_string();
    assert!(
        message.contains("first_step") && message.contains("\"binary\""),
        "{message}"
    );
}

/// The colour at points of the plane, sampled from the limit points of a fine level
/// (piecewise linear over its triangulated faces).
struct ColourField {
    triangles: Vec<[VertexData; 3]>,
    origin: Point,
    cell: f64,
    columns: usize,
    rows: usize,
    buckets: Vec<Vec<u32>>,
}

impl ColourField {
    fn new(mesh: &GradientMesh, depth: usize) -> ColourField {
        let (mut r, data) = refine(mesh, depth);
        let limit = r.limit(&data, depth);
        let t = r.topology(depth);
        let mut triangles = Vec::new();
        for f in 0..t.face_count() {
            let fv = t.face_vertices(f);
            for k in 1..fv.len() - 1 {
                triangles.push([fv[0], fv[k], fv[k + 1]].map(|v| limit[v as usize]));
            }
        }
        let (mut lo, mut hi) = (
            Point::new(f64::MAX, f64::MAX),
            Point::new(f64::MIN, f64::MIN),
        );
        for p in &limit {
            lo = Point::new(lo.x.min(p.position[0]), lo.y.min(p.position[1]));
            hi = Point::new(hi.x.max(p.position[0]), hi.y.max(p.position[1]));
        }
        let cell = ((hi.x - lo.x).max(hi.y - lo.y) / (triangles.len() as f64).sqrt()).max(1e-9);
        let columns = ((hi.x - lo.x) / cell) as usize + 1;
        let rows = ((hi.y - lo.y) / cell) as usize + 1;
        let mut buckets = vec![Vec::new(); columns * rows];
        for (i, tri) in triangles.iter().enumerate() {
            let x = tri.map(|p| ((p.position[0] - lo.x) / cell) as usize);
            let y = tri.map(|p| ((p.position[1] - lo.y) / cell) as usize);
            for row in *y.iter().min().unwrap()..=(*y.iter().max().unwrap()).min(rows - 1) {
                for col in *x.iter().min().unwrap()..=(*x.iter().max().unwrap()).min(columns - 1) {
                    buckets[row * columns + col].push(i as u32);
                }
            }
        }
        ColourField {
            triangles,
            origin: lo,
            cell,
            columns,
            rows,
            buckets,
        }
    }

    /// The Lab colour at `p`, if the surface covers it.
    fn colour(&self, p: Point) -> Option<[f64; 3]> {
        let col = ((p.x - self.origin.x) / self.cell).floor();
        let row = ((p.y - self.origin.y) / self.cell).floor();
        if col < 0.0 || row < 0.0 || col as usize >= self.columns || row as usize >= self.rows {
            return None;
        }
        for &i in &self.buckets[row as usize * self.columns + col as usize] {
            let [a, b, c] = &self.triangles[i as usize];
            let det = (b.position[0] - a.position[0]) * (c.position[1] - a.position[1])
                - (c.position[0] - a.position[0]) * (b.position[1] - a.position[1]);
            if det == 0.0 {
                continue;
            }
            let u = ((p.x - a.position[0]) * (c.position[1] - a.position[1])
                - (c.position[0] - a.position[0]) * (p.y - a.position[1]))
                / det;
            let v = ((b.position[0] - a.position[0]) * (p.y - a.position[1])
                - (p.x - a.position[0]) * (b.position[1] - a.position[1]))
                / det;
            if u >= 0.0 && v >= 0.0 && u + v <= 1.0 {
                let w = 1.0 - u - v;
                return Some(
                    [2, 3, 4]
                        .map(|k| w * a.to_array()[k] + u * b.to_array()[k] + v * c.to_array()[k]),
                );
            }
        }
        None
    }
}

/// The mean, 99th percentile and largest colour difference (CIE76, Lab units) between the
/// ternary and the binary step, over a 250 by 250 grid of points covered by both surfaces.
fn difference_from_ternary(mesh: &GradientMesh) -> [f64; 3] {
    let depth = 4;
    let ternary = ColourField::new(mesh, depth);
    let binary = ColourField::new(&binary(mesh.clone()), depth);
    let (mut lo, mut hi) = (
        Point::new(f64::MAX, f64::MAX),
        Point::new(f64::MIN, f64::MIN),
    );
    for p in &mesh.points {
        lo = Point::new(lo.x.min(p.position.x), lo.y.min(p.position.y));
        hi = Point::new(hi.x.max(p.position.x), hi.y.max(p.position.y));
    }
    let n = 250;
    let mut differences = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let p = Point::new(
                lo.x + (hi.x - lo.x) * (i as f64 + 0.5) / n as f64,
                lo.y + (hi.y - lo.y) * (j as f64 + 0.5) / n as f64,
            );
            if let (Some(a), Some(b)) = (ternary.colour(p), binary.colour(p)) {
                differences.push((0..3).map(|c| (a[c] - b[c]).powi(2)).sum::<f64>().sqrt());
            }
        }
    }
    assert!(differences.len() > n * n / 4, "the surfaces barely overlap");
    differences.sort_by(f64::total_cmp);
    let mean = differences.iter().sum::<f64>() / differences.len() as f64;
    let p99 = differences[differences.len() * 99 / 100];
    [mean, p99, differences[differences.len() - 1]]
}

/// The binary step looks like the ternary step: on grids with strongly different colours at
/// neighbouring points, on random meshes and on real artwork, the colours differ by little
/// on average. (The largest differences lie along sharp colour edges, where the two surfaces
/// put the edge a fraction of a pixel apart.) Run with `--nocapture` to see the figures.
#[test]
fn the_binary_step_looks_like_the_ternary_step() {
    let mut meshes = vec![
        ("grid, default handles".to_string(), grid(4, None), 0.5),
        ("grid, short handles".to_string(), grid(4, Some(0.2)), 0.5),
        ("grid, long handles".to_string(), grid(4, Some(0.45)), 0.7),
    ];
    for name in std::fs::read_dir(crate::realdata::dir())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".off"))
    {
        meshes.push((name.clone(), realdata(&name), 0.5));
    }
    let mut runner = proptest::test_runner::TestRunner::deterministic();
    for i in 0..4 {
        let spec = proptest::strategy::ValueTree::current(
            &proptest::strategy::Strategy::new_tree(&mesh_spec(), &mut runner).unwrap(),
        );
        meshes.push((format!("random mesh {i}"), build(&spec), 1.0));
    }
    meshes.sort_by(|a, b| a.0.cmp(&b.0));
    for (name, mesh, mean_bound) in meshes {
        let [mean, p99, max] = difference_from_ternary(&mesh);
        println!("{name}: mean {mean:.2}, 99th percentile {p99:.2}, max {max:.2}");
        assert!(mean < mean_bound, "{name}: mean {mean}, max {max}");
    }
}
