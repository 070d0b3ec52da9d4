//! Feature-adaptive evaluation of the limit surface, face by face of a low, all-quad level.
//!
//! A face of such a level whose corners are regular (interior of valence 4, regular boundary of
//! valence 3 or a corner with one face; no sharp or semi-sharp edge at them other than the
//! boundary, no vertex sharpness other than an infinitely sharp corner) is exactly a uniform
//! bicubic B-spline patch of its 16 surrounding points, in position as in colour and opacity,
//! because every later level applies the regular rules there. Missing points beyond a boundary
//! are phantoms `2 b - interior`, which reproduce the boundary rules (midpoint edges, `(1 6 1) / 8`
//! vertices, fixed corners), as OpenSubdiv's boundary and corner patches do. Such a patch is
//! evaluated directly on a grid of any density.
//!
//! Any other face (next to an extraordinary vertex, a crease or a semi-sharp feature) is
//! refined locally: the faces around its corners, extracted as a small mesh with their
//! sharpness, determine its whole limit surface, so refining that small mesh and applying the
//! limit stencils gives the same grid as refining the whole layer would.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use crate::catmull_clark::{self, Stencils};
use crate::level::Level;
use crate::limit_surface as limit;
use crate::mesh::{BoundaryInterpolation, CreasingMethod};
use crate::rules::{self, VertexRule};
use crate::topology::Topology;
use crate::validate::VertexData;
use rayon::prelude::*;

/// Samples `(n + 1)^2` of the limit surface over one face, row by row: index `j * (n + 1) + i`
/// is at parameter `(i / n, j / n)`, `u` running from the face's corner 0 to corner 1 and `v`
/// from corner 0 to corner 3.
pub(crate) type Grid = Vec<VertexData>;

/// The 16 control points of a regular patch: `cp[j][i]`, `i` along `u`, `j` along `v`; the
/// face's corners are `cp[1][1]`, `cp[1][2]`, `cp[2][2]` and `cp[2][1]`.
pub(crate) type ControlGrid = [[VertexData; 4]; 4];

/// The vertices of a regular patch's control grid, as [`ControlGrid`] places them; `None`
/// where a phantom point lies beyond a boundary.
type PatchPoints = [[Option<u32>; 4]; 4];

/// Where corner `c` of the face sits in the control grid, as `(i, j)`.
const GRID_CORNERS: [(isize, isize); 4] = [(1, 1), (2, 1), (2, 2), (1, 2)];

/// The uniform cubic B-spline basis functions at `t` in `0..=1`.
pub(crate) fn bspline_basis(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    let (t2, t3) = (t * t, t * t * t);
    [
        s * s * s / 6.0,
        (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0,
        (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0,
        t3 / 6.0,
    ]
}

/// The patch of `cp` at parameter `(u, v)`.
#[cfg(test)]
pub(crate) fn evaluate_patch_at(cp: &ControlGrid, u: f64, v: f64) -> VertexData {
    let (bu, bv) = (bspline_basis(u), bspline_basis(v));
    let mut p = VertexData::ZERO;
    for (j, row) in cp.iter().enumerate() {
        for (i, point) in row.iter().enumerate() {
            p.add_scaled(point, bu[i] * bv[j]);
        }
    }
    p
}

/// The patch of `cp` on a grid of `n x n` cells.
pub(crate) fn evaluate_patch(cp: &ControlGrid, n: usize) -> Grid {
    let mut out = Vec::with_capacity((n + 1) * (n + 1));
    evaluate_patch_with(cp, n, |_, _, p| out.push(p));
    out
}

/// [`evaluate_patch`] into `out` (cleared first), reusing its memory.
pub(crate) fn evaluate_patch_into(cp: &ControlGrid, n: usize, out: &mut Grid) {
    out.clear();
    out.reserve((n + 1) * (n + 1));
    evaluate_patch_with(cp, n, |_, _, p| out.push(p));
}

/// Calls `put(i, j, p)` with the patch of `cp` at parameter `(i / n, j / n)`, row by row.
fn evaluate_patch_with(cp: &ControlGrid, n: usize, mut put: impl FnMut(usize, usize, VertexData)) {
    // Most faces stop at a few cells: their basis values stay on the stack.
    let (mut small, mut large) = ([[0.0; 4]; 17], Vec::new());
    let basis: &mut [[f64; 4]] = if n < small.len() {
        &mut small[..=n]
    } else {
        large.resize(n + 1, [0.0; 4]);
        &mut large
    };
    for (i, b) in basis.iter_mut().enumerate() {
        *b = bspline_basis(i as f64 / n as f64);
    }
    for (j, bv) in basis.iter().enumerate() {
        // The four columns collapsed to this row's curve first: 16 then 4 terms per sample.
        let mut q = [VertexData::ZERO; 4];
        for (i, qi) in q.iter_mut().enumerate() {
            for (j, row) in cp.iter().enumerate() {
                qi.add_scaled(&row[i], bv[j]);
            }
        }
        for (i, bu) in basis.iter().enumerate() {
            let mut p = VertexData::ZERO;
            for (i, qi) in q.iter().enumerate() {
                p.add_scaled(qi, bu[i]);
            }
            put(i, j, p);
        }
    }
}

/// Whether vertex `v` keeps the regular B-spline rules at every later level: interior of
/// valence 4, boundary of valence 3 or a corner with a single face, with no sharpness but the
/// boundary's (and the corner's).
fn regular_corner(level: &Level, v: usize) -> bool {
    let t = &level.topology;
    let edges = t.vertex_edges(v);
    let faces = t.vertex_faces(v);
    for &e in edges {
        let s = level.edge_sharpness[e as usize];
        let fine = if t.is_boundary_edge(e as usize) {
            rules::is_infinite(s)
        } else {
            s == 0.0
        };
        if !fine {
            return false;
        }
    }
    if faces
        .iter()
        .any(|&f| t.face_vertices(f as usize).len() != 4)
    {
        return false;
    }
    let sharpness = level.vertex_sharpness[v];
    match (t.is_boundary_vertex(v), faces.len(), edges.len()) {
        (false, 4, 4) | (true, 2, 3) => sharpness == 0.0,
        (true, 1, 2) => rules::is_infinite(sharpness) && level.vertex_rule(v) == VertexRule::Corner,
        _ => false,
    }
}

/// The control points of face `f` of `level` (with data `data`) if its limit surface is a
/// regular B-spline patch (see the module documentation), phantom points included.
#[cfg(test)]
pub(crate) fn regular_patch(level: &Level, data: &[VertexData], f: usize) -> Option<ControlGrid> {
    regular_patch_with(level, data, f, |v| regular_corner(level, v))
}

/// Whether each vertex of `level` is a `regular_patch` corner: computed once for a level,
/// rather than four times (once per face around it) by `regular_patch`.
pub(crate) fn regular_corners(level: &Level) -> Vec<bool> {
    (0..level.topology.vertex_count())
        .into_par_iter()
        .map(|v| regular_corner(level, v))
        .collect()
}

/// `regular_patch` with the corners' regularity given (see [`regular_corners`]).
pub(crate) fn regular_patch_with(
    level: &Level,
    data: &[VertexData],
    f: usize,
    regular: impl Fn(usize) -> bool,
) -> Option<ControlGrid> {
    regular_patch_points(level, f, regular)
        .map(|points| control_grid(&points, |v| data[v as usize]))
}

/// The vertices of `level` at the places of a `regular_patch`'s control grid (`None` for the
/// phantoms beyond a boundary), if face `f`'s limit surface is one: which it is, and where
/// its points are, depends on the topology alone.
fn regular_patch_points(
    level: &Level,
    f: usize,
    regular: impl Fn(usize) -> bool,
) -> Option<PatchPoints> {
    let t = &level.topology;
    let fv = t.face_vertices(f);
    if fv.len() != 4 {
        return None;
    }
    let mut index: PatchPoints = [[None; 4]; 4];
    // Each outer point is reached from two corners: both must agree.
    let mut put = |(i, j): (isize, isize), v: u32| -> bool {
        let slot = &mut index[j as usize][i as usize];
        match *slot {
            Some(w) => w == v,
            None => {
                *slot = Some(v);
                true
            }
        }
    };
    let add = |a: (isize, isize), b: (isize, isize)| (a.0 + b.0, a.1 + b.1);
    let sub = |a: (isize, isize), b: (isize, isize)| (a.0 - b.0, a.1 - b.1);
    for c in 0..4 {
        let v = fv[c] as usize;
        if !regular(v) {
            return None;
        }
        let (g, g_next, g_prev) = (
            GRID_CORNERS[c],
            GRID_CORNERS[(c + 1) % 4],
            GRID_CORNERS[(c + 3) % 4],
        );
        // Outward across the edge to the previous corner, and across the edge to the next.
        let (a, b) = (sub(g, g_next), sub(g, g_prev));
        if !put(g, v as u32) {
            return None;
        }
        let (next, prev) = (fv[(c + 1) % 4], fv[(c + 3) % 4]);
        for (&face, &corner) in t.vertex_faces(v).iter().zip(t.vertex_face_corners(v)) {
            if face as usize == f {
                continue;
            }
            let gv = t.face_vertices(face as usize);
            let k = corner as usize;
            let (after, opposite, before) = (gv[(k + 1) % 4], gv[(k + 2) % 4], gv[(k + 3) % 4]);
            let ok = if after == next || before == next {
                let other = if after == next { before } else { after };
                put(add(g, b), other) && put(add(g_next, b), opposite)
            } else if after == prev || before == prev {
                let other = if after == prev { before } else { after };
                put(add(g, a), other) && put(add(g_prev, a), opposite)
            } else {
                put(add(add(g, a), b), opposite)
            };
            if !ok {
                return None;
            }
        }
    }
    Some(index)
}

/// The control grid of a regular patch whose points are `points` ([`regular_patch_points`]),
/// reading the data of point `v` as `data(v)`, with the phantoms reflected.
fn control_grid(points: &PatchPoints, data: impl Fn(u32) -> VertexData) -> ControlGrid {
    let mut cp = [[VertexData::ZERO; 4]; 4];
    let mut real = [[false; 4]; 4];
    for j in 0..4 {
        for i in 0..4 {
            if let Some(v) = points[j][i] {
                cp[j][i] = data(v);
                real[j][i] = true;
            }
        }
    }
    let reflect =
        |a: VertexData, b: VertexData| -> VertexData { a.zip_with(&b, |a, b| 2.0 * a - b) };
    // Phantoms beside the face's sides first (from the face's own corners)...
    for m in 1..=2 {
        if !real[m][0] {
            cp[m][0] = reflect(cp[m][1], cp[m][2]);
        }
        if !real[m][3] {
            cp[m][3] = reflect(cp[m][2], cp[m][1]);
        }
        if !real[0][m] {
            cp[0][m] = reflect(cp[1][m], cp[2][m]);
        }
        if !real[3][m] {
            cp[3][m] = reflect(cp[2][m], cp[1][m]);
        }
    }
    // ...then the outer corners, reflected across the boundary: along whichever line towards
    // the face holds real points (both are phantoms at a corner of the mesh, and agree).
    for (j, i, dj, di) in [(0, 0, 1, 1), (0, 3, 1, -1), (3, 0, -1, 1), (3, 3, -1, -1)] {
        if real[j][i] {
            continue;
        }
        let (j1, j2) = ((j as isize + dj) as usize, (j as isize + 2 * dj) as usize);
        let (i1, i2) = ((i as isize + di) as usize, (i as isize + 2 * di) as usize);
        cp[j][i] = if real[j1][i] && real[j2][i] {
            reflect(cp[j1][i], cp[j2][i])
        } else {
            reflect(cp[j][i1], cp[j][i2])
        };
    }
    cp
}

/// One quad of a locally refined face at some depth: its index in that level, the face it
/// descends from (its index among the faces refined together), and where its corners 0, 1, 2,
/// 3 sit in that face's grid of `2^depth` cells a side (origin, step from corner 0 to 1, step
/// from corner 0 to 3).
#[derive(Clone, Copy, Debug)]
struct Tile {
    face: u32,
    root: u32,
    origin: [i64; 2],
    u: [i64; 2],
    v: [i64; 2],
}

impl Tile {
    /// The four quads this one becomes one level down, whose faces there start at `first`,
    /// placed in the grid of the next depth (twice as fine). Child `c` sits at corner `c`, its
    /// first side along side `c`, its last along side `c - 1`.
    fn children(&self, first: usize) -> [Tile; 4] {
        let o = [2 * self.origin[0], 2 * self.origin[1]];
        let (u, v) = (self.u, self.v);
        let corners = [
            o,
            [o[0] + 2 * u[0], o[1] + 2 * u[1]],
            [o[0] + 2 * (u[0] + v[0]), o[1] + 2 * (u[1] + v[1])],
            [o[0] + 2 * v[0], o[1] + 2 * v[1]],
        ];
        std::array::from_fn(|c| {
            let p = corners[c];
            let towards = |q: [i64; 2]| [(q[0] - p[0]) / 2, (q[1] - p[1]) / 2];
            Tile {
                face: (first + c) as u32,
                root: self.root,
                origin: p,
                u: towards(corners[(c + 1) % 4]),
                v: towards(corners[(c + 3) % 4]),
            }
        })
    }
}

/// One depth of a neighbourhood's local refinement, as far as it depends on the topology
/// alone. Every neighbourhood cut out the same way shares it ([`ShapeCache`]); each keeps its
/// own data, as rows ([`LocalPatch`]).
struct ShapeDepth {
    /// The faces around `tiles`, as their own mesh (`None` when no tile is left).
    local: Option<Level>,
    /// The row of this depth's data that holds each vertex of `local`.
    local_rows: Vec<u32>,
    /// This depth's rows from the last depth's (`None` at depth 0, whose rows are the
    /// cut-out vertices' own data, in `local`'s order).
    refine: Option<Stencils>,
    /// The faces' descendants at this depth that are refined further.
    tiles: Vec<Tile>,
    /// Their descendants at this depth whose limit surface is a B-spline patch, with the
    /// rows of its points: evaluated directly, never refined.
    patches: Vec<(Tile, PatchPoints)>,
    /// The limit stencils of the corners of `tiles` over this depth's rows, with a slot per
    /// vertex of `local` (`u32::MAX` for none), once asked for (`None` if they fail).
    corner_limits: OnceLock<Option<(Vec<u32>, Stencils)>>,
}

/// The local refinement of one shape of neighbourhood, deepened as far as some face asks.
///
/// Its depths are built under a lock, and a [`LocalPatch`] is refined further under its
/// owner's lock (the renderer's face planning): nothing under them waits in rayon (the `_sequential`
/// subdivision and stencils), since a thread waiting there may take on a task that wants the
/// same lock, and deadlock.
struct LocalShape {
    /// The depths built so far, and whether the next one failed (its faces did not form a
    /// valid mesh on their own).
    depths: Mutex<(Vec<Arc<ShapeDepth>>, bool)>,
}

impl LocalShape {
    /// Depth `d`, built with those above it if need be; `None` if that failed.
    fn depth(&self, d: usize) -> Option<Arc<ShapeDepth>> {
        let mut guard = self.depths.lock().unwrap_or_else(|e| e.into_inner());
        let (depths, failed) = &mut *guard;
        while depths.len() <= d {
            if *failed {
                return None;
            }
            match deepen(depths.last().expect("depth 0")) {
                Some(next) => depths.push(Arc::new(next)),
                None => {
                    *failed = true;
                    return None;
                }
            }
        }
        Some(Arc::clone(&depths[d]))
    }
}

/// What determines a neighbourhood's local refinement: the cut-out mesh (vertex count,
/// faces), the sharpness of each corner's edge and of each vertex (as bits), the creasing
/// method, and which local faces are refined (in root order).
#[derive(PartialEq, Eq, Hash)]
struct ShapeKey {
    vertex_count: usize,
    offsets: Vec<u32>,
    corners: Vec<u32>,
    edge_sharpness: Vec<u64>,
    vertex_sharpness: Vec<u64>,
    creasing: CreasingMethod,
    roots: Vec<u32>,
}

/// The shapes of neighbourhood one layer's faces have been refined in. The structure of local
/// refinement (topology, stencils, which descendants are patches) is most of its cost, and
/// the neighbourhoods of a layer's extraordinary vertices often have the same shape: Glasses
/// cuts out 96 neighbourhoods of about 35 shapes at 1024 px.
#[derive(Default)]
pub(crate) struct ShapeCache(Mutex<HashMap<ShapeKey, Option<Arc<LocalShape>>>>);

impl ShapeCache {
    /// How many shapes it holds.
    pub fn len(&self) -> usize {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).len()
    }
}

/// Faces refined on their own, feature-adaptively: at each depth the descendants that have
/// become regular patches are set aside, and only the faces around the others (which
/// determine their limit surface) are refined further. Next to an extraordinary vertex one
/// descendant a depth stays irregular, along a crease a row of them, so the work per depth
/// stays nearly constant instead of growing fourfold.
///
/// The faces around one extraordinary vertex refine overlapping neighbourhoods: refined
/// together, they share the work (their neighbourhoods together are about three faces', not
/// one per face).
pub(crate) struct LocalPatch {
    shape: Arc<LocalShape>,
    /// The depths of `shape` used so far: a snapshot, read without the lock.
    depths: Vec<Arc<ShapeDepth>>,
    /// This neighbourhood's data at each depth (see [`ShapeDepth`]).
    rows: Vec<Vec<VertexData>>,
    /// The limit points of each depth's tile corners, once asked for.
    corner_limits: Vec<Option<Vec<VertexData>>>,
}

/// The faces `keep` (sorted) of `level` as a mesh of their own, in which kept face `k` is face
/// `k` ([`local_face`]): its vertices (as indices of `level`, in their local order), face
/// offsets and corners.
fn cut_out(level: &Level, keep: &[u32]) -> (Vec<u32>, Vec<u32>, Vec<u32>) {
    let t = &level.topology;
    let mut vertices: Vec<u32> = Vec::new();
    // Flat, as the topology keeps them: a list per face cost an allocation per face.
    let mut offsets = Vec::with_capacity(keep.len() + 1);
    let mut corners = Vec::with_capacity(4 * keep.len());
    offsets.push(0u32);
    VERTEX_MAP.with(|cell| {
        let mut vertex_map = cell.borrow_mut();
        if vertex_map.len() < t.vertex_count() {
            vertex_map.resize(t.vertex_count(), u32::MAX);
        }
        for &g in keep {
            for &v in t.face_vertices(g as usize) {
                if vertex_map[v as usize] == u32::MAX {
                    vertex_map[v as usize] = vertices.len() as u32;
                    vertices.push(v);
                }
                corners.push(vertex_map[v as usize]);
            }
            offsets.push(corners.len() as u32);
        }
        for &v in &vertices {
            vertex_map[v as usize] = u32::MAX;
        }
    });
    (vertices, offsets, corners)
}

/// The mesh [`cut_out`] of `level` (`vertices`, `offsets`, `corners`), with its sharpness. The
/// cut around it becomes a boundary (infinitely sharp): it changes only points that the kept
/// faces' inner limit surface does not depend on. `None` if it is not a valid mesh.
fn local_level(
    level: &Level,
    vertices: &[u32],
    offsets: Vec<u32>,
    corners: Vec<u32>,
) -> Option<Level> {
    let t = &level.topology;
    let topology = Topology::build(vertices.len(), offsets, corners, |_, _| false).ok()?;
    let edge_sharpness = (0..topology.edge_count())
        .map(|e| {
            let [a, b] = topology.edge_vertices(e);
            let (ga, gb) = (vertices[a as usize], vertices[b as usize]);
            t.vertex_edges(ga as usize)
                .iter()
                .find(|&&ge| t.other_vertex(ge as usize, ga) == gb)
                .map_or(0.0, |&ge| level.edge_sharpness[ge as usize])
        })
        .collect();
    let vertex_sharpness = vertices
        .iter()
        .map(|&v| level.vertex_sharpness[v as usize])
        .collect();
    Some(Level::new(
        topology,
        edge_sharpness,
        vertex_sharpness,
        level.creasing,
        BoundaryInterpolation::EdgeOnly,
    ))
}

thread_local! {
    /// [`cut_out`]'s map from a level's vertices to the neighbourhood's, all `u32::MAX`
    /// between calls: allocated once per thread, so that cutting a face's neighbourhood out of
    /// a large level costs the neighbourhood's size, not the level's (it was two arrays the
    /// size of the whole level per irregular face).
    static VERTEX_MAP: std::cell::RefCell<Vec<u32>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// The index of face `g` of a level among the faces `keep` (sorted) cut out of it.
fn local_face(keep: &[u32], g: u32) -> u32 {
    keep.binary_search(&g).expect("a kept face") as u32
}

/// The faces of `t` that share a vertex with one of `tiles`, in increasing order.
fn neighbourhood(t: &Topology, tiles: &[Tile]) -> Vec<u32> {
    let around = || {
        tiles
            .iter()
            .flat_map(|tile| t.face_vertices(tile.face as usize))
            .flat_map(|&v| t.vertex_faces(v as usize).iter().copied())
    };
    // Deeper down the tiles cover most of a (small) local level: marking its faces costs
    // less than sorting a list with every face about sixteen times in it. A few tiles in a
    // large level (the first depth) are sorted, so as not to pay for the whole level.
    if t.face_count() <= 64 * tiles.len() {
        let mut marked = vec![false; t.face_count()];
        for f in around() {
            marked[f as usize] = true;
        }
        return (0..t.face_count() as u32)
            .filter(|&f| marked[f as usize])
            .collect();
    }
    let mut faces: Vec<u32> = around().collect();
    faces.sort_unstable();
    faces.dedup();
    faces
}

/// The depth below `last` (which has tiles left): its children that are regular patches are
/// set aside, and the faces around the others kept. `None` if those do not form a valid mesh.
fn deepen(last: &ShapeDepth) -> Option<ShapeDepth> {
    let last_level = last.local.as_ref().expect("a depth with tiles has a mesh");
    let child = catmull_clark::refine_level_sequential(last_level);
    let mut tiles = Vec::with_capacity(4 * last.tiles.len());
    for tile in &last.tiles {
        tiles.extend(tile.children(last_level.topology.face_offset(tile.face as usize)));
    }
    // Rows only for the vertices of the faces around the children, where their patches'
    // control points and the next depth's neighbourhood lie: about half of the child's.
    let ct = &child.topology;
    let mut wanted = vec![false; ct.vertex_count()];
    for f in neighbourhood(ct, &tiles) {
        for &v in ct.face_vertices(f as usize) {
            wanted[v as usize] = true;
        }
    }
    let wanted: Vec<u32> = (0..ct.vertex_count() as u32)
        .filter(|&v| wanted[v as usize])
        .collect();
    let mut row_of = vec![u32::MAX; ct.vertex_count()];
    for (r, &v) in wanted.iter().enumerate() {
        row_of[v as usize] = r as u32;
    }
    let mut refine = catmull_clark::refine_stencils_at(last_level, &wanted);
    refine.remap_sources(&last.local_rows);
    let mut patches = Vec::new();
    tiles.retain(|tile| {
        let face = tile.face as usize;
        match regular_patch_points(&child, face, |v| regular_corner(&child, v)) {
            Some(points) => {
                patches.push((
                    *tile,
                    points.map(|row| row.map(|v| v.map(|v| row_of[v as usize]))),
                ));
                false
            }
            None => true,
        }
    });
    let (local, local_rows) = if tiles.is_empty() {
        (None, Vec::new())
    } else {
        let keep = neighbourhood(ct, &tiles);
        let (vertices, offsets, corners) = cut_out(&child, &keep);
        let local = local_level(&child, &vertices, offsets, corners)?;
        for tile in &mut tiles {
            tile.face = local_face(&keep, tile.face);
        }
        (
            Some(local),
            vertices.iter().map(|&v| row_of[v as usize]).collect(),
        )
    };
    Some(ShapeDepth {
        local,
        local_rows,
        refine: Some(refine),
        tiles,
        patches,
        corner_limits: OnceLock::new(),
    })
}

impl LocalPatch {
    /// Cuts out the neighbourhood of the faces `faces` of `level` (their roots are their
    /// indices in `faces`), whose refinement is shared through `cache` with those of the same
    /// shape; `None` if one is not a quad or the neighbourhood does not form a valid mesh on
    /// its own.
    pub fn new(
        level: &Level,
        data: &[VertexData],
        faces: &[usize],
        cache: &ShapeCache,
    ) -> Option<LocalPatch> {
        let t = &level.topology;
        if faces.iter().any(|&f| t.face_vertices(f).len() != 4) {
            return None;
        }
        let mut tiles: Vec<Tile> = faces
            .iter()
            .enumerate()
            .map(|(root, &f)| Tile {
                face: f as u32,
                root: root as u32,
                origin: [0, 0],
                u: [1, 0],
                v: [0, 1],
            })
            .collect();
        let keep = neighbourhood(t, &tiles);
        let (vertices, offsets, corners) = cut_out(level, &keep);
        for tile in &mut tiles {
            tile.face = local_face(&keep, tile.face);
        }
        let key = ShapeKey {
            vertex_count: vertices.len(),
            edge_sharpness: keep
                .iter()
                .flat_map(|&g| t.face_edges(g as usize))
                .map(|&e| level.edge_sharpness[e as usize].to_bits())
                .collect(),
            vertex_sharpness: vertices
                .iter()
                .map(|&v| level.vertex_sharpness[v as usize].to_bits())
                .collect(),
            creasing: level.creasing,
            roots: tiles.iter().map(|tile| tile.face).collect(),
            offsets,
            corners,
        };
        let shape = {
            let mut shapes = cache.0.lock().unwrap_or_else(|e| e.into_inner());
            match shapes.get(&key) {
                Some(shape) => shape.clone(),
                None => {
                    let local =
                        local_level(level, &vertices, key.offsets.clone(), key.corners.clone());
                    let shape = local.map(|local| {
                        Arc::new(LocalShape {
                            depths: Mutex::new((
                                vec![Arc::new(ShapeDepth {
                                    local: Some(local),
                                    local_rows: (0..vertices.len() as u32).collect(),
                                    refine: None,
                                    tiles,
                                    patches: Vec::new(),
                                    corner_limits: OnceLock::new(),
                                })],
                                false,
                            )),
                        })
                    });
                    shapes.insert(key, shape.clone());
                    shape
                }
            }
        }?;
        let first = shape.depth(0)?;
        Some(LocalPatch {
            shape,
            depths: vec![first],
            rows: vec![vertices.iter().map(|&v| data[v as usize]).collect()],
            corner_limits: vec![None],
        })
    }

    /// Refines this neighbourhood's data down to `depth`, or as far as tiles are left;
    /// `None` if the shape cannot be refined that far.
    fn reach(&mut self, depth: usize) -> Option<()> {
        while self.depths.len() <= depth && !self.depths.last().expect("depth 0").tiles.is_empty() {
            let next = self.shape.depth(self.depths.len())?;
            let rows = next
                .refine
                .as_ref()
                .expect("below depth 0")
                .apply_sequential(self.rows.last().expect("depth 0"));
            self.depths.push(next);
            self.rows.push(rows);
            self.corner_limits.push(None);
        }
        Some(())
    }

    /// The limit surface over face `root` on a grid of `n x n` cells (`n` a power of two):
    /// the patches set aside down to depth `log2 n` on their share of the grid, and the
    /// corners of the descendants still refined at that depth at their limit positions.
    pub fn grid(&mut self, root: usize, n: usize) -> Option<Grid> {
        let depth = n.trailing_zeros() as usize;
        self.reach(depth)?;
        let root = root as u32;
        let stride = n as i64 + 1;
        let mut grid = vec![VertexData::ZERO; (n + 1) * (n + 1)];
        for (d, (at, rows)) in self
            .depths
            .iter()
            .zip(&self.rows)
            .enumerate()
            .take(depth + 1)
        {
            // A tile of depth `d` spans `m` cells of the grid.
            let m = 1i64 << (depth - d);
            for (tile, points) in at.patches.iter().filter(|(tile, _)| tile.root == root) {
                let cp = control_grid(points, |r| rows[r as usize]);
                let o = [tile.origin[0] * m, tile.origin[1] * m];
                evaluate_patch_with(&cp, m as usize, |i, j, p| {
                    let (i, j) = (i as i64, j as i64);
                    let x = o[0] + i * tile.u[0] + j * tile.v[0];
                    let y = o[1] + i * tile.u[1] + j * tile.v[1];
                    grid[(y * stride + x) as usize] = p;
                });
            }
        }
        let Some(at) = self.depths.get(depth) else {
            return Some(grid);
        };
        let Some(level) = &at.local else {
            return Some(grid);
        };
        let t = &level.topology;
        // The limit points of the tiles' corners only (the ring around them is most of the
        // local level), each once, for every face refined together.
        let (slot, stencils) = at
            .corner_limits
            .get_or_init(|| {
                let mut slot = vec![u32::MAX; t.vertex_count()];
                let mut wanted = Vec::with_capacity(4 * at.tiles.len());
                for tile in &at.tiles {
                    for &v in t.face_vertices(tile.face as usize) {
                        if slot[v as usize] == u32::MAX {
                            slot[v as usize] = wanted.len() as u32;
                            wanted.push(v);
                        }
                    }
                }
                let mut stencils = limit::limit_stencils_for(level, &wanted)?;
                stencils.remap_sources(&at.local_rows);
                Some((slot, stencils))
            })
            .as_ref()?;
        let limits = self.corner_limits[depth]
            .get_or_insert_with(|| stencils.apply_sequential(&self.rows[depth]));
        for tile in at.tiles.iter().filter(|tile| tile.root == root) {
            let o = tile.origin;
            let corners = [
                o,
                [o[0] + tile.u[0], o[1] + tile.u[1]],
                [o[0] + tile.u[0] + tile.v[0], o[1] + tile.u[1] + tile.v[1]],
                [o[0] + tile.v[0], o[1] + tile.v[1]],
            ];
            for (k, &v) in t.face_vertices(tile.face as usize).iter().enumerate() {
                let p = corners[k];
                grid[(p[1] * stride + p[0]) as usize] = limits[slot[v as usize] as usize];
            }
        }
        Some(grid)
    }

    /// The limit surface over face `root` down to `depth`, as pieces: the control grids of the
    /// descendants set aside as B-spline patches at every depth (exact), and the descendants
    /// still irregular at `depth` as the places of their corners 0, 1, 2, 3 in the face's grid of
    /// `2^depth` cells a side (the samples of [`LocalPatch::grid`] there, or at twice those
    /// coordinates in a grid twice as fine). `None` if the shape cannot be refined that far.
    pub fn pieces(&mut self, root: usize, depth: usize) -> Option<Pieces> {
        self.reach(depth)?;
        let root = root as u32;
        let mut pieces = Pieces::default();
        for (at, rows) in self.depths.iter().zip(&self.rows).take(depth + 1) {
            for (tile, points) in at.patches.iter().filter(|(tile, _)| tile.root == root) {
                let cp = control_grid(points, |r| rows[r as usize]);
                // Turned back to the face's own orientation: `u` along the face's grid's x.
                pieces.patches.push(oriented(cp, tile));
            }
        }
        if let Some(at) = self.depths.get(depth) {
            for tile in at.tiles.iter().filter(|tile| tile.root == root) {
                let o = tile.origin;
                pieces.irregular.push([
                    o,
                    [o[0] + tile.u[0], o[1] + tile.u[1]],
                    [o[0] + tile.u[0] + tile.v[0], o[1] + tile.u[1] + tile.v[1]],
                    [o[0] + tile.v[0], o[1] + tile.v[1]],
                ]);
            }
        }
        Some(pieces)
    }
}

/// What [`LocalPatch::pieces`] gives: exact patches, and the corners of the irregular rest.
#[derive(Default)]
pub(crate) struct Pieces {
    /// Control grids of the descendants whose limit surface is a B-spline patch.
    pub patches: Vec<ControlGrid>,
    /// The descendants still irregular, as their corners' places in the face's grid.
    pub irregular: Vec<[[i64; 2]; 4]>,
}

/// The control grid `cp` of `tile` with its parameters turned so that `u` runs along the root
/// face's `u` and `v` along its `v`: tiles of a locally refined face are rotated or mirrored
/// against it, and a surface's orientation decides which sheet shows where it folds.
fn oriented(cp: ControlGrid, tile: &Tile) -> ControlGrid {
    let (u, v) = (tile.u, tile.v);
    // Each of the tile's steps is a unit step of the root's grid: x (`[1, 0]`) or y, either way.
    let along_x = u[0] != 0;
    let mut out = cp;
    for j in 0..4 {
        for i in 0..4 {
            // The root's (x, y) place of the tile's control point (i, j), within 0..4.
            let (x, y) = if along_x {
                (flip(i, u[0] < 0), flip(j, v[1] < 0))
            } else {
                (flip(j, v[0] < 0), flip(i, u[1] < 0))
            };
            out[y][x] = cp[j][i];
        }
    }
    out
}

fn flip(k: usize, reversed: bool) -> usize {
    if reversed {
        3 - k
    } else {
        k
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::catmull_clark::refine;
    use crate::mesh::CreasingMethod;

    /// An `n x n` grid of quads (vertex `j * (n + 1) + i`) with the boundary rules applied
    /// (corners infinitely sharp) and uneven data in all six coordinates.
    fn grid_level(n: u32) -> (Level, Vec<VertexData>) {
        let mut faces = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let v = j * (n + 1) + i;
                faces.push(vec![v, v + 1, v + n + 2, v + n + 1]);
            }
        }
        let nv = ((n + 1) * (n + 1)) as usize;
        let topology = Topology::from_faces(nv, &faces).unwrap();
        let ne = topology.edge_count();
        let level = Level::new(
            topology,
            vec![0.0; ne],
            vec![0.0; nv],
            CreasingMethod::Uniform,
            BoundaryInterpolation::EdgeAndCorner,
        );
        (level, uneven_data(nv))
    }

    fn uneven_data(nv: usize) -> Vec<VertexData> {
        (0..nv)
            .map(|k| {
                let x = k as f64;
                VertexData::from_array([
                    x * 1.3 + (x * 0.7).sin() * 2.0,
                    (x * 1.9).cos() * 3.0 + x * 0.2,
                    50.0 + 10.0 * (x * 0.37).sin(),
                    x * x * 0.01,
                    -(x * 0.11).cos(),
                    0.5 + 0.4 * (x * 0.5).sin(),
                ])
            })
            .collect()
    }

    fn close(a: VertexData, b: VertexData) -> bool {
        (0..6).all(|k| {
            (a.to_array()[k] - b.to_array()[k]).abs() < 1e-9 * (1.0 + a.to_array()[k].abs())
        })
    }

    /// The patch of face `f` at its corners equals the limit stencils; at its centre and side
    /// midpoints, the limits of the next level's face and edge points.
    fn check_patch(level: &Level, data: &[VertexData], f: usize) {
        let cp = regular_patch(level, data, f).expect("regular");
        let t = &level.topology;
        let lim = limit::limit_stencils(level).unwrap().apply(data);
        let fv = t.face_vertices(f);
        let corners = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
        for (k, &(u, v)) in corners.iter().enumerate() {
            let p = evaluate_patch_at(&cp, u, v);
            assert!(close(p, lim[fv[k] as usize]), "face {f} corner {k}: {p:?}");
        }
        let (child, stencils) = refine(level);
        let lim1 = limit::limit_stencils(&child)
            .unwrap()
            .apply(&stencils.apply(data));
        let centre = evaluate_patch_at(&cp, 0.5, 0.5);
        assert!(close(centre, lim1[f]), "face {f} centre");
        let mids = [(0.5, 0.0), (1.0, 0.5), (0.5, 1.0), (0.0, 0.5)];
        for (k, &(u, v)) in mids.iter().enumerate() {
            let e = t.face_edges(f)[k] as usize;
            let p = evaluate_patch_at(&cp, u, v);
            assert!(close(p, lim1[t.face_count() + e]), "face {f} side {k}");
        }
        // The grid evaluation agrees with the pointwise one.
        let g = evaluate_patch(&cp, 4);
        assert!(close(g[5 * 2 + 3], evaluate_patch_at(&cp, 0.75, 0.5)));
    }

    #[test]
    fn regular_patches_match_limit_stencils_inside_on_boundaries_and_corners() {
        let (level, data) = grid_level(4);
        // Interior (5), boundary sides (1, 4, 7, 13), corners (0, 3, 12, 15).
        for f in [5, 6, 10, 1, 4, 7, 13, 0, 3, 12, 15] {
            check_patch(&level, &data, f);
        }
    }

    #[test]
    fn irregular_faces_are_not_patches_and_refine_locally_like_the_whole_mesh() {
        // A valence-5 vertex: five quads around vertex 0, with a ring of quads around them.
        let (level, data) = star_level();
        let t = &level.topology;
        let centre = (0..t.vertex_count())
            .find(|&v| t.vertex_edges(v).len() == 5)
            .unwrap() as u32;
        for f in 0..t.face_count() {
            if t.face_vertices(f).contains(&centre) {
                assert!(regular_patch(&level, &data, f).is_none());
            }
        }
        // Local refinement of face 0 (an irregular face) equals refining the whole mesh: two
        // levels down.
        assert!(t.face_vertices(0).contains(&centre));
        let mut local = LocalPatch::new(&level, &data, &[0], &ShapeCache::default()).unwrap();
        let g = local.grid(0, 4).unwrap();
        let (l1, s1) = refine(&level);
        let (l2, s2) = refine(&l1);
        let d2 = s2.apply(&s1.apply(&data));
        let lim = limit::limit_stencils(&l2).unwrap().apply(&d2);
        // Grid corner (0, 0) is the face's corner 0; (4, 4) its corner 2; (2, 2) its centre,
        // which is vertex point of the level-1 face point 0 (face 0 at level 1).
        let (nf0, ne0) = (t.face_count(), t.edge_count());
        let (nf1, ne1) = (l1.topology.face_count(), l1.topology.edge_count());
        let fv = t.face_vertices(0);
        let vertex_point_2 = |v: usize| nf1 + ne1 + nf0 + ne0 + v;
        assert!(close(g[0], lim[vertex_point_2(fv[0] as usize)]));
        assert!(close(g[24], lim[vertex_point_2(fv[2] as usize)]));
        assert!(close(g[12], lim[nf1 + ne1]));
        // A regular face of the same mesh refined locally equals its patch.
        let regular = (0..t.face_count())
            .find(|&f| regular_patch(&level, &data, f).is_some())
            .expect("a regular face");
        let cp = regular_patch(&level, &data, regular).unwrap();
        let a = LocalPatch::new(&level, &data, &[regular], &ShapeCache::default())
            .unwrap()
            .grid(0, 4)
            .unwrap();
        let b = evaluate_patch(&cp, 4);
        for (p, q) in a.iter().zip(&b) {
            assert!(close(*p, *q), "{p:?} vs {q:?}");
        }
    }

    /// Face `f`'s grid of `n` cells from refining the whole of `level` `log2 n` times: the
    /// oracle for [`LocalPatch::grid`].
    fn whole_mesh_grid(level: &Level, data: &[VertexData], f: usize, n: usize) -> Grid {
        let (mut level, mut data) = (level.clone(), data.to_vec());
        let mut tiles = vec![Tile {
            face: f as u32,
            root: 0,
            origin: [0, 0],
            u: [1, 0],
            v: [0, 1],
        }];
        for _ in 0..n.trailing_zeros() {
            let children: Vec<Tile> = tiles
                .iter()
                .flat_map(|t| t.children(level.topology.face_offset(t.face as usize)))
                .collect();
            let (child, stencils) = refine(&level);
            data = stencils.apply(&data);
            level = child;
            tiles = children;
        }
        let lim = limit::limit_stencils(&level).unwrap().apply(&data);
        let stride = n as i64 + 1;
        let mut grid = vec![VertexData::from_array([f64::NAN; 6]); (n + 1) * (n + 1)];
        for tile in &tiles {
            let fv = level.topology.face_vertices(tile.face as usize);
            let o = tile.origin;
            let (u, v) = (tile.u, tile.v);
            let corners = [
                o,
                [o[0] + u[0], o[1] + u[1]],
                [o[0] + u[0] + v[0], o[1] + u[1] + v[1]],
                [o[0] + v[0], o[1] + v[1]],
            ];
            for k in 0..4 {
                let p = corners[k];
                grid[(p[1] * stride + p[0]) as usize] = lim[fv[k] as usize];
            }
        }
        grid
    }

    /// Checks face `f`'s local grids of 1 to 16 cells against the whole mesh's, and returns
    /// how many patches its local refinement set aside.
    fn check_local_grids(level: &Level, data: &[VertexData], f: usize) -> usize {
        let mut local = LocalPatch::new(level, data, &[f], &ShapeCache::default()).unwrap();
        for n in [1, 2, 4, 8, 16, 4] {
            let expected = whole_mesh_grid(level, data, f, n);
            let got = local.grid(0, n).unwrap();
            for (k, (a, b)) in got.iter().zip(&expected).enumerate() {
                assert!(
                    close(*a, *b),
                    "face {f}, n = {n}, sample {k}: {a:?} vs {b:?}"
                );
            }
        }
        local.depths.iter().map(|l| l.patches.len()).sum()
    }

    #[test]
    fn local_refinement_sets_regular_descendants_aside_without_changing_the_surface() {
        // Around a valence-5 vertex.
        let (level, data) = star_level();
        let around = faces_around_valence_5(&level);
        assert_eq!(around.len(), 5);
        for &f in &around {
            let set_aside = check_local_grids(&level, &data, f);
            // Three children a depth become regular: 3 at each of the four depths.
            assert_eq!(set_aside, 12, "face {f}");
        }
        // Along a semi-sharp crease (sharpness 2.5, decaying over three levels) and an
        // infinitely sharp one, up to the boundary, with a semi-sharp vertex.
        let (mut level, data) = grid_level(6);
        let t = level.topology.clone();
        let vertex = |i: u32, j: u32| j * 7 + i;
        let edge = |a: u32, b: u32| {
            (0..t.edge_count())
                .find(|&e| {
                    let [p, q] = t.edge_vertices(e);
                    (p, q) == (a, b) || (p, q) == (b, a)
                })
                .unwrap()
        };
        for i in 0..6 {
            level.edge_sharpness[edge(vertex(i, 3), vertex(i + 1, 3))] = 2.5;
            level.edge_sharpness[edge(vertex(3, i), vertex(3, i + 1))] = f64::INFINITY;
        }
        level.vertex_sharpness[vertex(2, 2) as usize] = 1.5;
        let level = Level::new(
            level.topology,
            level.edge_sharpness,
            level.vertex_sharpness,
            CreasingMethod::Uniform,
            BoundaryInterpolation::EdgeAndCorner,
        );
        let mut set_aside = 0;
        for f in 0..t.face_count() {
            if regular_patch(&level, &data, f).is_none() {
                set_aside += check_local_grids(&level, &data, f);
            }
        }
        assert!(set_aside > 0);
    }

    #[test]
    fn faces_refined_together_match_the_whole_mesh() {
        // The five faces around a valence-5 vertex, asked for in any order and at any count.
        let (level, data) = star_level();
        let around = faces_around_valence_5(&level);
        let mut group = LocalPatch::new(&level, &data, &around, &ShapeCache::default()).unwrap();
        for (root, n) in [
            (0, 1),
            (2, 4),
            (1, 2),
            (4, 16),
            (3, 8),
            (4, 1),
            (0, 16),
            (2, 2),
        ] {
            let expected = whole_mesh_grid(&level, &data, around[root], n);
            let got = group.grid(root, n).unwrap();
            for (k, (a, b)) in got.iter().zip(&expected).enumerate() {
                assert!(
                    close(*a, *b),
                    "root {root}, n = {n}, sample {k}: {a:?} vs {b:?}"
                );
            }
        }
    }

    #[test]
    fn neighbourhoods_of_one_shape_share_their_refinement_not_their_data() {
        let (level, data) = star_level();
        let around = faces_around_valence_5(&level);
        let other: Vec<VertexData> = data.iter().map(|d| d.map(|x| 2.0 * x + 1.0)).collect();
        let shared = ShapeCache::default();
        // The first asks for depth 4 before the second has anything; the second then needs
        // depths the first built, and one it did not.
        let mut a = LocalPatch::new(&level, &data, &around, &shared).unwrap();
        let first = a.grid(1, 16).unwrap();
        let mut b = LocalPatch::new(&level, &other, &around, &shared).unwrap();
        let second = [b.grid(3, 4).unwrap(), b.grid(2, 32).unwrap()];
        assert_eq!(shared.len(), 1, "one shape");
        let alone = |data: &[VertexData], root: usize, n: usize| {
            let mut patch = LocalPatch::new(&level, data, &around, &ShapeCache::default()).unwrap();
            patch.grid(root, n).unwrap()
        };
        assert_eq!(first, alone(&data, 1, 16));
        assert_eq!(second[0], alone(&other, 3, 4));
        assert_eq!(second[1], alone(&other, 2, 32));
        assert_ne!(first, alone(&other, 1, 16));
    }

    /// The faces of `level` around its vertex of valence 5.
    fn faces_around_valence_5(level: &Level) -> Vec<usize> {
        let t = &level.topology;
        let centre = (0..t.vertex_count())
            .find(|&v| t.vertex_edges(v).len() == 5)
            .unwrap() as u32;
        (0..t.face_count())
            .filter(|&f| t.face_vertices(f).contains(&centre))
            .collect()
    }

    /// Level 2 of a five-quad star subdivided twice: a valence-5 vertex (0) in an all-quad mesh
    /// with regular faces away from it.
    fn star_level() -> (Level, Vec<VertexData>) {
        let faces: Vec<Vec<u32>> = (0..5u32)
            .map(|k| vec![0, 1 + k, 6 + k, 1 + (k + 1) % 5])
            .collect();
        let topology = Topology::from_faces(11, &faces).unwrap();
        let ne = topology.edge_count();
        let mut level = Level::new(
            topology,
            vec![0.0; ne],
            vec![0.0; 11],
            CreasingMethod::Uniform,
            BoundaryInterpolation::EdgeAndCorner,
        );
        let mut data = uneven_data(11);
        for _ in 0..2 {
            let (child, st) = refine(&level);
            data = st.apply(&data);
            level = child;
        }
        (level, data)
    }
}
