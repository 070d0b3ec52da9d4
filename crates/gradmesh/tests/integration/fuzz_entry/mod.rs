//! Entry points shared by the fuzz targets (`fuzz/fuzz_targets/*.rs` include this file with
//! `#[path]`) and by `tests/integration/fuzz_replay.rs`, which replays the fuzz corpus and the
//! regression files through the same functions in a normal `cargo test`. Included standalone by
//! the fuzz targets, it uses no other module of the integration tests.
//!
//! Each entry point takes any input and panics only when the library misbehaves: a panic inside
//! the library, a non-finite number in refined or limit data, a colour that the limit surface
//! does not interpolate at its control point (the paper's Condition 1), or a document that does
//! not survive a write and read back unchanged.

#![allow(dead_code)]

pub mod pdf;
pub mod render;

use arbitrary::Arbitrary;
use gradmesh::formats::{self, json, Format};
use gradmesh::Refinement;
use gradmesh::{
    BoundaryInterpolation, ColourSpace, CreasingMethod, EdgeKind, Error, ErrorKind, GradientMesh,
    Limits, WedgeOverride,
};
use kurbo::{Point, Vec2};

/// Limits that keep one fuzz input fast: small refinements only.
pub fn fuzz_limits() -> Limits {
    Limits {
        refinement_level: 3,
        refined_faces: 1 << 14,
        ..Limits::DEFAULT
    }
}

/// Which parser a byte input goes to.
pub fn format_of_target(name: &str) -> Option<Format> {
    match name {
        "parse_json" => Some(Format::Json),
        "parse_off" => Some(Format::Off),
        "parse_obj" => Some(Format::Obj),
        "parse_svg" => Some(Format::Svg),
        _ => None,
    }
}

/// Parses `data` as `format`; a document that reads is written, read back and compared, and
/// each of its layers goes through [`check_mesh`] at depth 2.
pub fn parse(format: Format, data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let doc = match formats::read_str_with_limits(text, format, &fuzz_limits()) {
        Ok(doc) => doc,
        Err(e) => {
            check_error(&e);
            return;
        }
    };
    let once = json::write_document(&doc);
    let back = json::read_document(&once)
        .unwrap_or_else(|e| panic!("a written document does not read back: {e}\n{once}"));
    assert_eq!(back, doc, "the document changed in a round trip:\n{once}");
    assert_eq!(
        json::write_document(&back),
        once,
        "writing twice gave different bytes"
    );
    for mesh in &doc.layers {
        check_mesh(mesh, 2);
    }
}

/// An error must say something, and a limit error must be over its limit.
pub fn check_error(e: &Error) {
    let text = e.to_string();
    assert!(!text.trim().is_empty(), "empty message for {e:?}");
    if let ErrorKind::LimitExceeded { found, limit, .. } = &e.kind {
        assert!(found > limit, "{e}");
    }
}

/// Validates `mesh`, refines it to `depth` within [`fuzz_limits`], and checks that every level
/// and the limit are finite and that the limit colour and opacity at each control point's
/// vertex are the point's (Condition 1).
pub fn check_mesh(mesh: &GradientMesh, depth: usize) {
    let limits = fuzz_limits();
    let validated = gradmesh::validate(mesh);
    let (mut refinement, _warnings) = match Refinement::new_with_limits(mesh, depth, &limits) {
        Ok(r) => r,
        Err(e) => {
            check_error(&e);
            if let Err(v) = validated {
                assert_eq!(e, v, "refinement and validation disagree");
            }
            return;
        }
    };
    assert!(
        validated.is_ok(),
        "validation failed where refinement did not"
    );
    let data = refinement.evaluate();
    for (k, level) in data.levels.iter().enumerate() {
        assert_finite(level, refinement.topology(k), &format!("level {k}"));
    }
    // The limit at levels 0 and 1 refines to level 2.
    if limits
        .check_refinement(refinement.base(), depth.max(2))
        .is_err()
    {
        return;
    }
    let limit = refinement.limit(&data, depth);
    assert_finite(
        &limit,
        refinement.topology(depth),
        &format!("the limit of level {depth}"),
    );
    let base = refinement.base();
    let near_edits = points_next_to_edits(mesh);
    for v in 0..base.topology.vertex_count() {
        if near_edits.contains(&base.source_point[v]) {
            continue;
        }
        let at = refinement.vertex_at_level(v as u32, depth);
        for c in 2..6 {
            let (want, got) = (base.data[v].to_array()[c], limit[at].to_array()[c]);
            assert!(
                (want - got).abs() <= 1e-9 * want.abs().max(1.0),
                "Condition 1: vertex {v} channel {c}: limit {got}, control value {want}"
            );
        }
    }
}

/// The control points whose limit colour a multi-resolution edit changes: those with an edit
/// on their own vertex or next to it (sector coordinates both at most 1), whose ring after the
/// next step overlaps the point's (see the module docs of `gradmesh::edits`).
fn points_next_to_edits(mesh: &GradientMesh) -> std::collections::HashSet<u32> {
    mesh.edits
        .iter()
        .filter(|e| e.address.at[0] <= 1 && e.address.at[1] <= 1)
        .map(|e| e.address.point)
        .collect()
}

/// Asserts that the data of every vertex of `topology` is finite.
fn assert_finite(data: &[gradmesh::VertexData], _topology: &gradmesh::Topology, what: &str) {
    for (i, d) in data.iter().enumerate() {
        assert!(
            d.to_array().iter().all(|x| x.is_finite()),
            "{what}: vertex {i} is not finite: {d:?}"
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Structured random meshes

/// A scale for positions, to reach tiny and huge coordinates.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub enum Scale {
    /// Units.
    One,
    /// 1e-9.
    Tiny,
    /// 1e9.
    Huge,
    /// Any finite factor (others are replaced by 1).
    Any(f64),
}

impl Scale {
    fn factor(self) -> f64 {
        match self {
            Scale::One => 1.0,
            Scale::Tiny => 1e-9,
            Scale::Huge => 1e9,
            Scale::Any(f) if f.is_finite() && f != 0.0 => f,
            Scale::Any(_) => 1.0,
        }
    }
}

/// How the faces are made.
#[derive(Arbitrary, Clone, Debug)]
pub enum Shape {
    /// A `w` x `h` grid (1..=4 each) of cells: a quad, two triangles, or a hexagon with the
    /// next cell, by the cell's byte.
    Grid { w: u8, h: u8, cells: Vec<u8> },
    /// An `n`-gon (3..=10), alone or as a fan of triangles around a centre.
    Polygon { n: u8, fan: bool, closed_fan: bool },
    /// Faces of any indices (mostly invalid topology).
    Raw { points: u8, faces: Vec<Vec<u8>> },
}

/// A small mesh description that the fuzzer varies.
#[derive(Arbitrary, Clone, Debug)]
pub struct MeshDescription {
    pub shape: Shape,
    pub scale: Scale,
    pub offset: (i16, i16),
    /// Moves of points: (point, dx, dy) in grid units / 16.
    pub jitter: Vec<(u8, i8, i8)>,
    /// Points moved onto another point: (point, target).
    pub collapse: Vec<(u8, u8)>,
    pub colour_space: u8,
    pub colours: Vec<[i8; 3]>,
    pub opacity: Vec<u8>,
    pub corners: Vec<u8>,
    /// Handles: (point, neighbour slot, length in edge/8, turn).
    pub handles: Vec<(u8, u8, u8, i8)>,
    /// Edge tags: (edge slot, kind, sharpness in 1/4).
    pub edges: Vec<(u8, u8, u8)>,
    /// Wedge entries: (point, face, colour, opacity).
    pub wedges: Vec<(u8, u8, [i8; 3], Option<u8>)>,
    pub boundary_edge_only: bool,
    pub chaikin: bool,
    pub interpolate_positions: bool,
    pub reverse_faces: bool,
    pub depth: u8,
}

impl MeshDescription {
    /// The mesh described.
    pub fn build(&self) -> GradientMesh {
        let space = ColourSpace::ALL[self.colour_space as usize % ColourSpace::ALL.len()];
        let mut mesh = GradientMesh::new(space);
        mesh.boundary = if self.boundary_edge_only {
            BoundaryInterpolation::EdgeOnly
        } else {
            BoundaryInterpolation::EdgeAndCorner
        };
        mesh.creasing = if self.chaikin {
            CreasingMethod::Chaikin
        } else {
            CreasingMethod::Uniform
        };
        mesh.interpolate_positions = self.interpolate_positions;
        let scale = self.scale.factor();
        let origin = Point::new(self.offset.0 as f64, self.offset.1 as f64);
        let at = |x: f64, y: f64| Point::new((origin.x + x) * scale, (origin.y + y) * scale);
        match &self.shape {
            Shape::Grid { w, h, cells } => {
                let (w, h) = (1 + *w as u32 % 4, 1 + *h as u32 % 4);
                for j in 0..=h {
                    for i in 0..=w {
                        mesh.add_point(at(i as f64, j as f64), [0.0; 3]);
                    }
                }
                let id = |i: u32, j: u32| j * (w + 1) + i;
                for j in 0..h {
                    let mut i = 0;
                    while i < w {
                        let cell = cells.get((j * w + i) as usize).copied().unwrap_or(0) % 3;
                        let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                        match cell {
                            1 => {
                                mesh.add_face([a, b, c]);
                                mesh.add_face([a, c, d]);
                            }
                            2 if i + 1 < w => {
                                let (b2, c2) = (id(i + 2, j), id(i + 2, j + 1));
                                mesh.add_face([a, b, b2, c2, c, d]);
                                i += 1;
                            }
                            _ => {
                                mesh.add_face([a, b, c, d]);
                            }
                        }
                        i += 1;
                    }
                }
            }
            Shape::Polygon { n, fan, closed_fan } => {
                let n = 3 + *n as u32 % 8;
                for k in 0..n {
                    let t = std::f64::consts::TAU * k as f64 / n as f64;
                    mesh.add_point(at(4.0 * t.cos(), 4.0 * t.sin()), [0.0; 3]);
                }
                if *fan {
                    let c = mesh.add_point(at(0.0, 0.0), [0.0; 3]);
                    let last = if *closed_fan { n } else { n - 1 };
                    for k in 0..last {
                        mesh.add_face([c, k, (k + 1) % n]);
                    }
                } else {
                    mesh.add_face((0..n).collect::<Vec<_>>());
                }
            }
            Shape::Raw { points, faces } => {
                let n = 1 + *points as u32 % 12;
                for k in 0..n {
                    mesh.add_point(at((k % 4) as f64, (k / 4) as f64), [0.0; 3]);
                }
                for f in faces.iter().take(16) {
                    mesh.add_face(f.iter().take(8).map(|&i| i as u32 % n).collect::<Vec<_>>());
                }
            }
        }
        if self.reverse_faces {
            for f in &mut mesh.faces {
                f.reverse();
            }
        }
        let n = mesh.points.len();
        for &(p, dx, dy) in self.jitter.iter().take(32) {
            let p = &mut mesh.points[p as usize % n];
            p.position += Vec2::new(dx as f64, dy as f64) * (scale / 16.0);
        }
        for &(p, q) in self.collapse.iter().take(4) {
            mesh.points[p as usize % n].position = mesh.points[q as usize % n].position;
        }
        for (k, p) in mesh.points.iter_mut().enumerate() {
            let c = self.colours.get(k).copied().unwrap_or([0; 3]);
            p.colour = colour_in(space, c);
            p.opacity = self.opacity.get(k).map_or(1.0, |&o| o as f64 / 255.0);
            p.corner = self.corners.contains(&(k as u8));
        }
        for &(p, slot, len, turn) in self.handles.iter().take(32) {
            set_handle_by_slot(&mut mesh, p, slot, len, turn);
        }
        for &(slot, kind, sharpness) in self.edges.iter().take(16) {
            set_edge_by_slot(&mut mesh, slot, kind, sharpness);
        }
        if !mesh.faces.is_empty() {
            for &(p, f, c, o) in self.wedges.iter().take(8) {
                let face = f as u32 % mesh.faces.len() as u32;
                let corners = &mesh.faces[face as usize];
                let Some(&point) = corners.get(p as usize % corners.len().max(1)) else {
                    continue;
                };
                mesh.wedges.push(WedgeOverride {
                    point,
                    face,
                    colour: colour_in(space, c),
                    colour_text: None,
                    opacity: o.map(|o| o as f64 / 255.0),
                    handles: Default::default(),
                });
            }
        }
        mesh
    }
}

/// The edges of the faces of `mesh`, in a fixed order, for handles and tags.
fn face_edges(mesh: &GradientMesh) -> Vec<(u32, u32)> {
    let mut edges = Vec::new();
    for f in &mesh.faces {
        for k in 0..f.len() {
            edges.push((f[k], f[(k + 1) % f.len()]));
        }
    }
    edges
}

/// Sets the handle of point `p` (modulo the point count) towards its neighbour in `slot`: `len`
/// eighths of the edge, turned by `turn` / 64 radians. Nothing when the point has no edge.
pub fn set_handle_by_slot(mesh: &mut GradientMesh, p: u8, slot: u8, len: u8, turn: i8) {
    let n = mesh.points.len() as u32;
    if n == 0 {
        return;
    }
    let from = p as u32 % n;
    let ring: Vec<u32> = face_edges(mesh)
        .iter()
        .filter_map(|&(a, b)| (a == from).then_some(b).or((b == from).then_some(a)))
        .collect();
    let Some(&to) = ring.get(slot as usize % ring.len().max(1)) else {
        return;
    };
    let d = mesh.points[to as usize].position - mesh.points[from as usize].position;
    let (s, c) = (turn as f64 / 64.0).sin_cos();
    let r = len as f64 / 8.0;
    mesh.set_handle(
        from,
        to,
        Vec2::new(r * (c * d.x - s * d.y), r * (s * d.x + c * d.y)),
    );
}

/// Tags the face edge in `slot` (modulo the edge count): crease, semi-sharp crease of
/// `sharpness` / 4, discontinuous or smooth, by `kind`.
pub fn set_edge_by_slot(mesh: &mut GradientMesh, slot: u8, kind: u8, sharpness: u8) {
    let edges = face_edges(mesh);
    if edges.is_empty() {
        return;
    }
    let (a, b) = edges[slot as usize % edges.len()];
    let (kind, s) = match kind % 4 {
        0 => (EdgeKind::Crease, None),
        1 => (EdgeKind::Crease, Some(sharpness as f64 / 4.0)),
        2 => (EdgeKind::Discontinuous, None),
        _ => (EdgeKind::Smooth, None),
    };
    mesh.set_edge(a, b, kind, s);
}

/// A colour from three bytes, spread over the usual range of `space`.
pub fn colour_in(space: ColourSpace, c: [i8; 3]) -> [f64; 3] {
    let unit = |v: i8| (v as f64 + 128.0) / 255.0;
    match space {
        ColourSpace::Lab => [100.0 * unit(c[0]), c[1] as f64, c[2] as f64],
        ColourSpace::Oklab => [unit(c[0]), c[1] as f64 / 400.0, c[2] as f64 / 400.0],
        _ => [unit(c[0]), unit(c[1]), unit(c[2])],
    }
}

/// Builds the described mesh and checks it at its depth (0..=3).
pub fn pipeline(desc: &MeshDescription) {
    let mesh = desc.build();
    check_mesh(&mesh, desc.depth as usize % 4);
}

/// Decodes `data` as the pipeline target does (arbitrary's `arbitrary_take_rest`) and runs it.
pub fn pipeline_bytes(data: &[u8]) {
    if let Ok(desc) = MeshDescription::arbitrary_take_rest(arbitrary::Unstructured::new(data)) {
        pipeline(&desc);
    }
}

/// Runs the entry point of fuzz target `target` on `data`.
pub fn run_target(target: &str, data: &[u8]) {
    match format_of_target(target) {
        Some(Format::Svg) => parse_svg(data),
        Some(format) => parse(format, data),
        None if target == "pipeline" => pipeline_bytes(data),
        None if target == "render" => render::render_bytes(data),
        None if target == "parse_pdf" => pdf::parse_pdf(data),
        None if target == "parse_pdf_shading" => pdf::parse_pdf_shading(data),
        None if target == "vectorise" => vectorise_bytes(data),
        None => panic!("unknown fuzz target {target}"),
    }
}

/// The most pixels a picture of [`vectorise_bytes`] may have: a few thousand keep one input
/// within a fraction of a second.
pub const FUZZ_IMAGE_PIXELS: u64 = 1 << 12;

/// Decodes `data` as a PNG or JPEG picture (refused beyond [`FUZZ_IMAGE_PIXELS`] before
/// decoding) and vectorises it with a small budget: an error with a message, or a mesh within
/// the budget that validates, covers the picture's rectangle and renders back at a PSNR that is
/// a number.
pub fn vectorise_bytes(data: &[u8]) {
    let image = match gradmesh::RgbaImage::decode(data, FUZZ_IMAGE_PIXELS) {
        Ok(image) => image,
        Err(e) => {
            check_error(&e);
            return;
        }
    };
    assert!(
        image.width > 0 && image.height > 0,
        "an empty picture decoded"
    );
    let options = gradmesh::VectoriseOptions {
        points: Some(24),
        quality: gradmesh::Quality::Fast,
        ..gradmesh::VectoriseOptions::default()
    };
    let out = match gradmesh::vectorise(&image, &options) {
        Ok(out) => out,
        Err(e) => {
            check_error(&e);
            return;
        }
    };
    assert!(out.points <= 24, "{} points for a budget of 24", out.points);
    assert!(!out.psnr.is_nan(), "PSNR is not a number");
    assert_eq!(out.document.layers.len(), 1);
    let mesh = &out.document.layers[0];
    gradmesh::validate(mesh).unwrap_or_else(|e| panic!("the vectorised mesh is invalid: {e}"));
    let (w, h) = (f64::from(image.width), f64::from(image.height));
    for p in &mesh.points {
        let q = p.position;
        assert!(
            q.x >= -0.01 && q.x <= w + 0.01 && q.y >= -0.01 && q.y <= h + 0.01,
            "point {q:?} outside the {w} x {h} picture"
        );
        assert!(
            p.colour.iter().all(|c| c.is_finite()),
            "colour {:?}",
            p.colour
        );
    }
}

/// Reads `data` as SVG: the normalised scene keeps the guarantees the reader documents (see
/// [`check_scene`]), and the document converted from it goes through [`parse`]'s checks.
pub fn parse_svg(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match formats::svg::read_svg_with_limits(text, &fuzz_limits()) {
        Ok(scene) => check_scene(&scene),
        Err(e) => check_error(&e),
    }
    parse(Format::Svg, data);
}

/// The reader's guarantees: every number finite; every mesh a full grid of at least one patch
/// whose sides start and end at their corners; colours and opacities in 0..1; a view with a
/// positive size.
pub fn check_scene(scene: &formats::svg::SvgScene) {
    let finite = |p: kurbo::Point| p.x.is_finite() && p.y.is_finite();
    let unit = |x: f64| (0.0..=1.0).contains(&x);
    let view = scene.view_rect();
    assert!(
        view.width() > 0.0 && view.height() > 0.0 && finite(view.origin()),
        "view {view:?}"
    );
    for fill in &scene.fills {
        let grid = &fill.mesh;
        let (rows, columns) = (grid.rows, grid.columns);
        assert!(
            rows >= 1 && columns >= 1,
            "an empty grid in {}",
            fill.gradient_id
        );
        assert_eq!(grid.corners.len(), (rows + 1) * (columns + 1));
        assert_eq!(grid.row_sides.len(), (rows + 1) * columns);
        assert_eq!(grid.column_sides.len(), rows * (columns + 1));
        assert!(unit(fill.fill_opacity) && unit(fill.group_opacity));
        for corner in &grid.corners {
            assert!(finite(corner.position), "corner {corner:?}");
            assert!(corner.colour.iter().all(|&c| unit(c)) && unit(corner.opacity));
        }
        for i in 0..=rows {
            for j in 0..=columns {
                let at = grid.corner(i, j).position;
                if j < columns {
                    let side = grid.row_side(i, j);
                    assert_eq!((side.p0, side.p3), (at, grid.corner(i, j + 1).position));
                }
                if i < rows {
                    let side = grid.column_side(i, j);
                    assert_eq!((side.p0, side.p3), (at, grid.corner(i + 1, j).position));
                }
            }
        }
        let sides = grid.row_sides.iter().chain(&grid.column_sides);
        assert!(sides.flat_map(|s| [s.p1, s.p2]).all(finite));
        for element in fill.clip.elements() {
            let points: Vec<kurbo::Point> = match *element {
                kurbo::PathEl::MoveTo(a) | kurbo::PathEl::LineTo(a) => vec![a],
                kurbo::PathEl::QuadTo(a, b) => vec![a, b],
                kurbo::PathEl::CurveTo(a, b, c) => vec![a, b, c],
                kurbo::PathEl::ClosePath => vec![],
            };
            assert!(
                points.into_iter().all(finite),
                "the clip of {}",
                fill.gradient_id
            );
        }
    }
}
