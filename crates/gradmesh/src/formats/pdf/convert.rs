//! Patch-mesh shadings as layers of the scheme: a control point at each patch corner (corners
//! at one place with one colour are one point, so patches that share sides share points), a
//! quad face per patch, handles from the sides' inner control points.

use std::collections::{HashMap, HashSet};

use kurbo::{Point, Vec2};

use super::scene::{coons_interior, PdfPicture, ShadingFill};
use crate::colour::ColourSpace;
use crate::error::{Warning, WarningKind};
use crate::mesh::{edge_key, ControlPoint, Document, GradientMesh};

/// The document of every fill of `picture`, one layer per fill in paint order, with colours
/// in `space`, and the warnings of the reading and of the conversion.
pub fn picture_to_document(picture: &PdfPicture, space: ColourSpace) -> (Document, Vec<Warning>) {
    let mut warnings: Vec<Warning> = picture
        .warnings
        .iter()
        .map(|message| Warning::new(WarningKind::PdfLeftOut, message.clone()))
        .collect();
    let mut doc = Document::default();
    for (layer, fill) in picture.fills.iter().enumerate() {
        let (mesh, notes) = fill_to_layer(fill, space);
        warnings.extend(notes.into_iter().map(|message| Warning {
            layer: Some(layer),
            ..Warning::new(WarningKind::PdfLeftOut, message)
        }));
        doc.layers.push(mesh);
    }
    (doc, warnings)
}

/// Corners closer than this fraction of the mesh's size are at one place: a file may
/// quantise the same corner of two patches to neighbouring steps (32-bit coordinates step by
/// a quarter of a billionth of the range).
const POINT_TOLERANCE: f64 = 1e-6;
/// Colours closer than this in every component of the layer's space are the same.
const COLOUR_TOLERANCE: f64 = 1e-3;

/// The largest angle, in radians, between the two sides at a point of the outline for the
/// outline to count as smooth there.
const KINK_ANGLE: f64 = 0.01;

/// One fill as a layer, and what the conversion had to change.
///
/// Corners within a millionth of the mesh's size of each other and of the same colour (to a
/// thousandth) are one point. Every face runs the same way round; a patch that would run a shared side the same
/// way as its neighbour, or give a side a third face, keeps points of its own. A side of no
/// length (corners at one place, whatever their colours) is dropped, its first corner kept; a
/// patch with fewer than three distinct corners is left out. A point where patches meet only
/// at a corner becomes one point per fan of patches around it. Where the outline turns, the
/// point is a `corner`. The interior points of a tensor-product patch are not carried (the
/// scheme has no such control).
pub fn fill_to_layer(fill: &ShadingFill, space: ColourSpace) -> (GradientMesh, Vec<String>) {
    let mut notes = Vec::new();
    let mut mesh = GradientMesh::new(space);
    mesh.name = Some(fill.object.clone());
    let bounds = fill.control_bounds();
    let tolerance = POINT_TOLERANCE * bounds.width().max(bounds.height()).max(1.0);
    let mut grid = PointGrid::new(tolerance);
    let mut used = EdgeUse::default();
    let mut face_sides: Vec<Vec<[Point; 4]>> = Vec::new();
    let mut merged_colours = 0;
    for index in 0..fill.patches.len() {
        let (corners, curves) = patch_corners(fill, index, space);
        let mut face: Vec<u32> = corners.iter().map(|c| grid.shared(c, &mut mesh)).collect();
        if used.clashes(&face) {
            face = corners.iter().map(|c| grid.add(c, &mut mesh)).collect();
        }
        let (kept, merged) = without_empty_sides(&face, &curves, &mesh, tolerance);
        if kept.len() < 3 {
            notes.push(format!(
                "patch {index} has no area (fewer than three distinct corners): left out"
            ));
            continue;
        }
        merged_colours += usize::from(merged);
        let face: Vec<u32> = kept.iter().map(|k| k.0).collect();
        used.add(&face);
        face_sides.push(kept.iter().map(|k| k.1).collect());
        mesh.faces.push(face);
    }
    if merged_colours > 0 {
        notes.push(format!("{merged_colours} patch(es) have a side of no length between corners of different colours: the side is dropped and the first corner's colour kept"));
    }
    if fill.shading_type == 7 && tensor_interior_differs(fill, tolerance) {
        notes.push("the interior points of the tensor-product patches are not carried into the scheme: its faces take the Coons interior of their sides".into());
    }
    let split = split_fans(&mut mesh);
    if split > 0 {
        notes.push(format!("{split} point(s) where patches meet only at a corner are split, one per fan of patches"));
    }
    let sides: Vec<((u32, u32), [Point; 4])> = mesh
        .faces
        .iter()
        .zip(&face_sides)
        .flat_map(|(face, curves)| {
            (0..face.len()).map(move |k| ((face[k], face[(k + 1) % face.len()]), curves[k]))
        })
        .collect();
    set_handles(&mut mesh, &sides);
    let undirected = edge_counts(&mesh.faces);
    mark_kinks(&mut mesh, &sides, &undirected);
    (mesh, notes)
}

/// A corner of a patch: its place, colour in the layer's space and opacity.
type Corner = (Point, [f64; 3], f64);

/// The corners of patch `index` of `fill` around it, (0, 0), (0, 1), (1, 1), (1, 0), with the
/// side that leaves each; turned to run counter-clockwise in the picture (positive corner
/// area) when the patch runs the other way.
fn patch_corners(
    fill: &ShadingFill,
    index: usize,
    space: ColourSpace,
) -> ([Corner; 4], [[Point; 4]; 4]) {
    let patch = &fill.patches[index];
    let n = fill.colour.corner_components();
    let colour_at = |corner: usize| {
        let rgb = fill
            .colour
            .to_srgb(&patch.components[corner * n..corner * n + n]);
        ColourSpace::Srgb.convert(space, rgb)
    };
    let p = &patch.points;
    let opacity_at = |u: f64, v: f64| fill.opacity_at(index, u, v);
    let mut corners = [
        (p[0][0], colour_at(0), opacity_at(0.0, 0.0)),
        (p[0][3], colour_at(1), opacity_at(0.0, 1.0)),
        (p[3][3], colour_at(3), opacity_at(1.0, 1.0)),
        (p[3][0], colour_at(2), opacity_at(1.0, 0.0)),
    ];
    let mut curves = patch.sides();
    if patch.corner_area() < 0.0 {
        corners.reverse();
        curves.reverse();
        for c in &mut curves {
            c.reverse();
        }
        // Reversed, the sides run from corner k + 1 to k: shift them back in step.
        curves.rotate_left(1);
    }
    (corners, curves)
}

/// Whether some tensor-product patch of `fill` has interior points away from the Coons
/// interior of its sides.
fn tensor_interior_differs(fill: &ShadingFill, tolerance: f64) -> bool {
    fill.patches.iter().any(|patch| {
        let p = &patch.points;
        let mut coons = *p;
        coons_interior(&mut coons);
        (1..3)
            .flat_map(|i| (1..3).map(move |j| (i, j)))
            .any(|(i, j)| coons[i][j].distance(p[i][j]) > tolerance * 1e3)
    })
}

/// The points of a layer bucketed by place, to find a corner's point among those near it.
struct PointGrid {
    tolerance: f64,
    at: HashMap<(i64, i64), Vec<u32>>,
}

impl PointGrid {
    fn new(tolerance: f64) -> Self {
        PointGrid {
            tolerance,
            at: HashMap::new(),
        }
    }

    fn key(&self, p: Point) -> (i64, i64) {
        (
            (p.x / self.tolerance).floor() as i64,
            (p.y / self.tolerance).floor() as i64,
        )
    }

    /// The point at the corner's place with its colour and opacity, added if there is none.
    fn shared(&mut self, corner: &Corner, mesh: &mut GradientMesh) -> u32 {
        let &(position, colour, opacity) = corner;
        let same = |q: u32| {
            let point = &mesh.points[q as usize];
            point.position.distance(position) <= self.tolerance
                && (0..3).all(|k| (point.colour[k] - colour[k]).abs() <= COLOUR_TOLERANCE)
                && (point.opacity - opacity).abs() <= COLOUR_TOLERANCE
        };
        let (kx, ky) = self.key(position);
        let found = (kx - 1..=kx + 1)
            .flat_map(|x| (ky - 1..=ky + 1).map(move |y| (x, y)))
            .find_map(|cell| {
                self.at
                    .get(&cell)
                    .and_then(|list| list.iter().copied().find(|&q| same(q)))
            });
        found.unwrap_or_else(|| self.add(corner, mesh))
    }

    /// A new point at the corner.
    fn add(&mut self, corner: &Corner, mesh: &mut GradientMesh) -> u32 {
        let &(position, colour, opacity) = corner;
        let mut point = ControlPoint::new(position, colour);
        point.opacity = opacity;
        mesh.points.push(point);
        let index = (mesh.points.len() - 1) as u32;
        self.at.entry(self.key(position)).or_default().push(index);
        index
    }
}

/// The sides the faces so far run: each way, and how many faces each side has.
#[derive(Default)]
struct EdgeUse {
    directed: HashSet<(u32, u32)>,
    undirected: HashMap<(u32, u32), u32>,
}

impl EdgeUse {
    /// Whether `face` would run a side the same way as a face before it, or give a side a
    /// third face.
    fn clashes(&self, face: &[u32]) -> bool {
        (0..face.len()).any(|k| {
            let (a, b) = (face[k], face[(k + 1) % face.len()]);
            a != b
                && (self.directed.contains(&(a, b))
                    || self
                        .undirected
                        .get(&edge_key(a, b))
                        .is_some_and(|&c| c >= 2))
        })
    }

    fn add(&mut self, face: &[u32]) {
        for k in 0..face.len() {
            let (a, b) = (face[k], face[(k + 1) % face.len()]);
            self.directed.insert((a, b));
            *self.undirected.entry(edge_key(a, b)).or_default() += 1;
        }
    }
}

/// How many faces each side of `faces` has.
fn edge_counts(faces: &[Vec<u32>]) -> HashMap<(u32, u32), u32> {
    let mut counts = HashMap::new();
    for face in faces {
        for k in 0..face.len() {
            *counts
                .entry(edge_key(face[k], face[(k + 1) % face.len()]))
                .or_default() += 1;
        }
    }
    counts
}

/// The handles of the sides' inner control points, where a side's curve ends at its point.
fn set_handles(mesh: &mut GradientMesh, sides: &[((u32, u32), [Point; 4])]) {
    for &((a, b), curve) in sides {
        if curve[3] != mesh.points[b as usize].position {
            continue;
        }
        set_handle_if_not_default(mesh, a, b, curve[1] - curve[0]);
        set_handle_if_not_default(mesh, b, a, curve[2] - curve[3]);
    }
}

/// The corners of a face with the side that leaves each, corners at one place (within
/// `tolerance`) taken once, with the side that leaves the last of them; and whether corners
/// so joined had different points (different colours).
fn without_empty_sides(
    face: &[u32],
    curves: &[[Point; 4]],
    mesh: &GradientMesh,
    tolerance: f64,
) -> (Vec<(u32, [Point; 4])>, bool) {
    let at = |q: u32| mesh.points[q as usize].position;
    let together = |a: u32, b: u32| a == b || at(a).distance(at(b)) <= tolerance;
    let mut merged = false;
    let mut kept: Vec<(u32, [Point; 4])> = Vec::new();
    for k in 0..face.len() {
        match kept.last_mut() {
            Some(last) if together(last.0, face[k]) => {
                // A side of no length: the next side starts here.
                merged |= last.0 != face[k];
                last.1 = curves[k];
            }
            _ => kept.push((face[k], curves[k])),
        }
    }
    // The last corner at the first one's place: its side, of no length, goes with it.
    while kept.len() > 1 && together(kept[0].0, kept[kept.len() - 1].0) {
        let last = kept.pop().map_or(kept[0].0, |l| l.0);
        merged |= last != kept[0].0;
    }
    (kept, merged)
}

/// Gives each fan of faces around a point but the first a copy of the point, so that patches
/// meeting only at a corner leave no point non-manifold; the number of points added.
fn split_fans(mesh: &mut GradientMesh) -> usize {
    let mut corners_at: Vec<Vec<(usize, usize)>> = vec![Vec::new(); mesh.points.len()];
    for (f, face) in mesh.faces.iter().enumerate() {
        for (k, &q) in face.iter().enumerate() {
            corners_at[q as usize].push((f, k));
        }
    }
    let mut added = 0;
    for (point, corners) in corners_at.iter().enumerate() {
        for fan in fans(&mesh.faces, corners).iter().skip(1) {
            mesh.points.push(mesh.points[point].clone());
            let copy = (mesh.points.len() - 1) as u32;
            for &(f, k) in fan {
                mesh.faces[f][k] = copy;
            }
            added += 1;
        }
    }
    added
}

/// The corners `(face, index)` at one point grouped into fans: two corners are in one fan
/// when their faces share a side at the point (the same neighbouring point), in the order of
/// their first corners.
fn fans(faces: &[Vec<u32>], corners: &[(usize, usize)]) -> Vec<Vec<(usize, usize)>> {
    let mut group: Vec<usize> = (0..corners.len()).collect();
    let root = |group: &[usize], mut i: usize| {
        while group[i] != i {
            i = group[i];
        }
        i
    };
    let mut by_neighbour: HashMap<u32, usize> = HashMap::new();
    for (i, &(f, k)) in corners.iter().enumerate() {
        let face = &faces[f];
        let n = face.len();
        for q in [face[(k + 1) % n], face[(k + n - 1) % n]] {
            match by_neighbour.get(&q) {
                Some(&j) => {
                    let (a, b) = (root(&group, i), root(&group, j));
                    group[a.max(b)] = a.min(b);
                }
                None => {
                    by_neighbour.insert(q, i);
                }
            }
        }
    }
    let mut fans: Vec<Vec<(usize, usize)>> = Vec::new();
    let mut fan_of_root: HashMap<usize, usize> = HashMap::new();
    for (i, &corner) in corners.iter().enumerate() {
        let r = root(&group, i);
        let fan = *fan_of_root.entry(r).or_insert_with(|| {
            fans.push(Vec::new());
            fans.len() - 1
        });
        fans[fan].push(corner);
    }
    fans
}

/// Marks as `corner` the points of the outline where it turns.
fn mark_kinks(
    mesh: &mut GradientMesh,
    sides: &[((u32, u32), [Point; 4])],
    undirected: &HashMap<(u32, u32), u32>,
) {
    let mut incoming: HashMap<u32, Vec2> = HashMap::new();
    let mut outgoing: HashMap<u32, Vec2> = HashMap::new();
    for &((a, b), c) in sides {
        if undirected.get(&edge_key(a, b)) != Some(&1) {
            continue;
        }
        let start = [c[1], c[2], c[3]]
            .into_iter()
            .map(|p| p - c[0])
            .find(|v| v.hypot() > 0.0);
        let end = [c[2], c[1], c[0]]
            .into_iter()
            .map(|p| c[3] - p)
            .find(|v| v.hypot() > 0.0);
        if let (Some(s), Some(e)) = (start, end) {
            outgoing.insert(a, s);
            incoming.insert(b, e);
        }
    }
    for (point, into) in incoming {
        if let Some(out) = outgoing.get(&point) {
            if into.cross(*out).atan2(into.dot(*out)).abs() > KINK_ANGLE {
                mesh.points[point as usize].corner = true;
            }
        }
    }
}

/// Sets a handle unless it equals the default third of the edge (to rounding).
fn set_handle_if_not_default(mesh: &mut GradientMesh, from: u32, to: u32, handle: Vec2) {
    let default = mesh.handle(from, to);
    let scale = default.hypot().max(1e-300);
    if (handle - default).hypot() > 1e-9 * scale {
        mesh.set_handle(from, to, handle);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formats::pdf::{Patch, PdfColourSpace, ShadingColour};

    /// A flat patch with corners `(u, v)` = (0, 0), (0, 1), (1, 0), (1, 1) at `at` and RGB
    /// colours `rgb`, the control points bilinear between them.
    fn flat_patch(at: [(f64, f64); 4], rgb: [[f64; 3]; 4]) -> Patch {
        let mut points = [[Point::ZERO; 4]; 4];
        for (i, row) in points.iter_mut().enumerate() {
            for (j, point) in row.iter_mut().enumerate() {
                let (u, v) = (i as f64 / 3.0, j as f64 / 3.0);
                let w = [(1.0 - u) * (1.0 - v), (1.0 - u) * v, u * (1.0 - v), u * v];
                let x = (0..4).map(|k| w[k] * at[k].0).sum();
                let y = (0..4).map(|k| w[k] * at[k].1).sum();
                *point = Point::new(x, y);
            }
        }
        Patch {
            points,
            components: rgb.concat(),
        }
    }

    fn rgb_fill(patches: Vec<Patch>) -> ShadingFill {
        ShadingFill {
            object: "object 1".into(),
            shading_type: 6,
            patches,
            colour: ShadingColour {
                space: PdfColourSpace::Rgb,
                function: None,
            },
            clip: None,
            opacity: 1.0,
            corner_opacity: None,
        }
    }

    const GREY: [f64; 3] = [0.5, 0.5, 0.5];

    #[test]
    fn patches_meeting_only_at_a_corner_get_a_point_each() {
        let square = |x: f64, y: f64| {
            let at = [(x, y), (x, y + 1.0), (x + 1.0, y), (x + 1.0, y + 1.0)];
            flat_patch(at, [GREY; 4])
        };
        let fill = rgb_fill(vec![square(0.0, 0.0), square(1.0, 1.0)]);
        let (mesh, notes) = fill_to_layer(&fill, ColourSpace::Srgb);
        crate::validate(&mesh).unwrap();
        assert_eq!(mesh.faces.len(), 2);
        let corner_points: HashSet<u32> = mesh.faces.iter().flatten().copied().collect();
        assert_eq!(corner_points.len(), 8, "{:?}", mesh.faces);
        assert!(notes.iter().any(|n| n.contains("1 point(s)")), "{notes:?}");
    }

    #[test]
    fn a_side_of_no_length_between_two_colours_makes_a_triangle() {
        // The corners (1, 0) and (1, 1) at one place, red and blue.
        let at = [(0.0, 0.0), (0.0, 1.0), (1.0, 0.5), (1.0, 0.5)];
        let colours = [GREY, GREY, [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        let fill = rgb_fill(vec![flat_patch(at, colours)]);
        let (mesh, notes) = fill_to_layer(&fill, ColourSpace::Srgb);
        crate::validate(&mesh).unwrap();
        assert_eq!(mesh.faces.len(), 1);
        assert_eq!(mesh.faces[0].len(), 3, "{:?}", mesh.faces);
        assert!(
            notes.iter().any(|n| n.contains("side of no length")),
            "{notes:?}"
        );
    }
}
