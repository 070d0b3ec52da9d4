//! Flat topology of one refinement level: faces, edges and ordered vertex rings.
//!
//! Built once per level from face loops (structure of arrays, as OpenSubdiv's `Vtr::Level`),
//! and checked for manifoldness and consistent winding on the way.

use crate::error::ErrorKind;

/// Marks a missing face or edge.
pub const INVALID: u32 = u32::MAX;

/// Meshes with fewer corners than this are subdivided on one thread.
pub(crate) const PARALLEL_MIN_CORNERS: usize = 1 << 12;

/// The connectivity of a polygon mesh with boundaries.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Topology {
    pub(crate) vertex_count: usize,
    pub(crate) face_offsets: Vec<u32>,
    pub(crate) face_verts: Vec<u32>,
    /// Edge from corner `i` to corner `i + 1` of each face, parallel to `face_verts`.
    pub(crate) face_edges: Vec<u32>,
    pub(crate) edge_verts: Vec<[u32; 2]>,
    /// `[face running v0->v1, face running v1->v0]`; the second is `INVALID` on a boundary.
    pub(crate) edge_faces: Vec<[u32; 2]>,
    /// Ordered ring around each vertex: face `k` lies between ring edges `k` and `k + 1`.
    pub(crate) ring_offsets: Vec<u32>,
    pub(crate) ring_faces: Vec<u32>,
    /// Corner index of the vertex inside each ring face, parallel to `ring_faces`.
    pub(crate) ring_corners: Vec<u32>,
    pub(crate) edge_ring_offsets: Vec<u32>,
    pub(crate) ring_edges: Vec<u32>,
}

impl Topology {
    /// Builds the topology of `faces` (a flat list of corner indices with `face_offsets`) over
    /// `vertex_count` vertices. Half-edges for which `is_cut(face, corner)` holds are never
    /// paired with a twin: both sides of a cut edge become boundaries.
    ///
    /// Fails on indices out of range, faces with fewer than three corners or a repeated corner,
    /// edges shared by more than two faces or run twice in one direction, and vertices whose
    /// faces do not form one fan. Error indices are face and vertex indices of this input.
    pub fn build(
        vertex_count: usize,
        face_offsets: Vec<u32>,
        face_verts: Vec<u32>,
        is_cut: impl Fn(usize, usize) -> bool,
    ) -> Result<Topology, ErrorKind> {
        check_face_loops(vertex_count, &face_offsets, &face_verts)?;
        let corners = CornerLinks::new(&face_offsets, &face_verts);
        let order = corners.grouped_by_edge(vertex_count);
        let pairing = corners.pair_half_edges(&order, is_cut)?;
        let rings = corners.walk_rings(vertex_count, &pairing)?;
        let HalfEdgePairing {
            face_edges, edges, ..
        } = pairing;
        let faces = FaceLoops {
            face_offsets,
            face_verts,
            face_edges,
        };
        Ok(Topology::assemble(vertex_count, faces, edges, rings))
    }

    /// A topology from its parts.
    pub(crate) fn assemble(
        vertex_count: usize,
        faces: FaceLoops,
        edges: EdgeList,
        rings: Rings,
    ) -> Topology {
        Topology {
            vertex_count,
            face_offsets: faces.face_offsets,
            face_verts: faces.face_verts,
            face_edges: faces.face_edges,
            edge_verts: edges.edge_verts,
            edge_faces: edges.edge_faces,
            ring_offsets: rings.ring_offsets,
            ring_faces: rings.ring_faces,
            ring_corners: rings.ring_corners,
            edge_ring_offsets: rings.edge_ring_offsets,
            ring_edges: rings.ring_edges,
        }
    }

    /// Builds the topology of a list of face loops, with no cut edges.
    pub fn from_faces(vertex_count: usize, faces: &[Vec<u32>]) -> Result<Topology, ErrorKind> {
        let (offsets, verts) = flatten(faces);
        Topology::build(vertex_count, offsets, verts, |_, _| false)
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.vertex_count
    }

    /// Number of faces.
    pub fn face_count(&self) -> usize {
        self.face_offsets.len().saturating_sub(1)
    }

    /// Number of edges.
    pub fn edge_count(&self) -> usize {
        self.edge_verts.len()
    }

    /// Total number of face corners.
    pub fn corner_count(&self) -> usize {
        self.face_verts.len()
    }

    /// The corners of face `f`, in winding order.
    pub fn face_vertices(&self, f: usize) -> &[u32] {
        &self.face_verts[self.face_offsets[f] as usize..self.face_offsets[f + 1] as usize]
    }

    /// The edges of face `f`: edge `i` runs from corner `i` to corner `i + 1`.
    pub fn face_edges(&self, f: usize) -> &[u32] {
        &self.face_edges[self.face_offsets[f] as usize..self.face_offsets[f + 1] as usize]
    }

    /// Offset of face `f`'s first corner in the flat corner list.
    pub fn face_offset(&self, f: usize) -> usize {
        self.face_offsets[f] as usize
    }

    /// The two end vertices of edge `e`.
    pub fn edge_vertices(&self, e: usize) -> [u32; 2] {
        self.edge_verts[e]
    }

    /// The faces on either side of edge `e` (`INVALID` for a missing side).
    pub fn edge_faces(&self, e: usize) -> [u32; 2] {
        self.edge_faces[e]
    }

    /// Whether edge `e` has a face on one side only.
    pub fn is_boundary_edge(&self, e: usize) -> bool {
        self.edge_faces[e][1] == INVALID
    }

    /// The faces around vertex `v`, in ring order.
    pub fn vertex_faces(&self, v: usize) -> &[u32] {
        &self.ring_faces[self.ring_offsets[v] as usize..self.ring_offsets[v + 1] as usize]
    }

    /// The corner of `v` in each of [`Topology::vertex_faces`].
    pub fn vertex_face_corners(&self, v: usize) -> &[u32] {
        &self.ring_corners[self.ring_offsets[v] as usize..self.ring_offsets[v + 1] as usize]
    }

    /// The edges around vertex `v`, in ring order; one more than the faces on a boundary.
    pub fn vertex_edges(&self, v: usize) -> &[u32] {
        &self.ring_edges[self.edge_ring_offsets[v] as usize..self.edge_ring_offsets[v + 1] as usize]
    }

    /// Whether vertex `v` lies on a boundary (or has no face at all).
    pub fn is_boundary_vertex(&self, v: usize) -> bool {
        self.vertex_edges(v).len() != self.vertex_faces(v).len()
    }

    /// The vertex at the other end of edge `e` from `v`.
    pub fn other_vertex(&self, e: usize, v: u32) -> u32 {
        let [a, b] = self.edge_verts[e];
        if a == v {
            b
        } else {
            a
        }
    }

    /// Euler characteristic V - E + F (counting only vertices used by faces).
    pub fn euler_characteristic(&self) -> i64 {
        let used = (0..self.vertex_count)
            .filter(|&v| !self.vertex_faces(v).is_empty())
            .count();
        used as i64 - self.edge_count() as i64 + self.face_count() as i64
    }

    /// Checks, in debug builds, that a topology a refinement step assembled field by field
    /// is consistent: every ring corner names its vertex.
    pub(crate) fn debug_checked(self) -> Topology {
        #[cfg(debug_assertions)]
        for v in 0..self.vertex_count {
            for (&f, &c) in self.vertex_faces(v).iter().zip(self.vertex_face_corners(v)) {
                debug_assert_eq!(self.face_vertices(f as usize)[c as usize], v as u32);
            }
        }
        self
    }

    /// The topology after one Catmull-Clark split, built directly from this one (no search
    /// for twins): one face point per face, then one edge point per edge, then one vertex
    /// point per vertex. Child face `c` is the quad at flat corner `c`: `[vertex point, edge
    /// point of the outgoing edge, face point, edge point of the incoming edge]`. Child edges:
    /// `2 e + k` is the half of edge `e` at its end `k`; `2 E + c` joins the edge point of the
    /// outgoing edge at corner `c` to the face point.
    pub fn subdivide(&self) -> Topology {
        self.subdivide_on(self.corner_count() >= PARALLEL_MIN_CORNERS)
    }

    /// [`Topology::subdivide`] on the calling thread alone: for code that holds a lock, which
    /// must not wait in rayon (the thread could take on a task that wants the same lock).
    pub(crate) fn subdivide_sequential(&self) -> Topology {
        self.subdivide_on(false)
    }

    /// [`Topology::subdivide`], its parts built concurrently if `parallel`.
    fn subdivide_on(&self, parallel: bool) -> Topology {
        let split = CatmullClarkSplit::new(self);
        // Concurrently where it pays: a small mesh (a face's neighbourhood, refined locally)
        // is built in less time than handing its parts to other threads takes. The rings are
        // the largest part (about 14 words a parent corner, against 9 and 8): one thread takes
        // them while the other builds faces and edges, so that neither waits idle for long.
        let (rings, (faces, edges)) = if parallel {
            rayon::join(
                || split.rings(),
                || rayon::join(|| split.faces(), || split.edges()),
            )
        } else {
            (split.rings(), (split.faces(), split.edges()))
        };
        Topology::assemble(split.child_vertex_count(), faces, edges, rings)
    }

    /// Checks that this topology (built directly by a refinement step) has the connectivity
    /// that [`Topology::build`] finds from its faces: the same edges around every face, edges
    /// running `a -> b` in their first face, boundary flags, and rings in cyclic order.
    #[cfg(test)]
    pub(crate) fn assert_matches_a_rebuild(&self) {
        let child = self;
        let (o, v) = (child.face_offsets.clone(), child.face_verts.clone());
        let rebuilt = Topology::build(child.vertex_count(), o, v, |_, _| false).unwrap();
        assert_eq!(child.face_count(), rebuilt.face_count());
        assert_eq!(child.edge_count(), rebuilt.edge_count());
        // Edge ids differ between the two: compare edges by their end vertices.
        let ends = |t: &Topology, e: u32| {
            let [a, b] = t.edge_vertices(e as usize);
            (a.min(b), a.max(b))
        };
        for f in 0..child.face_count() {
            for (e1, e2) in child.face_edges(f).iter().zip(rebuilt.face_edges(f)) {
                assert_eq!(ends(child, *e1), ends(&rebuilt, *e2), "face {f}");
            }
        }
        for e in 0..child.edge_count() {
            let [a, b] = child.edge_vertices(e);
            let [f0, f1] = child.edge_faces(e);
            let runs = |f: u32, from: u32, to: u32| {
                let fv = child.face_vertices(f as usize);
                let k = fv.iter().position(|&x| x == from).unwrap();
                fv[(k + 1) % fv.len()] == to
            };
            assert!(runs(f0, a, b), "edge {e} runs a->b in its first face");
            if f1 != INVALID {
                assert!(runs(f1, b, a), "edge {e} runs b->a in its second face");
            }
        }
        for v in 0..child.vertex_count() {
            assert_eq!(
                child.is_boundary_vertex(v),
                rebuilt.is_boundary_vertex(v),
                "{v}"
            );
            let mut f1 = child.vertex_faces(v).to_vec();
            let f2 = rebuilt.vertex_faces(v).to_vec();
            // Same cyclic order, possibly rotated for interior vertices.
            if !child.is_boundary_vertex(v) && !f1.is_empty() {
                let k = f1.iter().position(|&f| f == f2[0]).unwrap();
                f1.rotate_left(k);
            }
            assert_eq!(f1, f2, "ring of {v}");
            for (&f, &c) in child
                .vertex_faces(v)
                .iter()
                .zip(child.vertex_face_corners(v))
            {
                assert_eq!(child.face_vertices(f as usize)[c as usize], v as u32);
            }
            let edges = child.vertex_edges(v);
            for (k, &f) in child.vertex_faces(v).iter().enumerate() {
                let fe = child.face_edges(f as usize);
                assert!(fe.contains(&edges[k]) && fe.contains(&edges[(k + 1) % edges.len()]));
            }
        }
    }

    /// Whether every face is a quad.
    pub fn is_all_quads(&self) -> bool {
        (0..self.face_count()).all(|f| self.face_vertices(f).len() == 4)
    }
}

/// Flattens face loops into offsets and corner indices.
pub fn flatten(faces: &[Vec<u32>]) -> (Vec<u32>, Vec<u32>) {
    let mut offsets = Vec::with_capacity(faces.len() + 1);
    let mut verts = Vec::with_capacity(faces.iter().map(Vec::len).sum());
    offsets.push(0);
    for f in faces {
        verts.extend_from_slice(f);
        offsets.push(verts.len() as u32);
    }
    (offsets, verts)
}

/// Counts the fans among the corners of one vertex (for the error message only).
fn count_fans(corners: &[u32], twin: &[u32], prev: &[u32], next: &[u32]) -> usize {
    let mut seen = vec![false; corners.len()];
    let index = |c: u32| corners.iter().position(|&x| x == c);
    let mut fans = 0;
    for i in 0..corners.len() {
        if seen[i] {
            continue;
        }
        fans += 1;
        let mut stack = vec![corners[i]];
        while let Some(c) = stack.pop() {
            let Some(k) = index(c) else { continue };
            if seen[k] {
                continue;
            }
            seen[k] = true;
            let t = twin[c as usize];
            if t != INVALID {
                stack.push(next[t as usize]);
            }
            let t = twin[prev[c as usize] as usize];
            if t != INVALID {
                stack.push(t);
            }
        }
    }
    fans
}

/// The face loops of a topology, as [`Topology`] holds them.
pub(crate) struct FaceLoops {
    pub(crate) face_offsets: Vec<u32>,
    pub(crate) face_verts: Vec<u32>,
    pub(crate) face_edges: Vec<u32>,
}

/// The edges of a topology, as [`Topology`] holds them.
pub(crate) struct EdgeList {
    pub(crate) edge_verts: Vec<[u32; 2]>,
    pub(crate) edge_faces: Vec<[u32; 2]>,
}

/// The ordered rings around the vertices of a topology, as [`Topology`] holds them, built one
/// vertex after the other.
pub(crate) struct Rings {
    pub(crate) ring_offsets: Vec<u32>,
    pub(crate) ring_faces: Vec<u32>,
    pub(crate) ring_corners: Vec<u32>,
    pub(crate) edge_ring_offsets: Vec<u32>,
    pub(crate) ring_edges: Vec<u32>,
}

impl Rings {
    /// Empty rings with room for `vertices` rings of `corners` faces and `edges` edges in all.
    pub(crate) fn with_capacity(vertices: usize, corners: usize, edges: usize) -> Rings {
        let mut rings = Rings {
            ring_offsets: Vec::with_capacity(vertices + 1),
            ring_faces: Vec::with_capacity(corners),
            ring_corners: Vec::with_capacity(corners),
            edge_ring_offsets: Vec::with_capacity(vertices + 1),
            ring_edges: Vec::with_capacity(edges),
        };
        rings.ring_offsets.push(0);
        rings.edge_ring_offsets.push(0);
        rings
    }

    /// Ends the ring of the current vertex: the faces and edges pushed since the last call.
    #[inline]
    pub(crate) fn close(&mut self) {
        self.ring_offsets.push(self.ring_faces.len() as u32);
        self.edge_ring_offsets.push(self.ring_edges.len() as u32);
    }

    /// Pushes a whole ring: its `(face, corner)` pairs and its edges.
    #[inline]
    pub(crate) fn push(&mut self, faces: &[(u32, u32)], edges: &[u32]) {
        for &(f, c) in faces {
            self.ring_faces.push(f);
            self.ring_corners.push(c);
        }
        self.ring_edges.extend_from_slice(edges);
        self.close();
    }
}

/// Refuses corner indices out of range, faces with fewer than three corners and faces that
/// visit a vertex twice.
fn check_face_loops(
    vertex_count: usize,
    face_offsets: &[u32],
    face_verts: &[u32],
) -> Result<(), ErrorKind> {
    let face_count = face_offsets.len().saturating_sub(1);
    // The last face (plus one) in which each vertex was seen: finds a repeated corner in
    // linear time, and the same one as a scan of the earlier corners would.
    let mut seen_in = vec![0u32; vertex_count];
    for f in 0..face_count {
        let corners = &face_verts[face_offsets[f] as usize..face_offsets[f + 1] as usize];
        for (i, &v) in corners.iter().enumerate() {
            if v as usize >= vertex_count {
                return Err(ErrorKind::IndexOutOfRange {
                    face: f,
                    corner: i,
                    index: v as u64,
                    count: vertex_count,
                });
            }
        }
        if corners.len() < 3 {
            return Err(ErrorKind::DegenerateFace {
                face: f,
                reason: format!("has {} corners, at least 3 are needed", corners.len()),
            });
        }
        for &v in corners {
            if seen_in[v as usize] == f as u32 + 1 {
                return Err(ErrorKind::DegenerateFace {
                    face: f,
                    reason: format!("visits point {v} twice"),
                });
            }
            seen_in[v as usize] = f as u32 + 1;
        }
    }
    Ok(())
}

/// The flat corner list of checked face loops, linked: half-edge `h` is corner `h`, running to
/// the next corner of its face.
struct CornerLinks<'a> {
    face_offsets: &'a [u32],
    face_verts: &'a [u32],
    corner_face: Vec<u32>,
    next_corner: Vec<u32>,
    prev_corner: Vec<u32>,
    /// The vertex each half-edge runs to, read once (the keys are taken many times).
    heads: Vec<u32>,
}

/// What pairing the half-edges found: each one's twin (`INVALID` on a boundary), the edge of
/// each, and the edges.
struct HalfEdgePairing {
    twin: Vec<u32>,
    face_edges: Vec<u32>,
    edges: EdgeList,
}

impl HalfEdgePairing {
    /// Makes the half-edges `hs` (one, or a pair of twins) a new edge.
    #[inline]
    fn push_edge(&mut self, hs: &[u32], corners: &CornerLinks) {
        let e = self.edges.edge_verts.len() as u32;
        let h0 = hs[0] as usize;
        self.edges
            .edge_verts
            .push([corners.face_verts[h0], corners.head(h0)]);
        let f1 = hs
            .get(1)
            .map_or(INVALID, |&h| corners.corner_face[h as usize]);
        self.edges.edge_faces.push([corners.corner_face[h0], f1]);
        for &h in hs {
            self.face_edges[h as usize] = e;
        }
        if let [a, b] = hs {
            self.twin[*a as usize] = *b;
            self.twin[*b as usize] = *a;
        }
    }
}

impl<'a> CornerLinks<'a> {
    fn new(face_offsets: &'a [u32], face_verts: &'a [u32]) -> Self {
        let face_count = face_offsets.len().saturating_sub(1);
        let corner_count = face_verts.len();
        let mut corner_face = vec![0u32; corner_count];
        let mut next_corner = vec![0u32; corner_count];
        let mut prev_corner = vec![0u32; corner_count];
        for f in 0..face_count {
            let (s, e) = (face_offsets[f], face_offsets[f + 1]);
            for h in s..e {
                corner_face[h as usize] = f as u32;
                next_corner[h as usize] = if h + 1 == e { s } else { h + 1 };
                prev_corner[h as usize] = if h == s { e - 1 } else { h - 1 };
            }
        }
        let heads = next_corner
            .iter()
            .map(|&n| face_verts[n as usize])
            .collect();
        CornerLinks {
            face_offsets,
            face_verts,
            corner_face,
            next_corner,
            prev_corner,
            heads,
        }
    }

    /// The vertex half-edge `h` runs to.
    #[inline]
    fn head(&self, h: usize) -> u32 {
        self.heads[h]
    }

    /// The undirected edge of half-edge `h`: its smaller vertex, then its larger.
    #[inline]
    fn key(&self, h: u32) -> (u32, u32) {
        let (a, b) = (self.face_verts[h as usize], self.heads[h as usize]);
        (a.min(b), a.max(b))
    }

    /// The half-edges in order of their undirected key: bucketed by the smaller vertex (linear
    /// time), each small bucket sorted by the larger one.
    fn grouped_by_edge(&self, vertex_count: usize) -> Vec<u32> {
        let corner_count = self.face_verts.len();
        let mut bucket_start = vec![0u32; vertex_count + 1];
        for h in 0..corner_count as u32 {
            bucket_start[self.key(h).0 as usize + 1] += 1;
        }
        for v in 0..vertex_count {
            bucket_start[v + 1] += bucket_start[v];
        }
        let mut fill = bucket_start.clone();
        let mut order = vec![0u32; corner_count];
        for h in 0..corner_count as u32 {
            let b = &mut fill[self.key(h).0 as usize];
            order[*b as usize] = h;
            *b += 1;
        }
        for v in 0..vertex_count {
            order[bucket_start[v] as usize..bucket_start[v + 1] as usize]
                .sort_unstable_by_key(|&h| (self.key(h).1, h));
        }
        order
    }

    /// Makes an edge of each group of half-edges with the same key in `order`: a pair of
    /// opposite half-edges becomes one interior edge, a half-edge alone or one of a cut a
    /// boundary edge. Refuses two half-edges in one direction and more than two.
    fn pair_half_edges(
        &self,
        order: &[u32],
        is_cut: impl Fn(usize, usize) -> bool,
    ) -> Result<HalfEdgePairing, ErrorKind> {
        let corner_count = self.face_verts.len();
        let mut pairing = HalfEdgePairing {
            twin: vec![INVALID; corner_count],
            face_edges: vec![INVALID; corner_count],
            edges: EdgeList {
                edge_verts: Vec::with_capacity(corner_count / 2 + 1),
                edge_faces: Vec::with_capacity(corner_count / 2 + 1),
            },
        };
        let cut = |h: u32| {
            let f = self.corner_face[h as usize] as usize;
            is_cut(f, (h - self.face_offsets[f]) as usize)
        };
        let mut i = 0;
        while i < order.len() {
            let k = self.key(order[i]);
            let mut j = i + 1;
            while j < order.len() && self.key(order[j]) == k {
                j += 1;
            }
            let group = &order[i..j];
            if group.iter().any(|&h| cut(h)) {
                for &h in group {
                    pairing.push_edge(&[h], self);
                }
            } else if group.len() == 1 {
                pairing.push_edge(group, self);
            } else if group.len() == 2 {
                let (h0, h1) = (group[0] as usize, group[1] as usize);
                if self.face_verts[h0] == self.face_verts[h1] {
                    return Err(ErrorKind::InconsistentWinding {
                        face_a: self.corner_face[h0] as usize,
                        face_b: self.corner_face[h1] as usize,
                        a: self.face_verts[h0],
                        b: self.head(h0),
                    });
                }
                pairing.push_edge(group, self);
            } else {
                let mut faces: Vec<usize> = group
                    .iter()
                    .map(|&h| self.corner_face[h as usize] as usize)
                    .collect();
                faces.sort_unstable();
                return Err(ErrorKind::NonManifoldEdge {
                    a: k.0,
                    b: k.1,
                    faces,
                });
            }
            i = j;
        }
        Ok(pairing)
    }

    /// The ring of each vertex, walked across twins from the start of its fan. Refuses a
    /// vertex whose faces form more than one fan.
    fn walk_rings(
        &self,
        vertex_count: usize,
        pairing: &HalfEdgePairing,
    ) -> Result<Rings, ErrorKind> {
        let HalfEdgePairing {
            twin, face_edges, ..
        } = pairing;
        let (face_verts, corner_count) = (self.face_verts, self.face_verts.len());
        // The corners of each vertex, bucketed.
        let mut vert_corner_offsets = vec![0u32; vertex_count + 1];
        for &v in face_verts {
            vert_corner_offsets[v as usize + 1] += 1;
        }
        for v in 0..vertex_count {
            vert_corner_offsets[v + 1] += vert_corner_offsets[v];
        }
        let mut fill = vert_corner_offsets.clone();
        let mut vert_corners = vec![0u32; corner_count];
        for (h, &v) in face_verts.iter().enumerate() {
            vert_corners[fill[v as usize] as usize] = h as u32;
            fill[v as usize] += 1;
        }

        let mut rings =
            Rings::with_capacity(vertex_count, corner_count, corner_count + vertex_count);
        for v in 0..vertex_count {
            let corners =
                &vert_corners[vert_corner_offsets[v] as usize..vert_corner_offsets[v + 1] as usize];
            if let Some(&c0) = corners.first() {
                let count = self.walk_fan(c0, twin, face_edges, &mut rings);
                if count != corners.len() {
                    return Err(ErrorKind::NonManifoldVertex {
                        point: v as u32,
                        fans: count_fans(corners, twin, &self.prev_corner, &self.next_corner),
                    });
                }
            }
            rings.close();
        }
        Ok(rings)
    }

    /// Pushes to `rings` the fan of faces around the vertex of corner `c0`, from its start:
    /// the corner whose incoming half-edge has no twin, or `c0` if the fan goes all the way
    /// round. Returns the number of faces pushed.
    #[inline]
    fn walk_fan(&self, c0: u32, twin: &[u32], face_edges: &[u32], rings: &mut Rings) -> usize {
        let mut start = c0;
        loop {
            let t = twin[self.prev_corner[start as usize] as usize];
            if t == INVALID || t == c0 {
                break;
            }
            start = t;
        }
        let mut c = start;
        let mut count = 0;
        rings
            .ring_edges
            .push(face_edges[self.prev_corner[c as usize] as usize]);
        loop {
            let f = self.corner_face[c as usize];
            rings.ring_faces.push(f);
            rings.ring_corners.push(c - self.face_offsets[f as usize]);
            count += 1;
            let out = face_edges[c as usize];
            let t = twin[c as usize];
            if t == INVALID {
                rings.ring_edges.push(out);
                break;
            }
            let next = self.next_corner[t as usize];
            if next == start {
                break;
            }
            rings.ring_edges.push(out);
            c = next;
        }
        count
    }
}

/// One Catmull-Clark split of a topology (see [`Topology::subdivide`]): the parent read once
/// per corner and edge, and the numbering of the child's vertices, edges and faces. Faces,
/// edges and rings are built independently, each array by one task in order (the same result
/// whatever the thread count); much of the cost is the first touch of fresh memory, which
/// both cores can take.
struct CatmullClarkSplit<'a> {
    parent: &'a Topology,
    face_count: usize,
    edge_count: usize,
    /// The face of each parent corner.
    corner_face: Vec<u32>,
    /// The corner at which each edge leaves its end 0 (in its first face) and its end 1 (in
    /// its second face).
    leaving: Vec<[u32; 2]>,
}

impl<'a> CatmullClarkSplit<'a> {
    fn new(parent: &'a Topology) -> Self {
        let (nf, ne, nc) = (
            parent.face_count(),
            parent.edge_count(),
            parent.corner_count(),
        );
        let mut corner_face = vec![0u32; nc];
        for f in 0..nf {
            corner_face[parent.face_offsets[f] as usize..parent.face_offsets[f + 1] as usize]
                .fill(f as u32);
        }
        let mut leaving = vec![[INVALID; 2]; ne];
        for c in 0..nc {
            let e = parent.face_edges[c] as usize;
            let side = usize::from(parent.face_verts[c] != parent.edge_verts[e][0]);
            leaving[e][side] = c as u32;
        }
        CatmullClarkSplit {
            parent,
            face_count: nf,
            edge_count: ne,
            corner_face,
            leaving,
        }
    }

    fn child_vertex_count(&self) -> usize {
        self.face_count + self.edge_count + self.parent.vertex_count
    }

    /// The face point of parent face `f`.
    #[inline]
    fn fp(&self, f: usize) -> u32 {
        f as u32
    }

    /// The edge point of parent edge `e`.
    #[inline]
    fn ep(&self, e: u32) -> u32 {
        (self.face_count + e as usize) as u32
    }

    /// The vertex point of parent vertex `v`.
    #[inline]
    fn vp(&self, v: u32) -> u32 {
        (self.face_count + self.edge_count + v as usize) as u32
    }

    /// The child edge from the edge point of the outgoing edge at corner `c` to the face point.
    #[inline]
    fn inner(&self, c: usize) -> u32 {
        (2 * self.edge_count + c) as u32
    }

    /// Which end of parent edge `e` vertex `v` is.
    #[inline]
    fn end_at(&self, e: u32, v: u32) -> usize {
        usize::from(self.parent.edge_verts[e as usize][0] != v)
    }

    /// The corner after `c` in its face.
    #[inline]
    fn next(&self, c: usize) -> usize {
        let f = self.corner_face[c] as usize;
        if c + 1 == self.parent.face_offsets[f + 1] as usize {
            self.parent.face_offsets[f] as usize
        } else {
            c + 1
        }
    }

    /// The corner before `c` in its face.
    #[inline]
    fn prev(&self, c: usize) -> usize {
        let f = self.corner_face[c] as usize;
        if c == self.parent.face_offsets[f] as usize {
            self.parent.face_offsets[f + 1] as usize - 1
        } else {
            c - 1
        }
    }

    /// Child face `c`: the quad at parent corner `c`.
    fn faces(&self) -> FaceLoops {
        let t = self.parent;
        let nc = t.corner_count();
        let mut face_offsets = Vec::with_capacity(nc + 1);
        let mut face_verts = Vec::with_capacity(4 * nc);
        let mut face_edges = Vec::with_capacity(4 * nc);
        for c in 0..nc {
            face_offsets.push(4 * c as u32);
            let (v, f) = (t.face_verts[c], self.corner_face[c] as usize);
            let (out, inc) = (t.face_edges[c], t.face_edges[self.prev(c)]);
            face_verts.extend_from_slice(&[self.vp(v), self.ep(out), self.fp(f), self.ep(inc)]);
            face_edges.extend_from_slice(&[
                half(out, self.end_at(out, v)),
                self.inner(c),
                self.inner(self.prev(c)),
                half(inc, self.end_at(inc, v)),
            ]);
        }
        face_offsets.push(4 * nc as u32);
        FaceLoops {
            face_offsets,
            face_verts,
            face_edges,
        }
    }

    /// The two halves of each parent edge, then the edge from each corner's outgoing edge
    /// point to its face point.
    fn edges(&self) -> EdgeList {
        let t = self.parent;
        let (ne, nc) = (self.edge_count, t.corner_count());
        let mut edge_verts = Vec::with_capacity(2 * ne + nc);
        let mut edge_faces = Vec::with_capacity(2 * ne + nc);
        let after = |c: u32| {
            if c == INVALID {
                INVALID
            } else {
                self.next(c as usize) as u32
            }
        };
        for e in 0..ne {
            let [a, b] = t.edge_verts[e];
            // Child face `c` is the quad at parent corner `c` (INVALID stays INVALID).
            let [c0, c1] = self.leaving[e];
            edge_verts.push([self.vp(a), self.ep(e as u32)]);
            edge_faces.push([c0, after(c1)]);
            edge_verts.push([self.ep(e as u32), self.vp(b)]);
            edge_faces.push([after(c0), c1]);
        }
        for c in 0..nc {
            edge_verts.push([
                self.ep(t.face_edges[c]),
                self.fp(self.corner_face[c] as usize),
            ]);
            edge_faces.push([c as u32, self.next(c) as u32]);
        }
        EdgeList {
            edge_verts,
            edge_faces,
        }
    }

    /// The rings of the face points, then the edge points, then the vertex points.
    fn rings(&self) -> Rings {
        let t = self.parent;
        let (nf, ne, nv, nc) = (
            self.face_count,
            self.edge_count,
            t.vertex_count,
            t.corner_count(),
        );
        let mut rings = Rings::with_capacity(self.child_vertex_count(), 4 * nc, 4 * nc + nv);
        // Face points: round the face backwards.
        for f in 0..nf {
            let (o, n) = (t.face_offsets[f] as usize, t.face_vertices(f).len());
            for k in 0..n {
                let c = o + (n - k) % n;
                rings.ring_faces.push(c as u32);
                rings.ring_corners.push(2);
                rings.ring_edges.push(self.inner(c));
            }
            rings.close();
        }
        // Edge points: two faces on each side of the edge.
        for e in 0..ne {
            let [c0, c1] = self.leaving[e];
            let c0n = self.next(c0 as usize) as u32;
            rings.ring_faces.extend_from_slice(&[c0, c0n]);
            rings.ring_corners.extend_from_slice(&[1, 3]);
            rings.ring_edges.extend_from_slice(&[
                half(e as u32, 0),
                self.inner(c0 as usize),
                half(e as u32, 1),
            ]);
            if c1 != INVALID {
                rings
                    .ring_faces
                    .extend_from_slice(&[c1, self.next(c1 as usize) as u32]);
                rings.ring_corners.extend_from_slice(&[1, 3]);
                rings.ring_edges.push(self.inner(c1 as usize));
            }
            rings.close();
        }
        // Vertex points: the parent ring, mapped.
        for v in 0..nv {
            for (&f, &c) in t.vertex_faces(v).iter().zip(t.vertex_face_corners(v)) {
                rings.ring_faces.push(t.face_offsets[f as usize] + c);
                rings.ring_corners.push(0);
            }
            for &e in t.vertex_edges(v) {
                rings.ring_edges.push(half(e, self.end_at(e, v as u32)));
            }
            rings.close();
        }
        rings
    }
}

/// The child edge that is the half of parent edge `e` at its end `k`.
#[inline]
fn half(e: u32, k: usize) -> u32 {
    2 * e + k as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: u32) -> Vec<Vec<u32>> {
        let mut faces = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let v = j * (n + 1) + i;
                faces.push(vec![v, v + 1, v + n + 2, v + n + 1]);
            }
        }
        faces
    }

    #[test]
    fn grid_rings() {
        let t = Topology::from_faces(16, &grid(3)).unwrap();
        assert_eq!(t.edge_count(), 24);
        assert_eq!(t.euler_characteristic(), 1);
        // Interior vertex 5: four faces, four edges; corner vertex 0: one face, two edges.
        assert_eq!(t.vertex_faces(5).len(), 4);
        assert_eq!(t.vertex_edges(5).len(), 4);
        assert!(!t.is_boundary_vertex(5));
        assert_eq!(t.vertex_faces(0).len(), 1);
        assert_eq!(t.vertex_edges(0).len(), 2);
        assert!(t.is_boundary_vertex(0));
        // Ring order: consecutive ring faces share the ring edge between them.
        for v in 0..16 {
            let faces = t.vertex_faces(v);
            let edges = t.vertex_edges(v);
            for (k, &f) in faces.iter().enumerate() {
                let fe = t.face_edges(f as usize);
                assert!(fe.contains(&edges[k]) && fe.contains(&edges[(k + 1) % edges.len()]));
            }
        }
    }

    /// The direct construction gives the same connectivity as building from the child faces.
    #[test]
    fn subdivide_matches_a_rebuild() {
        let mut faces = grid(3);
        faces.remove(4); // a hole
        let mut mixed = faces.clone();
        let q = mixed.remove(0);
        mixed.push(vec![q[0], q[1], q[2]]);
        mixed.push(vec![q[0], q[2], q[3]]);
        for faces in [faces, mixed] {
            let t = Topology::from_faces(16, &faces).unwrap();
            let child = t.subdivide();
            child.assert_matches_a_rebuild();
        }
    }

    #[test]
    fn rejects_bad_meshes() {
        let e = Topology::from_faces(4, &[vec![0, 1, 2], vec![0, 1, 3]]).unwrap_err();
        assert!(
            matches!(e, ErrorKind::InconsistentWinding { a: 0, b: 1, .. }),
            "{e:?}"
        );
        let e =
            Topology::from_faces(5, &[vec![0, 1, 2], vec![1, 0, 3], vec![0, 1, 4]]).unwrap_err();
        assert!(matches!(e, ErrorKind::NonManifoldEdge { .. }), "{e:?}");
        // Two triangles touching at a single point: a bow tie.
        let e = Topology::from_faces(5, &[vec![0, 1, 2], vec![0, 3, 4]]).unwrap_err();
        assert!(
            matches!(e, ErrorKind::NonManifoldVertex { point: 0, fans: 2 }),
            "{e:?}"
        );
        let e = Topology::from_faces(3, &[vec![0, 1]]).unwrap_err();
        assert!(
            matches!(e, ErrorKind::DegenerateFace { face: 0, .. }),
            "{e:?}"
        );
        let e = Topology::from_faces(3, &[vec![0, 1, 7]]).unwrap_err();
        assert!(
            matches!(e, ErrorKind::IndexOutOfRange { index: 7, .. }),
            "{e:?}"
        );
    }

    #[test]
    fn cut_edges_become_two_boundaries() {
        // A 4x4 grid of quads; cut the interior edge 6-7 (both ends interior).
        let faces = grid(4);
        let (o, v) = flatten(&faces);
        let t = Topology::build(25, o.clone(), v.clone(), |f, c| {
            let corners = &v[o[f] as usize..o[f + 1] as usize];
            let (a, b) = (corners[c], corners[(c + 1) % corners.len()]);
            (a.min(b), a.max(b)) == (6, 7)
        })
        .unwrap();
        assert_eq!(t.edge_count(), 41);
        let cut: Vec<usize> = (0..41)
            .filter(|&e| {
                let [a, b] = t.edge_vertices(e);
                (a.min(b), a.max(b)) == (6, 7)
            })
            .collect();
        assert_eq!(cut.len(), 2);
        assert!(cut.iter().all(|&e| t.is_boundary_edge(e)));
        assert!(t.is_boundary_vertex(6) && t.is_boundary_vertex(7));
        assert_eq!(t.vertex_edges(6).len(), 5);
    }
}
