//! The paper's alternative first refinement (section 4.5): two linear binary splits instead of
//! one ternary split, giving a pure quadrilateral level 1 in which every control point is
//! again surrounded by a ring of points of its own colour.
//!
//! A face with `n` corners becomes `4 n` quads. Along each base edge `V -> W` lie five points:
//! `V`, the quarter point `Q_V`, the midpoint `M`, `Q_W` and `W`; inside each face, one ring
//! face point `F` per corner, one inner point `N` per side (between `M` and the face centre)
//! and the face centre `C`. `Q_V` and the `F` at `V`'s corners form `V`'s 1-ring: they take
//! `V`'s colour, and the positions of the ternary step's ring drawn towards `V` (to 5/6 of the
//! handles). Every other point takes the average colour of the control points it lies between
//! and a position from the ternary step's points, so that the result looks like the ternary
//! step's (see [`binary_data`] and `docs/binary-step.md`).
//!
//! ("Quarter point" names its place in a binary split; with the default handles it lies at
//! 5/18 of the edge, see [`HANDLE_SCALE`].) Level-1 vertices are numbered so that the first
//! `nv + 2 ne + nc` have the same meaning as in the ternary step ([`edge_point`],
//! [`face_point`]):
//!
//! | vertices | index |
//! |---|---|
//! | vertex point of base vertex `v` | `v` |
//! | quarter point of base edge `e` near its end `k` | `nv + 2 e + k` |
//! | ring face point at base corner `c` | `nv + 2 ne + c` |
//! | midpoint of base edge `e` | `nv + 2 ne + nc + e` |
//! | centre of base face `f` | `nv + 2 ne + nc + ne + f` |
//! | inner point of the side leaving base corner `c` | `nv + 2 ne + nc + ne + nf + c` |
//!
//! Level-1 face `4 c + j` lies at base corner `c` (at `V`, in face `f`, with outgoing edge
//! `out` and incoming edge `inc`): `j = 0` is `[V, Q(out), F(c), Q(inc)]` (`V`'s ring),
//! `j = 1` is `[M(out), N(c), F(c), Q(out)]`, `j = 2` is `[C(f), N(prev c), F(c), N(c)]` and
//! `j = 3` is `[M(inc), Q(inc), F(c), N(prev c)]`. Level-1 edges `4 e .. 4 e + 4` run along
//! base edge `e` from its end 0 to its end 1; the other edges lie inside base faces.

use kurbo::{Point, Vec2};

use crate::level::Level;
use crate::ternary_step::{edge_point, face_point, face_point_position};
use crate::topology::Topology;
use crate::validate::{BaseMesh, VertexData};

/// The ring of a control point lies at this fraction of the ternary step's ring: the quarter
/// point at `V + 5/6 D`, the ring face points by the ternary face-point rule with the handles
/// scaled by 5/6.
///
/// With 5/6, the steepest colour gradient along an edge (at its midpoint) equals the ternary
/// step's for every handle length (symmetric handles), and the colours across the mesh come
/// closest to the ternary step's; 3/4 would split a grid uniformly but leave colours four to
/// six times further from the ternary step's (`docs/binary-step.md`).
pub const HANDLE_SCALE: f64 = 5.0 / 6.0;

/// Index of the midpoint of base edge `e`.
pub fn edge_midpoint(base: &Topology, e: u32) -> u32 {
    (base.vertex_count() + 2 * base.edge_count() + base.corner_count() + e as usize) as u32
}

/// Index of the centre of base face `f`.
pub fn face_centre(base: &Topology, f: usize) -> u32 {
    (base.vertex_count() + 3 * base.edge_count() + base.corner_count() + f) as u32
}

/// Index of the inner point on the side that leaves flat base corner `corner`: the point
/// between the midpoint of the corner's outgoing edge and the face centre.
pub fn inner_point(base: &Topology, corner: usize) -> u32 {
    (base.vertex_count() + 3 * base.edge_count() + base.face_count() + base.corner_count() + corner)
        as u32
}

/// Number of level-1 vertices.
fn level1_vertex_count(t: &Topology) -> usize {
    t.vertex_count() + 3 * t.edge_count() + t.face_count() + 2 * t.corner_count()
}

/// Index of the first of the four level-1 faces at flat base corner `corner` (see the module
/// documentation for their order).
pub fn first_child_face(corner: usize) -> usize {
    4 * corner
}

/// The topology of the two binary splits of `t`, numbered as in the module documentation:
/// [`Topology::subdivide`] twice, with the vertices renumbered (faces and edges keep the
/// numbering of the second split, so edges `4 e .. 4 e + 4` run along base edge `e` from its
/// end 0 to its end 1).
pub fn binary_topology(t: &Topology) -> Topology {
    let (nv, ne, nf, nc) = (
        t.vertex_count(),
        t.edge_count(),
        t.face_count(),
        t.corner_count(),
    );
    let once = t.subdivide();
    let twice = once.subdivide();
    // `Topology::subdivide` numbers face points, then edge points, then vertex points. `once`
    // has a face per base corner, and edges `2 e + k` (the half of base edge `e` at its end
    // `k`) then `2 ne + c` (from the midpoint of the edge leaving corner `c` to the centre).
    let ne1 = once.edge_count();
    let new_index = |x: usize| -> u32 {
        if x < nc {
            face_point(t, x)
        } else if x < nc + ne1 {
            let j = x - nc;
            if j < 2 * ne {
                (nv + j) as u32
            } else {
                inner_point(t, j - 2 * ne)
            }
        } else {
            let u = x - nc - ne1;
            if u < nf {
                face_centre(t, u)
            } else if u < nf + ne {
                edge_midpoint(t, (u - nf) as u32)
            } else {
                (u - nf - ne) as u32
            }
        }
    };
    let count = twice.vertex_count();
    let renumber: Vec<u32> = (0..count).map(new_index).collect();
    let mut old_index = vec![0u32; count];
    for (x, &u) in renumber.iter().enumerate() {
        old_index[u as usize] = x as u32;
    }

    let faces = twice.face_count();
    let mut face_offsets = Vec::with_capacity(faces + 1);
    let mut face_verts = Vec::with_capacity(twice.corner_count());
    let mut face_edges = Vec::with_capacity(twice.corner_count());
    for f in 0..faces {
        face_offsets.push(face_verts.len() as u32);
        face_verts.extend(twice.face_vertices(f).iter().map(|&x| renumber[x as usize]));
        face_edges.extend_from_slice(twice.face_edges(f));
    }
    face_offsets.push(face_verts.len() as u32);
    let edges = twice.edge_count();
    let edge_verts = (0..edges)
        .map(|e| twice.edge_vertices(e).map(|x| renumber[x as usize]))
        .collect();
    let edge_faces = (0..edges).map(|e| twice.edge_faces(e)).collect();
    let mut ring_offsets = Vec::with_capacity(count + 1);
    let mut ring_faces = Vec::with_capacity(twice.corner_count());
    let mut ring_corners = Vec::with_capacity(twice.corner_count());
    let mut edge_ring_offsets = Vec::with_capacity(count + 1);
    let mut ring_edges = Vec::with_capacity(twice.corner_count() + count);
    ring_offsets.push(0);
    edge_ring_offsets.push(0);
    for &x in &old_index {
        ring_faces.extend_from_slice(twice.vertex_faces(x as usize));
        ring_corners.extend_from_slice(twice.vertex_face_corners(x as usize));
        ring_edges.extend_from_slice(twice.vertex_edges(x as usize));
        ring_offsets.push(ring_faces.len() as u32);
        edge_ring_offsets.push(ring_edges.len() as u32);
    }
    Topology {
        vertex_count: count,
        face_offsets,
        face_verts,
        face_edges,
        edge_verts,
        edge_faces,
        ring_offsets,
        ring_faces,
        ring_corners,
        edge_ring_offsets,
        ring_edges,
    }
    .debug_checked()
}

/// The level-1 topology and sharpness of `base`: [`binary_topology`], with the four level-1
/// edges along each base edge carrying its sharpness and the vertex point of each base vertex
/// its sharpness; the boundary rules applied by [`Level::new`].
pub fn binary_level(base: &BaseMesh) -> Level {
    let t = &base.topology;
    let topology = binary_topology(t);
    let mut edge_sharpness = vec![0.0; topology.edge_count()];
    for (e, &s) in base.edge_sharpness.iter().enumerate() {
        edge_sharpness[4 * e..4 * e + 4].fill(s);
    }
    let mut vertex_sharpness = vec![0.0; topology.vertex_count()];
    vertex_sharpness[..t.vertex_count()].copy_from_slice(&base.vertex_sharpness);
    Level::new(
        topology,
        edge_sharpness,
        vertex_sharpness,
        base.creasing,
        base.boundary,
    )
}

/// The average of the data of some base vertices, at `position`: the colour and opacity of a
/// point that is not in any control point's ring.
fn blend(base: &BaseMesh, vertices: &[u32], position: Point) -> VertexData {
    let mut d = VertexData::ZERO;
    for &v in vertices {
        d += base.data[v as usize];
    }
    let n = vertices.len() as f64;
    d = d.map(|s| s / n);
    d.position = [position.x, position.y];
    d
}

/// The base vertices whose mean colour and opacity each level-1 vertex takes (colours do not
/// depend on positions or handles): a control point's ring its own vertex, an edge's midpoint
/// its two ends, an inner point the two ends of its side, a face centre the face's corners.
/// Numbered as the level-1 vertices.
pub fn colour_sources(t: &Topology) -> Vec<Vec<u32>> {
    let mut sources = vec![Vec::new(); level1_vertex_count(t)];
    for v in 0..t.vertex_count() as u32 {
        sources[v as usize] = vec![v];
    }
    for e in 0..t.edge_count() as u32 {
        let ends = t.edge_vertices(e as usize);
        for (end, &v) in ends.iter().enumerate() {
            sources[edge_point(t, e, end) as usize] = vec![v];
        }
        sources[edge_midpoint(t, e) as usize] = ends.to_vec();
    }
    for f in 0..t.face_count() {
        let (fv, o) = (t.face_vertices(f), t.face_offset(f));
        for (i, &v) in fv.iter().enumerate() {
            sources[face_point(t, o + i) as usize] = vec![v];
            sources[inner_point(t, o + i) as usize] = vec![v, fv[(i + 1) % fv.len()]];
        }
        sources[face_centre(t, f) as usize] = fv.to_vec();
    }
    sources
}

/// The level-1 data of `base` (derivation in `docs/binary-step.md`).
///
/// * The ring of each control point `V` (its quarter points and ring face points) has `V`'s
///   colour and opacity. Positions: the ternary step's edge and face points drawn towards `V`
///   by [`HANDLE_SCALE`]: `Q = V + 5/6 D`, and `F` by [`face_point_position`] with the handles
///   scaled by 5/6.
/// * The midpoint of an edge `V W` is the midpoint of the ternary edge points, `(V + D_V + W +
///   D_W) / 2`, with the average colour of `V` and `W`.
/// * The inner point of a side is the side's midpoint moved into the face by the average of
///   the steps from its two quarter points to their ring face points, with the average colour
///   of the side's ends.
/// * The face centre is the centroid of the ternary face points (the centre of the ternary
///   step's central polygon), with the average colour of the face's corners.
pub fn binary_data(base: &BaseMesh) -> Vec<VertexData> {
    let t = &base.topology;
    let mut out = vec![VertexData::ZERO; level1_vertex_count(t)];
    let pos = |v: u32| {
        let d = &base.data[v as usize];
        d.point()
    };
    let with_position = |v: u32, p: Point| {
        let mut d = base.data[v as usize];
        d.position[0] = p.x;
        d.position[1] = p.y;
        d
    };
    let at = |out: &[VertexData], i: u32| out[i as usize].point();
    out[..t.vertex_count()].copy_from_slice(&base.data);
    for e in 0..t.edge_count() {
        let ends = t.edge_vertices(e);
        let h = base.edge_handles[e];
        for (end, &v) in ends.iter().enumerate() {
            let q = pos(v) + h[end] * HANDLE_SCALE;
            out[edge_point(t, e as u32, end) as usize] = with_position(v, q);
        }
        let m = (pos(ends[0]) + h[0]).midpoint(pos(ends[1]) + h[1]);
        out[edge_midpoint(t, e as u32) as usize] = blend(base, &ends, m);
    }
    let end_of = |e: u32, v: u32| usize::from(t.edge_vertices(e as usize)[0] != v);
    let handle = |e: u32, v: u32| base.edge_handles[e as usize][end_of(e, v)];
    for f in 0..t.face_count() {
        let fv = t.face_vertices(f);
        let fe = t.face_edges(f);
        let o = t.face_offset(f);
        let n = fv.len();
        let centroid = fv.iter().fold(Vec2::ZERO, |acc, &v| acc + pos(v).to_vec2()) / n as f64;
        let c = centroid.to_point();
        let mut ternary_centre = Vec2::ZERO;
        for i in 0..n {
            let (next, prev) = ((i + 1) % n, (i + n - 1) % n);
            let (v0, v1, v2) = (pos(fv[i]), pos(fv[next]), pos(fv[prev]));
            let (d1, d2) = (handle(fe[i], fv[i]), handle(fe[prev], fv[i]));
            let p = face_point_position(v0, v1, v2, d1 * HANDLE_SCALE, d2 * HANDLE_SCALE, c);
            out[face_point(t, o + i) as usize] = with_position(fv[i], p);
            ternary_centre += face_point_position(v0, v1, v2, d1, d2, c).to_vec2();
        }
        for i in 0..n {
            let next = (i + 1) % n;
            let e = fe[i];
            let step = |corner: usize, v: u32| {
                at(&out, face_point(t, o + corner)) - at(&out, edge_point(t, e, end_of(e, v)))
            };
            let inward = (step(i, fv[i]) + step(next, fv[next])) * 0.5;
            let p = at(&out, edge_midpoint(t, e)) + inward;
            out[inner_point(t, o + i) as usize] = blend(base, &[fv[i], fv[next]], p);
        }
        let centre = (ternary_centre / n as f64).to_point();
        out[face_centre(t, f) as usize] = blend(base, fv, centre);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ColourSpace, GradientMesh};

    /// A square of side 4 and a triangle on its right, with default handles.
    fn square_and_triangle() -> BaseMesh {
        let mut mesh = GradientMesh::new(ColourSpace::Lab);
        for (x, y) in [(0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (0.0, 4.0), (7.0, 2.0)] {
            mesh.add_point(Point::new(x, y), [x * 10.0, y * 10.0, 5.0]);
        }
        mesh.add_face([0, 1, 2, 3]);
        mesh.add_face([1, 4, 2]);
        BaseMesh::new(&mesh).unwrap().0
    }

    /// Level 1's colours and opacities are the means of the colours of [`colour_sources`].
    #[test]
    fn colours_are_the_means_of_their_sources() {
        let mut base = square_and_triangle();
        for (v, d) in base.data.iter_mut().enumerate() {
            d.opacity = 0.2 + 0.15 * v as f64;
        }
        let data = binary_data(&base);
        let sources = colour_sources(&base.topology);
        assert_eq!(sources.len(), data.len());
        for (d, src) in data.iter().zip(&sources) {
            for c in 2..6 {
                let mean = src
                    .iter()
                    .map(|&s| base.data[s as usize].to_array()[c])
                    .sum::<f64>()
                    / src.len() as f64;
                assert!((d.to_array()[c] - mean).abs() < 1e-12, "{d:?} from {src:?}");
            }
        }
    }

    #[test]
    fn faces_are_laid_out_as_documented() {
        let base = square_and_triangle();
        let t = &base.topology;
        let level = binary_level(&base);
        assert_eq!(level.topology.face_count(), 4 * t.corner_count());
        let end = |e: u32, v: u32| usize::from(t.edge_vertices(e as usize)[0] != v);
        for f in 0..t.face_count() {
            let (fv, fe, o) = (t.face_vertices(f), t.face_edges(f), t.face_offset(f));
            let n = fv.len();
            for i in 0..n {
                let (c, prev) = (o + i, (i + n - 1) % n);
                let (out, inc) = (fe[i], fe[prev]);
                let q_out = edge_point(t, out, end(out, fv[i]));
                let q_inc = edge_point(t, inc, end(inc, fv[i]));
                let fp = face_point(t, c);
                let expect = [
                    [fv[i], q_out, fp, q_inc],
                    [edge_midpoint(t, out), inner_point(t, c), fp, q_out],
                    [
                        face_centre(t, f),
                        inner_point(t, o + prev),
                        fp,
                        inner_point(t, c),
                    ],
                    [edge_midpoint(t, inc), q_inc, fp, inner_point(t, o + prev)],
                ];
                for (j, e) in expect.iter().enumerate() {
                    let got = level.topology.face_vertices(first_child_face(c) + j);
                    assert_eq!(got, e, "corner {c} quad {j}");
                }
            }
        }
    }

    /// Default handles on a square: level 1 is the tensor grid of the edge's five points
    /// `0, 5/18, 1/2, 13/18, 1` (the ternary step's thirds drawn to 5/6 of the handles).
    #[test]
    fn default_handles_split_a_square_regularly() {
        let base = square_and_triangle();
        let t = &base.topology;
        let d = binary_data(&base);
        let at = |i: u32| Point::new(d[i as usize].position[0], d[i as usize].position[1]);
        let close = |i: u32, x: f64, y: f64| {
            let p = at(i);
            assert!(
                (p - Point::new(x, y)).hypot() < 1e-12,
                "{i}: {p:?} vs ({x}, {y})"
            );
        };
        let (a, b) = (4.0 * 5.0 / 18.0, 4.0 * 13.0 / 18.0);
        // Square 0: corners 0..4 are the flat corners 0..4 of face 0.
        for (c, (x, y)) in [(a, a), (b, a), (b, b), (a, b)].into_iter().enumerate() {
            close(face_point(t, c), x, y);
        }
        for (c, (x, y)) in [(2.0, a), (b, 2.0), (2.0, b), (a, 2.0)]
            .into_iter()
            .enumerate()
        {
            close(inner_point(t, c), x, y);
        }
        close(face_centre(t, 0), 2.0, 2.0);
        for e in 0..t.edge_count() as u32 {
            let [a, b] = t.edge_vertices(e as usize).map(at);
            close(edge_midpoint(t, e), 0.5 * (a.x + b.x), 0.5 * (a.y + b.y));
            for (k, (p, q)) in [(a, b), (b, a)].into_iter().enumerate() {
                let expect = p.lerp(q, 5.0 / 18.0);
                close(edge_point(t, e, k), expect.x, expect.y);
            }
        }
    }

    /// On a parallelogram whose handles lie along its edges, equal on opposite sides, level 1
    /// is a tensor-product grid: `V0 + x_i e1 + y_j e2` with the five points of each
    /// direction, `0, 5/6 s, (1 + s - s') / 2, 1 - 5/6 s', 1` for handles `s e` and `-s' e`.
    #[test]
    fn a_parallelogram_splits_as_a_tensor_product() {
        let (v0, e1, e2) = (
            Point::new(1.0, 2.0),
            Vec2::new(6.0, 1.0),
            Vec2::new(2.0, 5.0),
        );
        let (s, s1, r, r1) = (0.4, 0.15, 0.2, 0.45);
        let mut mesh = GradientMesh::new(ColourSpace::Lab);
        for p in [v0, v0 + e1, v0 + e1 + e2, v0 + e2] {
            mesh.add_point(p, [50.0, 0.0, 0.0]);
        }
        mesh.add_face([0, 1, 2, 3]);
        for (a, b, h) in [
            (0, 1, e1 * s),
            (3, 2, e1 * s),
            (1, 0, -e1 * s1),
            (2, 3, -e1 * s1),
            (0, 3, e2 * r),
            (1, 2, e2 * r),
            (3, 0, -e2 * r1),
            (2, 1, -e2 * r1),
        ] {
            mesh.set_handle(a, b, h);
        }
        let base = BaseMesh::new(&mesh).unwrap().0;
        let t = &base.topology;
        let d = binary_data(&base);
        let k = HANDLE_SCALE;
        let x = [0.0, k * s, (1.0 + s - s1) / 2.0, 1.0 - k * s1, 1.0];
        let y = [0.0, k * r, (1.0 + r - r1) / 2.0, 1.0 - k * r1, 1.0];
        let grid = |(i, j): (i32, i32)| v0 + e1 * x[i as usize] + e2 * y[j as usize];
        let p = |i: u32| Point::new(d[i as usize].position[0], d[i as usize].position[1]);
        let close = |i: u32, q: (i32, i32)| {
            let (got, want) = (p(i), grid(q));
            assert!(
                (got - want).hypot() < 1e-12,
                "{i}: {got:?} vs {want:?} at {q:?}"
            );
        };
        let end = |e: u32, v: u32| usize::from(t.edge_vertices(e as usize)[0] != v);
        let fe = t.face_edges(0);
        // Grid index of each corner; from corner i, `dn` steps towards the next corner and
        // `dp` towards the previous one.
        let corner: [(i32, i32); 4] = [(0, 0), (4, 0), (4, 4), (0, 4)];
        let plus = |a: (i32, i32), b: (i32, i32), k: i32| (a.0 + k * b.0, a.1 + k * b.1);
        for i in 0..4 {
            let (a, next, prev) = (corner[i], corner[(i + 1) % 4], corner[(i + 3) % 4]);
            let dn = ((next.0 - a.0).signum(), (next.1 - a.1).signum());
            let dp = ((prev.0 - a.0).signum(), (prev.1 - a.1).signum());
            let e = fe[i];
            close(edge_point(t, e, end(e, i as u32)), plus(a, dn, 1));
            close(edge_midpoint(t, e), plus(a, dn, 2));
            close(edge_point(t, e, end(e, (i as u32 + 1) % 4)), plus(a, dn, 3));
            close(face_point(t, i), plus(plus(a, dn, 1), dp, 1));
            close(inner_point(t, i), plus(plus(a, dn, 2), dp, 1));
        }
        close(face_centre(t, 0), (2, 2));
    }

    /// The direct construction has the connectivity that a rebuild from its faces finds, and
    /// edges `4 e .. 4 e + 4` run along base edge `e`.
    #[test]
    fn binary_topology_matches_a_rebuild() {
        // A 3x3 grid with a hole in the middle and one cell split into triangles.
        let mut faces = Vec::new();
        for j in 0..3u32 {
            for i in 0..3u32 {
                let v = j * 4 + i;
                if (i, j) == (1, 1) {
                    continue;
                }
                if (i, j) == (0, 0) {
                    faces.push(vec![v, v + 1, v + 5]);
                    faces.push(vec![v, v + 5, v + 4]);
                } else {
                    faces.push(vec![v, v + 1, v + 5, v + 4]);
                }
            }
        }
        let t = Topology::from_faces(16, &faces).unwrap();
        let child = binary_topology(&t);
        child.assert_matches_a_rebuild();
        assert_eq!(child.euler_characteristic(), t.euler_characteristic());
        for e in 0..t.edge_count() {
            let [a, b] = t.edge_vertices(e);
            let chain = [
                a,
                edge_point(&t, e as u32, 0),
                edge_midpoint(&t, e as u32),
                edge_point(&t, e as u32, 1),
                b,
            ];
            for k in 0..4 {
                assert_eq!(child.edge_vertices(4 * e + k), [chain[k], chain[k + 1]]);
            }
        }
    }

    #[test]
    fn zero_handles_give_no_nan() {
        let mut base = square_and_triangle();
        base.edge_handles
            .iter_mut()
            .for_each(|h| *h = [Vec2::ZERO; 2]);
        let d = binary_data(&base);
        assert!(d.iter().flat_map(|d| d.to_array()).all(|x| x.is_finite()));
        // The ring collapses onto its control point.
        let t = &base.topology;
        assert_eq!(d[face_point(t, 0) as usize], base.data[0]);
    }
}
