//! Checking a [`GradientMesh`] and turning it into the base level of refinement.
//!
//! The base level is the user's mesh with every point on a discontinuous edge split into one
//! vertex per wedge (the faces between two discontinuous edges), so that the two sides of a
//! discontinuous edge are separate boundaries with their own colours and handles.

use std::collections::{BTreeMap, HashMap};

use kurbo::Vec2;

use crate::edit_check::{check_edits, EditSet};
use crate::error::{Error, ErrorKind, Warning};
use crate::mesh::{
    edge_key, BoundaryInterpolation, CreasingMethod, EdgeKind, FirstStep, GradientMesh,
};
use crate::topology::{flatten, Topology};

pub use crate::scheme::{
    MAX_HANDLE_RATIO, MAX_INTERPOLATED_MAGNITUDE, MAX_MAGNITUDE, MIN_EDGE_LENGTH,
};

/// Per-vertex data carried through refinement: `[x, y, c0, c1, c2, opacity]`.
pub type VertexData = [f64; 6];

/// The validated base level: topology with discontinuities split, and the data on it.
#[derive(Clone, Debug)]
pub struct BaseMesh {
    /// Topology of the split mesh.
    pub topology: Topology,
    /// Position, colour and opacity of each split vertex.
    pub data: Vec<VertexData>,
    /// The control point each split vertex comes from. Points keep their index; extra wedges
    /// of points on discontinuous edges are appended.
    pub source_point: Vec<u32>,
    /// Handles per edge of `topology`: at `edge_vertices(e)[0]` and at `[1]`.
    pub edge_handles: Vec<[Vec2; 2]>,
    /// Sharpness per edge (0 smooth; boundaries are sharp by the rules regardless).
    pub edge_sharpness: Vec<f64>,
    /// Sharpness per vertex (infinite for corners).
    pub vertex_sharpness: Vec<f64>,
    /// Boundary interpolation rule.
    pub boundary: BoundaryInterpolation,
    /// Creasing method.
    pub creasing: CreasingMethod,
    /// Whether limit positions interpolate the control points.
    pub interpolate_positions: bool,
    /// The special first refinement (level 1).
    pub first_step: FirstStep,
    /// The multi-resolution edits, checked.
    pub edits: EditSet,
}

fn not_finite(what: String, value: f64) -> Error {
    ErrorKind::NotFinite {
        what,
        value: value.to_string(),
    }
    .into()
}

fn invalid(what: String, message: impl Into<String>) -> Error {
    ErrorKind::Invalid {
        what,
        message: message.into(),
    }
    .into()
}

/// Points whose colour lies outside the sRGB gamut that get a warning each; the rest are
/// counted in one more.
const GAMUT_WARNINGS_LISTED: usize = 10;

/// Checks a mesh; on success returns the warnings (legal but suspicious input).
pub fn validate(mesh: &GradientMesh) -> Result<Vec<Warning>, Error> {
    BaseMesh::new(mesh).map(|(_, warnings)| warnings)
}

impl BaseMesh {
    /// Validates `mesh` and builds its base level, with the warnings found.
    pub fn new(mesh: &GradientMesh) -> Result<(BaseMesh, Vec<Warning>), Error> {
        let mut warnings = Vec::new();
        let warn = |warnings: &mut Vec<Warning>, message: String| {
            warnings.push(Warning {
                layer: None,
                message,
            })
        };
        check_numbers(mesh)?;
        let n = mesh.points.len();

        // The user's topology, whole: it must be manifold before any cut.
        let (offsets, flat_corners) = flatten(&mesh.faces);
        let whole = Topology::build(n, offsets.clone(), flat_corners.clone(), |_, _| false)?;
        // Whether points a and b are joined by an edge: a scan of a's ring (no hash table).
        let has_edge = |a: u32, b: u32| {
            (a as usize) < n
                && whole
                    .vertex_edges(a as usize)
                    .iter()
                    .any(|&e| whole.other_vertex(e as usize, a) == b)
        };
        for e in 0..whole.edge_count() {
            let [a, b] = whole.edge_vertices(e);
            let (p, q) = (
                mesh.points[a as usize].position,
                mesh.points[b as usize].position,
            );
            if p == q {
                return Err(ErrorKind::ZeroLengthEdge {
                    a: a.min(b),
                    b: a.max(b),
                    x: p.x,
                    y: p.y,
                }
                .into());
            }
            // hypot is at least the larger component: only tiny edges need it.
            let (dx, dy) = ((q.x - p.x).abs(), (q.y - p.y).abs());
            let len = if dx.max(dy) >= MIN_EDGE_LENGTH {
                dx.max(dy)
            } else {
                dx.hypot(dy)
            };
            if len < MIN_EDGE_LENGTH {
                return Err(invalid(
                    format!("edge {}-{}", a.min(b), a.max(b)),
                    format!("its length {len:e} is below {MIN_EDGE_LENGTH:e}: too short to refine"),
                ));
            }
        }
        for &(a, b) in mesh.edges.keys() {
            if !has_edge(a, b) {
                return Err(ErrorKind::NoSuchEdge {
                    what: "edge tag".into(),
                    a,
                    b,
                }
                .into());
            }
        }
        for (&(from, to), h) in &mesh.handles {
            if !has_edge(from, to) {
                return Err(ErrorKind::NoSuchEdge {
                    what: format!("handle of point {from}"),
                    a: from,
                    b: to,
                }
                .into());
            }
            let len = edge_length(mesh, from, to);
            check_handle_ratio(&format!("handle of point {from} towards {to}"), *h, len)?;
            if h.hypot() > 0.5 * len * (1.0 + 1e-9) {
                warn(
                    &mut warnings,
                    format!(
                        "handle of point {from} towards {to} is longer than half its edge ({:.4} > {:.4}): the surface may fold",
                        h.hypot(),
                        0.5 * len
                    ),
                );
            }
        }

        // Without discontinuous edges no point is split: the whole topology is the base level.
        let any_discontinuous = mesh
            .edges
            .values()
            .any(|t| t.kind == EdgeKind::Discontinuous);
        let is_discontinuous = |a: u32, b: u32| {
            any_discontinuous
                && mesh
                    .edges
                    .get(&edge_key(a, b))
                    .is_some_and(|t| t.kind == EdgeKind::Discontinuous)
        };

        // Wedges: split each point's fan at discontinuous interior edges.
        // wedge_of_corner[corner] = split vertex index.
        let mut corner_vertex: Vec<u32> = flat_corners;
        let mut source_point: Vec<u32> = (0..n as u32).collect();
        // The number of faces of each split vertex's wedge, to tell whole points from wedges.
        let mut wedge_face_count: Vec<u32> =
            (0..n).map(|v| whole.vertex_faces(v).len() as u32).collect();
        for v in (0..n).filter(|_| any_discontinuous) {
            let faces = whole.vertex_faces(v);
            let corners = whole.vertex_face_corners(v);
            let edges = whole.vertex_edges(v);
            if faces.is_empty() {
                continue;
            }
            let boundary = whole.is_boundary_vertex(v);
            let cut_at = |k: usize| {
                let e = edges[k % edges.len()] as usize;
                !whole.is_boundary_edge(e) && {
                    let [a, b] = whole.edge_vertices(e);
                    is_discontinuous(a, b)
                }
            };
            let cuts: Vec<usize> = (0..faces.len()).filter(|&k| cut_at(k)).collect();
            // Face k lies between ring edges k and k+1; a new wedge starts at each cut edge.
            let wedge_count = if boundary {
                cuts.len() + 1
            } else {
                cuts.len().max(1)
            };
            let mut wedge_of_face = vec![0usize; faces.len()];
            if wedge_count > 1 {
                for (k, w) in wedge_of_face.iter_mut().enumerate() {
                    // Number of cuts at ring edges <= k (edge k precedes face k).
                    let c = cuts.iter().filter(|&&e| e <= k).count();
                    *w = if boundary {
                        c
                    } else {
                        (c + cuts.len() - 1) % cuts.len()
                    };
                }
            }
            if wedge_count == 1 {
                continue;
            }
            let mut ids = vec![v as u32];
            wedge_face_count[v] = 0;
            for _ in 1..wedge_count {
                ids.push(source_point.len() as u32);
                source_point.push(v as u32);
                wedge_face_count.push(0);
            }
            for (k, &f) in faces.iter().enumerate() {
                let id = ids[wedge_of_face[k]];
                corner_vertex[whole.face_offset(f as usize) + corners[k] as usize] = id;
                wedge_face_count[id as usize] += 1;
            }
        }

        // Data of each split vertex, with wedge overrides.
        let split_count = source_point.len();
        let mut data: Vec<_> = source_point
            .iter()
            .map(|&p| {
                let cp = &mesh.points[p as usize];
                [
                    cp.position.x,
                    cp.position.y,
                    cp.colour[0],
                    cp.colour[1],
                    cp.colour[2],
                    cp.opacity,
                ]
            })
            .collect();
        // The split vertex of each (point, face) corner, to find wedge entries in constant time.
        let mut wedge_at: HashMap<(u32, u32), u32> = HashMap::new();
        if !mesh.wedges.is_empty() {
            wedge_at.reserve(corner_vertex.len());
            for (f, face) in mesh.faces.iter().enumerate() {
                let o = whole.face_offset(f);
                for (c, &p) in face.iter().enumerate() {
                    wedge_at.insert((p, f as u32), corner_vertex[o + c]);
                }
            }
        }
        let mut override_handles: Vec<Option<&BTreeMap<u32, Vec2>>> = vec![None; split_count];
        let mut overridden = vec![false; split_count];
        for (i, w) in mesh.wedges.iter().enumerate() {
            let what = format!("wedge {i} (point {}, face {})", w.point, w.face);
            if w.point as usize >= n || w.face as usize >= mesh.faces.len() {
                return Err(invalid(
                    what,
                    "refers to a point or face that does not exist",
                ));
            }
            let Some(id) = wedge_at.get(&(w.point, w.face)).map(|&id| id as usize) else {
                return Err(invalid(what, "the face does not contain the point"));
            };
            if overridden[id] {
                return Err(invalid(
                    what,
                    "another wedge entry already sets this side of the point",
                ));
            }
            overridden[id] = true;
            let d = &mut data[id];
            d[2..5].copy_from_slice(&w.colour);
            if let Some(o) = w.opacity {
                d[5] = o;
            }
            for (&to, &h) in &w.handles {
                if !has_edge(w.point, to) {
                    return Err(ErrorKind::NoSuchEdge {
                        what: format!("handle of {what}"),
                        a: w.point,
                        b: to,
                    }
                    .into());
                }
                check_handle_ratio(
                    &format!("handle of {what} towards {to}"),
                    h,
                    edge_length(mesh, w.point, to),
                )?;
            }
            override_handles[id] = Some(&w.handles);
            if wedge_face_count[id] as usize == whole.vertex_faces(w.point as usize).len() {
                warn(
                    &mut warnings,
                    format!("{what}: the point is on no discontinuous edge, so the entry recolours it on every side"),
                );
            }
        }

        let unused: Vec<usize> = (0..n)
            .filter(|&v| whole.vertex_faces(v).is_empty())
            .collect();
        // The split topology: discontinuous edges are cut into two boundaries.
        let topology = if any_discontinuous {
            Topology::build(split_count, offsets, corner_vertex, |f, c| {
                let face = &mesh.faces[f];
                is_discontinuous(face[c], face[(c + 1) % face.len()])
            })
            .map_err(Error::from)?
        } else {
            whole
        };

        let mut edge_handles = Vec::with_capacity(topology.edge_count());
        let mut edge_sharpness = Vec::with_capacity(topology.edge_count());
        for e in 0..topology.edge_count() {
            let [a, b] = topology.edge_vertices(e);
            let (pa, pb) = (source_point[a as usize], source_point[b as usize]);
            let handle = |s: u32, from: u32, to: u32| {
                override_handles[s as usize]
                    .and_then(|h| h.get(&to))
                    .copied()
                    .unwrap_or_else(|| mesh.handle(from, to))
            };
            edge_handles.push([handle(a, pa, pb), handle(b, pb, pa)]);
            edge_sharpness.push(mesh.edge_tag(pa, pb).effective_sharpness());
        }
        let vertex_sharpness = source_point
            .iter()
            .map(|&p| {
                if mesh.points[p as usize].corner {
                    crate::mesh::SHARPNESS_INFINITE
                } else {
                    0.0
                }
            })
            .collect();

        for v in unused {
            warn(&mut warnings, format!("point {v} is not used by any face"));
        }
        // One warning per point for the first few; a count for the rest (a mesh made in a wide
        // space may have thousands, and formatting them cost a tenth of validation).
        let mut outside = 0usize;
        for (v, p) in mesh.points.iter().enumerate() {
            if !mesh.colour_space.in_srgb_gamut(p.colour) {
                outside += 1;
                if outside <= GAMUT_WARNINGS_LISTED {
                    warn(
                        &mut warnings,
                        format!(
                            "point {v}: colour {:?} ({}) is outside the sRGB gamut",
                            p.colour,
                            mesh.colour_space.name()
                        ),
                    );
                }
            }
        }
        if outside > GAMUT_WARNINGS_LISTED {
            warn(
                &mut warnings,
                format!(
                    "{} more points have colours outside the sRGB gamut",
                    outside - GAMUT_WARNINGS_LISTED
                ),
            );
        }

        Ok((
            BaseMesh {
                topology,
                data,
                source_point,
                edge_handles,
                edge_sharpness,
                vertex_sharpness,
                boundary: mesh.boundary,
                creasing: mesh.creasing,
                interpolate_positions: mesh.interpolate_positions,
                first_step: mesh.first_step,
                edits: EditSet::default(),
            },
            warnings,
        ))
        .and_then(|(mut base, warnings)| {
            base.edits = check_edits(
                &base.topology,
                &base.source_point,
                base.first_step,
                &mesh.edits,
                mesh.fine_edits,
                mesh.colour_space,
            )?;
            Ok((base, warnings))
        })
    }
}

/// The length of the edge between points `a` and `b`, without overflow or underflow.
fn edge_length(mesh: &GradientMesh, a: u32, b: u32) -> f64 {
    let d = mesh.points[b as usize].position - mesh.points[a as usize].position;
    d.x.hypot(d.y)
}

/// Refuses a handle more than [`MAX_HANDLE_RATIO`] times as long as its edge.
fn check_handle_ratio(what: &str, h: Vec2, edge_length: f64) -> Result<(), Error> {
    let len = h.x.hypot(h.y);
    if len > MAX_HANDLE_RATIO * edge_length {
        return Err(invalid(
            what.to_string(),
            format!(
                "its length {len:e} is more than {MAX_HANDLE_RATIO:e} times its edge's \
                 ({edge_length:e})"
            ),
        ));
    }
    Ok(())
}

/// Refuses a finite value beyond [`MAX_MAGNITUDE`].
fn check_magnitude(what: impl FnOnce() -> String, v: f64) -> Result<(), Error> {
    if v.abs() > MAX_MAGNITUDE {
        return Err(invalid(
            what(),
            format!("{v:e} is beyond ±{MAX_MAGNITUDE:e}, the largest magnitude refined without overflow"),
        ));
    }
    Ok(())
}

fn check_numbers(mesh: &GradientMesh) -> Result<(), Error> {
    for (i, p) in mesh.points.iter().enumerate() {
        for (name, v) in [("x", p.position.x), ("y", p.position.y)] {
            if !v.is_finite() {
                return Err(not_finite(format!("point {i} {name}"), v));
            }
            check_magnitude(|| format!("point {i} {name}"), v)?;
            if mesh.interpolate_positions && v.abs() > MAX_INTERPOLATED_MAGNITUDE {
                return Err(invalid(
                    format!("point {i} {name}"),
                    format!(
                        "{v:e} is beyond ±{MAX_INTERPOLATED_MAGNITUDE:e}, the largest magnitude \
                         with interpolate_positions"
                    ),
                ));
            }
        }
        for (k, &c) in p.colour.iter().enumerate() {
            if !c.is_finite() {
                return Err(not_finite(format!("point {i} colour channel {k}"), c));
            }
            check_magnitude(|| format!("point {i} colour channel {k}"), c)?;
        }
        if !p.opacity.is_finite() {
            return Err(not_finite(format!("point {i} opacity"), p.opacity));
        }
        if !(0.0..=1.0).contains(&p.opacity) {
            return Err(invalid(
                format!("point {i}"),
                format!("opacity must be in 0..1, found {}", p.opacity),
            ));
        }
    }
    for (&(from, to), h) in &mesh.handles {
        for (name, v) in [("x", h.x), ("y", h.y)] {
            if !v.is_finite() {
                return Err(not_finite(format!("handle {from}->{to} {name}"), v));
            }
            check_magnitude(|| format!("handle {from}->{to} {name}"), v)?;
        }
        if from as usize >= mesh.points.len() || to as usize >= mesh.points.len() {
            return Err(ErrorKind::NoSuchEdge {
                what: format!("handle of point {from}"),
                a: from,
                b: to,
            }
            .into());
        }
    }
    for (&(a, b), t) in &mesh.edges {
        if let Some(s) = t.sharpness {
            if !s.is_finite() || s < 0.0 {
                return Err(invalid(
                    format!("edge {a}-{b}"),
                    format!("sharpness must be a finite number >= 0, found {s}"),
                ));
            }
        }
    }
    for (i, w) in mesh.wedges.iter().enumerate() {
        for (k, &c) in w.colour.iter().enumerate() {
            if !c.is_finite() {
                return Err(not_finite(format!("wedge {i} colour channel {k}"), c));
            }
            check_magnitude(|| format!("wedge {i} colour channel {k}"), c)?;
        }
        if let Some(o) = w.opacity {
            if !(0.0..=1.0).contains(&o) {
                return Err(invalid(
                    format!("wedge {i}"),
                    format!("opacity must be in 0..1, found {o}"),
                ));
            }
        }
        for (to, h) in &w.handles {
            if !h.x.is_finite() || !h.y.is_finite() {
                return Err(not_finite(
                    format!("wedge {i} handle towards {to}"),
                    h.x + h.y,
                ));
            }
            check_magnitude(|| format!("wedge {i} handle towards {to}"), h.x)?;
            check_magnitude(|| format!("wedge {i} handle towards {to}"), h.y)?;
        }
    }
    Ok(())
}
