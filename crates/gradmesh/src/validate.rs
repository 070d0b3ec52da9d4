//! Checking a [`GradientMesh`] and turning it into the base level of refinement.
//!
//! The base level is the user's mesh with every point on a discontinuous edge split into one
//! vertex per wedge (the faces between two discontinuous edges), so that the two sides of a
//! discontinuous edge are separate boundaries with their own colours and handles.

use std::collections::{BTreeMap, HashMap};

use kurbo::{Point, Vec2};

use crate::edit_check::{check_edits, EditSet};
use crate::error::{Error, ErrorKind, Warning, WarningKind};
use crate::mesh::{
    edge_key, BoundaryInterpolation, CreasingMethod, EdgeKind, FirstStep, GradientMesh,
};
use crate::topology::{flatten, Topology};

pub use crate::scheme::{
    MAX_HANDLE_RATIO, MAX_INTERPOLATED_MAGNITUDE, MAX_MAGNITUDE, MIN_EDGE_LENGTH,
};

/// Per-vertex data carried through refinement: position, colour (three channels of the working
/// space) and opacity. Refinement combines whole vertices with the same weights
/// ([`VertexData::add_scaled`], the arithmetic operators); [`VertexData::to_array`] and
/// [`VertexData::from_array`] give the flat form `[x, y, c0, c1, c2, opacity]`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct VertexData {
    /// `[x, y]` in the plane of the mesh.
    pub position: [f64; 2],
    /// The three channels of the colour, in the mesh's working colour space.
    pub colour: [f64; 3],
    /// Opacity, 0 transparent to 1 opaque.
    pub opacity: f64,
}

impl VertexData {
    /// Zero in every coordinate: the start of a weighted sum.
    pub const ZERO: VertexData = VertexData {
        position: [0.0; 2],
        colour: [0.0; 3],
        opacity: 0.0,
    };

    /// The data of a point at `position` with `colour` and `opacity`.
    pub fn new(position: Point, colour: [f64; 3], opacity: f64) -> Self {
        VertexData {
            position: [position.x, position.y],
            colour,
            opacity,
        }
    }

    /// The data from its flat form `[x, y, c0, c1, c2, opacity]`.
    #[inline]
    pub fn from_array(a: [f64; 6]) -> Self {
        VertexData {
            position: [a[0], a[1]],
            colour: [a[2], a[3], a[4]],
            opacity: a[5],
        }
    }

    /// The flat form `[x, y, c0, c1, c2, opacity]`.
    #[inline]
    pub fn to_array(&self) -> [f64; 6] {
        let ([x, y], [c0, c1, c2]) = (self.position, self.colour);
        [x, y, c0, c1, c2, self.opacity]
    }

    /// The position as a point.
    #[inline]
    pub fn point(&self) -> Point {
        Point::new(self.position[0], self.position[1])
    }

    /// The colour and opacity: the attributes the renderer interpolates.
    #[inline]
    pub fn attributes(&self) -> [f64; 4] {
        let [c0, c1, c2] = self.colour;
        [c0, c1, c2, self.opacity]
    }

    /// `f` applied to every coordinate.
    #[inline]
    pub fn map(&self, f: impl FnMut(f64) -> f64) -> Self {
        Self::from_array(self.to_array().map(f))
    }

    /// `f` applied to each pair of coordinates of `self` and `other`.
    #[inline]
    pub fn zip_with(&self, other: &Self, mut f: impl FnMut(f64, f64) -> f64) -> Self {
        let (a, b) = (self.to_array(), other.to_array());
        Self::from_array(std::array::from_fn(|k| f(a[k], b[k])))
    }

    /// Adds `w * other` to `self`, coordinate by coordinate: a term of a weighted sum.
    #[inline]
    pub fn add_scaled(&mut self, other: &Self, w: f64) {
        self.position[0] += w * other.position[0];
        self.position[1] += w * other.position[1];
        self.colour[0] += w * other.colour[0];
        self.colour[1] += w * other.colour[1];
        self.colour[2] += w * other.colour[2];
        self.opacity += w * other.opacity;
    }

    /// The weighted sum of `terms`, added in order from zero.
    #[inline]
    pub fn weighted_sum<'a>(terms: impl IntoIterator<Item = (&'a VertexData, f64)>) -> Self {
        let mut sum = Self::ZERO;
        for (d, w) in terms {
            sum.add_scaled(d, w);
        }
        sum
    }

    /// The point a fraction `t` of the way from `self` to `other`: `self + t * (other - self)`.
    #[inline]
    pub fn lerp(&self, other: &Self, t: f64) -> Self {
        self.zip_with(other, |a, b| a + t * (b - a))
    }
}

impl std::ops::Add for VertexData {
    type Output = VertexData;
    #[inline]
    fn add(self, other: VertexData) -> VertexData {
        self.zip_with(&other, |a, b| a + b)
    }
}

impl std::ops::Sub for VertexData {
    type Output = VertexData;
    #[inline]
    fn sub(self, other: VertexData) -> VertexData {
        self.zip_with(&other, |a, b| a - b)
    }
}

impl std::ops::Mul<f64> for VertexData {
    type Output = VertexData;
    #[inline]
    fn mul(self, w: f64) -> VertexData {
        self.map(|a| a * w)
    }
}

impl std::ops::Mul<VertexData> for f64 {
    type Output = VertexData;
    #[inline]
    fn mul(self, d: VertexData) -> VertexData {
        d.map(|a| self * a)
    }
}

impl std::ops::AddAssign for VertexData {
    #[inline]
    fn add_assign(&mut self, other: VertexData) {
        *self = *self + other;
    }
}

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
        check_numbers(mesh)?;
        let n = mesh.points.len();

        // The user's topology, whole: it must be manifold before any cut.
        let (offsets, flat_corners) = flatten(&mesh.faces);
        let whole = Topology::build(n, offsets.clone(), flat_corners.clone(), |_, _| false)?;
        check_edge_lengths(mesh, &whole)?;
        check_edge_tags(mesh, &whole)?;
        check_handles(mesh, &whole, &mut warnings)?;

        let cuts = Discontinuities::of(mesh);
        let wedges = Wedges::split(&whole, flat_corners, &cuts);
        let mut data = wedges.vertex_data(mesh);
        let override_handles =
            apply_wedge_entries(mesh, &whole, &wedges, &mut data, &mut warnings)?;
        // Warned before the split topology is built: a failure there drops every warning.
        for v in (0..n).filter(|&v| whole.vertex_faces(v).is_empty()) {
            warn(
                &mut warnings,
                WarningKind::UnusedPoint,
                format!("point {v} is not used by any face"),
            );
        }
        let Wedges {
            corner_vertex,
            source_point,
            ..
        } = wedges;
        // The split topology: discontinuous edges are cut into two boundaries.
        let topology = if cuts.any {
            Topology::build(source_point.len(), offsets, corner_vertex, |f, c| {
                let face = &mesh.faces[f];
                cuts.between(face[c], face[(c + 1) % face.len()])
            })
            .map_err(Error::from)?
        } else {
            whole
        };
        let (edge_handles, edge_sharpness) =
            edge_handles_and_sharpness(mesh, &topology, &source_point, &override_handles);
        let vertex_sharpness = vertex_sharpness(mesh, &source_point);
        warn_outside_gamut(mesh, &mut warnings);

        let edits = check_edits(
            &topology,
            &source_point,
            mesh.first_step,
            &mesh.edits,
            mesh.fine_edits,
            mesh.colour_space,
        )?;
        let base = BaseMesh {
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
            edits,
        };
        Ok((base, warnings))
    }
}

fn warn(warnings: &mut Vec<Warning>, kind: WarningKind, message: String) {
    warnings.push(Warning::new(kind, message))
}

/// Whether points `a` and `b` are joined by an edge of `whole`: a scan of `a`'s ring (no hash
/// table).
fn has_edge(whole: &Topology, a: u32, b: u32) -> bool {
    (a as usize) < whole.vertex_count()
        && whole
            .vertex_edges(a as usize)
            .iter()
            .any(|&e| whole.other_vertex(e as usize, a) == b)
}

/// Refuses edges of zero length or too short to refine.
fn check_edge_lengths(mesh: &GradientMesh, whole: &Topology) -> Result<(), Error> {
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
    Ok(())
}

/// Refuses edge tags on pairs of points that no face edge joins.
fn check_edge_tags(mesh: &GradientMesh, whole: &Topology) -> Result<(), Error> {
    for &(a, b) in mesh.edges.keys() {
        if !has_edge(whole, a, b) {
            return Err(ErrorKind::NoSuchEdge {
                what: "edge tag".into(),
                a,
                b,
            }
            .into());
        }
    }
    Ok(())
}

/// Refuses handles off the mesh's edges or far too long, and warns of those that may fold the
/// surface.
fn check_handles(
    mesh: &GradientMesh,
    whole: &Topology,
    warnings: &mut Vec<Warning>,
) -> Result<(), Error> {
    for (&(from, to), h) in &mesh.handles {
        if !has_edge(whole, from, to) {
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
                warnings,
                WarningKind::HandleMayFold,
                format!(
                    "handle of point {from} towards {to} is longer than half its edge ({:.4} > {:.4}): the surface may fold",
                    h.hypot(),
                    0.5 * len
                ),
            );
        }
    }
    Ok(())
}

/// The discontinuous edges of a mesh.
struct Discontinuities<'a> {
    mesh: &'a GradientMesh,
    /// Whether there is any: without, no point is split and the whole topology is the base
    /// level.
    any: bool,
}

impl<'a> Discontinuities<'a> {
    fn of(mesh: &'a GradientMesh) -> Self {
        let any = mesh
            .edges
            .values()
            .any(|t| t.kind == EdgeKind::Discontinuous);
        Discontinuities { mesh, any }
    }

    /// Whether the edge between points `a` and `b` is discontinuous.
    fn between(&self, a: u32, b: u32) -> bool {
        self.any
            && self
                .mesh
                .edges
                .get(&edge_key(a, b))
                .is_some_and(|t| t.kind == EdgeKind::Discontinuous)
    }
}

/// The points split into one vertex per wedge: each point's fan cut at its discontinuous
/// interior edges. Points keep their index; extra wedges are appended.
struct Wedges {
    /// The split vertex at each flat corner of the faces.
    corner_vertex: Vec<u32>,
    /// The point each split vertex comes from.
    source_point: Vec<u32>,
    /// The number of faces of each split vertex's wedge, to tell whole points from wedges.
    face_count: Vec<u32>,
}

impl Wedges {
    fn split(whole: &Topology, flat_corners: Vec<u32>, cuts: &Discontinuities) -> Wedges {
        let n = whole.vertex_count();
        let mut wedges = Wedges {
            corner_vertex: flat_corners,
            source_point: (0..n as u32).collect(),
            face_count: (0..n).map(|v| whole.vertex_faces(v).len() as u32).collect(),
        };
        for v in (0..n).filter(|_| cuts.any) {
            wedges.split_point(whole, v, cuts);
        }
        wedges
    }

    /// Splits point `v` into its wedges, if it has more than one.
    fn split_point(&mut self, whole: &Topology, v: usize, cuts: &Discontinuities) {
        let faces = whole.vertex_faces(v);
        let corners = whole.vertex_face_corners(v);
        if faces.is_empty() {
            return;
        }
        let Some((wedge_count, wedge_of_face)) = wedge_of_each_face(whole, v, cuts) else {
            return;
        };
        let mut ids = vec![v as u32];
        self.face_count[v] = 0;
        for _ in 1..wedge_count {
            ids.push(self.source_point.len() as u32);
            self.source_point.push(v as u32);
            self.face_count.push(0);
        }
        for (k, &f) in faces.iter().enumerate() {
            let id = ids[wedge_of_face[k]];
            self.corner_vertex[whole.face_offset(f as usize) + corners[k] as usize] = id;
            self.face_count[id as usize] += 1;
        }
    }

    /// Position, colour and opacity of each split vertex, from its point.
    fn vertex_data(&self, mesh: &GradientMesh) -> Vec<VertexData> {
        self.source_point
            .iter()
            .map(|&p| {
                let cp = &mesh.points[p as usize];
                VertexData::new(cp.position, cp.colour, cp.opacity)
            })
            .collect()
    }
}

/// The number of wedges of point `v`, and the wedge of each face around it in ring order;
/// `None` when the point has one wedge only.
fn wedge_of_each_face(
    whole: &Topology,
    v: usize,
    cuts: &Discontinuities,
) -> Option<(usize, Vec<usize>)> {
    let faces = whole.vertex_faces(v);
    let edges = whole.vertex_edges(v);
    let boundary = whole.is_boundary_vertex(v);
    let cut_at = |k: usize| {
        let e = edges[k % edges.len()] as usize;
        !whole.is_boundary_edge(e) && {
            let [a, b] = whole.edge_vertices(e);
            cuts.between(a, b)
        }
    };
    let cut_edges: Vec<usize> = (0..faces.len()).filter(|&k| cut_at(k)).collect();
    // Face k lies between ring edges k and k+1; a new wedge starts at each cut edge.
    let wedge_count = if boundary {
        cut_edges.len() + 1
    } else {
        cut_edges.len().max(1)
    };
    if wedge_count == 1 {
        return None;
    }
    let wedge_of_face = (0..faces.len())
        .map(|k| {
            // Number of cuts at ring edges <= k (edge k precedes face k).
            let c = cut_edges.iter().filter(|&&e| e <= k).count();
            if boundary {
                c
            } else {
                (c + cut_edges.len() - 1) % cut_edges.len()
            }
        })
        .collect();
    Some((wedge_count, wedge_of_face))
}

/// Applies the mesh's wedge entries (colour, opacity, handles of one side of a point) to
/// `data`; returns the handles each split vertex takes from an entry.
fn apply_wedge_entries<'m>(
    mesh: &'m GradientMesh,
    whole: &Topology,
    wedges: &Wedges,
    data: &mut [VertexData],
    warnings: &mut Vec<Warning>,
) -> Result<Vec<Option<&'m BTreeMap<u32, Vec2>>>, Error> {
    let (n, split_count) = (mesh.points.len(), wedges.source_point.len());
    // The split vertex of each (point, face) corner, to find wedge entries in constant time.
    let mut wedge_at: HashMap<(u32, u32), u32> = HashMap::new();
    if !mesh.wedges.is_empty() {
        wedge_at.reserve(wedges.corner_vertex.len());
        for (f, face) in mesh.faces.iter().enumerate() {
            let o = whole.face_offset(f);
            for (c, &p) in face.iter().enumerate() {
                wedge_at.insert((p, f as u32), wedges.corner_vertex[o + c]);
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
        d.colour = w.colour;
        if let Some(o) = w.opacity {
            d.opacity = o;
        }
        for (&to, &h) in &w.handles {
            if !has_edge(whole, w.point, to) {
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
        if wedges.face_count[id] as usize == whole.vertex_faces(w.point as usize).len() {
            warn(
                warnings,
                WarningKind::WedgeEntryWithoutDiscontinuity,
                format!("{what}: the point is on no discontinuous edge, so the entry recolours it on every side"),
            );
        }
    }
    Ok(override_handles)
}

/// The handles and sharpness of each edge of the split `topology`; a wedge entry's handles
/// take the place of its point's.
fn edge_handles_and_sharpness(
    mesh: &GradientMesh,
    topology: &Topology,
    source_point: &[u32],
    override_handles: &[Option<&BTreeMap<u32, Vec2>>],
) -> (Vec<[Vec2; 2]>, Vec<f64>) {
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
    (edge_handles, edge_sharpness)
}

/// The sharpness of each split vertex: infinite at corners.
fn vertex_sharpness(mesh: &GradientMesh, source_point: &[u32]) -> Vec<f64> {
    source_point
        .iter()
        .map(|&p| {
            if mesh.points[p as usize].corner {
                crate::mesh::SHARPNESS_INFINITE
            } else {
                0.0
            }
        })
        .collect()
}

/// Warns of colours outside the sRGB gamut: one warning per point for the first few, a count
/// for the rest (a mesh made in a wide space may have thousands, and formatting them all is
/// a noticeable part of validation).
fn warn_outside_gamut(mesh: &GradientMesh, warnings: &mut Vec<Warning>) {
    let mut outside = 0usize;
    for (v, p) in mesh.points.iter().enumerate() {
        if !mesh.colour_space.in_srgb_gamut(p.colour) {
            outside += 1;
            if outside <= GAMUT_WARNINGS_LISTED {
                warn(
                    warnings,
                    WarningKind::OutsideGamut,
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
        let more = outside - GAMUT_WARNINGS_LISTED;
        let message = format!("{more} more points have colours outside the sRGB gamut");
        warnings.push(Warning::new(WarningKind::OutsideGamut, message).counting(more));
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
