//! Joining meshes that meet along their sides into one mesh: the pieces of one surface written
//! as separate meshes (gradmesh's SVG export writes a mesh gradient per patch grid) become one
//! mesh with shared control points, so that they refine and draw as one surface without seams.

use std::collections::{BTreeMap, HashMap};

use kurbo::{Point, Vec2};

use crate::mesh::{edge_key, GradientMesh, WedgeOverride};
use crate::union_find::UnionFind;
use crate::validate::validate;

mod t_junctions;

/// How close two sides must be to count as one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JoinTolerance {
    /// The largest distance between matching corners, and between matching handles (as
    /// vectors), in the meshes' units.
    pub position: f64,
    /// The largest difference of any colour channel between matching corners, in the meshes'
    /// colour space.
    pub colour: f64,
    /// The largest difference of opacity between matching corners.
    pub opacity: f64,
}

/// One mesh of [`join_meshes`]: the joined mesh and the indices of the meshes it is made of,
/// in order.
#[derive(Clone, Debug, PartialEq)]
pub struct Joined {
    /// The mesh.
    pub mesh: GradientMesh,
    /// The input meshes it holds, lowest first.
    pub sources: Vec<usize>,
}

/// `meshes` with every set of meshes that meet along sides joined into one mesh.
///
/// Two boundary sides of different meshes meet when they run between the same two places in
/// opposite directions (the faces on both sides wound alike), their handles at both ends are
/// the same, and so are the colours and opacities of their ends, within `tolerance`; their
/// corners then become shared control points. Meshes with different options (colour space,
/// boundary rule, creasing, first step, position interpolation, fine edits) never meet. A
/// joined mesh takes the place of its lowest member, keeps that member's name and options,
/// and carries every member's handles, edge tags, side entries and edits over to the shared
/// numbering. A set whose joined mesh would not be valid (two sides meeting at a place where
/// a third also meets, say) stays apart, as do meshes that meet no other.
///
/// Before sides are compared, a boundary side with another mesh's boundary corner inside it
/// (a T-junction: a coarse patch beside two finer ones) is cut there, when the corner's colour
/// and opacity are the side's own at that place within `tolerance`: the face holding the side
/// gets the corner as one more point, so that the finer sides meet its parts. Meshes that stay
/// apart keep their sides uncut. Where the cuts leave more meshes apart than joining without
/// them (a set made invalid by a folded patch, say), the meshes are joined without cuts.
pub fn join_meshes(meshes: &[GradientMesh], tolerance: JoinTolerance) -> Vec<Joined> {
    let cut = t_junctions::split_sides_at_corners(meshes, tolerance);
    let with_cuts = join_sides(&cut, meshes, tolerance);
    let without = join_sides(meshes, meshes, tolerance);
    if with_cuts.len() <= without.len() {
        with_cuts
    } else {
        without
    }
}

/// [`join_meshes`] of `meshes` (the `originals`, some sides cut): a set that would not be
/// valid joined gives its originals.
fn join_sides(
    meshes: &[GradientMesh],
    originals: &[GradientMesh],
    tolerance: JoinTolerance,
) -> Vec<Joined> {
    let offsets = point_offsets(meshes);
    let mut points = UnionFind::new(*offsets.last().unwrap_or(&0));
    let mut groups = UnionFind::new(meshes.len());
    for (i, a, j, b) in meeting_sides(meshes, tolerance) {
        let (ia, ib) = (offsets[i] + a.0 as usize, offsets[i] + a.1 as usize);
        let (jb, ja) = (offsets[j] + b.0 as usize, offsets[j] + b.1 as usize);
        points.union(ia, ja);
        points.union(ib, jb);
        groups.union(i, j);
    }
    let mut members: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for i in 0..meshes.len() {
        members.entry(groups.find(i)).or_default().push(i);
    }
    let mut out = Vec::new();
    for sources in members.into_values() {
        let joined = (sources.len() > 1)
            .then(|| joined_mesh(meshes, &sources, &offsets, &mut points))
            .filter(|mesh| validate(mesh).is_ok());
        match joined {
            Some(mesh) => out.push(Joined { mesh, sources }),
            None => out.extend(sources.into_iter().map(|i| Joined {
                mesh: originals[i].clone(),
                sources: vec![i],
            })),
        }
    }
    out.sort_by_key(|j| j.sources[0]);
    out
}

/// The index of each mesh's first point in one numbering of all points, and the total last.
fn point_offsets(meshes: &[GradientMesh]) -> Vec<usize> {
    let mut offsets = Vec::with_capacity(meshes.len() + 1);
    let mut total = 0;
    offsets.push(0);
    for mesh in meshes {
        total += mesh.points.len();
        offsets.push(total);
    }
    offsets
}

/// The directed boundary sides of `mesh` (`a` to `b` as the face that holds it winds).
fn boundary_sides(mesh: &GradientMesh) -> Vec<(u32, u32)> {
    let mut uses: HashMap<(u32, u32), usize> = HashMap::new();
    for face in &mesh.faces {
        for k in 0..face.len() {
            *uses
                .entry(edge_key(face[k], face[(k + 1) % face.len()]))
                .or_default() += 1;
        }
    }
    let mut sides = Vec::new();
    for face in &mesh.faces {
        for k in 0..face.len() {
            let (a, b) = (face[k], face[(k + 1) % face.len()]);
            if uses.get(&edge_key(a, b)) == Some(&1) {
                sides.push((a, b));
            }
        }
    }
    sides
}

/// Whether meshes may be joined at all: the same options.
fn same_options(a: &GradientMesh, b: &GradientMesh) -> bool {
    a.colour_space == b.colour_space
        && a.boundary == b.boundary
        && a.creasing == b.creasing
        && a.interpolate_positions == b.interpolate_positions
        && a.first_step == b.first_step
        && a.fine_edits == b.fine_edits
}

/// A side `(a, b)` of mesh `mesh`, as [`meeting_sides`] compares them.
#[derive(Clone, Copy)]
struct Side {
    mesh: usize,
    a: u32,
    b: u32,
}

/// Every pair of sides that meet: `(i, (a, b), j, (c, d))` where side `a -> b` of mesh `i`
/// meets side `c -> d` of mesh `j` (`c` at `b`, `d` at `a`), `i < j`.
#[allow(clippy::type_complexity)]
fn meeting_sides(
    meshes: &[GradientMesh],
    tolerance: JoinTolerance,
) -> Vec<(usize, (u32, u32), usize, (u32, u32))> {
    let cell = (4.0 * tolerance.position).max(f64::MIN_POSITIVE);
    let key = |p: Point| ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64);
    let mut by_start: HashMap<(i64, i64), Vec<Side>> = HashMap::new();
    for (i, mesh) in meshes.iter().enumerate() {
        for (a, b) in boundary_sides(mesh) {
            let at = key(mesh.points[a as usize].position);
            by_start.entry(at).or_default().push(Side { mesh: i, a, b });
        }
    }
    let mut found = Vec::new();
    for (i, mesh) in meshes.iter().enumerate() {
        for (a, b) in boundary_sides(mesh) {
            let (cx, cy) = key(mesh.points[b as usize].position);
            for dx in -1..=1 {
                for dy in -1..=1 {
                    let Some(near) = by_start.get(&(cx + dx, cy + dy)) else {
                        continue;
                    };
                    for other in near.iter().filter(|s| s.mesh > i) {
                        let theirs = &meshes[other.mesh];
                        if same_options(mesh, theirs)
                            && sides_meet((mesh, a, b), (theirs, other.a, other.b), tolerance)
                        {
                            found.push((i, (a, b), other.mesh, (other.a, other.b)));
                        }
                    }
                }
            }
        }
    }
    found
}

/// Whether side `a -> b` of `m` and side `c -> d` of `n` are the same side run the other way:
/// `c` matches `b` and `d` matches `a`, in place, handles, colour and opacity.
fn sides_meet(
    (m, a, b): (&GradientMesh, u32, u32),
    (n, c, d): (&GradientMesh, u32, u32),
    tolerance: JoinTolerance,
) -> bool {
    let close = |p: Point, q: Point| p.distance(q) <= tolerance.position;
    let close_vec = |u: Vec2, v: Vec2| (u - v).hypot() <= tolerance.position;
    let same_paint = |p: u32, q: u32| {
        let (p, q) = (&m.points[p as usize], &n.points[q as usize]);
        (p.opacity - q.opacity).abs() <= tolerance.opacity
            && p.colour
                .iter()
                .zip(&q.colour)
                .all(|(x, y)| (x - y).abs() <= tolerance.colour)
    };
    let at = |mesh: &GradientMesh, p: u32| mesh.points[p as usize].position;
    close(at(m, a), at(n, d))
        && close(at(m, b), at(n, c))
        && close_vec(m.handle(a, b), n.handle(d, c))
        && close_vec(m.handle(b, a), n.handle(c, d))
        && same_paint(a, d)
        && same_paint(b, c)
}

/// The meshes `sources` as one mesh whose points are the sets of `points` (in the numbering of
/// `offsets`): the first point of each set is kept.
fn joined_mesh(
    meshes: &[GradientMesh],
    sources: &[usize],
    offsets: &[usize],
    points: &mut UnionFind,
) -> GradientMesh {
    let first = &meshes[sources[0]];
    let mut out = GradientMesh {
        points: Vec::new(),
        faces: Vec::new(),
        handles: BTreeMap::new(),
        edges: BTreeMap::new(),
        wedges: Vec::new(),
        edits: Vec::new(),
        ..first.clone()
    };
    let mut new_index: HashMap<usize, u32> = HashMap::new();
    for &i in sources {
        let mesh = &meshes[i];
        let mut map = Vec::with_capacity(mesh.points.len());
        for (p, point) in mesh.points.iter().enumerate() {
            let root = points.find(offsets[i] + p);
            let index = *new_index.entry(root).or_insert_with(|| {
                out.points.push(point.clone());
                (out.points.len() - 1) as u32
            });
            out.points[index as usize].corner |= point.corner;
            map.push(index);
        }
        carry_over(&mut out, mesh, &map);
    }
    mark_corners(&mut out);
    out
}

/// Adds the faces, handles, edge tags, side entries and edits of `mesh` to `out`, its point
/// `p` being `map[p]` there.
fn carry_over(out: &mut GradientMesh, mesh: &GradientMesh, map: &[u32]) {
    let face_offset = out.faces.len() as u32;
    let m = |p: u32| map[p as usize];
    out.faces
        .extend(mesh.faces.iter().map(|f| f.iter().map(|&p| m(p)).collect()));
    for (&(from, to), &h) in &mesh.handles {
        out.handles.entry((m(from), m(to))).or_insert(h);
    }
    for (&(a, b), tag) in &mesh.edges {
        out.edges.entry(edge_key(m(a), m(b))).or_insert(*tag);
    }
    out.wedges.extend(mesh.wedges.iter().map(|w| WedgeOverride {
        point: m(w.point),
        face: w.face + face_offset,
        handles: w.handles.iter().map(|(&to, &h)| (m(to), h)).collect(),
        ..w.clone()
    }));
    out.edits.extend(mesh.edits.iter().map(|e| {
        let mut e = e.clone();
        e.address.face += face_offset;
        e.address.point = m(e.address.point);
        e
    }));
}

/// The largest angle, in radians, at which the outline still counts as smooth at a point.
const KINK_ANGLE: f64 = 0.01;

/// Points that joining took off the outline are no longer `corner`s; points on the outline
/// where it turns (by more than [`KINK_ANGLE`]) are.
fn mark_corners(mesh: &mut GradientMesh) {
    let sides = boundary_sides(mesh);
    let mut on_outline = vec![false; mesh.points.len()];
    let mut incoming: HashMap<u32, u32> = HashMap::new();
    for &(a, b) in &sides {
        on_outline[a as usize] = true;
        on_outline[b as usize] = true;
        incoming.insert(b, a);
    }
    let mut turns = Vec::new();
    for &(p, next) in &sides {
        let Some(&previous) = incoming.get(&p) else {
            continue;
        };
        let (back, ahead) = (mesh.handle(p, previous), mesh.handle(p, next));
        let angle = (-back).cross(ahead).atan2((-back).dot(ahead)).abs();
        if back.hypot() > 0.0 && ahead.hypot() > 0.0 && angle > KINK_ANGLE {
            turns.push(p);
        }
    }
    for (p, point) in mesh.points.iter_mut().enumerate() {
        point.corner &= on_outline[p];
    }
    for p in turns {
        mesh.points[p as usize].corner = true;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::ColourSpace;

    const TIGHT: JoinTolerance = JoinTolerance {
        position: 1e-6,
        colour: 1e-6,
        opacity: 1e-6,
    };

    /// A one-patch mesh: the unit square with its top-left corner at `(x, y)`, each corner's
    /// colour given by its place, so that meshes meeting at a place agree on its colour.
    fn square(x: f64, y: f64) -> GradientMesh {
        let mut mesh = GradientMesh::new(ColourSpace::Srgb);
        for (px, py) in [(x, y), (x + 1.0, y), (x + 1.0, y + 1.0), (x, y + 1.0)] {
            mesh.add_point(Point::new(px, py), [px / 4.0, py / 4.0, 0.5]);
        }
        mesh.add_face(vec![0, 1, 2, 3]);
        mesh
    }

    fn place(mesh: &GradientMesh, x: f64, y: f64) -> Option<usize> {
        let at = Point::new(x, y);
        mesh.points
            .iter()
            .position(|p| p.position.distance(at) < 1e-9)
    }

    #[test]
    fn two_squares_sharing_a_side_become_one_mesh() {
        let joined = join_meshes(&[square(0.0, 0.0), square(1.0, 0.0)], TIGHT);
        assert_eq!(joined.len(), 1);
        let mesh = &joined[0].mesh;
        assert_eq!(joined[0].sources, vec![0, 1]);
        assert_eq!((mesh.points.len(), mesh.faces.len()), (6, 2));
        let (top, bottom) = (
            place(mesh, 1.0, 0.0).unwrap(),
            place(mesh, 1.0, 1.0).unwrap(),
        );
        for corner in [top, bottom] {
            let uses = mesh
                .faces
                .iter()
                .filter(|f| f.contains(&(corner as u32)))
                .count();
            assert_eq!(uses, 2, "the shared corner is in both faces");
        }
        validate(mesh).unwrap();
    }

    #[test]
    fn four_squares_around_a_point_share_it_as_an_inner_point() {
        let meshes = [
            square(0.0, 0.0),
            square(1.0, 0.0),
            square(0.0, 1.0),
            square(1.0, 1.0),
        ];
        let joined = join_meshes(&meshes, TIGHT);
        assert_eq!(joined.len(), 1);
        let mesh = &joined[0].mesh;
        assert_eq!((mesh.points.len(), mesh.faces.len()), (9, 4));
        let centre = place(mesh, 1.0, 1.0).unwrap() as u32;
        assert_eq!(mesh.faces.iter().filter(|f| f.contains(&centre)).count(), 4);
        assert!(boundary_sides(mesh)
            .iter()
            .all(|&(a, b)| a != centre && b != centre));
        validate(mesh).unwrap();
    }

    #[test]
    fn sides_with_other_handles_colours_or_places_stay_apart() {
        let mut bent = square(1.0, 0.0);
        bent.set_handle(3, 0, Vec2::new(0.2, -0.3));
        let mut recoloured = square(1.0, 0.0);
        recoloured.points[0].colour[2] = 0.9;
        let mut moved = square(1.0, 0.0);
        moved.points[0].position.x += 1e-3;
        moved.points[3].position.x += 1e-3;
        for other in [bent, recoloured, moved] {
            let joined = join_meshes(&[square(0.0, 0.0), other.clone()], TIGHT);
            assert_eq!(joined.len(), 2);
            assert_eq!(joined[1].mesh, other);
        }
    }

    #[test]
    fn corners_within_the_tolerance_meet() {
        let mut near = square(1.0, 0.0);
        near.points[0].position.x += 1e-3;
        near.points[3].position.y -= 1e-3;
        let loose = JoinTolerance {
            position: 1e-2,
            colour: 1e-6,
            opacity: 1e-6,
        };
        let joined = join_meshes(&[square(0.0, 0.0), near], loose);
        assert_eq!(joined.len(), 1);
        assert_eq!(joined[0].mesh.points.len(), 6);
    }

    #[test]
    fn a_joined_mesh_takes_the_place_of_its_lowest_member() {
        let apart = square(10.0, 10.0);
        let meshes = [square(0.0, 0.0), apart.clone(), square(1.0, 0.0)];
        let joined = join_meshes(&meshes, TIGHT);
        let sources: Vec<_> = joined.iter().map(|j| j.sources.clone()).collect();
        assert_eq!(sources, vec![vec![0, 2], vec![1]]);
        assert_eq!(joined[1].mesh, apart);
    }

    #[test]
    fn sides_run_the_same_way_do_not_meet() {
        let mut flipped = square(1.0, 0.0);
        flipped.faces[0].reverse();
        let joined = join_meshes(&[square(0.0, 0.0), flipped], TIGHT);
        assert_eq!(joined.len(), 2);
    }
}
