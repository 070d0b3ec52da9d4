//! A refinement level: its topology and the sharpness of its edges and vertices, from which
//! Pixar's rules choose how each vertex is refined.

use crate::rules::{self, VertexRule};
use crate::scheme::{BoundaryInterpolation, CreasingMethod, SHARPNESS_INFINITE};
use crate::topology::Topology;
use crate::validate::BaseMesh;

/// One refinement level: topology plus the sharpness that drives the rules.
#[derive(Clone, Debug)]
pub struct Level {
    /// Connectivity.
    pub topology: Topology,
    /// Sharpness per edge; boundary edges are infinitely sharp.
    pub edge_sharpness: Vec<f64>,
    /// Sharpness per vertex; corners are infinitely sharp.
    pub vertex_sharpness: Vec<f64>,
    /// How semi-sharp creases decay.
    pub creasing: CreasingMethod,
}

impl Level {
    /// Whether semi-sharpness still touches the boundary: the outline is only a uniform
    /// B-spline of the boundary vertices once it has decayed there.
    pub(crate) fn semi_sharp_on_boundary(&self) -> bool {
        let t = &self.topology;
        let semi = |s: f64| rules::is_sharp(s) && !rules::is_infinite(s);
        (0..t.vertex_count()).any(|v| {
            t.is_boundary_vertex(v)
                && (semi(self.vertex_sharpness[v])
                    || t.vertex_edges(v)
                        .iter()
                        .any(|&e| semi(self.edge_sharpness[e as usize])))
        })
    }

    /// A level with the boundary rules applied: boundary edges infinitely sharp and, under
    /// [`BoundaryInterpolation::EdgeAndCorner`], boundary vertices with a single face made
    /// corners (as OpenSubdiv does to its base level).
    pub fn new(
        topology: Topology,
        mut edge_sharpness: Vec<f64>,
        mut vertex_sharpness: Vec<f64>,
        creasing: CreasingMethod,
        boundary: BoundaryInterpolation,
    ) -> Level {
        // Found from the boundary edges: in a manifold fan, the boundary vertices are their
        // ends (a test per vertex is a noticeable share of a large mesh's setup).
        let corners = boundary == BoundaryInterpolation::EdgeAndCorner;
        for (e, s) in edge_sharpness.iter_mut().enumerate() {
            if topology.is_boundary_edge(e) {
                *s = SHARPNESS_INFINITE;
                if corners {
                    for v in topology.edge_vertices(e) {
                        if topology.vertex_faces(v as usize).len() == 1 {
                            vertex_sharpness[v as usize] = SHARPNESS_INFINITE;
                        }
                    }
                }
            }
        }
        Level {
            topology,
            edge_sharpness,
            vertex_sharpness,
            creasing,
        }
    }

    /// The base level itself as a Catmull-Clark level, for plain Catmull-Clark refinement
    /// without the ternary step (to compare schemes, or to check against OpenSubdiv).
    pub fn from_base(base: &BaseMesh) -> Level {
        Level::new(
            base.topology.clone(),
            base.edge_sharpness.clone(),
            base.vertex_sharpness.clone(),
            base.creasing,
            base.boundary,
        )
    }

    /// The sharpness of the edges around `v`, in ring order.
    pub fn incident_sharpness(&self, v: usize) -> Vec<f64> {
        self.topology
            .vertex_edges(v)
            .iter()
            .map(|&e| self.edge_sharpness[e as usize])
            .collect()
    }

    /// The sharpness of the child edge that is the half of edge `e` at its end `v`. Only
    /// Chaikin creasing looks at the other edges around `v`.
    pub fn half_edge_sharpness(&self, e: u32, v: u32) -> f64 {
        let s = self.edge_sharpness[e as usize];
        match self.creasing {
            CreasingMethod::Uniform => rules::decrement_sharpness(s),
            CreasingMethod::Chaikin => {
                rules::child_edge_sharpness(self.creasing, s, &self.incident_sharpness(v as usize))
            }
        }
    }

    /// The rule that applies at vertex `v` at this level.
    pub fn vertex_rule(&self, v: usize) -> VertexRule {
        let sharp = self
            .topology
            .vertex_edges(v)
            .iter()
            .filter(|&&e| rules::is_sharp(self.edge_sharpness[e as usize]))
            .count();
        rules::vertex_rule(self.vertex_sharpness[v], sharp)
    }

    /// Whether vertex `v` is regular: interior, valence 4, smooth, all faces quads.
    pub fn is_regular_vertex(&self, v: usize) -> bool {
        let t = &self.topology;
        !t.is_boundary_vertex(v)
            && t.vertex_edges(v).len() == 4
            && self.vertex_rule(v) == VertexRule::Smooth
            && t.vertex_faces(v)
                .iter()
                .all(|&f| t.face_vertices(f as usize).len() == 4)
    }
}
