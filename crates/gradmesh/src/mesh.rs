//! The gradient-mesh model: control points, faces, handles and edge tags, as a user edits them.

use std::collections::BTreeMap;

use kurbo::{Point, Vec2};

use crate::colour::ColourSpace;
use crate::multires::{Edit, FineEdits, VertexAddress};
pub use crate::scheme::{BoundaryInterpolation, CreasingMethod, FirstStep, SHARPNESS_INFINITE};

/// A picture: gradient meshes drawn in order, the first at the bottom.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Document {
    /// The meshes, bottom first.
    pub layers: Vec<GradientMesh>,
    /// The part of the plane the picture shows, when the document says (a vectorised picture
    /// whose mesh covers only part of it keeps the picture's rectangle): `gradmesh render`
    /// draws it by default, one pixel per unit. `None`: the points' bounding box.
    pub view: Option<kurbo::Rect>,
}

impl Document {
    /// A document of `layers`, the first at the bottom, with no view of its own.
    pub fn new(layers: Vec<GradientMesh>) -> Document {
        Document { layers, view: None }
    }
}

/// One control point of a gradient mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct ControlPoint {
    /// Position in the plane (y grows downward, as in SVG).
    pub position: Point,
    /// Colour coordinates in the mesh's working colour space.
    pub colour: [f64; 3],
    /// Opacity in 0..=1.
    pub opacity: f64,
    /// Keep this point as a corner (infinitely sharp vertex) during refinement.
    pub corner: bool,
    /// How the colour was written in the source file (a CSS colour string), kept so that saving
    /// gives back the same text. Written back only while it still denotes `colour`.
    pub colour_text: Option<String>,
}

impl ControlPoint {
    /// A point at `position` with `colour`, fully opaque, not a corner.
    pub fn new(position: Point, colour: [f64; 3]) -> Self {
        ControlPoint {
            position,
            colour,
            opacity: 1.0,
            corner: false,
            colour_text: None,
        }
    }
}

/// How an edge of the control mesh joins the two sides of the surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum EdgeKind {
    /// C1 (the default).
    Smooth,
    /// C0: position and colour continuous, derivative not.
    Crease,
    /// C-1: the two sides are separate and may carry different colours and handles.
    Discontinuous,
}

impl EdgeKind {
    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            EdgeKind::Smooth => "smooth",
            EdgeKind::Crease => "crease",
            EdgeKind::Discontinuous => "discontinuous",
        }
    }
}

/// The tag of one edge of the control mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeTag {
    /// Smooth, crease or discontinuous.
    pub kind: EdgeKind,
    /// Sharpness of a crease: `None` is infinitely sharp; a fractional value gives a semi-sharp
    /// edge (Pixar's rules). Ignored for other kinds.
    pub sharpness: Option<f64>,
}

impl EdgeTag {
    /// The sharpness the refinement uses for this edge (0 when smooth).
    pub fn effective_sharpness(&self) -> f64 {
        match self.kind {
            EdgeKind::Smooth => 0.0,
            EdgeKind::Crease => self.sharpness.unwrap_or(SHARPNESS_INFINITE),
            // Discontinuous edges become boundaries; their sharpness is that of a boundary.
            EdgeKind::Discontinuous => SHARPNESS_INFINITE,
        }
    }
}

/// The colour, opacity and handles of one side of a discontinuous edge at one of its points.
///
/// The faces around a point on a discontinuous edge fall into wedges separated by the
/// discontinuous edges; each wedge is refined as a separate control point. A wedge without an
/// override uses the point's own colour, opacity and handles.
#[derive(Clone, Debug, PartialEq)]
pub struct WedgeOverride {
    /// Index of the control point.
    pub point: u32,
    /// A face around the point: the override applies to the whole wedge that contains it.
    pub face: u32,
    /// Colour of the point on this side.
    pub colour: [f64; 3],
    /// Kept source text of the colour, as for [`ControlPoint::colour_text`].
    pub colour_text: Option<String>,
    /// Opacity on this side (default: the point's).
    pub opacity: Option<f64>,
    /// Handles on this side, by the neighbour they point to (default: the point's, or a third of
    /// the edge).
    pub handles: BTreeMap<u32, Vec2>,
}

/// One gradient mesh: a manifold polygon mesh with a colour per control point and a handle per
/// (control point, incident edge).
#[derive(Clone, Debug, PartialEq)]
pub struct GradientMesh {
    /// An optional name (a layer name in the authors' files).
    pub name: Option<String>,
    /// The working colour space of every colour in this mesh.
    pub colour_space: ColourSpace,
    /// Boundary interpolation rule.
    pub boundary: BoundaryInterpolation,
    /// Sharpness subdivision rule for semi-sharp creases.
    pub creasing: CreasingMethod,
    /// Move each control point's vertex after the first step (ternary or binary) so that the
    /// limit surface passes through the control point (paper section 4.5). Off by default, as
    /// in the paper.
    pub interpolate_positions: bool,
    /// The special first refinement: one ternary split (default) or two binary splits.
    pub first_step: FirstStep,
    /// The control points.
    pub points: Vec<ControlPoint>,
    /// Faces as loops of point indices, all wound the same way.
    pub faces: Vec<Vec<u32>>,
    /// Handles given explicitly, keyed by (point, neighbour). A missing handle defaults to one
    /// third of its edge.
    pub handles: BTreeMap<(u32, u32), Vec2>,
    /// Edge tags, keyed by the point pair with the smaller index first. Untagged edges are smooth.
    pub edges: BTreeMap<(u32, u32), EdgeTag>,
    /// Per-side colours and handles at discontinuous edges.
    pub wedges: Vec<WedgeOverride>,
    /// Multi-resolution edits of refined vertices (see [`VertexAddress`]), at most one per vertex.
    pub edits: Vec<Edit>,
    /// Which edits the mesh allows below level 0.
    pub fine_edits: FineEdits,
}

impl Default for GradientMesh {
    fn default() -> Self {
        GradientMesh {
            name: None,
            colour_space: ColourSpace::Lab,
            boundary: BoundaryInterpolation::EdgeAndCorner,
            creasing: CreasingMethod::Uniform,
            interpolate_positions: false,
            first_step: FirstStep::Ternary,
            points: Vec::new(),
            faces: Vec::new(),
            handles: BTreeMap::new(),
            edges: BTreeMap::new(),
            wedges: Vec::new(),
            edits: Vec::new(),
            fine_edits: FineEdits::ColourAndPosition,
        }
    }
}

/// The key of an undirected edge: the smaller index first.
pub fn edge_key(a: u32, b: u32) -> (u32, u32) {
    if a <= b {
        (a, b)
    } else {
        (b, a)
    }
}

impl GradientMesh {
    /// An empty mesh in the given working colour space.
    pub fn new(colour_space: ColourSpace) -> Self {
        GradientMesh {
            colour_space,
            ..GradientMesh::default()
        }
    }

    /// Adds a control point and returns its index.
    pub fn add_point(&mut self, position: Point, colour: [f64; 3]) -> u32 {
        self.points.push(ControlPoint::new(position, colour));
        (self.points.len() - 1) as u32
    }

    /// Adds a face (a loop of point indices) and returns its index.
    pub fn add_face(&mut self, corners: impl Into<Vec<u32>>) -> u32 {
        self.faces.push(corners.into());
        (self.faces.len() - 1) as u32
    }

    /// Tags the edge between `a` and `b`.
    pub fn set_edge(&mut self, a: u32, b: u32, kind: EdgeKind, sharpness: Option<f64>) {
        let key = edge_key(a, b);
        if kind == EdgeKind::Smooth {
            self.edges.remove(&key);
        } else {
            self.edges.insert(key, EdgeTag { kind, sharpness });
        }
    }

    /// The tag of the edge between `a` and `b` (smooth when untagged).
    pub fn edge_tag(&self, a: u32, b: u32) -> EdgeTag {
        self.edges.get(&edge_key(a, b)).copied().unwrap_or(EdgeTag {
            kind: EdgeKind::Smooth,
            sharpness: None,
        })
    }

    /// The handle of point `from` along its edge towards `to`: the explicit one, or one third of
    /// the edge.
    pub fn handle(&self, from: u32, to: u32) -> Vec2 {
        if let Some(h) = self.handles.get(&(from, to)) {
            return *h;
        }
        let (p, q) = (
            self.points[from as usize].position,
            self.points[to as usize].position,
        );
        (q - p) / 3.0
    }

    /// Sets the handle of point `from` along its edge towards `to`.
    pub fn set_handle(&mut self, from: u32, to: u32, handle: Vec2) {
        self.handles.insert((from, to), handle);
    }

    /// The edit of the vertex named `address`, if any (the name as written: a vertex on a
    /// sector's side has other names too).
    pub fn edit(&self, address: &VertexAddress) -> Option<&Edit> {
        self.edits.iter().find(|e| e.address == *address)
    }

    /// Adds `edit`, or replaces the edit with the same address; returns the one replaced.
    pub fn set_edit(&mut self, edit: Edit) -> Option<Edit> {
        match self.edits.iter_mut().find(|e| e.address == edit.address) {
            Some(old) => Some(std::mem::replace(old, edit)),
            None => {
                self.edits.push(edit);
                None
            }
        }
    }

    /// Removes the edit with `address`; returns it.
    pub fn remove_edit(&mut self, address: &VertexAddress) -> Option<Edit> {
        let i = self.edits.iter().position(|e| e.address == *address)?;
        Some(self.edits.remove(i))
    }

    /// Number of corners over all faces.
    pub fn corner_count(&self) -> usize {
        self.faces.iter().map(Vec::len).sum()
    }
}
