//! Limits that protect against runaway input: how large a file, a mesh and a refinement may be.
//!
//! Every reader and [`Refinement::new_with_limits`](crate::refine::Refinement::new_with_limits)
//! checks its input against a [`Limits`] before allocating for it, and refuses with
//! [`ErrorKind::LimitExceeded`] naming what was counted, how much was asked for and the limit.
//! The defaults suit an interactive program on a machine with a few GB of memory; a caller that
//! trusts its input raises a field:
//!
//! ```
//! use gradmesh::Limits;
//!
//! let limits = Limits {
//!     refined_faces: 1 << 26,
//!     ..Limits::default()
//! };
//! assert!(limits.refined_faces > Limits::DEFAULT.refined_faces);
//! ```
//!
//! The memory of a refinement is estimated from the counts of the base mesh before any level is
//! built ([`estimate_refinement`]): the ternary step turns a face of `n` corners into
//! `1 + 2n` faces with `9n` corners (the binary step into `4n` quads), and every Catmull-Clark
//! step turns each corner into a quad, so level `k >= 2` has `4^(k-2) * corners(level 1)`
//! faces.

use std::fmt::Write as _;

use crate::error::{Error, ErrorKind};
use crate::mesh::GradientMesh;
use crate::scheme::{FirstStep, SHARPNESS_INFINITE};
use crate::validate::BaseMesh;

/// Bounds on the size of inputs and of refinements.
///
/// Each field is checked on its own, and each gives its own [`ErrorKind::LimitExceeded`] error
/// (see `docs/errors.md`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Limits {
    /// The most control points in one mesh (default 2^24).
    pub points: u64,
    /// The most faces in one mesh (default 2^24).
    pub faces: u64,
    /// The most face corners in one mesh, summed over its faces (default 2^26).
    pub corners: u64,
    /// The deepest refinement level (default 12).
    pub refinement_level: usize,
    /// The most faces of the deepest refinement level built, estimated before building
    /// (default 2^23, about 5 GB with the data of every level).
    pub refined_faces: u64,
    /// The deepest nesting of JSON arrays and objects (default 64; a document needs 7).
    pub nesting_depth: usize,
    /// The largest input, in bytes (default 256 MiB).
    pub input_bytes: u64,
}

impl Limits {
    /// The default limits.
    pub const DEFAULT: Limits = Limits {
        points: 1 << 24,
        faces: 1 << 24,
        corners: 1 << 26,
        refinement_level: 12,
        refined_faces: 1 << 23,
        nesting_depth: 64,
        input_bytes: 256 * 1024 * 1024,
    };

    /// No limit beyond what the program can represent: refinements whose indices would not fit
    /// in 32 bits are still refused. For trusted input only.
    pub const NONE: Limits = Limits {
        points: u64::MAX,
        faces: u64::MAX,
        corners: u64::MAX,
        refinement_level: usize::MAX,
        refined_faces: u64::MAX,
        nesting_depth: usize::MAX,
        input_bytes: u64::MAX,
    };

    /// Refuses an input of `len` bytes.
    pub fn check_input_bytes(&self, len: u64) -> Result<(), Error> {
        check("the input size in bytes", len, self.input_bytes)
    }

    /// Refuses a mesh with more points, faces or corners than allowed.
    pub fn check_mesh(&self, mesh: &GradientMesh) -> Result<(), Error> {
        check(
            "the number of points",
            mesh.points.len() as u64,
            self.points,
        )?;
        check("the number of faces", mesh.faces.len() as u64, self.faces)?;
        check(
            "the number of corners",
            mesh.corner_count() as u64,
            self.corners,
        )
    }

    /// Refuses to refine `base` to level `depth` when the level is too deep, or when the faces
    /// of the deepest level built would exceed [`Limits::refined_faces`], or when an index of
    /// any level would not fit in 32 bits. Nothing is built: the counts are estimated
    /// ([`estimate_refinement`]). On success, returns the estimate.
    pub fn check_refinement(
        &self,
        base: &BaseMesh,
        depth: usize,
    ) -> Result<RefinementEstimate, Error> {
        check(
            "the refinement level",
            depth as u64,
            self.refinement_level as u64,
        )?;
        let estimate = estimate_refinement(base, depth);
        let Some(deepest) = estimate.levels.last() else {
            return Ok(estimate);
        };
        let level = estimate.levels.len() - 1;
        let extra = if level > depth {
            format!(", built for the interpolated positions beyond the level {depth} asked for")
        } else {
            String::new()
        };
        if deepest.faces > self.refined_faces {
            return Err(ErrorKind::LimitExceeded {
                what: format!(
                    "the number of faces of refinement level {level} (about {} of memory{extra})",
                    human_bytes(estimate.bytes)
                ),
                found: deepest.faces,
                limit: self.refined_faces,
            }
            .into());
        }
        for (k, c) in estimate.levels.iter().enumerate() {
            let largest = c.vertices.max(c.edges).max(c.corners).max(c.faces);
            if largest >= u64::from(u32::MAX) {
                return Err(ErrorKind::LimitExceeded {
                    what: format!(
                        "the largest element count of refinement level {k} (vertices, edges or \
                         corners; indices are 32-bit)"
                    ),
                    found: largest,
                    limit: u64::from(u32::MAX) - 1,
                }
                .into());
            }
        }
        Ok(estimate)
    }
}

impl Default for Limits {
    fn default() -> Self {
        Limits::DEFAULT
    }
}

fn check(what: &str, found: u64, limit: u64) -> Result<(), Error> {
    if found > limit {
        return Err(ErrorKind::LimitExceeded {
            what: what.into(),
            found,
            limit,
        }
        .into());
    }
    Ok(())
}

/// The element counts of one refinement level.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LevelCounts {
    /// Vertices.
    pub vertices: u64,
    /// Edges.
    pub edges: u64,
    /// Faces.
    pub faces: u64,
    /// Face corners (the sum of the faces' sizes).
    pub corners: u64,
}

impl LevelCounts {
    /// The counts after the ternary step: a face of `n` corners becomes a central `n`-gon, `n`
    /// corner quads and `n` edge quads; each edge gains two points, each corner one.
    pub fn after_ternary_step(&self) -> LevelCounts {
        let (v, e, f, c) = (self.vertices, self.edges, self.faces, self.corners);
        LevelCounts {
            vertices: v.saturating_add(e.saturating_mul(2)).saturating_add(c),
            edges: e.saturating_add(c).saturating_mul(3),
            faces: f.saturating_add(c.saturating_mul(2)),
            corners: c.saturating_mul(9),
        }
    }

    /// The counts after the two binary splits: a face of `n` corners becomes `4n` quads; each
    /// edge gains three points, each face one, each corner two.
    pub fn after_binary_step(&self) -> LevelCounts {
        let (v, e, f, c) = (self.vertices, self.edges, self.faces, self.corners);
        LevelCounts {
            vertices: sum(&[(1, v), (3, e), (1, f), (2, c)]),
            edges: sum(&[(4, e), (6, c)]),
            faces: c.saturating_mul(4),
            corners: c.saturating_mul(16),
        }
    }

    /// The counts after a Catmull-Clark step: one quad per corner.
    pub fn after_catmull_clark(&self) -> LevelCounts {
        let (v, e, f, c) = (self.vertices, self.edges, self.faces, self.corners);
        LevelCounts {
            vertices: v.saturating_add(e).saturating_add(f),
            edges: e.saturating_mul(2).saturating_add(c),
            faces: c,
            corners: c.saturating_mul(4),
        }
    }

    /// Bytes of a level's topology and sharpness (flat `u32` arrays, `f64` sharpness).
    fn level_bytes(&self) -> u64 {
        let (v, e, f, c) = (self.vertices, self.edges, self.faces, self.corners);
        // face offsets, corners and their edges, edge ends and faces, ordered rings around
        // each vertex, sharpness of edges and vertices.
        sum(&[(4, f), (8, c), (16, e), (12, c), (12, v), (8, e), (8, v)])
    }

    /// Bytes of the stencils that compute the next level from this one: one term per face
    /// corner for face points, about four per edge for edge points, `1 + 2 valence` per vertex
    /// (12 bytes a term), and an offset per child vertex.
    fn stencil_bytes(&self) -> u64 {
        let (v, e, f, c) = (self.vertices, self.edges, self.faces, self.corners);
        let terms = sum(&[(1, c), (4, e), (1, v), (4, e), (1, c)]);
        sum(&[(12, terms), (4, v), (4, e), (4, f)])
    }
}

fn sum(terms: &[(u64, u64)]) -> u64 {
    terms
        .iter()
        .fold(0u64, |acc, &(k, n)| acc.saturating_add(k.saturating_mul(n)))
}

/// Bytes of one level's data (`[x, y, c0, c1, c2, opacity]` per vertex).
const DATA_BYTES_PER_VERTEX: u64 = 48;

/// What a refinement would build, counted before building it.
///
/// The byte count errs on the high side: on an 8 x 8 grid of quads refined to levels 4 to 7,
/// it was 1.25 to 1.28 times the growth of the peak resident memory of
/// `Refinement::new` + `evaluate` + `limit` (about 615 bytes per face of the deepest level).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RefinementEstimate {
    /// The counts of levels `0..=d`, where `d` is the deepest level built: the depth asked for,
    /// or more when the mesh interpolates positions (see [`estimate_refinement`]).
    pub levels: Vec<LevelCounts>,
    /// Approximate bytes of the topology, stencils and evaluated data of every level, and of
    /// the limit stencils of the deepest one.
    pub bytes: u64,
}

/// The counts and memory of the refinement of `base` down to level `depth`, as
/// [`Refinement::from_base`](crate::refine::Refinement::from_base) builds it, without building
/// anything.
///
/// A mesh with [`GradientMesh::interpolate_positions`] builds at least level 2, and further
/// while a semi-sharp crease has not decayed (up to level 12): a crease of sharpness `s` decays
/// by level `ceil(s) + 1`. [`Refinement::limit`](crate::refine::Refinement::limit) at level 0
/// or 1 builds level 2: estimate depth 2 for it.
pub fn estimate_refinement(base: &BaseMesh, depth: usize) -> RefinementEstimate {
    let t = &base.topology;
    let mut deepest = depth;
    if base.interpolate_positions {
        let semi = base
            .edge_sharpness
            .iter()
            .chain(&base.vertex_sharpness)
            .copied()
            .filter(|&s| s > 0.0 && s < SHARPNESS_INFINITE)
            .fold(0.0f64, f64::max);
        let decayed = if semi > 0.0 {
            (semi.ceil() as usize + 1).min(12)
        } else {
            2
        };
        deepest = deepest.max(decayed.max(2));
    }
    estimate_counts(
        LevelCounts {
            vertices: t.vertex_count() as u64,
            edges: t.edge_count() as u64,
            faces: t.face_count() as u64,
            corners: t.corner_count() as u64,
        },
        base.first_step,
        deepest,
    )
}

/// The counts and memory of refining a base level with the counts `base` down to level
/// `depth` (exactly `depth`, whatever the mesh's options), with `first_step` as level 1.
pub fn estimate_counts(
    base: LevelCounts,
    first_step: FirstStep,
    depth: usize,
) -> RefinementEstimate {
    let mut levels = vec![base];
    let mut bytes = base.vertices.saturating_mul(DATA_BYTES_PER_VERTEX);
    // Deeper levels only grow; stop counting once the numbers saturate.
    for k in 1..=depth {
        let parent = levels[k - 1];
        let child = if k == 1 {
            match first_step {
                FirstStep::Ternary => parent.after_ternary_step(),
                FirstStep::Binary => parent.after_binary_step(),
            }
        } else {
            parent.after_catmull_clark()
        };
        bytes = bytes
            .saturating_add(child.level_bytes())
            .saturating_add(child.vertices.saturating_mul(DATA_BYTES_PER_VERTEX));
        if k >= 2 {
            bytes = bytes.saturating_add(parent.stencil_bytes());
        }
        levels.push(child);
        if child.faces == u64::MAX {
            break;
        }
    }
    if depth >= 1 {
        // Limit stencils of the deepest level, and the copies of its data that limit points
        // take.
        let d = levels[levels.len() - 1];
        bytes = bytes
            .saturating_add(d.stencil_bytes())
            .saturating_add(d.vertices.saturating_mul(2 * DATA_BYTES_PER_VERTEX));
    }
    RefinementEstimate { levels, bytes }
}

pub use crate::error::group_digits;

/// A byte count for people: `9.8 GB`, `512 kB` (powers of 1000).
pub fn human_bytes(bytes: u64) -> String {
    let units = ["bytes", "kB", "MB", "GB", "TB", "PB", "EB"];
    let mut value = bytes as f64;
    let mut unit = 0;
    while value >= 1000.0 && unit + 1 < units.len() {
        value /= 1000.0;
        unit += 1;
    }
    let mut s = String::new();
    if unit == 0 {
        write!(s, "{bytes} bytes").unwrap();
    } else if value < 10.0 {
        write!(s, "{value:.1} {}", units[unit]).unwrap();
    } else {
        write!(s, "{value:.0} {}", units[unit]).unwrap();
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ColourSpace;
    use kurbo::Point;

    fn triangle() -> GradientMesh {
        let mut mesh = GradientMesh::new(ColourSpace::Lab);
        let a = mesh.add_point(Point::new(0.0, 0.0), [50.0, 0.0, 0.0]);
        let b = mesh.add_point(Point::new(1.0, 0.0), [50.0, 0.0, 0.0]);
        let c = mesh.add_point(Point::new(0.0, 1.0), [50.0, 0.0, 0.0]);
        mesh.add_face([a, b, c]);
        mesh
    }

    #[test]
    fn counts_match_the_refinement() {
        let mut mesh = triangle();
        let d = mesh.add_point(Point::new(1.0, 1.0), [50.0, 0.0, 0.0]);
        mesh.add_face([1, d, 2]);
        let (r, _) = crate::refine::Refinement::new(&mesh, 4).unwrap();
        let estimate = estimate_refinement(r.base(), 4);
        assert_eq!(estimate.levels.len(), 5);
        for (k, c) in estimate.levels.iter().enumerate() {
            let t = r.topology(k);
            assert_eq!(
                *c,
                LevelCounts {
                    vertices: t.vertex_count() as u64,
                    edges: t.edge_count() as u64,
                    faces: t.face_count() as u64,
                    corners: t.corner_count() as u64,
                },
                "level {k}"
            );
        }
        // Level k >= 2 has 4^(k-2) times the corners of level 1 as faces.
        let c1 = estimate.levels[1].corners;
        assert_eq!(estimate.levels[4].faces, 16 * c1);
    }

    #[test]
    fn binary_step_counts_match() {
        let mut mesh = triangle();
        let d = mesh.add_point(Point::new(1.0, 1.0), [50.0, 0.0, 0.0]);
        mesh.add_face([1, d, 2]);
        mesh.first_step = FirstStep::Binary;
        let (r, _) = crate::refine::Refinement::new(&mesh, 3).unwrap();
        let estimate = estimate_refinement(r.base(), 3);
        for (k, c) in estimate.levels.iter().enumerate() {
            let t = r.topology(k);
            assert_eq!(
                (c.vertices, c.edges, c.faces, c.corners),
                (
                    t.vertex_count() as u64,
                    t.edge_count() as u64,
                    t.face_count() as u64,
                    t.corner_count() as u64
                ),
                "level {k}"
            );
        }
    }

    #[test]
    fn interpolated_positions_build_deeper() {
        let mut mesh = triangle();
        mesh.interpolate_positions = true;
        let (base, _) = BaseMesh::new(&mesh).unwrap();
        assert_eq!(estimate_refinement(&base, 0).levels.len(), 3);
        mesh.set_edge(0, 1, crate::EdgeKind::Crease, Some(3.5));
        // A boundary edge is sharp anyway; an interior semi-sharp edge needs more faces.
        let (base, _) = BaseMesh::new(&mesh).unwrap();
        let built = estimate_refinement(&base, 1).levels.len() - 1;
        let (r, _) = crate::refine::Refinement::new(&mesh, 1).unwrap();
        assert!(built >= r.depth(), "{built} < {}", r.depth());
    }

    #[test]
    fn deep_refinement_is_refused_with_the_estimate() {
        let (base, _) = BaseMesh::new(&triangle()).unwrap();
        let e = Limits::DEFAULT.check_refinement(&base, 12).unwrap_err();
        let text = e.to_string();
        assert!(
            text.starts_with(
                "the number of faces of refinement level 12 (about 22 GB of memory) is 28,311,552, above the limit of 8,388,608"
            ),
            "{text}"
        );
        let e = Limits::DEFAULT.check_refinement(&base, 13).unwrap_err();
        assert_eq!(
            e.to_string(),
            "the refinement level is 13, above the limit of 12"
        );
        // Without limits, 32-bit indices still bound the levels.
        let e = Limits::NONE.check_refinement(&base, 40).unwrap_err();
        assert!(e.to_string().contains("indices are 32-bit"), "{e}");
        assert!(Limits::DEFAULT.check_refinement(&base, 10).is_ok());
    }

    #[test]
    fn numbers_for_people() {
        assert_eq!(group_digits(0), "0");
        assert_eq!(group_digits(999), "999");
        assert_eq!(group_digits(1000), "1,000");
        assert_eq!(group_digits(123_456_789), "123,456,789");
        assert_eq!(human_bytes(999), "999 bytes");
        assert_eq!(human_bytes(9_800_000_000), "9.8 GB");
        assert_eq!(human_bytes(512_000), "512 kB");
        assert_eq!(human_bytes(u64::MAX), "18 EB");
    }
}
