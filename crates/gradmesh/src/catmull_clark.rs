//! One Catmull-Clark step with Pixar's rules: the child topology and the stencils that compute
//! every child vertex from parent vertices.
//!
//! Topology and stencils depend only on connectivity and sharpness, never on positions or
//! colours, so they are computed once and any per-vertex data is refined by applying them.

pub use crate::level::Level;
use crate::rules::{self, VertexRule};
use crate::topology::{Topology, INVALID};
use crate::validate::VertexData;

/// Sparse weights: child vertex `i` is the sum of `weights[k] * parent[sources[k]]` over
/// `k` in `offsets[i]..offsets[i + 1]`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Stencils {
    offsets: Vec<u32>,
    sources: Vec<u32>,
    weights: Vec<f64>,
}

impl Stencils {
    /// An empty table.
    pub fn new() -> Self {
        Stencils {
            offsets: vec![0],
            sources: Vec::new(),
            weights: Vec::new(),
        }
    }

    /// Appends one stencil, merging repeated sources and dropping zero weights.
    pub fn push(&mut self, terms: &mut Vec<(u32, f64)>) {
        terms.sort_unstable_by_key(|t| t.0);
        let mut last = INVALID;
        for &(s, w) in terms.iter() {
            if s == last {
                *self.weights.last_mut().expect("a previous term") += w;
            } else {
                self.sources.push(s);
                self.weights.push(w);
                last = s;
            }
        }
        // Drop terms that cancelled or were zero.
        let start = *self.offsets.last().expect("offsets start with 0") as usize;
        let mut keep = start;
        for k in start..self.sources.len() {
            if self.weights[k] != 0.0 {
                self.sources[keep] = self.sources[k];
                self.weights[keep] = self.weights[k];
                keep += 1;
            }
        }
        self.sources.truncate(keep);
        self.weights.truncate(keep);
        self.offsets.push(keep as u32);
        terms.clear();
    }

    /// Number of stencils (child vertices).
    pub fn len(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Whether the table is empty.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The sources and weights of stencil `i`.
    pub fn stencil(&self, i: usize) -> (&[u32], &[f64]) {
        let (s, e) = (self.offsets[i] as usize, self.offsets[i + 1] as usize);
        (&self.sources[s..e], &self.weights[s..e])
    }

    /// Applies the stencils to parent data.
    pub fn apply(&self, parent: &[VertexData]) -> Vec<VertexData> {
        let mut out = vec![VertexData::ZERO; self.len()];
        self.apply_into(parent, &mut out);
        out
    }

    /// [`Stencils::apply`] on the calling thread alone (see
    /// [`Topology::subdivide_sequential`]).
    pub(crate) fn apply_sequential(&self, parent: &[VertexData]) -> Vec<VertexData> {
        let mut out = vec![VertexData::ZERO; self.len()];
        self.apply_range(0, parent, &mut out);
        out
    }

    /// Writes stencils `first..first + out.len()` applied to `parent` into `out`.
    fn apply_range(&self, first: usize, parent: &[VertexData], out: &mut [VertexData]) {
        for (i, o) in out.iter_mut().enumerate() {
            let (src, w) = self.stencil(first + i);
            let mut acc = VertexData::ZERO;
            for (&s, &w) in src.iter().zip(w) {
                acc.add_scaled(&parent[s as usize], w);
            }
            *o = acc;
        }
    }

    /// Applies the stencils to parent data, writing into `out` (one entry per stencil).
    ///
    /// Large tables are applied in parallel; every stencil is summed in the same order whatever
    /// the thread count, so the result does not depend on it.
    pub fn apply_into(&self, parent: &[VertexData], out: &mut [VertexData]) {
        use rayon::prelude::*;
        const CHUNK: usize = 1 << 12;
        if out.len() <= CHUNK {
            self.apply_range(0, parent, out);
        } else {
            out.par_chunks_mut(CHUNK)
                .enumerate()
                .for_each(|(k, chunk)| self.apply_range(k * CHUNK, parent, chunk));
        }
    }

    /// The table of stencils `0..n`, stencil `i` made of the terms `terms(i, buffer)` pushes
    /// into an empty buffer. Built in parallel by ranges and concatenated in order: the same
    /// table whatever the thread count.
    pub fn build(n: usize, terms: impl Fn(usize, &mut Vec<(u32, f64)>) + Sync) -> Stencils {
        use rayon::prelude::*;
        const CHUNK: usize = STENCIL_CHUNK;
        let range = |r: std::ops::Range<usize>| build_range(r, &terms);
        if n <= CHUNK {
            return range(0..n);
        }
        let parts: Vec<Stencils> = (0..n.div_ceil(CHUNK))
            .into_par_iter()
            .map(|k| range(k * CHUNK..((k + 1) * CHUNK).min(n)))
            .collect();
        Stencils::concat(&parts)
    }

    /// An empty table with room for `n` stencils of `terms` terms in all.
    pub fn with_capacity(n: usize, terms: usize) -> Self {
        let mut stencils = Stencils::new();
        stencils.offsets.reserve(n);
        stencils.sources.reserve(terms);
        stencils.weights.reserve(terms);
        stencils
    }

    /// The tables `parts` one after the other.
    pub fn concat(parts: &[Stencils]) -> Stencils {
        let n: usize = parts.iter().map(|p| p.len()).sum();
        let terms: usize = parts.iter().map(|p| p.sources.len()).sum();
        let mut stencils = Stencils::with_capacity(n, terms);
        for part in parts {
            stencils.append(part);
        }
        stencils
    }

    /// Reads source `s` from index `map[s]` of the data applied to instead. The terms keep
    /// their order, so that the sums are the same bit for bit.
    pub fn remap_sources(&mut self, map: &[u32]) {
        for s in &mut self.sources {
            *s = map[*s as usize];
        }
    }

    /// Appends the stencils of `other` after these.
    pub fn append(&mut self, other: &Stencils) {
        let base = *self.offsets.last().expect("offsets start with 0");
        self.offsets
            .extend(other.offsets[1..].iter().map(|&o| o + base));
        self.sources.extend_from_slice(&other.sources);
        self.weights.extend_from_slice(&other.weights);
    }
}

/// Adds the terms of the centroid of face `f`, scaled by `scale`.
fn face_centroid_terms(t: &Topology, f: usize, scale: f64, terms: &mut Vec<(u32, f64)>) {
    let verts = t.face_vertices(f);
    let w = scale / verts.len() as f64;
    terms.extend(verts.iter().map(|&v| (v, w)));
}

/// Adds the terms of the vertex mask of `rule` at vertex `v`, scaled by `scale`. `sharp(k)`
/// tells whether ring edge `k` counts as sharp for the crease mask.
fn vertex_mask_terms(
    parent: &Level,
    v: usize,
    rule: VertexRule,
    sharp: impl Fn(usize) -> bool,
    scale: f64,
    terms: &mut Vec<(u32, f64)>,
) {
    let t = &parent.topology;
    match rule {
        VertexRule::Corner => terms.push((v as u32, scale)),
        VertexRule::Crease => {
            terms.push((v as u32, 0.75 * scale));
            for (k, &e) in t.vertex_edges(v).iter().enumerate() {
                if sharp(k) {
                    terms.push((t.other_vertex(e as usize, v as u32), 0.125 * scale));
                }
            }
        }
        // A point no face uses has no ring: it stays where it is.
        VertexRule::Smooth | VertexRule::Dart if t.vertex_edges(v).is_empty() => {
            terms.push((v as u32, scale))
        }
        VertexRule::Smooth | VertexRule::Dart => {
            let edges = t.vertex_edges(v);
            let n = edges.len() as f64;
            terms.push((v as u32, scale * (n - 2.0) / n));
            let w = scale / (n * n);
            for &e in edges {
                terms.push((t.other_vertex(e as usize, v as u32), w));
            }
            for &f in t.vertex_faces(v) {
                face_centroid_terms(t, f as usize, w, terms);
            }
        }
    }
}

/// Refines `parent` by one Catmull-Clark step.
///
/// Child vertices are numbered: one face point per parent face, then one edge point per parent
/// edge, then one vertex point per parent vertex. Child face `c` is the quad at corner `c` of
/// the flat parent corner list: `[vertex point, edge point of the outgoing edge, face point,
/// edge point of the incoming edge]`, wound like its parent.
pub fn refine(parent: &Level) -> (Level, Stencils) {
    let t = &parent.topology;
    let child = refine_level(parent);
    let stencils = Stencils::build(
        t.face_count() + t.edge_count() + t.vertex_count(),
        stencil_terms(parent),
    );
    (child, stencils)
}

/// The child level of `parent`, as [`refine`] gives it, without the stencils.
pub fn refine_level(parent: &Level) -> Level {
    refine_level_with(parent, parent.topology.subdivide())
}

/// [`refine_level`] on the calling thread alone (see [`Topology::subdivide_sequential`]).
pub(crate) fn refine_level_sequential(parent: &Level) -> Level {
    refine_level_with(parent, parent.topology.subdivide_sequential())
}

/// The child level of `parent`, whose topology is `child_topology`.
fn refine_level_with(parent: &Level, child_topology: Topology) -> Level {
    let t = &parent.topology;
    let (nf, ne, nv) = (t.face_count(), t.edge_count(), t.vertex_count());
    let vertex_point = |v: u32| (nf + ne + v as usize) as u32;

    // Child sharpness: vertex sharpness decays; each half of a parent edge gets the sharpness
    // subdivided at its end vertex; edges inside parent faces are smooth.
    let mut child_vertex_sharpness = vec![0.0; child_topology.vertex_count()];
    for v in 0..nv {
        child_vertex_sharpness[vertex_point(v as u32) as usize] =
            rules::decrement_sharpness(parent.vertex_sharpness[v]);
    }
    let mut child_edge_sharpness = vec![0.0; child_topology.edge_count()];
    for f in 0..nf {
        let fv = t.face_vertices(f);
        let fe = t.face_edges(f);
        let n = fv.len();
        let base = t.face_offset(f);
        for i in 0..n {
            let child_edges = child_topology.face_edges(base + i);
            child_edge_sharpness[child_edges[0] as usize] =
                parent.half_edge_sharpness(fe[i], fv[i]);
            child_edge_sharpness[child_edges[3] as usize] =
                parent.half_edge_sharpness(fe[(i + n - 1) % n], fv[i]);
        }
    }
    Level {
        topology: child_topology,
        edge_sharpness: child_edge_sharpness,
        vertex_sharpness: child_vertex_sharpness,
        creasing: parent.creasing,
    }
}

/// The stencils of the child vertices `vertices` of `parent`, in that order: the rows of
/// [`refine`]'s table for them, so that applied they give its data bit for bit. For a face
/// refined locally, whose next depth keeps a few of the child's faces.
pub fn refine_stencils_at(parent: &Level, vertices: &[u32]) -> Stencils {
    let terms = stencil_terms(parent);
    let mut stencils = Stencils::with_capacity(vertices.len(), 10 * vertices.len());
    let mut buffer = Vec::with_capacity(64);
    for &v in vertices {
        terms(v as usize, &mut buffer);
        stencils.push(&mut buffer);
    }
    stencils
}

/// The data of the child of `parent`: equal to `refine(parent).1.apply(data)`, bit for bit,
/// but without building the child level or keeping the stencil table (each range of stencils
/// is built, applied and dropped). For the last level of a refinement, when only its data is
/// needed.
pub fn refine_data(parent: &Level, data: &[VertexData]) -> Vec<VertexData> {
    use rayon::prelude::*;
    let t = &parent.topology;
    let n = t.face_count() + t.edge_count() + t.vertex_count();
    let terms = stencil_terms(parent);
    let mut out = vec![VertexData::ZERO; n];
    out.par_chunks_mut(STENCIL_CHUNK)
        .enumerate()
        .for_each(|(k, chunk)| {
            let first = k * STENCIL_CHUNK;
            build_range(first..first + chunk.len(), &terms).apply_into(data, chunk);
        });
    out
}

/// Stencils built per task (and held at once per thread by [`refine_data`]).
const STENCIL_CHUNK: usize = 1 << 14;

/// The stencils `r` (numbered from 0 in the result) of the terms `terms(i, buffer)` pushes.
fn build_range(
    r: std::ops::Range<usize>,
    terms: &(impl Fn(usize, &mut Vec<(u32, f64)>) + Sync),
) -> Stencils {
    let mut stencils = Stencils::with_capacity(r.len(), 10 * r.len());
    let mut buffer = Vec::with_capacity(64);
    for i in r {
        terms(i, &mut buffer);
        stencils.push(&mut buffer);
    }
    stencils
}

/// The terms of child vertex `i` of `parent`: face points, then edge points, then vertex
/// points. Needs nothing of the child level: the child rule of a vertex point comes from the
/// halves of its parent edges, which are its child edges in the same ring order.
fn stencil_terms(parent: &Level) -> impl Fn(usize, &mut Vec<(u32, f64)>) + Sync + '_ {
    let t = &parent.topology;
    let (nf, ne) = (t.face_count(), t.edge_count());
    let face_stencil = move |f: usize, terms: &mut Vec<(u32, f64)>| {
        face_centroid_terms(t, f, 1.0, terms);
    };
    let edge_stencil = move |e: usize, terms: &mut Vec<(u32, f64)>| {
        let [a, b] = t.edge_vertices(e);
        let s = parent.edge_sharpness[e];
        let [f0, f1] = t.edge_faces(e);
        // Crease weight: 1 for sharpness >= 1 or a boundary, fractional in between.
        let crease = if f1 == INVALID {
            1.0
        } else {
            s.clamp(0.0, 1.0)
        };
        terms.push((a, 0.5 * crease));
        terms.push((b, 0.5 * crease));
        if crease < 1.0 {
            let smooth = 1.0 - crease;
            terms.push((a, 0.25 * smooth));
            terms.push((b, 0.25 * smooth));
            face_centroid_terms(t, f0 as usize, 0.25 * smooth, terms);
            face_centroid_terms(t, f1 as usize, 0.25 * smooth, terms);
        }
    };
    let vertex_stencil = move |v: usize, terms: &mut Vec<(u32, f64)>| {
        let parent_rule = parent.vertex_rule(v);
        let child_vertex_sharpness = rules::decrement_sharpness(parent.vertex_sharpness[v]);
        let child_sharp_count = t
            .vertex_edges(v)
            .iter()
            .filter(|&&e| rules::is_sharp(parent.half_edge_sharpness(e, v as u32)))
            .count();
        let child_rule = rules::vertex_rule(child_vertex_sharpness, child_sharp_count);
        let parent_sharp =
            |k: usize| rules::is_sharp(parent.edge_sharpness[t.vertex_edges(v)[k] as usize]);
        if parent_rule == child_rule || parent_rule <= VertexRule::Dart {
            vertex_mask_terms(parent, v, parent_rule, parent_sharp, 1.0, terms);
        } else {
            // The rule relaxes at this level: blend the two masks (Pixar's semi-sharp rule).
            // Child ring edge k is the half of parent ring edge k at this vertex.
            let child_incident: Vec<f64> = t
                .vertex_edges(v)
                .iter()
                .map(|&e| parent.half_edge_sharpness(e, v as u32))
                .collect();
            let child_sharp = |k: usize| rules::is_sharp(child_incident[k]);
            let w = rules::fractional_weight(
                parent.vertex_sharpness[v],
                child_vertex_sharpness,
                &parent.incident_sharpness(v),
                &child_incident,
            );
            vertex_mask_terms(parent, v, parent_rule, parent_sharp, w, terms);
            vertex_mask_terms(parent, v, child_rule, child_sharp, 1.0 - w, terms);
        }
    };
    move |i: usize, terms: &mut Vec<(u32, f64)>| {
        if i < nf {
            face_stencil(i, terms)
        } else if i < nf + ne {
            edge_stencil(i - nf, terms)
        } else {
            vertex_stencil(i - nf - ne, terms)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::{CreasingMethod, SHARPNESS_INFINITE};

    fn level(faces: &[Vec<u32>], nv: usize) -> Level {
        let topology = Topology::from_faces(nv, faces).unwrap();
        let edge_sharpness = (0..topology.edge_count())
            .map(|e| {
                if topology.is_boundary_edge(e) {
                    SHARPNESS_INFINITE
                } else {
                    0.0
                }
            })
            .collect();
        Level {
            vertex_sharpness: vec![0.0; nv],
            topology,
            edge_sharpness,
            creasing: CreasingMethod::Uniform,
        }
    }

    fn weights_of(st: &Stencils, i: usize) -> Vec<(u32, f64)> {
        let (s, w) = st.stencil(i);
        s.iter().copied().zip(w.iter().copied()).collect()
    }

    /// A closed star: valence-n vertex 0 in the middle of n quads, with the outer ring
    /// closed off... here: an open fan of n quads around vertex 0, whose centre is interior.
    fn quad_fan(n: u32) -> (Vec<Vec<u32>>, usize) {
        // Vertex 0 centre; spokes 1..=n; diagonals n+1..=2n.
        let faces = (0..n)
            .map(|i| vec![0, 1 + i, n + 1 + i, 1 + (i + 1) % n])
            .collect();
        (faces, 1 + 2 * n as usize)
    }

    #[test]
    fn smooth_vertex_mask_of_a_star() {
        for n in 3..=7u32 {
            let (faces, nv) = quad_fan(n);
            let l = level(&faces, nv);
            let (_, st) = refine(&l);
            let (nf, ne) = (l.topology.face_count(), l.topology.edge_count());
            let w = weights_of(&st, nf + ne);
            let nn = n as f64;
            // Centre: (n-2)/n + n * 1/n^2 * 1/4 (its share of every face centroid).
            let centre = w.iter().find(|t| t.0 == 0).unwrap().1;
            assert!((centre - ((nn - 2.0) / nn + 1.0 / (4.0 * nn))).abs() < 1e-12);
            // Spoke: 1/n^2 as edge neighbour + 2 faces * 1/(4 n^2).
            let spoke = w.iter().find(|t| t.0 == 1).unwrap().1;
            assert!((spoke - 1.5 / (nn * nn)).abs() < 1e-12);
            // Diagonal: one face * 1/(4 n^2).
            let diag = w.iter().find(|t| t.0 == n + 1).unwrap().1;
            assert!((diag - 0.25 / (nn * nn)).abs() < 1e-12);
            let total: f64 = w.iter().map(|t| t.1).sum();
            assert!((total - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn crease_and_corner_masks() {
        // Boundary vertex of a 2x1 strip: B-spline curve rule (1, 6, 1) / 8.
        let faces = vec![vec![0, 1, 4, 3], vec![1, 2, 5, 4]];
        let l = level(&faces, 6);
        let (child, st) = refine(&l);
        let (nf, ne) = (2, 7);
        let w = weights_of(&st, nf + ne + 1);
        assert_eq!(w, vec![(0, 0.125), (1, 0.75), (2, 0.125)]);
        // Corner rule under edge-and-corner is decided by vertex sharpness: here none, so the
        // single-face vertex 0 is a crease with its two boundary edges.
        assert_eq!(l.vertex_rule(0), VertexRule::Crease);
        let mut l2 = l.clone();
        l2.vertex_sharpness[0] = SHARPNESS_INFINITE;
        let (_, st2) = refine(&l2);
        assert_eq!(weights_of(&st2, nf + ne), vec![(0, 1.0)]);
        // Boundary edge point: midpoint.
        let boundary_edge = (0..ne).find(|&e| l.topology.is_boundary_edge(e)).unwrap();
        let [a, b] = l.topology.edge_vertices(boundary_edge);
        let mut expect = vec![(a, 0.5), (b, 0.5)];
        expect.sort_by_key(|t| t.0);
        assert_eq!(weights_of(&st, nf + boundary_edge), expect);
        assert!(child.topology.is_all_quads());
        assert_eq!(
            child.topology.euler_characteristic(),
            l.topology.euler_characteristic()
        );
    }

    #[test]
    fn dart_uses_the_smooth_mask_and_semi_sharp_edges_blend() {
        let (faces, nv) = quad_fan(5);
        let mut l = level(&faces, nv);
        let spoke = (0..l.topology.edge_count())
            .find(|&e| {
                let [a, b] = l.topology.edge_vertices(e);
                (a.min(b), a.max(b)) == (0, 1)
            })
            .unwrap();
        let smooth = refine(&l).1;
        l.edge_sharpness[spoke] = SHARPNESS_INFINITE;
        let (nf, ne) = (l.topology.face_count(), l.topology.edge_count());
        let dart = refine(&l).1;
        assert_eq!(l.vertex_rule(0), VertexRule::Dart);
        assert_eq!(weights_of(&dart, nf + ne), weights_of(&smooth, nf + ne));
        // A semi-sharp spoke of sharpness 0.25: its edge point blends midpoint and smooth rule.
        l.edge_sharpness[spoke] = 0.25;
        let semi = refine(&l).1;
        let (s, w) = semi.stencil(nf + spoke);
        let (s0, w0) = smooth.stencil(nf + spoke);
        let weight = |src: &[u32], wt: &[f64], v: u32| {
            src.iter().position(|&x| x == v).map_or(0.0, |k| wt[k])
        };
        let expect = 0.75 * weight(s0, w0, 0) + 0.25 * 0.5;
        assert!((weight(s, w, 0) - expect).abs() < 1e-12);
    }

    #[test]
    fn regular_grid_matches_uniform_bspline_refinement() {
        // Interior vertex of a regular grid: (1/64) * [1 6 1; 6 36 6; 1 6 1].
        let n = 4u32;
        let mut faces = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let v = j * (n + 1) + i;
                faces.push(vec![v, v + 1, v + n + 2, v + n + 1]);
            }
        }
        let l = level(&faces, 25);
        let (_, st) = refine(&l);
        let (nf, ne) = (16, 40);
        let centre = 12u32;
        let w = weights_of(&st, nf + ne + centre as usize);
        for (s, wt) in w {
            let (dx, dy) = (
                (s as i32 % 5 - 2).unsigned_abs(),
                (s as i32 / 5 - 2).unsigned_abs(),
            );
            let f = |d: u32| match d {
                0 => 6.0,
                1 => 1.0,
                _ => 0.0,
            };
            assert!((wt - f(dx) * f(dy) / 64.0).abs() < 1e-12, "{s}: {wt}");
        }
    }
}
