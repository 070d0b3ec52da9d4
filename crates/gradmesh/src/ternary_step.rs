//! The special first refinement of the paper (sections 4.2-4.3): a linear ternary split whose
//! new points take their colour from the control point they surround and their position from
//! the handles.
//!
//! A face with `n` corners becomes a central `n`-gon of face points, `n` corner quads and `n`
//! edge quads. Level-1 vertices are numbered: one vertex point per base vertex, two edge points
//! per base edge (the one near `edge_vertices(e)[0]` first), one face point per base corner.

use std::ops::Range;

use kurbo::{Point, Vec2};

use crate::level::Level;
use crate::topology::{Topology, INVALID, PARALLEL_MIN_CORNERS};
use crate::validate::{BaseMesh, VertexData};

/// Index of the vertex point of base vertex `v`.
pub fn vertex_point(v: u32) -> u32 {
    v
}

/// Index of the edge point of base edge `e` near its end vertex `end` (0 or 1).
pub fn edge_point(base: &Topology, e: u32, end: usize) -> u32 {
    (base.vertex_count() + 2 * e as usize + end) as u32
}

/// Index of the face point at flat corner `corner` of the base topology.
pub fn face_point(base: &Topology, corner: usize) -> u32 {
    (base.vertex_count() + 2 * base.edge_count() + corner) as u32
}

/// Which end of edge `e` vertex `v` is.
fn end_of(base: &Topology, e: u32, v: u32) -> usize {
    usize::from(base.edge_vertices(e as usize)[0] != v)
}

/// Index of the first level-1 face made from base face `f`: its central face; the corner
/// quads follow, then the edge quads.
pub fn first_child_face(base: &Topology, f: usize) -> usize {
    f + 2 * base.face_offset(f)
}

/// The level-1 topology and sharpness of `base`.
pub fn ternary_level(base: &BaseMesh) -> Level {
    let t = &base.topology;
    let topology = ternary_topology(t);
    // The three level-1 edges along a base edge (numbered 3e, 3e + 1, 3e + 2) inherit its
    // sharpness; edges inside base faces are smooth.
    let mut edge_sharpness = vec![0.0; topology.edge_count()];
    for (e, &s) in base.edge_sharpness.iter().enumerate() {
        edge_sharpness[3 * e..3 * e + 3].fill(s);
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

/// The topology of the ternary split of `t`, built directly (no search for twins).
///
/// Faces of base face `f` (offset `o`, `n` corners) start at `f + 2 o`: the central face, then
/// the corner quad `Q(c)` of each corner `c`, then the edge quad `X(c)` of each corner (the quad
/// along the edge leaving `c`). Edges: `3 e + k` joins the vertex point at end `k` of base edge
/// `e` to the edge point there, `3 e + 2` joins the two edge points; for each base corner `c`,
/// `3 E + 3 c` joins the edge point of the outgoing edge to the face point `FP(c)`, `+ 1` the
/// edge point of the incoming edge to `FP(c)`, `+ 2` joins `FP(c)` to the next face point.
pub fn ternary_topology(t: &Topology) -> Topology {
    let (nf, ne, nv, nc) = (
        t.face_count(),
        t.edge_count(),
        t.vertex_count(),
        t.corner_count(),
    );
    let ep = |e: u32, k: u32| nv as u32 + 2 * e + k;
    let fp = |c: usize| (nv + 2 * ne + c) as u32;
    let along = |e: u32, k: u32| 3 * e + k;
    let middle = |e: u32| 3 * e + 2;
    let out_spoke = |c: usize| (3 * ne + 3 * c) as u32;
    let in_spoke = |c: usize| (3 * ne + 3 * c + 1) as u32;
    let rim = |c: usize| (3 * ne + 3 * c + 2) as u32;

    // Per base corner, once: its face, neighbours, the ends of its two edges at its vertex,
    // and its corner quad Q(c) and edge quad X(c). Plain array reads in the loops below.
    let mut corner_face = vec![0u32; nc];
    let mut next = vec![0u32; nc];
    let mut prev = vec![0u32; nc];
    let mut end_out = vec![0u32; nc];
    let mut end_in = vec![0u32; nc];
    let mut quad = vec![0u32; nc];
    let mut side = vec![0u32; nc];
    for f in 0..nf {
        let (o, e) = (t.face_offsets[f] as usize, t.face_offsets[f + 1] as usize);
        let n = e - o;
        for c in o..e {
            let (nx, pv) = (
                if c + 1 == e { o } else { c + 1 },
                if c == o { e - 1 } else { c - 1 },
            );
            let v = t.face_verts[c];
            corner_face[c] = f as u32;
            next[c] = nx as u32;
            prev[c] = pv as u32;
            end_out[c] = u32::from(t.edge_verts[t.face_edges[c] as usize][0] != v);
            end_in[c] = u32::from(t.edge_verts[t.face_edges[pv] as usize][0] != v);
            quad[c] = (f + o + 1 + c) as u32;
            side[c] = (f + o + 1 + n + c) as u32;
        }
    }
    let central = |f: usize| (f + 2 * t.face_offsets[f] as usize) as u32;
    // Edge point of the outgoing and incoming edges at corner c, near c's vertex.
    let ep_out = |c: usize| ep(t.face_edges[c], end_out[c]);
    let ep_in = |c: usize| ep(t.face_edges[prev[c] as usize], end_in[c]);

    // Faces, edges and rings are independent: built concurrently (each array by one task, in
    // order, so the result does not depend on the thread count). Most of the cost is the first
    // touch of fresh memory, which both cores can take.
    let faces = || {
        let face_count = nf + 2 * nc;
        let mut face_offsets = Vec::with_capacity(face_count + 1);
        let mut face_verts = Vec::with_capacity(9 * nc);
        let mut face_edges = Vec::with_capacity(9 * nc);
        face_offsets.push(0u32);
        for f in 0..nf {
            let (o, e) = (t.face_offsets[f] as usize, t.face_offsets[f + 1] as usize);
            for c in o..e {
                face_verts.push(fp(c));
                face_edges.push(rim(c));
            }
            face_offsets.push(face_verts.len() as u32);
            for c in o..e {
                let (eo, ei) = (t.face_edges[c], t.face_edges[prev[c] as usize]);
                face_verts.extend_from_slice(&[t.face_verts[c], ep_out(c), fp(c), ep_in(c)]);
                face_edges.extend_from_slice(&[
                    along(eo, end_out[c]),
                    out_spoke(c),
                    in_spoke(c),
                    along(ei, end_in[c]),
                ]);
                face_offsets.push(face_verts.len() as u32);
            }
            for c in o..e {
                let nx = next[c] as usize;
                face_verts.extend_from_slice(&[ep_out(c), ep_in(nx), fp(nx), fp(c)]);
                face_edges.extend_from_slice(&[
                    middle(t.face_edges[c]),
                    in_spoke(nx),
                    rim(c),
                    out_spoke(c),
                ]);
                face_offsets.push(face_verts.len() as u32);
            }
        }
        (face_offsets, face_verts, face_edges)
    };

    // The corner at which each base edge leaves its end 0 (first face) and end 1 (second face).
    let mut leaving = vec![[INVALID; 2]; ne];
    for c in 0..nc {
        leaving[t.face_edges[c] as usize][end_out[c] as usize] = c as u32;
    }
    let quad_of = |c: u32| quad[c as usize];
    let side_of = |c: u32| side[c as usize];
    let or_invalid = |c: u32, f: &dyn Fn(u32) -> u32| if c == INVALID { INVALID } else { f(c) };

    let edges = || {
        let mut edge_verts = Vec::with_capacity(3 * ne + 3 * nc);
        let mut edge_faces = Vec::with_capacity(3 * ne + 3 * nc);
        for e in 0..ne as u32 {
            let [a, b] = t.edge_verts[e as usize];
            let [c0, c1] = leaving[e as usize];
            edge_verts.push([a, ep(e, 0)]);
            edge_faces.push([quad_of(c0), or_invalid(c1, &|c| quad_of(next[c as usize]))]);
            edge_verts.push([ep(e, 1), b]);
            edge_faces.push([quad_of(next[c0 as usize]), or_invalid(c1, &quad_of)]);
            edge_verts.push([ep(e, 0), ep(e, 1)]);
            edge_faces.push([side_of(c0), or_invalid(c1, &side_of)]);
        }
        for c in 0..nc {
            let (nx, pv) = (next[c] as usize, prev[c] as usize);
            edge_verts.push([ep_out(c), fp(c)]);
            edge_faces.push([quad[c], side[c]]);
            edge_verts.push([ep_in(c), fp(c)]);
            edge_faces.push([side[pv], quad[c]]);
            edge_verts.push([fp(c), fp(nx)]);
            edge_faces.push([central(corner_face[c] as usize), side[c]]);
        }
        (edge_verts, edge_faces)
    };

    // Every level-1 corner is in one ring; each ring has one more edge on a boundary.
    let vertex_count = nv + 2 * ne + nc;
    let rings = || {
        let mut ring_offsets = Vec::with_capacity(vertex_count + 1);
        let mut ring_faces = Vec::with_capacity(9 * nc);
        let mut ring_corners = Vec::with_capacity(9 * nc);
        let mut edge_ring_offsets = Vec::with_capacity(vertex_count + 1);
        let mut ring_edges = Vec::with_capacity(9 * nc + vertex_count);
        ring_offsets.push(0u32);
        edge_ring_offsets.push(0u32);
        // Vertex points: the base ring, mapped onto the corner quads.
        for v in 0..nv {
            let (r0, r1) = (t.ring_offsets[v] as usize, t.ring_offsets[v + 1] as usize);
            for k in r0..r1 {
                let f = t.ring_faces[k] as usize;
                ring_faces.push(quad[t.face_offsets[f] as usize + t.ring_corners[k] as usize]);
                ring_corners.push(0);
            }
            for &e in t.vertex_edges(v) {
                ring_edges.push(along(e, u32::from(t.edge_verts[e as usize][0] != v as u32)));
            }
            ring_offsets.push(ring_faces.len() as u32);
            edge_ring_offsets.push(ring_edges.len() as u32);
        }
        let mut push_ring = |faces: &[(u32, u32)], edges: &[u32]| {
            for &(f, c) in faces {
                ring_faces.push(f);
                ring_corners.push(c);
            }
            ring_edges.extend_from_slice(edges);
            ring_offsets.push(ring_faces.len() as u32);
            edge_ring_offsets.push(ring_edges.len() as u32);
        };
        // Edge points, near end 0 then near end 1 of each base edge.
        for e in 0..ne as u32 {
            let [c0, c1] = leaving[e as usize].map(|c| c as usize);
            let next0 = next[c0] as usize;
            if leaving[e as usize][1] == INVALID {
                push_ring(
                    &[(quad[c0], 1), (side[c0], 0)],
                    &[along(e, 0), out_spoke(c0), middle(e)],
                );
                push_ring(
                    &[(side[c0], 1), (quad[next0], 3)],
                    &[middle(e), in_spoke(next0), along(e, 1)],
                );
            } else {
                let next1 = next[c1] as usize;
                push_ring(
                    &[
                        (quad[c0], 1),
                        (side[c0], 0),
                        (side[c1], 1),
                        (quad[next1], 3),
                    ],
                    &[along(e, 0), out_spoke(c0), middle(e), in_spoke(next1)],
                );
                push_ring(
                    &[
                        (quad[c1], 1),
                        (side[c1], 0),
                        (side[c0], 1),
                        (quad[next0], 3),
                    ],
                    &[along(e, 1), out_spoke(c1), middle(e), in_spoke(next0)],
                );
            }
        }
        // Face points.
        for c in 0..nc {
            let f = corner_face[c] as usize;
            let pv = prev[c] as usize;
            push_ring(
                &[
                    (quad[c], 2),
                    (side[pv], 2),
                    (central(f), c as u32 - t.face_offsets[f]),
                    (side[c], 3),
                ],
                &[out_spoke(c), in_spoke(c), rim(pv), rim(c)],
            );
        }
        (
            ring_offsets,
            ring_faces,
            ring_corners,
            edge_ring_offsets,
            ring_edges,
        )
    };
    // A level 1 of nine times the corners: concurrently where that pays, the rings (the
    // largest part) against faces and edges (see `subdivide`).
    let (rings, ((face_offsets, face_verts, face_edges), (edge_verts, edge_faces))) =
        if 9 * nc < PARALLEL_MIN_CORNERS {
            (rings(), (faces(), edges()))
        } else {
            rayon::join(rings, || rayon::join(faces, edges))
        };
    let (ring_offsets, ring_faces, ring_corners, edge_ring_offsets, ring_edges) = rings;

    Topology {
        vertex_count,
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

/// The position of the face point at corner `V0` of a face (the bilinear rule of section 4.3,
/// with the weights as corrected in the paper notes):
/// `F = V0 + (1 - d2) D1 + (1 - d1) D2 + d1 d2 (C - V0)`, with `d = 2 |D| / |edge|`.
///
/// `D1` is the handle along the edge to the next corner `V1`, `D2` along the edge to the
/// previous corner `V2`, and `C` the centroid of the face.
pub fn face_point_position(v0: Point, v1: Point, v2: Point, d1: Vec2, d2: Vec2, c: Point) -> Point {
    let (w1, w2) = (handle_weight(d1, v1 - v0), handle_weight(d2, v2 - v0));
    face_point_from_weights(v0, d1, d2, w1, w2, c)
}

/// `d = 2 |D| / |edge|` of [`face_point_position`]: a handle's length relative to half its
/// edge's. The same for either direction of `edge` (a length only sees magnitudes).
fn handle_weight(handle: Vec2, edge: Vec2) -> f64 {
    // f64::hypot, not Vec2::hypot: no overflow or underflow at extreme scales.
    let length = |v: Vec2| v.x.hypot(v.y);
    2.0 * length(handle) / length(edge)
}

/// [`face_point_position`] from the weights of its two handles.
fn face_point_from_weights(v0: Point, d1: Vec2, d2: Vec2, w1: f64, w2: f64, c: Point) -> Point {
    v0 + d1 * (1.0 - w2) + d2 * (1.0 - w1) + (c - v0) * (w1 * w2)
}

/// The level-1 data of `base`: positions from the handles, colours copied from the control
/// point each new point surrounds.
pub fn ternary_data(base: &BaseMesh) -> Vec<VertexData> {
    ternary_data_on(base, base.topology.corner_count() >= PARALLEL_MIN_CORNERS)
}

/// [`ternary_data`], computed concurrently if `parallel` (each point by the same arithmetic
/// either way).
fn ternary_data_on(base: &BaseMesh, parallel: bool) -> Vec<VertexData> {
    let t = &base.topology;
    let (nv, ne) = (t.vertex_count(), t.edge_count());
    let mut out = vec![[0.0; 6]; nv + 2 * ne + t.corner_count()];
    let pos = |v: u32| {
        let d = &base.data[v as usize];
        Point::new(d[0], d[1])
    };
    let with_position = |v: u32, p: Point| {
        let mut d = base.data[v as usize];
        d[0] = p.x;
        d[1] = p.y;
        d
    };
    let (vertex_points, rest) = out.split_at_mut(nv);
    let (edge_points, face_points) = rest.split_at_mut(2 * ne);
    vertex_points.copy_from_slice(&base.data);
    // Per edge end: the edge point, and the weight of its handle (each edge's lengths are
    // taken once here rather than at each of the up to four corners that read them).
    let mut weights = vec![[0.0; 2]; ne];
    let edges = |first: usize, points: &mut [VertexData], weights: &mut [[f64; 2]]| {
        for (k, (pair, w)) in points.chunks_exact_mut(2).zip(weights).enumerate() {
            let e = first + k;
            let [a, b] = t.edge_vertices(e);
            let edge = pos(b) - pos(a);
            for (end, v) in [a, b].into_iter().enumerate() {
                let h = base.edge_handles[e][end];
                pair[end] = with_position(v, pos(v) + h);
                w[end] = handle_weight(h, edge);
            }
        }
    };
    if parallel {
        use rayon::prelude::*;
        const EDGES: usize = 1 << 11;
        edge_points
            .par_chunks_mut(2 * EDGES)
            .zip(weights.par_chunks_mut(EDGES))
            .enumerate()
            .for_each(|(i, (points, w))| edges(i * EDGES, points, w));
    } else {
        edges(0, edge_points, &mut weights);
    }
    let weight = |e: u32, v: u32| weights[e as usize][end_of(t, e, v)];
    let handle = |e: u32, v: u32| base.edge_handles[e as usize][end_of(t, e, v)];
    // Face points of faces `faces`, whose corners are `points` (face points are numbered
    // in corner order).
    let face_points_of = |faces: Range<usize>, points: &mut [VertexData]| {
        let first = t.face_offset(faces.start);
        for f in faces {
            let fv = t.face_vertices(f);
            let fe = t.face_edges(f);
            let n = fv.len();
            let centroid = fv.iter().fold(Vec2::ZERO, |acc, &v| acc + pos(v).to_vec2()) / n as f64;
            let c = centroid.to_point();
            let at = t.face_offset(f) - first;
            for i in 0..n {
                let prev = (i + n - 1) % n;
                let (v0, eo, ei) = (fv[i], fe[i], fe[prev]);
                let p = face_point_from_weights(
                    pos(v0),
                    handle(eo, v0),
                    handle(ei, v0),
                    weight(eo, v0),
                    weight(ei, v0),
                    c,
                );
                points[at + i] = with_position(v0, p);
            }
        }
    };
    if parallel {
        split_faces(t, 0..t.face_count(), face_points, &face_points_of);
    } else {
        face_points_of(0..t.face_count(), face_points);
    }
    out
}

/// Calls `each(faces, corners)` on runs of faces that together cover `faces`, concurrently,
/// with `corners` the part of `slots` (one per corner of `faces`) that belongs to the run.
fn split_faces<T: Send>(
    t: &Topology,
    faces: Range<usize>,
    slots: &mut [T],
    each: &(impl Fn(Range<usize>, &mut [T]) + Sync),
) {
    const FACES: usize = 1 << 10;
    if faces.len() <= FACES {
        return each(faces, slots);
    }
    let middle = faces.start + faces.len() / 2;
    let (left, right) = slots.split_at_mut(t.face_offset(middle) - t.face_offset(faces.start));
    rayon::join(
        || split_faces(t, faces.start..middle, left, each),
        || split_faces(t, middle..faces.end, right, each),
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parallelogram_face_point_is_the_tensor_corner() {
        let v0 = Point::new(1.0, 2.0);
        let (e1, e2) = (Vec2::new(3.0, 0.5), Vec2::new(0.7, 2.0));
        let c = v0 + (e1 + e2) * 0.5;
        for (a, b) in [(0.1, 0.3), (0.33, 0.25), (0.5, 0.05), (0.0, 0.2)] {
            let (d1, d2) = (e1 * a, e2 * b);
            let f = face_point_position(v0, v0 + e1, v0 + e2, d1, d2, c);
            let expect = v0 + d1 + d2;
            assert!((f - expect).hypot() < 1e-12, "{f:?} vs {expect:?}");
        }
    }

    #[test]
    fn default_handles_split_a_square_in_thirds() {
        let v0 = Point::ZERO;
        let f = face_point_position(
            v0,
            Point::new(3.0, 0.0),
            Point::new(0.0, 3.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.0, 1.0),
            Point::new(1.5, 1.5),
        );
        assert!((f - Point::new(1.0, 1.0)).hypot() < 1e-12);
    }

    /// The direct construction gives the connectivity that building from the faces gives.
    #[test]
    fn ternary_topology_matches_a_rebuild() {
        // A quad, a triangle and a pentagon around a boundary, with a hole-free fan.
        let faces = vec![vec![0, 1, 2, 3], vec![1, 4, 2], vec![2, 4, 5, 6, 3]];
        let t = Topology::from_faces(7, &faces).unwrap();
        let child = ternary_topology(&t);
        child.assert_matches_a_rebuild();
        assert_eq!(child.euler_characteristic(), t.euler_characteristic());
    }

    /// Every point of a mesh large enough to be computed concurrently: the same bits on one
    /// thread and on several, and the face points those of [`face_point_position`].
    #[test]
    fn concurrent_data_matches_the_formulas() {
        use crate::{ColourSpace, GradientMesh};
        let n = 40;
        let mut m = GradientMesh::new(ColourSpace::Lab);
        for j in 0..=n {
            for i in 0..=n {
                let jitter = f64::from((i * 7 + j * 13) % 10) * 0.03;
                m.add_point(
                    Point::new(f64::from(i) + jitter, f64::from(j) - jitter),
                    [f64::from(i), f64::from(j), 0.0],
                );
            }
        }
        for j in 0..n {
            for i in 0..n {
                let v = j * (n + 1) + i;
                if (i + j) % 3 == 0 {
                    m.add_face(vec![v, v + 1, v + n + 2]);
                    m.add_face(vec![v, v + n + 2, v + n + 1]);
                } else {
                    m.add_face(vec![v, v + 1, v + n + 2, v + n + 1]);
                }
                // Handles of every length along the bottom edges, both ways.
                let scale = 0.05 + f64::from((i * 5 + j) % 9) * 0.05;
                m.set_handle(v, v + 1, Vec2::new(scale, 0.01));
                m.set_handle(v + 1, v, Vec2::new(-0.4 * scale, 0.0));
            }
        }
        let (base, _) = BaseMesh::new(&m).unwrap();
        let t = &base.topology;
        assert!(t.corner_count() >= PARALLEL_MIN_CORNERS);
        let (one, many) = (ternary_data_on(&base, false), ternary_data_on(&base, true));
        let bits = |d: &[VertexData]| d.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&one), bits(&many));
        assert_eq!(ternary_data(&base), many);

        let pos = |v: u32| Point::new(base.data[v as usize][0], base.data[v as usize][1]);
        let handle = |e: u32, v: u32| base.edge_handles[e as usize][end_of(t, e, v)];
        for f in 0..t.face_count() {
            let (fv, fe) = (t.face_vertices(f), t.face_edges(f));
            let k = fv.len();
            let c =
                (fv.iter().fold(Vec2::ZERO, |a, &v| a + pos(v).to_vec2()) / k as f64).to_point();
            for i in 0..k {
                let (next, prev) = ((i + 1) % k, (i + k - 1) % k);
                let p = face_point_position(
                    pos(fv[i]),
                    pos(fv[next]),
                    pos(fv[prev]),
                    handle(fe[i], fv[i]),
                    handle(fe[prev], fv[i]),
                    c,
                );
                let d = many[face_point(t, t.face_offset(f) + i) as usize];
                assert_eq!(
                    [d[0].to_bits(), d[1].to_bits()],
                    [p.x.to_bits(), p.y.to_bits()]
                );
                assert_eq!(d[2..], base.data[fv[i] as usize][2..]);
            }
        }
    }

    #[test]
    fn zero_handles_give_no_nan() {
        let f = face_point_position(
            Point::ZERO,
            Point::new(1.0, 0.0),
            Point::new(0.0, 1.0),
            Vec2::ZERO,
            Vec2::ZERO,
            Point::new(0.3, 0.3),
        );
        assert_eq!(f, Point::ZERO);
    }
}
