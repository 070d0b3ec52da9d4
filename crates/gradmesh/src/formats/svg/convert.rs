//! Mesh gradients as layers of the scheme: a control point at each patch corner, a quad face
//! per patch, handles from the sides' inner control points.

use std::collections::BTreeSet;

use kurbo::CubicBez;

use super::scene::{MeshFill, MeshGrid, SvgScene};
use crate::colour::{parse_css_colour, ColourSpace};
use crate::error::{Warning, WarningKind};
use crate::mesh::{edge_key, ControlPoint, Document, GradientMesh};
use crate::union_find::UnionFind;

/// The document of every fill of `scene`, one layer per fill in paint order, with colours in
/// `space`, and the warnings of the reading and of the conversion.
pub fn scene_to_document(scene: &SvgScene, space: ColourSpace) -> (Document, Vec<Warning>) {
    let mut warnings = scene.warnings.clone();
    let mut doc = Document::default();
    for (layer, fill) in scene.fills.iter().enumerate() {
        let (mesh, notes) = fill_to_layer(fill, space);
        warnings.extend(notes.into_iter().map(|w| Warning {
            layer: Some(layer),
            ..w
        }));
        doc.layers.push(mesh);
    }
    (doc, warnings)
}

/// One fill as a layer, and what the conversion had to change.
///
/// Corners joined by a side of zero length (all four control points at one place, as in a
/// star whose patches meet at its centre) become one control point, and a patch left with
/// fewer than three corners is dropped, so that the layer has no zero-length edge. Where the
/// mesh's outline turns, the point is a `corner`. A corner's opacity is its stop's opacity
/// times the fill's `fill-opacity` and group opacity.
pub fn fill_to_layer(fill: &MeshFill, space: ColourSpace) -> (GradientMesh, Vec<Warning>) {
    let grid = &fill.mesh;
    let (rows, columns) = (grid.rows, grid.columns);
    let index = |i: usize, j: usize| i * (columns + 1) + j;
    let mut merged = corners_joined_by_empty_sides(grid);

    let mut notes = Vec::new();
    let mut mesh = GradientMesh::new(space);
    mesh.name = Some(fill.gradient_id.clone());
    let opacity_scale = fill.fill_opacity * fill.group_opacity;
    let mut point_of = vec![u32::MAX; grid.corners.len()];
    for k in 0..grid.corners.len() {
        let root = merged.find(k);
        let corner = &grid.corners[k];
        if point_of[root] == u32::MAX {
            let (colour, colour_text) = layer_colour(corner.colour, space);
            let mut point = ControlPoint::new(corner.position, colour);
            point.opacity = corner.opacity * opacity_scale;
            point.colour_text = colour_text;
            mesh.points.push(point);
            point_of[root] = (mesh.points.len() - 1) as u32;
        } else if grid.corners[root].colour != corner.colour
            || grid.corners[root].opacity != corner.opacity
        {
            notes.push(Warning::new(WarningKind::SvgReadDifferently, format!(
                "corner ({}, {}) meets corner ({}, {}) across a side of zero length but has another colour or opacity: the first is kept",
                k / (columns + 1), k % (columns + 1), root / (columns + 1), root % (columns + 1)
            )));
        }
        point_of[k] = point_of[root];
    }

    for (i, j) in boundary_kinks(grid) {
        mesh.points[point_of[index(i, j)] as usize].corner = true;
    }

    let mut edges = BTreeSet::new();
    for r in 0..rows {
        for c in 0..columns {
            let mut face: Vec<u32> = [
                index(r, c),
                index(r, c + 1),
                index(r + 1, c + 1),
                index(r + 1, c),
            ]
            .iter()
            .map(|&k| point_of[k])
            .collect();
            face.dedup();
            while face.len() > 1 && face.first() == face.last() {
                face.pop();
            }
            if face.len() < 3 {
                notes.push(Warning::new(WarningKind::SvgMeshLeftOut, format!("the patch in row {r}, column {c} has no area (its sides have zero length): left out")));
                continue;
            }
            for k in 0..face.len() {
                edges.insert(edge_key(face[k], face[(k + 1) % face.len()]));
            }
            mesh.faces.push(face);
        }
    }

    let sides = (0..=rows)
        .flat_map(|i| (0..columns).map(move |j| (i, j, i, j + 1)))
        .chain((0..rows).flat_map(|i| (0..=columns).map(move |j| (i, j, i + 1, j))));
    for (i0, j0, i1, j1) in sides {
        let side = if i0 == i1 {
            grid.row_side(i0, j0)
        } else {
            grid.column_side(i0, j0)
        };
        let (a, b) = (point_of[index(i0, j0)], point_of[index(i1, j1)]);
        if a != b && edges.contains(&edge_key(a, b)) {
            set_handle_if_not_default(&mut mesh, a, b, side.p1 - side.p0);
            set_handle_if_not_default(&mut mesh, b, a, side.p2 - side.p3);
        }
    }
    (mesh, notes)
}

/// The corners in sets joined by sides of zero length (all four control points within a
/// billionth of the mesh's size of each other).
fn corners_joined_by_empty_sides(grid: &MeshGrid) -> UnionFind {
    let (rows, columns) = (grid.rows, grid.columns);
    let index = |i: usize, j: usize| i * (columns + 1) + j;
    let bounds = grid.control_bounds();
    let tolerance = 1e-9 * bounds.width().max(bounds.height()).max(1.0);
    let degenerate = |s: &CubicBez| {
        [s.p1, s.p2, s.p3]
            .iter()
            .all(|p| p.distance(s.p0) <= tolerance)
    };

    let mut merged = UnionFind::new(grid.corners.len());
    for i in 0..=rows {
        for j in 0..columns {
            if degenerate(&grid.row_side(i, j)) {
                merged.union(index(i, j), index(i, j + 1));
            }
        }
    }
    for i in 0..rows {
        for j in 0..=columns {
            if degenerate(&grid.column_side(i, j)) {
                merged.union(index(i, j), index(i + 1, j));
            }
        }
    }
    merged
}

/// The largest angle, in radians, between the two sides at a corner on the grid's outline for
/// the outline to count as smooth there.
const KINK_ANGLE: f64 = 0.01;

/// The corners on the grid's outline, other than its four ends, where the outline turns: the
/// scheme keeps them sharp (`corner`), as a Coons mesh draws them. The four ends are corners
/// of the scheme's boundary rule already.
fn boundary_kinks(grid: &MeshGrid) -> Vec<(usize, usize)> {
    let (rows, columns) = (grid.rows, grid.columns);
    let mut kinks = Vec::new();
    let mut check = |at: (usize, usize), before: CubicBez, after: CubicBez| {
        let (incoming, outgoing) = (end_tangent(before), start_tangent(after));
        if incoming.hypot() > 0.0
            && outgoing.hypot() > 0.0
            && incoming.cross(outgoing).atan2(incoming.dot(outgoing)).abs() > KINK_ANGLE
        {
            kinks.push(at);
        }
    };
    for j in 1..columns {
        check((0, j), grid.row_side(0, j - 1), grid.row_side(0, j));
        check(
            (rows, j),
            grid.row_side(rows, j - 1),
            grid.row_side(rows, j),
        );
    }
    for i in 1..rows {
        check((i, 0), grid.column_side(i - 1, 0), grid.column_side(i, 0));
        check(
            (i, columns),
            grid.column_side(i - 1, columns),
            grid.column_side(i, columns),
        );
    }
    kinks
}

/// The direction a cubic leaves its start in (zero when it has no length).
fn start_tangent(c: CubicBez) -> kurbo::Vec2 {
    [c.p1, c.p2, c.p3]
        .into_iter()
        .map(|p| p - c.p0)
        .find(|v| v.hypot() > 0.0)
        .unwrap_or_default()
}

/// The direction a cubic arrives at its end in (zero when it has no length).
fn end_tangent(c: CubicBez) -> kurbo::Vec2 {
    start_tangent(CubicBez::new(c.p3, c.p2, c.p1, c.p0)) * -1.0
}

/// Sets a handle unless it equals the default third of the edge (to rounding), so that the
/// file keeps only the handles that say something.
fn set_handle_if_not_default(mesh: &mut GradientMesh, from: u32, to: u32, handle: kurbo::Vec2) {
    let default = mesh.handle(from, to);
    let scale = default.hypot().max(1e-300);
    if (handle - default).hypot() > 1e-9 * scale {
        mesh.set_handle(from, to, handle);
    }
}

/// `#rrggbb` when the colour is exactly an 8-bit sRGB colour, as stop colours are.
/// A stop colour in the layer's space, with its `#rrggbb` text when it has one. A colour with
/// text is converted as the native format reads that text, so that the document keeps the text
/// through a write and read back.
fn layer_colour(rgb: [f64; 3], space: ColourSpace) -> ([f64; 3], Option<String>) {
    if let Some(text) = hex_colour(rgb) {
        if let Ok((colour, _)) = parse_css_colour(&text, space) {
            return (colour, Some(text));
        }
    }
    (ColourSpace::Srgb.convert(space, rgb), None)
}

fn hex_colour(rgb: [f64; 3]) -> Option<String> {
    let bytes = rgb.map(|v| (v * 255.0).round());
    let exact = rgb
        .iter()
        .zip(&bytes)
        .all(|(v, b)| (v * 255.0 - b).abs() < 1e-9 && (0.0..=255.0).contains(b));
    exact.then(|| {
        format!(
            "#{:02x}{:02x}{:02x}",
            bytes[0] as u8, bytes[1] as u8, bytes[2] as u8
        )
    })
}
