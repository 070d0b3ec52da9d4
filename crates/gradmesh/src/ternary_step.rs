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
use crate::topology::{EdgeList, FaceLoops, Rings, Topology, INVALID, PARALLEL_MIN_CORNERS};
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
    let split = TernarySplit::new(t);
    // A level 1 of nine times the corners: concurrently where that pays, the rings (the
    // largest part) against faces and edges (see `Topology::subdivide`).
    let (rings, (faces, edges)) = if 9 * t.corner_count() < PARALLEL_MIN_CORNERS {
        (split.rings(), (split.faces(), split.edges()))
    } else {
        rayon::join(
            || split.rings(),
            || rayon::join(|| split.faces(), || split.edges()),
        )
    };
    Topology::assemble(split.child_vertex_count(), faces, edges, rings).debug_checked()
}

/// The ternary split of a topology (see [`ternary_topology`]): the base read once per corner,
/// and the numbering of level 1's vertices, edges and faces. Faces, edges and rings are built
/// independently, each array by one task in order, so the result does not depend on the
/// thread count; most of the cost is the first touch of fresh memory, which both cores can
/// take.
struct TernarySplit<'a> {
    base: &'a Topology,
    /// Per base corner: its face, the next and previous corners of the face, which end of its
    /// outgoing and of its incoming edge its vertex is, its corner quad Q(c) and its edge quad
    /// X(c). Plain array reads in the loops that build level 1.
    corner_face: Vec<u32>,
    next: Vec<u32>,
    prev: Vec<u32>,
    end_out: Vec<u32>,
    end_in: Vec<u32>,
    quad: Vec<u32>,
    side: Vec<u32>,
    /// The corner at which each base edge leaves its end 0 (first face) and end 1 (second
    /// face).
    leaving: Vec<[u32; 2]>,
}

impl<'a> TernarySplit<'a> {
    fn new(t: &'a Topology) -> Self {
        let (nf, ne, nc) = (t.face_count(), t.edge_count(), t.corner_count());
        let mut split = TernarySplit {
            base: t,
            corner_face: vec![0u32; nc],
            next: vec![0u32; nc],
            prev: vec![0u32; nc],
            end_out: vec![0u32; nc],
            end_in: vec![0u32; nc],
            quad: vec![0u32; nc],
            side: vec![0u32; nc],
            leaving: vec![[INVALID; 2]; ne],
        };
        for f in 0..nf {
            let (o, e) = (t.face_offsets[f] as usize, t.face_offsets[f + 1] as usize);
            let n = e - o;
            for c in o..e {
                let (nx, pv) = (
                    if c + 1 == e { o } else { c + 1 },
                    if c == o { e - 1 } else { c - 1 },
                );
                let v = t.face_verts[c];
                split.corner_face[c] = f as u32;
                split.next[c] = nx as u32;
                split.prev[c] = pv as u32;
                split.end_out[c] = u32::from(t.edge_verts[t.face_edges[c] as usize][0] != v);
                split.end_in[c] = u32::from(t.edge_verts[t.face_edges[pv] as usize][0] != v);
                split.quad[c] = (f + o + 1 + c) as u32;
                split.side[c] = (f + o + 1 + n + c) as u32;
            }
        }
        for c in 0..nc {
            split.leaving[t.face_edges[c] as usize][split.end_out[c] as usize] = c as u32;
        }
        split
    }

    fn child_vertex_count(&self) -> usize {
        let t = self.base;
        t.vertex_count() + 2 * t.edge_count() + t.corner_count()
    }

    /// The edge point of base edge `e` near its end `k`.
    #[inline]
    fn ep(&self, e: u32, k: u32) -> u32 {
        self.base.vertex_count() as u32 + 2 * e + k
    }

    /// The face point at base corner `c`.
    #[inline]
    fn fp(&self, c: usize) -> u32 {
        (self.base.vertex_count() + 2 * self.base.edge_count() + c) as u32
    }

    /// The edge from corner `c`'s outgoing edge point to its face point.
    #[inline]
    fn out_spoke(&self, c: usize) -> u32 {
        (3 * self.base.edge_count() + 3 * c) as u32
    }

    /// The edge from corner `c`'s incoming edge point to its face point.
    #[inline]
    fn in_spoke(&self, c: usize) -> u32 {
        (3 * self.base.edge_count() + 3 * c + 1) as u32
    }

    /// The edge from corner `c`'s face point to the next corner's.
    #[inline]
    fn rim(&self, c: usize) -> u32 {
        (3 * self.base.edge_count() + 3 * c + 2) as u32
    }

    /// The central face of base face `f`.
    #[inline]
    fn central(&self, f: usize) -> u32 {
        (f + 2 * self.base.face_offsets[f] as usize) as u32
    }

    /// The edge point of the outgoing edge at corner `c`, near `c`'s vertex.
    #[inline]
    fn ep_out(&self, c: usize) -> u32 {
        self.ep(self.base.face_edges[c], self.end_out[c])
    }

    /// The edge point of the incoming edge at corner `c`, near `c`'s vertex.
    #[inline]
    fn ep_in(&self, c: usize) -> u32 {
        self.ep(self.base.face_edges[self.prev[c] as usize], self.end_in[c])
    }

    /// Per base face: the central face, the corner quads, the edge quads.
    fn faces(&self) -> FaceLoops {
        let t = self.base;
        let (nf, nc) = (t.face_count(), t.corner_count());
        let face_count = nf + 2 * nc;
        let mut face_offsets = Vec::with_capacity(face_count + 1);
        let mut face_verts = Vec::with_capacity(9 * nc);
        let mut face_edges = Vec::with_capacity(9 * nc);
        face_offsets.push(0u32);
        for f in 0..nf {
            let (o, e) = (t.face_offsets[f] as usize, t.face_offsets[f + 1] as usize);
            for c in o..e {
                face_verts.push(self.fp(c));
                face_edges.push(self.rim(c));
            }
            face_offsets.push(face_verts.len() as u32);
            for c in o..e {
                let (eo, ei) = (t.face_edges[c], t.face_edges[self.prev[c] as usize]);
                face_verts.extend_from_slice(&[
                    t.face_verts[c],
                    self.ep_out(c),
                    self.fp(c),
                    self.ep_in(c),
                ]);
                face_edges.extend_from_slice(&[
                    along(eo, self.end_out[c]),
                    self.out_spoke(c),
                    self.in_spoke(c),
                    along(ei, self.end_in[c]),
                ]);
                face_offsets.push(face_verts.len() as u32);
            }
            for c in o..e {
                let nx = self.next[c] as usize;
                face_verts.extend_from_slice(&[
                    self.ep_out(c),
                    self.ep_in(nx),
                    self.fp(nx),
                    self.fp(c),
                ]);
                face_edges.extend_from_slice(&[
                    middle(t.face_edges[c]),
                    self.in_spoke(nx),
                    self.rim(c),
                    self.out_spoke(c),
                ]);
                face_offsets.push(face_verts.len() as u32);
            }
        }
        FaceLoops {
            face_offsets,
            face_verts,
            face_edges,
        }
    }

    /// The three edges along each base edge, then the three edges of each base corner.
    fn edges(&self) -> EdgeList {
        let t = self.base;
        let (ne, nc) = (t.edge_count(), t.corner_count());
        let mut edge_verts = Vec::with_capacity(3 * ne + 3 * nc);
        let mut edge_faces = Vec::with_capacity(3 * ne + 3 * nc);
        let quad_of = |c: u32| self.quad[c as usize];
        let side_of = |c: u32| self.side[c as usize];
        for e in 0..ne as u32 {
            let [a, b] = t.edge_verts[e as usize];
            let [c0, c1] = self.leaving[e as usize];
            edge_verts.push([a, self.ep(e, 0)]);
            edge_faces.push([
                quad_of(c0),
                or_invalid(c1, |c| quad_of(self.next[c as usize])),
            ]);
            edge_verts.push([self.ep(e, 1), b]);
            edge_faces.push([quad_of(self.next[c0 as usize]), or_invalid(c1, quad_of)]);
            edge_verts.push([self.ep(e, 0), self.ep(e, 1)]);
            edge_faces.push([side_of(c0), or_invalid(c1, side_of)]);
        }
        for c in 0..nc {
            let (nx, pv) = (self.next[c] as usize, self.prev[c] as usize);
            edge_verts.push([self.ep_out(c), self.fp(c)]);
            edge_faces.push([self.quad[c], self.side[c]]);
            edge_verts.push([self.ep_in(c), self.fp(c)]);
            edge_faces.push([self.side[pv], self.quad[c]]);
            edge_verts.push([self.fp(c), self.fp(nx)]);
            edge_faces.push([self.central(self.corner_face[c] as usize), self.side[c]]);
        }
        EdgeList {
            edge_verts,
            edge_faces,
        }
    }

    /// The rings of the vertex points, then the edge points, then the face points. Every
    /// level-1 corner is in one ring; each ring has one more edge on a boundary.
    fn rings(&self) -> Rings {
        let t = self.base;
        let (nv, nc) = (t.vertex_count(), t.corner_count());
        let vertex_count = self.child_vertex_count();
        let mut rings = Rings::with_capacity(vertex_count, 9 * nc, 9 * nc + vertex_count);
        // Vertex points: the base ring, mapped onto the corner quads.
        for v in 0..nv {
            let (r0, r1) = (t.ring_offsets[v] as usize, t.ring_offsets[v + 1] as usize);
            for k in r0..r1 {
                let f = t.ring_faces[k] as usize;
                rings
                    .ring_faces
                    .push(self.quad[t.face_offsets[f] as usize + t.ring_corners[k] as usize]);
                rings.ring_corners.push(0);
            }
            for &e in t.vertex_edges(v) {
                rings
                    .ring_edges
                    .push(along(e, u32::from(t.edge_verts[e as usize][0] != v as u32)));
            }
            rings.close();
        }
        self.edge_point_rings(&mut rings);
        self.face_point_rings(&mut rings);
        rings
    }

    /// The rings of the edge points, near end 0 then near end 1 of each base edge.
    fn edge_point_rings(&self, rings: &mut Rings) {
        let (quad, side) = (&self.quad, &self.side);
        for e in 0..self.base.edge_count() as u32 {
            let [c0, c1] = self.leaving[e as usize].map(|c| c as usize);
            let next0 = self.next[c0] as usize;
            if self.leaving[e as usize][1] == INVALID {
                rings.push(
                    &[(quad[c0], 1), (side[c0], 0)],
                    &[along(e, 0), self.out_spoke(c0), middle(e)],
                );
                rings.push(
                    &[(side[c0], 1), (quad[next0], 3)],
                    &[middle(e), self.in_spoke(next0), along(e, 1)],
                );
            } else {
                let next1 = self.next[c1] as usize;
                rings.push(
                    &[
                        (quad[c0], 1),
                        (side[c0], 0),
                        (side[c1], 1),
                        (quad[next1], 3),
                    ],
                    &[
                        along(e, 0),
                        self.out_spoke(c0),
                        middle(e),
                        self.in_spoke(next1),
                    ],
                );
                rings.push(
                    &[
                        (quad[c1], 1),
                        (side[c1], 0),
                        (side[c0], 1),
                        (quad[next0], 3),
                    ],
                    &[
                        along(e, 1),
                        self.out_spoke(c1),
                        middle(e),
                        self.in_spoke(next0),
                    ],
                );
            }
        }
    }

    /// The rings of the face points, one per base corner.
    fn face_point_rings(&self, rings: &mut Rings) {
        let t = self.base;
        for c in 0..t.corner_count() {
            let f = self.corner_face[c] as usize;
            let pv = self.prev[c] as usize;
            rings.push(
                &[
                    (self.quad[c], 2),
                    (self.side[pv], 2),
                    (self.central(f), c as u32 - t.face_offsets[f]),
                    (self.side[c], 3),
                ],
                &[
                    self.out_spoke(c),
                    self.in_spoke(c),
                    self.rim(pv),
                    self.rim(c),
                ],
            );
        }
    }
}

/// The level-1 edge along base edge `e` at its end `k`.
#[inline]
fn along(e: u32, k: u32) -> u32 {
    3 * e + k
}

/// The level-1 edge joining the two edge points of base edge `e`.
#[inline]
fn middle(e: u32) -> u32 {
    3 * e + 2
}

/// `f(c)`, or `INVALID` for a missing corner `c`.
#[inline]
fn or_invalid(c: u32, f: impl Fn(u32) -> u32) -> u32 {
    if c == INVALID {
        INVALID
    } else {
        f(c)
    }
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

/// The base vertex whose colour and opacity each level-1 vertex copies (the ternary step's
/// colours do not depend on positions or handles): a vertex point its own vertex, an edge
/// point the end it lies near, a face point the corner it lies at.
pub fn colour_sources(t: &Topology) -> Vec<u32> {
    let mut sources: Vec<u32> = (0..t.vertex_count() as u32).collect();
    sources.extend((0..t.edge_count()).flat_map(|e| t.edge_vertices(e)));
    sources.extend_from_slice(&t.face_verts);
    sources
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
    let mut out = vec![VertexData::ZERO; nv + 2 * ne + t.corner_count()];
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

    /// Each level-1 vertex copies the colour and opacity of its [`colour_sources`] vertex.
    #[test]
    fn colours_are_copied_from_their_sources() {
        use crate::{ColourSpace, GradientMesh};
        let mut m = GradientMesh::new(ColourSpace::Lab);
        for (i, (x, y)) in [(0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (0.0, 4.0), (7.0, 2.0)]
            .into_iter()
            .enumerate()
        {
            let p = m.add_point(Point::new(x, y), [x * 10.0, y * 10.0, i as f64]);
            m.points[p as usize].opacity = 0.5 + 0.1 * i as f64;
        }
        m.add_face([0, 1, 2, 3]);
        m.add_face([1, 4, 2]);
        let base = BaseMesh::new(&m).unwrap().0;
        let data = ternary_data(&base);
        let sources = colour_sources(&base.topology);
        assert_eq!(sources.len(), data.len());
        for (d, &s) in data.iter().zip(&sources) {
            assert_eq!(d.to_array()[2..], base.data[s as usize].to_array()[2..]);
        }
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
        let bits = |d: &[VertexData]| {
            d.iter()
                .flat_map(|d| d.to_array())
                .map(|x| x.to_bits())
                .collect::<Vec<_>>()
        };
        assert_eq!(bits(&one), bits(&many));
        assert_eq!(ternary_data(&base), many);

        let pos = |v: u32| {
            Point::new(
                base.data[v as usize].position[0],
                base.data[v as usize].position[1],
            )
        };
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
                    [d.position[0].to_bits(), d.position[1].to_bits()],
                    [p.x.to_bits(), p.y.to_bits()]
                );
                assert_eq!(d.to_array()[2..], base.data[fv[i] as usize].to_array()[2..]);
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
