//! The mesh tools of one click: new meshes (a grid, an ellipse, a drawn outline), the loop cut,
//! a point added inside a face, and dissolving points and edges.
//!
//! Each tool changes one layer's mesh and says what to select next ([`Selection`]); the
//! [`History`](crate::editor::History) checks the result with the validator as for every edit.
//! New points are appended to the layer's points and new faces to its faces, so the points and
//! faces a tool does not touch keep their numbers (dissolving renumbers what follows the points
//! and faces it removes). New points inside an existing surface take its colour where they are
//! ([`SurfaceSamples`]).

mod cuts;
mod dissolve;
mod shapes;

pub use cuts::{add_point_in_face, insert_point_on_edge, loop_cut};
pub use dissolve::{dissolve_edge, dissolve_points, remove_faces_and_points};
pub use shapes::{add_ellipse, add_grid, add_outline, MAX_GRID, MAX_OUTLINE_POINTS};

use gradmesh::{ColourSpace, GradientMesh, LevelPoints, Limits, VertexData};
use kurbo::{CubicBez, Point};
use serde::Serialize;

/// What a tool leaves selected: the points and the face the user works on next.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Selection {
    /// The layer.
    pub layer: usize,
    /// Points, in the order made.
    pub points: Vec<u32>,
    /// A face.
    pub face: Option<u32>,
}

/// What a tool did: the selection for the page and, when it did more than asked, a note.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ToolResult {
    /// The points and face to select (the layer is set by the caller).
    pub selection: Selection,
    /// A note for the user.
    pub note: Option<String>,
}

/// The edge's curve from `a` to `b`: a cubic through the two handles.
pub fn edge_curve(mesh: &GradientMesh, a: u32, b: u32) -> CubicBez {
    let (pa, pb) = (
        mesh.points[a as usize].position,
        mesh.points[b as usize].position,
    );
    CubicBez::new(pa, pa + mesh.handle(a, b), pb + mesh.handle(b, a), pb)
}

/// The edge key of `a` and `b` (smaller index first), as `GradientMesh::edges` holds them.
pub fn edge_key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// The colours of a new shape's corners, left top, right top, right bottom, left bottom, in
/// `space`.
pub fn palette(space: ColourSpace) -> [[f64; 3]; 4] {
    match space {
        ColourSpace::Lab => [
            [60.0, 60.0, 40.0],
            [85.0, -10.0, 80.0],
            [50.0, -40.0, -30.0],
            [40.0, 50.0, -60.0],
        ],
        _ => [
            [0.9, 0.3, 0.2],
            [0.95, 0.85, 0.2],
            [0.2, 0.6, 0.7],
            [0.4, 0.2, 0.7],
        ],
    }
}

/// The palette blended bilinearly at `(u, v)` of a new shape's box (0 to 1 each way).
pub fn palette_at(space: ColourSpace, u: f64, v: f64) -> [f64; 3] {
    let [lt, rt, rb, lb] = palette(space);
    [0, 1, 2].map(|i| {
        let top = lt[i] + (rt[i] - lt[i]) * u;
        let bottom = lb[i] + (rb[i] - lb[i]) * u;
        top + (bottom - top) * v
    })
}

/// Vertices of a layer's limit surface (position, colour, opacity), for the colour of new
/// points: a new point takes the colour and opacity of the nearest sample.
pub struct SurfaceSamples {
    samples: Vec<VertexData>,
}

/// The most quads of the refined level sampled (about; the level is chosen from the corners).
const MAX_SAMPLED_QUADS: usize = 400_000;

impl SurfaceSamples {
    /// The limit points of `mesh` at the deepest of levels 2 to 4 that keeps within
    /// `MAX_SAMPLED_QUADS`; `None` when the mesh has no faces or cannot be refined.
    pub fn of(mesh: &GradientMesh) -> Option<SurfaceSamples> {
        if mesh.faces.is_empty() {
            return None;
        }
        // Level 1 has about as many quads as 9/4 of the corners, and each level after it four
        // times as many.
        let mut level = 2;
        let level_1_quads = mesh.corner_count() * 9 / 4;
        while level < 4 && level_1_quads << (2 * level) <= MAX_SAMPLED_QUADS {
            level += 1;
        }
        let (refined, _) =
            gradmesh::refine_level(mesh, level, LevelPoints::Limit, &Limits::default()).ok()?;
        Some(SurfaceSamples {
            samples: refined.data,
        })
    }

    /// The colour and opacity (within 0 to 1) of the sample nearest `at`.
    pub fn nearest(&self, at: Point) -> Option<([f64; 3], f64)> {
        let distance =
            |s: &VertexData| (s.position[0] - at.x).powi(2) + (s.position[1] - at.y).powi(2);
        self.samples
            .iter()
            .min_by(|a, b| distance(a).total_cmp(&distance(b)))
            // Rounding can take a limit opacity of 1 a little past it.
            .map(|s| (s.colour, s.opacity.clamp(0.0, 1.0)))
    }
}

/// The surface's colour and opacity at each of `positions`, or `fallback(i)` where the layer
/// has no surface to sample.
pub fn colours_at(
    mesh: &GradientMesh,
    positions: &[Point],
    fallback: impl Fn(usize) -> ([f64; 3], f64),
) -> Vec<([f64; 3], f64)> {
    let samples = SurfaceSamples::of(mesh);
    (positions.iter().enumerate())
        .map(|(i, &at)| {
            (samples.as_ref())
                .and_then(|s| s.nearest(at))
                .unwrap_or_else(|| fallback(i))
        })
        .collect()
}

/// Drops the multi-resolution edits on `faces` (whose corners a tool changed, so their
/// addresses would name other vertices); returns a note saying how many went.
fn drop_edits_on(mesh: &mut GradientMesh, faces: &[u32]) -> Option<String> {
    let before = mesh.edits.len();
    mesh.edits.retain(|e| !faces.contains(&e.address.face));
    let dropped = before - mesh.edits.len();
    (dropped > 0).then(|| {
        format!(
            "{dropped} multi-resolution edit{} on the changed faces went with them",
            if dropped == 1 { "" } else { "s" }
        )
    })
}

/// Points a side override (wedge) that names `face` at a point no longer in it at the face of
/// `faces` that now holds the point.
fn move_wedges(mesh: &mut GradientMesh, face: u32, faces: &[u32]) {
    let GradientMesh {
        wedges, faces: f, ..
    } = mesh;
    for w in wedges.iter_mut().filter(|w| w.face == face) {
        if !f[face as usize].contains(&w.point) {
            if let Some(&g) = faces.iter().find(|&&g| f[g as usize].contains(&w.point)) {
                w.face = g;
            }
        }
    }
}

#[cfg(test)]
mod tests;
