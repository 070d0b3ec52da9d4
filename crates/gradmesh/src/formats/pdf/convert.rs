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
/// way as its neighbour, or give a side a third face, keeps points of its own. A patch with
/// fewer than three distinct corners is left out. Where the outline turns, the point is a
/// `corner`. The interior points of a tensor-product patch are not carried (the scheme has no
/// such control).
pub fn fill_to_layer(fill: &ShadingFill, space: ColourSpace) -> (GradientMesh, Vec<String>) {
    let mut notes = Vec::new();
    let mut mesh = GradientMesh::new(space);
    mesh.name = Some(fill.object.clone());
    let bounds = fill.control_bounds();
    let tolerance = POINT_TOLERANCE * bounds.width().max(bounds.height()).max(1.0);
    let key = |p: Point| {
        (
            (p.x / tolerance).floor() as i64,
            (p.y / tolerance).floor() as i64,
        )
    };
    let mut at: HashMap<(i64, i64), Vec<u32>> = HashMap::new();
    let mut directed: HashSet<(u32, u32)> = HashSet::new();
    let mut undirected: HashMap<(u32, u32), u32> = HashMap::new();
    let mut sides: Vec<((u32, u32), [Point; 4])> = Vec::new();
    let mut interior_dropped = false;
    let n = fill.colour.corner_components();
    for (index, patch) in fill.patches.iter().enumerate() {
        let colour_at = |corner: usize| {
            let rgb = fill
                .colour
                .to_srgb(&patch.components[corner * n..corner * n + n]);
            ColourSpace::Srgb.convert(space, rgb)
        };
        // Around the patch: (0, 0), (0, 1), (1, 1), (1, 0), with the sides between them.
        let p = &patch.points;
        let opacity_at = |u: f64, v: f64| fill.opacity_at(index, u, v);
        let mut corners = [
            (p[0][0], colour_at(0), opacity_at(0.0, 0.0)),
            (p[0][3], colour_at(1), opacity_at(0.0, 1.0)),
            (p[3][3], colour_at(3), opacity_at(1.0, 1.0)),
            (p[3][0], colour_at(2), opacity_at(1.0, 0.0)),
        ];
        let mut curves = patch.sides().to_vec();
        if patch.corner_area() < 0.0 {
            corners.reverse();
            curves.reverse();
            for c in &mut curves {
                c.reverse();
            }
            // Reversed, the sides run from corner k + 1 to k: shift them back in step.
            curves.rotate_left(1);
        }
        if fill.shading_type == 7 {
            let mut coons = *p;
            coons_interior(&mut coons);
            interior_dropped |= (1..3)
                .flat_map(|i| (1..3).map(move |j| (i, j)))
                .any(|(i, j)| coons[i][j].distance(p[i][j]) > tolerance * 1e3);
        }
        let mut shared =
            |position: Point, colour: [f64; 3], opacity: f64, mesh: &mut GradientMesh| {
                let (kx, ky) = key(position);
                let same = |q: u32| {
                    let point = &mesh.points[q as usize];
                    point.position.distance(position) <= tolerance
                        && (0..3).all(|k| (point.colour[k] - colour[k]).abs() <= COLOUR_TOLERANCE)
                        && (point.opacity - opacity).abs() <= COLOUR_TOLERANCE
                };
                let found = (kx - 1..=kx + 1)
                    .flat_map(|x| (ky - 1..=ky + 1).map(move |y| (x, y)))
                    .find_map(|cell| {
                        at.get(&cell)
                            .and_then(|list| list.iter().copied().find(|&q| same(q)))
                    });
                found.unwrap_or_else(|| {
                    new_point(mesh, &mut at, key(position), position, colour, opacity)
                })
            };
        let mut face: Vec<u32> = corners
            .iter()
            .map(|&(q, c, o)| shared(q, c, o, &mut mesh))
            .collect();
        let clashes = (0..face.len()).any(|k| {
            let (a, b) = (face[k], face[(k + 1) % face.len()]);
            a != b
                && (directed.contains(&(a, b))
                    || undirected.get(&edge_key(a, b)).is_some_and(|&c| c >= 2))
        });
        if clashes {
            face = corners
                .iter()
                .map(|&(q, c, o)| new_point(&mut mesh, &mut at, key(q), q, c, o))
                .collect();
        }
        let kept = without_empty_sides(&face, &curves);
        if kept.len() < 3 {
            notes.push(format!(
                "patch {index} has no area (fewer than three distinct corners): left out"
            ));
            continue;
        }
        let face: Vec<u32> = kept.iter().map(|k| k.0).collect();
        for k in 0..face.len() {
            let (a, b) = (face[k], face[(k + 1) % face.len()]);
            directed.insert((a, b));
            *undirected.entry(edge_key(a, b)).or_default() += 1;
            sides.push(((a, b), kept[k].1));
        }
        mesh.faces.push(face);
    }
    if interior_dropped {
        notes.push("the interior points of the tensor-product patches are not carried into the scheme: its faces take the Coons interior of their sides".into());
    }
    for &((a, b), curve) in &sides {
        if curve[3] != mesh.points[b as usize].position {
            continue;
        }
        set_handle_if_not_default(&mut mesh, a, b, curve[1] - curve[0]);
        set_handle_if_not_default(&mut mesh, b, a, curve[2] - curve[3]);
    }
    mark_kinks(&mut mesh, &sides, &undirected);
    (mesh, notes)
}

/// The corners of a face with the side that leaves each, corners joined by a side of no
/// length taken once (with the side that leaves the last of them).
fn without_empty_sides(face: &[u32], curves: &[[Point; 4]]) -> Vec<(u32, [Point; 4])> {
    let mut kept: Vec<(u32, [Point; 4])> = Vec::new();
    for k in 0..4 {
        if kept.last().map(|l| l.0) != Some(face[k]) {
            kept.push((face[k], curves[k]));
        } else if let Some(last) = kept.last_mut() {
            // A side of no length: the next side starts here.
            last.1 = curves[k];
        }
    }
    while kept.len() > 1 && kept.first().map(|f| f.0) == kept.last().map(|l| l.0) {
        kept.pop();
    }
    kept
}

fn new_point(
    mesh: &mut GradientMesh,
    at: &mut HashMap<(i64, i64), Vec<u32>>,
    key: (i64, i64),
    position: Point,
    colour: [f64; 3],
    opacity: f64,
) -> u32 {
    let mut point = ControlPoint::new(position, colour);
    point.opacity = opacity;
    mesh.points.push(point);
    let index = (mesh.points.len() - 1) as u32;
    at.entry(key).or_default().push(index);
    index
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
