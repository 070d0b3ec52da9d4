//! T-junctions between meshes: a boundary corner of one mesh lying inside a boundary side of
//! another, as where gradmesh's SVG export writes a coarse patch beside finer ones (around an
//! irregular point). Splitting the side there gives the finer meshes' sides a side to meet.

use std::collections::HashMap;

use kurbo::{CubicBez, ParamCurve, ParamCurveDeriv, ParamCurveNearest, Point};

use super::{boundary_sides, same_options, JoinTolerance};
use crate::mesh::{edge_key, ControlPoint, GradientMesh};

/// A corner found inside a side: the side is to be split at `t` with a copy of `point`.
struct Split {
    side: (u32, u32),
    t: f64,
    point: ControlPoint,
}

/// `meshes` with each boundary side split where a boundary corner of another mesh (with the
/// same options) lies on it, within `tolerance` of the side's curve and away from its ends,
/// with the colour and opacity the side has there (linear along the side, as a patch's side
/// is painted). The new point takes the corner's place, colour and opacity; the side's handles
/// become those of its parts (the curve is cut, not changed) and its edge tag goes to each
/// part. Meshes with fine edits or per-side entries are left as they are (their addresses name
/// faces by their corners).
pub(super) fn split_sides_at_corners(
    meshes: &[GradientMesh],
    tolerance: JoinTolerance,
) -> Vec<GradientMesh> {
    let corners = CornerGrid::new(meshes, tolerance);
    meshes
        .iter()
        .enumerate()
        .map(|(i, mesh)| {
            if !mesh.edits.is_empty() || !mesh.wedges.is_empty() {
                return mesh.clone();
            }
            // A place goes into one side only (a folded patch can pass it twice).
            let mut splits: Vec<Split> = Vec::new();
            for side in boundary_sides(mesh) {
                for split in corners.on_side(meshes, i, side, tolerance) {
                    let at = split.point.position;
                    if !splits
                        .iter()
                        .any(|s| s.point.position.distance(at) <= tolerance.position)
                    {
                        splits.push(split);
                    }
                }
            }
            if splits.is_empty() {
                mesh.clone()
            } else {
                split_sides(mesh, splits)
            }
        })
        .collect()
}

/// The boundary corners of all meshes in square cells, for finding those near a side.
struct CornerGrid {
    cell: f64,
    cells: HashMap<(i64, i64), Vec<(usize, u32)>>,
}

/// A side whose box spans more cells than this is compared with every corner instead.
const MAX_CELLS_PER_SIDE: i64 = 256;

impl CornerGrid {
    fn new(meshes: &[GradientMesh], tolerance: JoinTolerance) -> CornerGrid {
        let mut chords: Vec<f64> = Vec::new();
        for mesh in meshes {
            for (a, b) in boundary_sides(mesh) {
                let (p, q) = (
                    mesh.points[a as usize].position,
                    mesh.points[b as usize].position,
                );
                chords.push(p.distance(q));
            }
        }
        chords.sort_by(f64::total_cmp);
        let median = chords.get(chords.len() / 2).copied().unwrap_or(1.0);
        let cell = median.max(4.0 * tolerance.position).max(f64::MIN_POSITIVE);
        let mut grid = CornerGrid {
            cell,
            cells: HashMap::new(),
        };
        for (j, mesh) in meshes.iter().enumerate() {
            for (a, _) in boundary_sides(mesh) {
                let at = grid.key(mesh.points[a as usize].position);
                grid.cells.entry(at).or_default().push((j, a));
            }
        }
        grid
    }

    fn key(&self, p: Point) -> (i64, i64) {
        (
            (p.x / self.cell).floor() as i64,
            (p.y / self.cell).floor() as i64,
        )
    }

    /// The corners of meshes other than `i` that lie inside side `(a, b)` of mesh `i`.
    fn on_side(
        &self,
        meshes: &[GradientMesh],
        i: usize,
        (a, b): (u32, u32),
        tolerance: JoinTolerance,
    ) -> Vec<Split> {
        let mesh = &meshes[i];
        let curve = side_curve(mesh, a, b);
        let rect = curve.p0.to_vec2();
        let (mut lo, mut hi) = (rect.to_point(), rect.to_point());
        for p in [curve.p1, curve.p2, curve.p3] {
            lo = Point::new(lo.x.min(p.x), lo.y.min(p.y));
            hi = Point::new(hi.x.max(p.x), hi.y.max(p.y));
        }
        let margin = tolerance.position;
        let (k0, k1) = (
            self.key(Point::new(lo.x - margin, lo.y - margin)),
            self.key(Point::new(hi.x + margin, hi.y + margin)),
        );
        let mut found = Vec::new();
        let mut look = |&(j, c): &(usize, u32)| {
            let corner = &meshes[j].points[c as usize];
            let at = corner.position;
            let in_box = at.x >= lo.x - margin
                && at.x <= hi.x + margin
                && at.y >= lo.y - margin
                && at.y <= hi.y + margin;
            if in_box && j != i && same_options(mesh, &meshes[j]) {
                if let Some(t) = inside(&curve, corner.position, tolerance.position) {
                    let seen = |s: &Split| s.point.position.distance(at) <= tolerance.position;
                    if paint_matches(mesh, (a, b), t, corner, tolerance) && !found.iter().any(seen)
                    {
                        found.push(Split {
                            side: (a, b),
                            t,
                            point: ControlPoint {
                                corner: false,
                                ..corner.clone()
                            },
                        });
                    }
                }
            }
        };
        if (k1.0 - k0.0 + 1) * (k1.1 - k0.1 + 1) > MAX_CELLS_PER_SIDE {
            self.cells.values().flatten().for_each(&mut look);
        } else {
            for x in k0.0..=k1.0 {
                for y in k0.1..=k1.1 {
                    self.cells
                        .get(&(x, y))
                        .into_iter()
                        .flatten()
                        .for_each(&mut look);
                }
            }
        }
        found
    }
}

/// The cubic of side `a -> b` of `mesh`.
fn side_curve(mesh: &GradientMesh, a: u32, b: u32) -> CubicBez {
    let (p, q) = (
        mesh.points[a as usize].position,
        mesh.points[b as usize].position,
    );
    CubicBez::new(p, p + mesh.handle(a, b), q + mesh.handle(b, a), q)
}

/// The parameter of the point of `curve` nearest `p`, if `p` is within `tolerance` of it and
/// farther than that from both ends.
fn inside(curve: &CubicBez, p: Point, tolerance: f64) -> Option<f64> {
    // A side whose ends meet (a folded or collapsed patch) is not cut.
    if curve.p0.distance(curve.p3) <= tolerance
        || p.distance(curve.p0) <= tolerance
        || p.distance(curve.p3) <= tolerance
    {
        return None;
    }
    let rough = curve.nearest(p, 0.25 * tolerance);
    if rough.distance_sq.sqrt() > 2.0 * tolerance {
        return None;
    }
    let t = refine_nearest(curve, p, rough.t);
    (curve.eval(t).distance(p) <= tolerance && t > 0.0 && t < 1.0).then_some(t)
}

/// `t` moved by Newton's method towards the parameter where `curve` comes nearest `p` (where
/// the curve's tangent is square to the line to `p`), kept in 0..1.
fn refine_nearest(curve: &CubicBez, p: Point, mut t: f64) -> f64 {
    let (d1, d2) = (curve.deriv(), curve.deriv().deriv());
    for _ in 0..4 {
        let off = curve.eval(t) - p;
        let (v, a) = (d1.eval(t).to_vec2(), d2.eval(t).to_vec2());
        let slope = v.dot(v) + off.dot(a);
        if slope.abs() < 1e-300 {
            break;
        }
        t = (t - off.dot(v) / slope).clamp(0.0, 1.0);
    }
    t
}

/// Whether `corner`'s colour and opacity are those of side `(a, b)` of `mesh` at `t` (linear
/// between its ends), within `tolerance`.
fn paint_matches(
    mesh: &GradientMesh,
    (a, b): (u32, u32),
    t: f64,
    corner: &ControlPoint,
    tolerance: JoinTolerance,
) -> bool {
    let (p, q) = (&mesh.points[a as usize], &mesh.points[b as usize]);
    let lerp = |x: f64, y: f64| x + t * (y - x);
    (lerp(p.opacity, q.opacity) - corner.opacity).abs() <= tolerance.opacity
        && (0..3)
            .all(|k| (lerp(p.colour[k], q.colour[k]) - corner.colour[k]).abs() <= tolerance.colour)
}

/// `mesh` with its sides split at `splits`: each new point goes into the face holding its side,
/// in order along the side.
fn split_sides(mesh: &GradientMesh, mut splits: Vec<Split>) -> GradientMesh {
    let mut out = mesh.clone();
    splits.sort_by(|x, y| x.side.cmp(&y.side).then(x.t.total_cmp(&y.t)));
    let mut start = 0;
    while start < splits.len() {
        let side = splits[start].side;
        let end = start
            + splits[start..]
                .iter()
                .take_while(|s| s.side == side)
                .count();
        split_side(&mut out, mesh, &splits[start..end]);
        start = end;
    }
    out
}

/// Splits side `(a, b)` of `out` (as it is in `mesh`) at the increasing parameters of `splits`.
fn split_side(out: &mut GradientMesh, mesh: &GradientMesh, splits: &[Split]) {
    let (a, b) = splits[0].side;
    let curve = side_curve(mesh, a, b);
    let mut chain = vec![a];
    for split in splits {
        out.points.push(split.point.clone());
        chain.push((out.points.len() - 1) as u32);
    }
    chain.push(b);
    let ts: Vec<f64> = std::iter::once(0.0)
        .chain(splits.iter().map(|s| s.t))
        .chain(std::iter::once(1.0))
        .collect();
    out.handles.remove(&(a, b));
    out.handles.remove(&(b, a));
    let tag = out.edges.remove(&edge_key(a, b));
    for k in 0..chain.len() - 1 {
        let part = curve.subsegment(ts[k]..ts[k + 1]);
        let (from, to) = (chain[k], chain[k + 1]);
        // The part's ends are the points themselves: the handles are relative to them.
        let (p, q) = (
            out.points[from as usize].position,
            out.points[to as usize].position,
        );
        out.set_handle(from, to, part.p1 - p);
        out.set_handle(to, from, part.p2 - q);
        if let Some(tag) = tag {
            out.edges.insert(edge_key(from, to), tag);
        }
    }
    let inner = &chain[1..chain.len() - 1];
    for face in &mut out.faces {
        if let Some(k) = (0..face.len()).find(|&k| face[k] == a && face[(k + 1) % face.len()] == b)
        {
            for (n, &p) in inner.iter().enumerate() {
                face.insert(k + 1 + n, p);
            }
            break;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{join_meshes, JoinTolerance};
    use crate::colour::ColourSpace;
    use crate::mesh::GradientMesh;
    use crate::validate::validate;
    use kurbo::Point;

    const TIGHT: JoinTolerance = JoinTolerance {
        position: 1e-6,
        colour: 1e-6,
        opacity: 1e-6,
    };

    /// A one-patch mesh over the rectangle `(x, y, w, h)`, each corner's colour linear in its
    /// place (so that a side's colour at any place is the colour of that place).
    fn rect(x: f64, y: f64, w: f64, h: f64) -> GradientMesh {
        let mut mesh = GradientMesh::new(ColourSpace::Srgb);
        for (px, py) in [(x, y), (x + w, y), (x + w, y + h), (x, y + h)] {
            mesh.add_point(Point::new(px, py), [px / 4.0, py / 4.0, 0.5]);
        }
        mesh.add_face(vec![0, 1, 2, 3]);
        mesh
    }

    /// A 2 x 2 square beside two unit squares stacked: the corner between the small squares
    /// lies inside the big square's right side. The side is cut there and the three join into
    /// one mesh, the big face a pentagon.
    #[test]
    fn a_corner_inside_a_side_cuts_it_and_the_meshes_join() {
        let meshes = [
            rect(0.0, 0.0, 2.0, 2.0),
            rect(2.0, 0.0, 1.0, 1.0),
            rect(2.0, 1.0, 1.0, 1.0),
        ];
        let joined = join_meshes(&meshes, TIGHT);
        assert_eq!(joined.len(), 1, "one mesh");
        let mesh = &joined[0].mesh;
        validate(mesh).unwrap();
        assert_eq!(mesh.points.len(), 8);
        let mut sides: Vec<usize> = mesh.faces.iter().map(|f| f.len()).collect();
        sides.sort();
        assert_eq!(sides, [4, 4, 5]);
        // The cut side's parts keep the straight line: handles a third of each part.
        let t = mesh
            .points
            .iter()
            .position(|p| p.position.distance(Point::new(2.0, 1.0)) < 1e-9)
            .unwrap() as u32;
        let top = mesh
            .points
            .iter()
            .position(|p| p.position.distance(Point::new(2.0, 0.0)) < 1e-9)
            .unwrap() as u32;
        let h = mesh.handle(t, top);
        assert!(
            (h.x).abs() < 1e-9 && (h.y + 1.0 / 3.0).abs() < 1e-9,
            "{h:?}"
        );
    }

    /// A corner whose colour is not the side's there leaves the side whole: the small squares
    /// join each other, the big one stays apart.
    #[test]
    fn a_corner_of_another_colour_does_not_cut() {
        let (mut upper, mut lower) = (rect(2.0, 0.0, 1.0, 1.0), rect(2.0, 1.0, 1.0, 1.0));
        upper.points[3].colour = [0.9, 0.1, 0.1];
        lower.points[0].colour = [0.9, 0.1, 0.1];
        let meshes = [rect(0.0, 0.0, 2.0, 2.0), upper, lower];
        let joined = join_meshes(&meshes, TIGHT);
        assert_eq!(joined.len(), 2);
        assert_eq!(joined[0].mesh, meshes[0], "the big square stays whole");
        assert_eq!(joined[1].sources, [1, 2]);
    }
}
