//! The whole refinement: topology of every level built once, data evaluated on demand.
//!
//! Level 0 is the validated input (discontinuities split), level 1 the result of the ternary
//! step (or of the two binary splits, [`FirstStep::Binary`]), level `k` that step followed by
//! `k - 1` Catmull-Clark steps. Only the first step's positions depend non-linearly on the
//! data (through the handles); every later level is a fixed linear map, so re-evaluating
//! after an edit costs one pass over the stencils.

use std::sync::atomic::{AtomicU64, Ordering};

use crate::binary_step;
use crate::catmull_clark::{self, Level, Stencils};
use crate::colour::ColourSpace;
use crate::edit_check::check_edits;
use crate::edits;
use crate::error::{Error, Warning, WarningKind};
use crate::limit_surface;
use crate::mesh::{FirstStep, GradientMesh};
use crate::multires::{Edit, FineEdits};
use crate::rules;
use crate::size_limits::Limits;
use crate::ternary_step;
use crate::topology::Topology;
use crate::validate::{BaseMesh, VertexData};

/// The topology of every level of a mesh's refinement, and the stencils between levels.
#[derive(Clone, Debug)]
pub struct Refinement {
    base: BaseMesh,
    /// `levels[k - 1]` is level `k`.
    levels: Vec<Level>,
    /// `stencils[k - 1]` computes level `k + 1` from level `k`.
    stencils: Vec<Stencils>,
    /// With interpolated positions: the level at which limit stencils are exact (every
    /// semi-sharp feature has decayed), and those stencils.
    interpolation: Option<(usize, Stencils)>,
    /// Names this topology: [`Refinement::from_base`] gives each refinement its own, and
    /// [`Refinement::rebase`] keeps it (see [`Refinement::topology_id`]).
    topology_id: u64,
}

/// The next [`Refinement::topology_id`].
static NEXT_TOPOLOGY_ID: AtomicU64 = AtomicU64::new(0);

/// The data (positions, colours, opacity) of every level of a [`Refinement`].
#[derive(Clone, Debug, PartialEq)]
pub struct RefinedData {
    /// `levels[k]` holds the data of level `k`.
    pub levels: Vec<Vec<VertexData>>,
}

impl Refinement {
    /// Validates `mesh` and refines its topology down to level `depth`, within
    /// [`Limits::DEFAULT`] (see [`Refinement::new_with_limits`]).
    pub fn new(mesh: &GradientMesh, depth: usize) -> Result<(Refinement, Vec<Warning>), Error> {
        Refinement::new_with_limits(mesh, depth, &Limits::DEFAULT)
    }

    /// As [`Refinement::new`], but first refuses a mesh beyond `limits` (points, faces,
    /// corners) and a refinement whose deepest level would exceed them (level, faces, 32-bit
    /// indices), estimated before anything is built ([`Limits::check_refinement`]). The level
    /// below the deepest edit counts too: limits and renderings refine that far.
    pub fn new_with_limits(
        mesh: &GradientMesh,
        depth: usize,
        limits: &Limits,
    ) -> Result<(Refinement, Vec<Warning>), Error> {
        limits.check_mesh(mesh)?;
        let (base, warnings) = BaseMesh::new(mesh)?;
        limits.check_refinement(&base, depth)?;
        // Limits below the deepest edit refine one level further than it.
        let edited = base.edits.deepest_level();
        if edited > 0 {
            limits.check_refinement(&base, edited + 1)?;
        }
        Ok((Refinement::from_base(base, depth), warnings))
    }

    /// Refines the topology of an already validated base level down to level `depth`, with no
    /// limit: check the refinement first ([`Limits::check_refinement`]) when the base comes from
    /// untrusted input. With interpolated positions it builds the levels their limit stencils
    /// need (below every semi-sharp feature: up to level 12).
    pub fn from_base(base: BaseMesh, depth: usize) -> Refinement {
        let mut r = Refinement {
            base,
            levels: Vec::new(),
            stencils: Vec::new(),
            interpolation: None,
            topology_id: NEXT_TOPOLOGY_ID.fetch_add(1, Ordering::Relaxed),
        };
        r.extend_to(depth);
        if r.base.interpolate_positions {
            // Limit stencils are exact once no semi-sharp feature is left (sharpness 10 is
            // infinite, so at most ten levels).
            let mut d = 2;
            r.extend_to(d);
            while d < 12 && has_semi_sharp(r.level(d)) {
                d += 1;
                r.extend_to(d);
            }
            let limit =
                limit_surface::limit_stencils(r.level(d)).expect("level 2 and below are quads");
            r.interpolation = Some((d, limit));
        }
        r
    }

    /// An identifier shared only by refinements of the same topology and stencils: this one,
    /// its clones, and itself after [`Refinement::rebase`]. What was computed on one of its
    /// levels (a renderer's plans per face, say) fits any refinement with the same identifier,
    /// whose data may differ.
    pub fn topology_id(&self) -> u64 {
        self.topology_id
    }

    /// Takes `base` as the base level instead, keeping every level built, if it refines to the
    /// same topology and stencils (the same split topology, sharpness and rules: an edit of
    /// positions, colours, handles or multi-resolution edits); gives it back otherwise.
    pub fn rebase(&mut self, base: BaseMesh) -> Result<(), Box<BaseMesh>> {
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let (a, b) = (&self.base, &base);
        let same = a.topology == b.topology
            && a.source_point == b.source_point
            && bits(&a.edge_sharpness) == bits(&b.edge_sharpness)
            && bits(&a.vertex_sharpness) == bits(&b.vertex_sharpness)
            && a.boundary == b.boundary
            && a.creasing == b.creasing
            && a.interpolate_positions == b.interpolate_positions
            && a.first_step == b.first_step;
        if !same {
            return Err(Box::new(base));
        }
        self.base = base;
        Ok(())
    }

    /// `kept` with `base` as its base level if it refines to the same topology and stencils
    /// (see [`Refinement::rebase`]), else a new refinement of `base` to level `depth`: what an
    /// editor calls after an edit, to build levels only when the edit changed the topology.
    pub fn rebased_or_new(kept: Option<Refinement>, base: BaseMesh, depth: usize) -> Refinement {
        match kept {
            Some(mut r) => match r.rebase(base) {
                Ok(()) => r,
                Err(base) => Refinement::from_base(*base, depth),
            },
            None => Refinement::from_base(base, depth),
        }
    }

    /// Refines further so that level `depth` exists.
    pub fn extend_to(&mut self, depth: usize) {
        if depth >= 1 && self.levels.is_empty() {
            self.levels.push(first_level(&self.base));
        }
        while self.levels.len() < depth {
            let (child, stencils) = catmull_clark::refine(self.levels.last().expect("level 1"));
            self.levels.push(child);
            self.stencils.push(stencils);
        }
    }

    /// The deepest level built.
    pub fn depth(&self) -> usize {
        self.levels.len()
    }

    /// The validated base level.
    pub fn base(&self) -> &BaseMesh {
        &self.base
    }

    /// Level `k >= 1` (its topology and sharpness).
    pub fn level(&self, k: usize) -> &Level {
        &self.levels[k - 1]
    }

    /// The topology of level `k` (level 0 is the base).
    pub fn topology(&self, k: usize) -> &Topology {
        if k == 0 {
            &self.base.topology
        } else {
            &self.levels[k - 1].topology
        }
    }

    /// The topology of level `k`, taking the refinement apart.
    fn into_topology(mut self, k: usize) -> Topology {
        if k == 0 {
            self.base.topology
        } else {
            self.levels.swap_remove(k - 1).topology
        }
    }

    /// The index at level `k` of the vertex that base vertex `v` becomes (its vertex point at
    /// every level). Levels beyond [`Refinement::depth`] are not built: `k` must not exceed it.
    pub fn vertex_at_level(&self, v: u32, k: usize) -> usize {
        let mut index = v as usize;
        for j in 1..k {
            let t = self.topology(j);
            index += t.face_count() + t.edge_count();
        }
        index
    }

    /// The stencils from level `k >= 1` to level `k + 1`.
    pub fn stencils(&self, k: usize) -> &Stencils {
        &self.stencils[k - 1]
    }

    /// Evaluates the data of every level from the base data.
    pub fn evaluate(&self) -> RefinedData {
        self.evaluate_from(&self.base)
    }

    /// Evaluates every level from other base data on the same topology (for example after an
    /// edit of positions, colours, handles or multi-resolution edits): no topology is rebuilt.
    ///
    /// # Panics
    /// If `base` has another topology than the one refined.
    pub fn evaluate_from(&self, base: &BaseMesh) -> RefinedData {
        self.evaluate_to(base, self.levels.len())
    }

    /// [`Refinement::evaluate_from`] down to level `depth` only (or the deepest built).
    pub fn evaluate_to(&self, base: &BaseMesh, depth: usize) -> RefinedData {
        let depth = depth.min(self.levels.len());
        let mut levels = vec![base.data.clone()];
        if depth >= 1 {
            levels.push(self.first_level_data(base));
        }
        for k in 1..depth {
            let next = self.next_level_data_from(base, k, &levels[k]);
            levels.push(next);
        }
        RefinedData { levels }
    }

    /// The level-1 data of `base`: the first step, the position correction when positions are
    /// interpolated, and the level-1 edits.
    fn first_level_data(&self, base: &BaseMesh) -> Vec<VertexData> {
        let mut level1 = first_data(base);
        if let Some((d, limit)) = &self.interpolation {
            self.interpolate_positions(base, *d, limit, &mut level1);
        }
        self.apply_edits(base, 1, None, &mut level1);
        level1
    }

    /// The data of level `k + 1` (`k >= 1`) from that of level `k`: one Catmull-Clark step, then
    /// the multi-resolution edits. Level `k + 1` must be built ([`Refinement::extend_to`]).
    /// Renderers and writers that go one level further should use this, not the bare stencils,
    /// so that edits apply.
    pub fn next_level_data(&self, k: usize, data: &[VertexData]) -> Vec<VertexData> {
        self.next_level_data_from(&self.base, k, data)
    }

    /// As [`Refinement::next_level_data`], with the edits of other base data.
    pub fn next_level_data_from(
        &self,
        base: &BaseMesh,
        k: usize,
        data: &[VertexData],
    ) -> Vec<VertexData> {
        let mut next = self.stencils(k).apply(data);
        self.apply_edits(base, k + 1, Some(data), &mut next);
        next
    }

    /// Applies the edits of level `k` (and the rings of those of level `k - 1`).
    fn apply_edits(
        &self,
        base: &BaseMesh,
        k: usize,
        previous: Option<&[VertexData]>,
        data: &mut [VertexData],
    ) {
        if base.edits.is_empty() || base.edits.deepest_level() + 1 < k {
            return;
        }
        let levels: Vec<&Topology> = self.levels[..k].iter().map(|l| &l.topology).collect();
        edits::apply(base, &levels, &base.edits, k, previous, data);
    }

    /// The index at its level of the vertex that edit `i` of the base level names, building the
    /// topology down to that level if needed.
    pub fn edited_vertex(&mut self, i: usize) -> Option<usize> {
        let edit = self.base.edits.edits.get(i)?.clone();
        self.extend_to(edit.edit.address.level as usize);
        let levels: Vec<&Topology> = self.levels.iter().map(|l| &l.topology).collect();
        edits::vertex_of(&self.base.topology, &levels, &edit).map(|v| v as usize)
    }

    /// Replaces the multi-resolution edits (checked against the base level); the next
    /// [`Refinement::evaluate`] applies them. No topology is rebuilt.
    pub fn set_edits(&mut self, edits: &[Edit], fine: FineEdits) -> Result<(), Error> {
        let space = self.base.edits.space;
        let working = self.base.edits.working;
        let base = &self.base;
        let mut set = check_edits(
            &base.topology,
            &base.source_point,
            base.first_step,
            edits,
            fine,
            space,
        )?;
        set.working = working;
        self.base.edits = set;
        Ok(())
    }

    /// Declares that the edits' colours are written in `space` while the data is in another
    /// working space (a renderer that interpolates a mesh in another space converts the points'
    /// colours, then says in which space the edits were written).
    pub fn set_edit_colour_space(&mut self, space: ColourSpace) {
        self.base.edits.space = space;
    }

    /// The limit position, colour and opacity of every vertex of level `k`, refining one or two
    /// levels further where level `k` still has faces that are not quads, and below the
    /// deepest edit.
    pub fn limit(&mut self, data: &RefinedData, k: usize) -> Vec<VertexData> {
        // Vertex v of level j has the vertex point nf + ne + v at level j + 1 (j >= 1), and
        // vertex point v at level 1 (j = 0); both have the same limit.
        let mut j = k;
        let mut index: Vec<u32> = (0..self.topology(k).vertex_count() as u32).collect();
        // Edits of level `d` change the data of level `d + 1` (their rings) and below: the limit
        // stencils apply from there on.
        let exact_from = match self.base.edits.deepest_level() {
            0 => 0,
            d => d + 1,
        };
        loop {
            if j >= 1 && j >= exact_from {
                if let Some(st) = limit_surface::limit_stencils(self.level(j)) {
                    let at_j = self.level_data(data, j);
                    let all = st.apply(&at_j);
                    return index.iter().map(|&i| all[i as usize]).collect();
                }
            }
            if j >= 1 {
                let t = self.topology(j);
                let shift = (t.face_count() + t.edge_count()) as u32;
                index.iter_mut().for_each(|i| *i += shift);
            }
            j += 1;
            self.extend_to(j);
        }
    }

    /// Moves the vertex point of every control point at level 1 so that its limit position is
    /// the control point (paper section 4.5, after Loop et al.). A vertex point's limit depends
    /// on its own position with a fixed weight `w` and on its ring, which holds no other vertex
    /// point; so moving every vertex point by one unit at once reveals each `w`, and one
    /// correction `(target - limit) / w` per point is exact: no global system.
    fn interpolate_positions(
        &self,
        base: &BaseMesh,
        depth: usize,
        limit: &Stencils,
        level1: &mut [VertexData],
    ) {
        let n = base.topology.vertex_count();
        let limit_positions = |data: &[VertexData]| -> Vec<[f64; 2]> {
            let mut d = data.to_vec();
            for k in 1..depth {
                d = self.stencils(k).apply(&d);
            }
            (0..n as u32)
                .map(|v| {
                    let (src, w) = limit.stencil(self.vertex_at_level(v, depth));
                    src.iter().zip(w).fold([0.0; 2], |acc, (&s, &w)| {
                        [
                            acc[0] + w * d[s as usize].position[0],
                            acc[1] + w * d[s as usize].position[1],
                        ]
                    })
                })
                .collect()
        };
        let before = limit_positions(level1);
        let mut shifted = level1.to_vec();
        for d in &mut shifted[..n] {
            d.position[0] += 1.0;
            d.position[1] += 1.0;
        }
        let after = limit_positions(&shifted);
        for v in 0..n {
            for c in 0..2 {
                let weight = after[v][c] - before[v][c];
                level1[v].position[c] += (base.data[v].position[c] - before[v][c]) / weight;
            }
        }
    }

    /// The data at level `j`, computing levels beyond those in `data` when needed.
    fn level_data(&self, data: &RefinedData, j: usize) -> Vec<VertexData> {
        if let Some(d) = data.levels.get(j) {
            return d.clone();
        }
        let mut d = data.levels.last().expect("level 0").clone();
        let mut at = data.levels.len() - 1;
        if at == 0 {
            d = self.first_level_data(&self.base);
            at = 1;
        }
        while at < j {
            d = self.next_level_data(at, &d);
            at += 1;
        }
        d
    }
}

/// Level 1 (topology and sharpness) by the first step that `base` asks for.
fn first_level(base: &BaseMesh) -> Level {
    match base.first_step {
        FirstStep::Ternary => ternary_step::ternary_level(base),
        FirstStep::Binary => binary_step::binary_level(base),
    }
}

/// The level-1 data by the first step that `base` asks for.
fn first_data(base: &BaseMesh) -> Vec<VertexData> {
    match base.first_step {
        FirstStep::Ternary => ternary_step::ternary_data(base),
        FirstStep::Binary => binary_step::binary_data(base),
    }
}

/// Whether a level still has a semi-sharp (finite, non-zero) edge or vertex.
fn has_semi_sharp(level: &Level) -> bool {
    let semi = |&s: &f64| rules::is_sharp(s) && !rules::is_infinite(s);
    level.edge_sharpness.iter().any(semi) || level.vertex_sharpness.iter().any(semi)
}

/// One level of a mesh's refinement: its topology and the data of its vertices.
#[derive(Clone, Debug, PartialEq)]
pub struct RefinedLevel {
    /// The level's faces, edges and vertex rings.
    pub topology: Topology,
    /// Position, colour (in the mesh's colour space) and opacity of each vertex.
    pub data: Vec<VertexData>,
}

/// Which points of a level [`refine_level`] gives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LevelPoints {
    /// The refined control points.
    Control,
    /// The points of the limit surface that the level's vertices converge to.
    Limit,
}

/// Level `level` of `mesh`, its control points or their limits, within `limits`; warnings
/// include edits that lie below a level of control points and have no effect on it.
///
/// Without edits or interpolated positions, a level of control points is computed holding at
/// most two levels at a time and never the last step's stencils: the memory of the output
/// and of its parent level, not of the whole refinement.
pub fn refine_level(
    mesh: &GradientMesh,
    level: usize,
    points: LevelPoints,
    limits: &Limits,
) -> Result<(RefinedLevel, Vec<Warning>), Error> {
    let streamed = points == LevelPoints::Control
        && level >= 1
        && !mesh.interpolate_positions
        && mesh.edits.is_empty();
    if streamed {
        return refine_level_streamed(mesh, level, limits);
    }
    let (mut refinement, mut warnings) = Refinement::new_with_limits(mesh, level, limits)?;
    let deepest_edit = refinement.base().edits.deepest_level();
    match points {
        // Limit points of levels 0 and 1 are computed from level 2.
        LevelPoints::Limit => {
            limits.check_refinement(refinement.base(), level.max(2))?;
        }
        LevelPoints::Control if deepest_edit > level => warnings.push(Warning::new(
            WarningKind::EditsBelowLevel,
            format!(
                "edits down to level {deepest_edit} lie below the level written ({level}) and \
                 have no effect on it"
            ),
        )),
        LevelPoints::Control => {}
    }
    let mut all = refinement.evaluate();
    let data = match points {
        LevelPoints::Limit => refinement.limit(&all, level),
        LevelPoints::Control => std::mem::take(&mut all.levels[level]),
    };
    drop(all);
    let topology = refinement.into_topology(level);
    Ok((RefinedLevel { topology, data }, warnings))
}

/// [`refine_level`] of control points at `level >= 1` for a mesh without edits or
/// interpolated positions, one step at a time.
fn refine_level_streamed(
    mesh: &GradientMesh,
    level: usize,
    limits: &Limits,
) -> Result<(RefinedLevel, Vec<Warning>), Error> {
    limits.check_mesh(mesh)?;
    let (base, warnings) = BaseMesh::new(mesh)?;
    limits.check_refinement(&base, level)?;
    let (mut parent, mut data) = match base.first_step {
        FirstStep::Ternary => (
            ternary_step::ternary_level(&base),
            ternary_step::ternary_data(&base),
        ),
        FirstStep::Binary => (
            binary_step::binary_level(&base),
            binary_step::binary_data(&base),
        ),
    };
    drop(base);
    for _ in 2..level {
        let (child, stencils) = catmull_clark::refine(&parent);
        data = stencils.apply(&data);
        parent = child;
    }
    let topology = if level >= 2 {
        data = catmull_clark::refine_data(&parent, &data);
        parent.topology.subdivide()
    } else {
        parent.topology
    };
    Ok((RefinedLevel { topology, data }, warnings))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::EdgeKind;
    use kurbo::{Point, Vec2};

    /// A 3 x 2 grid of quads with colours.
    fn grid() -> GradientMesh {
        let mut m = GradientMesh::new(ColourSpace::Lab);
        for j in 0..3 {
            for i in 0..4 {
                let (x, y) = (i as f64, j as f64);
                m.add_point(Point::new(10.0 * x, 10.0 * y), [50.0 + x, 5.0 * y, -x * y]);
            }
        }
        for j in 0..2 {
            for i in 0..3 {
                let a = 4 * j + i;
                m.add_face(vec![a, a + 1, a + 5, a + 4]);
            }
        }
        m
    }

    /// An edit of the data (a point moved and recoloured, a handle turned) keeps the levels
    /// built and evaluates as a refinement made afresh; another topology or sharpness is
    /// refused.
    #[test]
    fn rebase_keeps_levels_for_data_edits_only() {
        let mesh = grid();
        let (mut kept, _) = Refinement::new(&mesh, 3).unwrap();
        let mut edited = mesh.clone();
        edited.points[5].position.x += 1.5;
        edited.points[6].colour[1] -= 7.0;
        edited.handles.insert((5, 6), Vec2::new(2.0, 1.0));
        let (base, _) = BaseMesh::new(&edited).unwrap();
        assert!(kept.rebase(base).is_ok());
        let (fresh, _) = Refinement::new(&edited, 3).unwrap();
        assert_eq!(kept.depth(), 3);
        assert_eq!(kept.evaluate(), fresh.evaluate());

        let mut creased = mesh.clone();
        creased.set_edge(5, 6, EdgeKind::Crease, Some(2.0));
        let (base, _) = BaseMesh::new(&creased).unwrap();
        assert!(kept.rebase(base).is_err());
        let mut more = mesh.clone();
        more.add_point(Point::new(40.0, 30.0), [50.0, 0.0, 0.0]);
        more.add_face(vec![10, 11, 12]);
        let (base, _) = BaseMesh::new(&more).unwrap();
        assert!(kept.rebase(base).is_err());
    }

    /// What an editor keeps: the same refinement (its identifier and levels) after a data
    /// edit, a new one to the asked depth after a change of topology or with nothing kept.
    #[test]
    fn rebased_or_new_keeps_the_refinement_only_for_the_same_topology() {
        let mesh = grid();
        let (kept, _) = Refinement::new(&mesh, 3).unwrap();
        let id = kept.topology_id();
        let mut edited = mesh.clone();
        edited.points[5].colour[0] += 4.0;
        let (base, _) = BaseMesh::new(&edited).unwrap();
        let again = Refinement::rebased_or_new(Some(kept), base, 1);
        assert_eq!((again.topology_id(), again.depth()), (id, 3));
        assert_eq!(
            again.evaluate(),
            Refinement::new(&edited, 3).unwrap().0.evaluate()
        );

        let mut creased = mesh.clone();
        creased.set_edge(5, 6, EdgeKind::Crease, Some(2.0));
        let (base, _) = BaseMesh::new(&creased).unwrap();
        let new = Refinement::rebased_or_new(Some(again), base, 1);
        assert_ne!(new.topology_id(), id);
        assert_eq!(new.depth(), 1);
        let (base, _) = BaseMesh::new(&mesh).unwrap();
        let none = Refinement::rebased_or_new(None, base, 2);
        assert_ne!(none.topology_id(), new.topology_id());
        assert_eq!(none.depth(), 2);
    }
}
