//! Multi-resolution edits (paper section 5): colour, opacity and position changes to vertices
//! of refined levels, kept in the document and applied during refinement.
//!
//! # Addressing
//!
//! A refined vertex is named through the coarse element it descends from, so that the name
//! depends on the control mesh's connectivity only: moving, recolouring or re-handling the
//! coarse mesh leaves every edit on its element. Each face is cut into one *sector* per corner
//! (the part of the face nearer that corner than the others, bounded by the face's edge midpoints
//! and its centre); a [`VertexAddress`] names a face, the control point at one of its corners,
//! a level and integer coordinates `at = [i, j]` in that sector's grid:
//!
//! - `i` runs along the face's edge from the corner towards the next corner (winding order),
//!   `j` along the edge towards the previous corner;
//! - at level 1 (the ternary step) the sector holds four vertices: `[0, 0]` the vertex point of
//!   the control point, `[1, 0]` and `[0, 1]` the edge points near it on the next and previous
//!   edges, `[1, 1]` the face point at that corner;
//! - at level `k >= 2` the sector is a grid of `m x m` quads, `m = 3 * 2^(k - 2)`: `[0, 0]` the
//!   corner, `[m, 0]` the midpoint of the next edge, `[0, m]` that of the previous edge,
//!   `[m, m]` the face's centre. Each Catmull-Clark step doubles the coordinates: the vertex point
//!   of `[i, j]` is `[2i, 2j]`, odd coordinates are edge and face points.
//!
//! Vertices on a sector's sides have several names (one per sector that touches them); two
//! edits may not name the same vertex.
//!
//! # What an edit does
//!
//! Edits of level `k` are applied to the level-`k` data right after it is computed, before the
//! next step, all at once (each reads the data as subdivision left it):
//!
//! - **Colour and opacity** give the vertex a target: the colour the subdivision gives there
//!   plus an offset (relative, the default: the detail follows coarse recolouring), or a colour
//!   given outright (absolute). The vertex takes the target, and so does its whole ring after
//!   the next step (its vertex point and the edge and face points around it): the same
//!   construction the ternary step makes around each control point, so the target is the limit
//!   colour at that vertex exactly, and every colour stays inside the hull of the colours in
//!   play. A ring point shared by several edited vertices takes the mean of their targets.
//!   An edit on a control point's own vertex or next to it (sector coordinates both at most 1)
//!   therefore changes that control point's limit colour: the paper's Condition 1 then holds
//!   at the edit, not at the point.
//! - **Position** is an offset in the vertex's local frame: `offset[0]` times the sector grid's
//!   edge from the vertex in direction `i`, plus `offset[1]` times its edge in direction `j`
//!   (the edges of level `k`, before this level's edits). Subdivision commutes with affine
//!   maps, so moving, rotating or scaling the coarse mesh carries the details along. A vertex on
//!   a discontinuous edge moves with its copies on the other side.
//!
//! Relative colour offsets are in the mesh's colour space. Edits need the ternary first step.

use std::collections::HashMap;

use kurbo::Vec2;

use crate::edit_check::{CheckedEdit, EditSet};
use crate::multires::{ColourEdit, OpacityEdit, VertexAddress};
use crate::ternary_step;
use crate::topology::{Topology, INVALID};
use crate::validate::{BaseMesh, VertexData};

// ---------------------------------------------------------------------------------------------
// Finding the vertex an address names

/// The edge between `a` and `b`, if any.
fn find_edge(t: &Topology, a: u32, b: u32) -> Option<u32> {
    t.vertex_edges(a as usize)
        .iter()
        .copied()
        .find(|&e| t.other_vertex(e as usize, a) == b)
}

/// The face on edge `a`-`b` that also has corner `c`.
fn find_face(t: &Topology, a: u32, b: u32, c: u32) -> Option<u32> {
    let e = find_edge(t, a, b)?;
    t.edge_faces(e as usize)
        .into_iter()
        .find(|&f| f != INVALID && t.face_vertices(f as usize).contains(&c))
}

/// Indices of the three kinds of point a Catmull-Clark step makes from level `t`.
struct Children<'a> {
    t: &'a Topology,
}

impl Children<'_> {
    fn face_point(&self, f: u32) -> u32 {
        f
    }
    fn edge_point(&self, a: u32, b: u32) -> Option<u32> {
        find_edge(self.t, a, b).map(|e| (self.t.face_count() as u32) + e)
    }
    fn vertex_point(&self, v: u32) -> u32 {
        (self.t.face_count() + self.t.edge_count()) as u32 + v
    }
}

/// Resolves sector coordinates to vertex indices, level by level, remembering what it found.
pub(crate) struct Resolver<'a> {
    base: &'a Topology,
    /// `levels[k - 1]` is the topology of level `k`.
    levels: Vec<&'a Topology>,
    face: usize,
    corner: usize,
    memo: HashMap<(usize, u32, u32), u32>,
}

impl<'a> Resolver<'a> {
    /// A resolver for the sector of `face` at `corner` (its position in the face). `levels`
    /// holds the topology of levels 1, 2, ... as deep as will be asked.
    pub fn new(base: &'a Topology, levels: Vec<&'a Topology>, face: usize, corner: usize) -> Self {
        Resolver {
            base,
            levels,
            face,
            corner,
            memo: HashMap::new(),
        }
    }

    /// The level-1 points around the sector: `[A, B, C, D, B', D', C', D'']` as in
    /// [`Resolver::at_level_2`].
    fn level_1_points(&self) -> [u32; 8] {
        let t = self.base;
        let f = self.face;
        let n = t.face_vertices(f).len();
        let c = self.corner;
        let (next, prev) = ((c + 1) % n, (c + n - 1) % n);
        let verts = t.face_vertices(f);
        let (v, w, u) = (verts[c], verts[next], verts[prev]);
        let edges = t.face_edges(f);
        let (e_next, e_prev) = (edges[c], edges[prev]);
        let end = |e: u32, x: u32| usize::from(t.edge_vertices(e as usize)[0] != x);
        let offset = t.face_offset(f);
        [
            ternary_step::vertex_point(v),
            ternary_step::edge_point(t, e_next, end(e_next, v)),
            ternary_step::edge_point(t, e_prev, end(e_prev, v)),
            ternary_step::face_point(t, offset + c),
            ternary_step::edge_point(t, e_next, end(e_next, w)),
            ternary_step::face_point(t, offset + next),
            ternary_step::edge_point(t, e_prev, end(e_prev, u)),
            ternary_step::face_point(t, offset + prev),
        ]
    }

    /// The level-2 vertex at `[i, j]`, `i, j <= 3`, from the level-1 topology. With `A` the
    /// corner's vertex point, `B`/`C` the edge points near it on the next/previous edge, `D` the
    /// face point at the corner, `B'`, `C'` the other edge points on those edges and `D'`, `D''`
    /// the face points at the next and previous corners:
    /// ```text
    ///   j=3  EP(C C')   FP(C C' D'' D)  EP(D D'')  FP(centre)
    ///   j=2  VP(C)      EP(C D)         VP(D)      EP(D D')
    ///   j=1  EP(A C)    FP(A B D C)     EP(B D)    FP(B B' D' D)
    ///   j=0  VP(A)      EP(A B)         VP(B)      EP(B B')
    ///        i=0        i=1             i=2        i=3
    /// ```
    fn at_level_2(&self, i: u32, j: u32) -> Option<u32> {
        let t1 = *self.levels.first()?;
        let [a, b, c, d, b2, d2, c2, d3] = self.level_1_points();
        let k = Children { t: t1 };
        let face = |x, y, z| find_face(t1, x, y, z).map(|f| k.face_point(f));
        match (i, j) {
            (0, 0) => Some(k.vertex_point(a)),
            (2, 0) => Some(k.vertex_point(b)),
            (0, 2) => Some(k.vertex_point(c)),
            (2, 2) => Some(k.vertex_point(d)),
            (1, 0) => k.edge_point(a, b),
            (0, 1) => k.edge_point(a, c),
            (2, 1) => k.edge_point(b, d),
            (1, 2) => k.edge_point(c, d),
            (1, 1) => face(a, b, d),
            (3, 0) => k.edge_point(b, b2),
            (3, 1) => face(b, b2, d2),
            (3, 2) => k.edge_point(d, d2),
            (0, 3) => k.edge_point(c, c2),
            (1, 3) => face(c, c2, d3),
            (2, 3) => k.edge_point(d, d3),
            (3, 3) => {
                Some(k.face_point(ternary_step::first_child_face(self.base, self.face) as u32))
            }
            _ => None,
        }
    }

    /// The index at `level` of the vertex at `[i, j]`, or `None` if the level is not built (or
    /// the coordinates are outside the sector).
    pub fn vertex(&mut self, level: usize, i: u32, j: u32) -> Option<u32> {
        if level > self.levels.len() {
            return None;
        }
        if let Some(&v) = self.memo.get(&(level, i, j)) {
            return Some(v);
        }
        let found = match level {
            0 => None,
            1 => {
                let p = self.level_1_points();
                match (i, j) {
                    (0, 0) => Some(p[0]),
                    (1, 0) => Some(p[1]),
                    (0, 1) => Some(p[2]),
                    (1, 1) => Some(p[3]),
                    _ => None,
                }
            }
            2 => self.at_level_2(i, j),
            _ => {
                let parent = *self.levels.get(level - 2)?;
                let k = Children { t: parent };
                let (lo_i, hi_i, lo_j, hi_j) = (i / 2, i.div_ceil(2), j / 2, j.div_ceil(2));
                match (i % 2, j % 2) {
                    (0, 0) => self
                        .vertex(level - 1, lo_i, lo_j)
                        .map(|v| k.vertex_point(v)),
                    (1, 0) | (0, 1) => {
                        let a = self.vertex(level - 1, lo_i, lo_j)?;
                        let b = self.vertex(level - 1, hi_i, hi_j)?;
                        k.edge_point(a, b)
                    }
                    _ => {
                        let a = self.vertex(level - 1, lo_i, lo_j)?;
                        let b = self.vertex(level - 1, hi_i, lo_j)?;
                        let c = self.vertex(level - 1, hi_i, hi_j)?;
                        find_face(parent, a, b, c).map(|f| k.face_point(f))
                    }
                }
            }
        };
        if let Some(v) = found {
            self.memo.insert((level, i, j), v);
        }
        found
    }
}

// ---------------------------------------------------------------------------------------------
// Applying edits

/// One edit located at its level.
struct Located<'e> {
    edit: &'e CheckedEdit,
    vertex: u32,
    /// The sector grid's edges from the vertex in directions `i` and `j`, as vertex pairs.
    frame: Option<[[u32; 2]; 2]>,
}

/// Locates the edits of `level`. `levels[k - 1]` is the topology of level `k`, built at least
/// down to `level`.
///
/// Checked edits always resolve to distinct vertices; an edit that did not (a bug) is skipped
/// rather than stopping the evaluation.
fn locate<'e>(
    base: &Topology,
    levels: &[&Topology],
    set: &'e EditSet,
    level: usize,
) -> Vec<Located<'e>> {
    let mut out = Vec::new();
    let mut taken = std::collections::HashSet::new();
    for ce in &set.edits {
        let a = ce.edit.address;
        if a.level as usize != level {
            continue;
        }
        let mut r = Resolver::new(base, levels[..level].to_vec(), a.face as usize, ce.corner);
        let [i, j] = a.at;
        let Some(vertex) = r.vertex(level, i, j) else {
            debug_assert!(false, "edit {} ({a}) names no vertex", ce.index);
            continue;
        };
        if !taken.insert(vertex) {
            debug_assert!(
                false,
                "edit {} ({a}) names a vertex already edited",
                ce.index
            );
            continue;
        }
        let frame = match ce.edit.offset {
            Some(_) => {
                let m = VertexAddress::sector_size(a.level);
                let step = |x: u32| if x < m { x + 1 } else { x - 1 };
                let (si, sj) = (step(i), step(j));
                let (Some(ni), Some(nj)) = (r.vertex(level, si, j), r.vertex(level, i, sj)) else {
                    debug_assert!(false, "edit {} ({a}) has no frame", ce.index);
                    continue;
                };
                // Pairs (from, to) so that `to - from` points along +i and +j.
                let pi = if si > i { [vertex, ni] } else { [ni, vertex] };
                let pj = if sj > j { [vertex, nj] } else { [nj, vertex] };
                Some([pi, pj])
            }
            None => None,
        };
        out.push(Located {
            edit: ce,
            vertex,
            frame,
        });
    }
    out
}

/// The boundary vertices of a level sorted by x, to find the copies of a vertex across
/// discontinuous edges (the same position, another vertex) without a scan per edit.
struct BoundaryIndex {
    by_x: Vec<(f64, u32)>,
}

impl BoundaryIndex {
    fn new(t: &Topology, data: &[VertexData]) -> Self {
        let mut by_x: Vec<(f64, u32)> = (0..t.vertex_count() as u32)
            .filter(|&w| t.is_boundary_vertex(w as usize))
            .map(|w| (data[w as usize].position[0], w))
            .collect();
        by_x.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        BoundaryIndex { by_x }
    }

    /// The other boundary vertices at the position of `v`.
    fn copies(&self, data: &[VertexData], v: u32) -> Vec<u32> {
        let p = data[v as usize].position;
        let tol = 1e-12 * (1.0 + p[0].abs().max(p[1].abs()));
        let start = self.by_x.partition_point(|&(x, _)| x < p[0] - tol);
        self.by_x[start..]
            .iter()
            .take_while(|&&(x, _)| x <= p[0] + tol)
            .map(|&(_, w)| w)
            .filter(|&w| w != v && (data[w as usize].position[1] - p[1]).abs() <= tol)
            .collect()
    }
}

/// Applies the edits of `level` to its data, after flattening the rings of the previous level's
/// colour edits. `levels[k - 1]` is the topology of level `k`; `previous` is the data of level
/// `level - 1` after its own edits (ignored at level 1).
pub(crate) fn apply(
    base: &BaseMesh,
    levels: &[&Topology],
    set: &EditSet,
    level: usize,
    previous: Option<&[VertexData]>,
    data: &mut [VertexData],
) {
    let working = set.working;
    if set.edits.is_empty() {
        return;
    }
    if level >= 2 {
        if let Some(prev) = previous {
            flatten_rings(base, levels, set, level - 1, prev, data);
        }
    }
    let located = locate(&base.topology, levels, set, level);
    if located.is_empty() {
        return;
    }
    let t = levels[level - 1];
    // Every change is computed from the data as subdivision left it, then written.
    let mut writes: Vec<(u32, VertexData)> = Vec::with_capacity(located.len());
    let mut moves: Vec<(u32, Vec2)> = Vec::new();
    let mut boundary: Option<BoundaryIndex> = None;
    for l in &located {
        let mut d = data[l.vertex as usize];
        let old = d;
        match l.edit.edit.colour {
            Some(ColourEdit::Set(c)) => {
                let c = set.space.convert(working, c);
                d.colour = c;
            }
            Some(ColourEdit::Offset(delta)) => {
                let here = old.colour;
                let target = if set.space == working {
                    [here[0] + delta[0], here[1] + delta[1], here[2] + delta[2]]
                } else {
                    let c = working.convert(set.space, here);
                    set.space
                        .convert(working, [c[0] + delta[0], c[1] + delta[1], c[2] + delta[2]])
                };
                d.colour = target;
            }
            None => {}
        }
        match l.edit.edit.opacity {
            Some(OpacityEdit::Set(o)) => d.opacity = o,
            Some(OpacityEdit::Offset(o)) => d.opacity = (old.opacity + o).clamp(0.0, 1.0),
            None => {}
        }
        if let (Some(off), Some([pi, pj])) = (l.edit.edit.offset, l.frame) {
            let edge = |[a, b]: [u32; 2]| {
                let (p, q) = (data[a as usize].point(), data[b as usize].point());
                q - p
            };
            let delta = edge(pi) * off.x + edge(pj) * off.y;
            moves.push((l.vertex, delta));
            if t.is_boundary_vertex(l.vertex as usize) {
                let index = boundary.get_or_insert_with(|| BoundaryIndex::new(t, data));
                for w in index.copies(data, l.vertex) {
                    moves.push((w, delta));
                }
            }
        }
        writes.push((l.vertex, d));
    }
    for (v, d) in writes {
        data[v as usize].colour = d.colour;
        data[v as usize].opacity = d.opacity;
    }
    for (v, delta) in moves {
        data[v as usize].position[0] += delta.x;
        data[v as usize].position[1] += delta.y;
    }
}

/// Gives the ring after the step of every colour-edited vertex of `level` (its vertex point and
/// the edge and face points around it, numbered as [`crate::catmull_clark`] numbers level
/// `level + 1`) the vertex's edited colour or opacity; shared ring points take the mean.
fn flatten_rings(
    base: &BaseMesh,
    levels: &[&Topology],
    set: &EditSet,
    level: usize,
    previous: &[VertexData],
    next: &mut [VertexData],
) {
    let located = locate(&base.topology, levels, set, level);
    let t = levels[level - 1];
    let k = Children { t };
    // Per ring point: colour sum and count, opacity sum and count.
    let mut sums: HashMap<u32, ([f64; 3], u32, f64, u32)> = HashMap::new();
    for l in located.iter().filter(|l| l.edit.edit.changes_colour()) {
        let v = l.vertex;
        let d = previous[v as usize];
        let ring = std::iter::once(k.vertex_point(v))
            .chain(
                t.vertex_edges(v as usize)
                    .iter()
                    .map(|&e| t.face_count() as u32 + e),
            )
            .chain(t.vertex_faces(v as usize).iter().map(|&f| k.face_point(f)));
        for p in ring {
            let s = sums.entry(p).or_insert(([0.0; 3], 0, 0.0, 0));
            if l.edit.edit.colour.is_some() {
                for c in 0..3 {
                    s.0[c] += d.colour[c];
                }
                s.1 += 1;
            }
            if l.edit.edit.opacity.is_some() {
                s.2 += d.opacity;
                s.3 += 1;
            }
        }
    }
    for (p, (c, nc, o, no)) in sums {
        let d = &mut next[p as usize];
        if nc > 0 {
            d.colour = c.map(|c| c / nc as f64);
        }
        if no > 0 {
            d.opacity = o / no as f64;
        }
    }
}

/// The index at its level of the vertex an edit names, given the topology of levels 1 to that
/// level (`levels[k - 1]` is level `k`).
pub(crate) fn vertex_of(base: &Topology, levels: &[&Topology], edit: &CheckedEdit) -> Option<u32> {
    let a = edit.edit.address;
    let level = a.level as usize;
    if level > levels.len() {
        return None;
    }
    Resolver::new(base, levels[..level].to_vec(), a.face as usize, edit.corner)
        .vertex(level, a.at[0], a.at[1])
}
