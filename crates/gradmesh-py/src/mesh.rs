//! `gradmesh.Mesh` and `gradmesh.Document`: immutable Python views of the library's model, with
//! numpy arrays out and validated construction from arrays.

use std::collections::BTreeMap;

use gradmesh::formats::{self, Format};
use gradmesh::{
    ColourEdit, ColourSpace, ControlPoint, EdgeKind, EdgeTag, FirstStep, GradientMesh, OpacityEdit,
};
use kurbo::{Point, Vec2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};

use crate::arrays::{self, face_csr, to_rows, to_vector};
use crate::{error, invalid, warn};

/// One gradient mesh: control points with colours (in the mesh's colour space) and opacity,
/// faces, handles and edge tags. Immutable: `with_colours` and `with_points` give new meshes.
#[pyclass(module = "gradmesh", frozen)]
#[derive(Clone)]
pub struct Mesh {
    pub mesh: GradientMesh,
}

/// Checks a mesh the library's way, issuing its warnings; errors name the place.
pub fn validated(py: Python<'_>, mesh: GradientMesh) -> PyResult<Mesh> {
    let warnings = gradmesh::validate(&mesh).map_err(error)?;
    warn(py, &warnings)?;
    Ok(Mesh { mesh })
}

fn parse_colour_space(name: &str) -> PyResult<ColourSpace> {
    ColourSpace::from_name(name).ok_or_else(|| {
        invalid(format!(
            "colour_space: {name:?} is not one of \"lab\", \"oklab\", \"srgb-linear\", \"srgb\""
        ))
    })
}

pub fn parse_first_step(name: &str) -> PyResult<FirstStep> {
    match name {
        "ternary" => Ok(FirstStep::Ternary),
        "binary" => Ok(FirstStep::Binary),
        _ => Err(invalid(format!(
            "first_step: {name:?} is not \"ternary\" or \"binary\""
        ))),
    }
}

/// Edge tags from `{(a, b): "crease" | "discontinuous" | ("crease", sharpness)}`.
fn parse_edges(dict: &Bound<'_, PyDict>) -> PyResult<BTreeMap<(u32, u32), EdgeTag>> {
    let mut tags = BTreeMap::new();
    for (key, value) in dict.iter() {
        let (a, b): (u32, u32) = key
            .extract()
            .map_err(|_| invalid(format!("edges: key {key} is not a pair of point indices")))?;
        let (kind, sharpness): (String, Option<f64>) = match value.extract::<String>() {
            Ok(kind) => (kind, None),
            Err(_) => value.extract().map_err(|_| {
                invalid(format!(
                    "edges[({a}, {b})]: expected \"crease\", \"discontinuous\" or (\"crease\", sharpness)"
                ))
            })?,
        };
        let kind = match kind.as_str() {
            "smooth" => EdgeKind::Smooth,
            "crease" => EdgeKind::Crease,
            "discontinuous" => EdgeKind::Discontinuous,
            other => {
                return Err(invalid(format!(
                "edges[({a}, {b})]: {other:?} is not \"smooth\", \"crease\" or \"discontinuous\""
            )))
            }
        };
        if kind != EdgeKind::Smooth {
            tags.insert((a.min(b), a.max(b)), EdgeTag { kind, sharpness });
        }
    }
    Ok(tags)
}

/// Handles from `{(point, neighbour): (dx, dy)}`.
fn parse_handles(dict: &Bound<'_, PyDict>) -> PyResult<BTreeMap<(u32, u32), Vec2>> {
    let mut handles = BTreeMap::new();
    for (key, value) in dict.iter() {
        let (from, to): (u32, u32) = key
            .extract()
            .map_err(|_| invalid(format!("handles: key {key} is not a pair of point indices")))?;
        let (x, y): (f64, f64) = value.extract().map_err(|_| {
            invalid(format!(
                "handles[({from}, {to})]: expected a pair of numbers (dx, dy)"
            ))
        })?;
        handles.insert((from, to), Vec2::new(x, y));
    }
    Ok(handles)
}

#[pymethods]
impl Mesh {
    /// A mesh from arrays: `points` (N, 2), `faces` (sequences of point indices), `colours`
    /// (N, 3) in `colour_space`, `opacity` (N,) in 0..1 (default 1). Checked as a file is: a
    /// bad array or mesh raises `gradmesh.Error` naming the place.
    #[new]
    #[pyo3(signature = (points, faces, colours, opacity=None, *, colour_space="lab", name=None,
        corners=None, handles=None, edges=None, first_step="ternary", interpolate_positions=false))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        points: &Bound<'_, PyAny>,
        faces: &Bound<'_, PyAny>,
        colours: &Bound<'_, PyAny>,
        opacity: Option<&Bound<'_, PyAny>>,
        colour_space: &str,
        name: Option<String>,
        corners: Option<Vec<u32>>,
        handles: Option<&Bound<'_, PyDict>>,
        edges: Option<&Bound<'_, PyDict>>,
        first_step: &str,
        interpolate_positions: bool,
    ) -> PyResult<Mesh> {
        let xy = arrays::rows(points, "points", 2, None)?;
        let n = xy.len() / 2;
        let rgb = arrays::rows(colours, "colours", 3, Some(n))?;
        let alpha = match opacity {
            Some(o) => arrays::vector(o, "opacity", n)?,
            None => vec![1.0; n],
        };
        let mut mesh = GradientMesh::new(parse_colour_space(colour_space)?);
        mesh.name = name;
        mesh.first_step = parse_first_step(first_step)?;
        mesh.interpolate_positions = interpolate_positions;
        for i in 0..n {
            let mut p = ControlPoint::new(
                Point::new(xy[2 * i], xy[2 * i + 1]),
                [rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]],
            );
            p.opacity = alpha[i];
            mesh.points.push(p);
        }
        for c in corners.unwrap_or_default() {
            let point = mesh.points.get_mut(c as usize).ok_or_else(|| {
                invalid(format!("corners: point {c} does not exist ({n} points)"))
            })?;
            point.corner = true;
        }
        mesh.faces = arrays::faces(faces)?;
        if let Some(h) = handles {
            mesh.handles = parse_handles(h)?;
        }
        if let Some(e) = edges {
            mesh.edges = parse_edges(e)?;
        }
        validated(py, mesh)
    }

    /// Control point positions, (N, 2) float64 (y down, as in SVG).
    #[getter]
    fn points<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        let p = &self.mesh.points;
        to_rows(
            py,
            p.iter()
                .flat_map(|p| [p.position.x, p.position.y])
                .collect(),
            2,
        )
    }

    /// Control point colours, (N, 3) float64, in the mesh's colour space.
    #[getter]
    fn colours<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        to_rows(
            py,
            self.mesh.points.iter().flat_map(|p| p.colour).collect(),
            3,
        )
    }

    /// Control point opacity, (N,) float64 in 0..1.
    #[getter]
    fn opacity<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        to_vector(py, self.mesh.points.iter().map(|p| p.opacity).collect())
    }

    /// Whether each point is kept as a corner, (N,) bool.
    #[getter]
    fn corners<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        to_vector(py, self.mesh.points.iter().map(|p| p.corner).collect())
    }

    /// The faces, a list of int64 arrays of point indices.
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let faces = self.mesh.faces.iter().map(|f| {
            let f: Vec<i64> = f.iter().map(|&v| i64::from(v)).collect();
            to_vector(py, f)
        });
        PyList::new(py, faces)
    }

    /// Offsets of each face's corners in `face_points`, (F + 1,) int64.
    #[getter]
    fn face_offsets<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        to_vector(py, face_csr(&self.mesh.faces).0)
    }

    /// Every face's point indices one after the other, int64 (see `face_offsets`).
    #[getter]
    fn face_points<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        to_vector(py, face_csr(&self.mesh.faces).1)
    }

    /// The working colour space: "lab", "oklab", "srgb-linear" or "srgb".
    #[getter]
    fn colour_space(&self) -> &'static str {
        self.mesh.colour_space.name()
    }

    /// The mesh's name, if any.
    #[getter]
    fn name(&self) -> Option<String> {
        self.mesh.name.clone()
    }

    /// The first refinement step: "ternary" or "binary".
    #[getter]
    fn first_step(&self) -> &'static str {
        self.mesh.first_step.name()
    }

    /// Whether the limit surface passes through the control points.
    #[getter]
    fn interpolate_positions(&self) -> bool {
        self.mesh.interpolate_positions
    }

    /// Tagged edges: `{(a, b): (kind, sharpness)}`, kind "crease" or "discontinuous",
    /// sharpness None for infinitely sharp.
    #[getter]
    fn edges<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let dict = PyDict::new(py);
        for (&(a, b), tag) in &self.mesh.edges {
            dict.set_item((a, b), (tag.kind.name(), tag.sharpness))?;
        }
        Ok(dict)
    }

    /// Handles given explicitly: `{(point, neighbour): (dx, dy)}` (the others are a third of
    /// their edge).
    #[getter]
    fn handles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let dict = PyDict::new(py);
        for (&(a, b), h) in &self.mesh.handles {
            dict.set_item((a, b), (h.x, h.y))?;
        }
        Ok(dict)
    }

    /// Multi-resolution edits: one dict per edit, with "address" (level, face, point, (i, j))
    /// and "colour" (("offset" | "set", (c0, c1, c2)) or None), "opacity" (("offset" | "set",
    /// value) or None) and "offset" ((x, y) or None).
    #[getter]
    fn edits<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let list = PyList::empty(py);
        for e in &self.mesh.edits {
            let a = &e.address;
            let dict = PyDict::new(py);
            dict.set_item("address", (a.level, a.face, a.point, (a.at[0], a.at[1])))?;
            let colour = e.colour.map(|c| match c {
                ColourEdit::Offset(c) => ("offset", (c[0], c[1], c[2])),
                ColourEdit::Set(c) => ("set", (c[0], c[1], c[2])),
            });
            dict.set_item("colour", colour)?;
            let opacity = e.opacity.map(|o| match o {
                OpacityEdit::Offset(x) => ("offset", x),
                OpacityEdit::Set(x) => ("set", x),
            });
            dict.set_item("opacity", opacity)?;
            dict.set_item("offset", e.offset.map(|v| (v.x, v.y)))?;
            list.append(dict)?;
        }
        Ok(list)
    }

    /// Number of per-side overrides at discontinuous edges (their data is in `to_json`).
    #[getter]
    fn wedge_count(&self) -> usize {
        self.mesh.wedges.len()
    }

    /// This mesh with other colours (N, 3) and, if given, opacity (N,): everything else kept.
    #[pyo3(signature = (colours, opacity=None))]
    fn with_colours(
        &self,
        py: Python<'_>,
        colours: &Bound<'_, PyAny>,
        opacity: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Mesh> {
        let n = self.mesh.points.len();
        let rgb = arrays::rows(colours, "colours", 3, Some(n))?;
        let alpha = opacity
            .map(|o| arrays::vector(o, "opacity", n))
            .transpose()?;
        let mut mesh = self.mesh.clone();
        for (i, p) in mesh.points.iter_mut().enumerate() {
            p.colour = [rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]];
            p.colour_text = None;
            if let Some(a) = &alpha {
                p.opacity = a[i];
            }
        }
        validated(py, mesh)
    }

    /// This mesh with its points moved to `points` (N, 2): everything else kept.
    fn with_points(&self, py: Python<'_>, points: &Bound<'_, PyAny>) -> PyResult<Mesh> {
        let xy = arrays::rows(points, "points", 2, Some(self.mesh.points.len()))?;
        let mut mesh = self.mesh.clone();
        for (i, p) in mesh.points.iter_mut().enumerate() {
            p.position = Point::new(xy[2 * i], xy[2 * i + 1]);
        }
        validated(py, mesh)
    }

    /// The warnings the mesh gives (legal but suspicious input), as strings.
    fn warnings(&self) -> PyResult<Vec<String>> {
        let warnings = gradmesh::validate(&self.mesh).map_err(error)?;
        Ok(warnings.iter().map(ToString::to_string).collect())
    }

    fn __len__(&self) -> usize {
        self.mesh.points.len()
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<Mesh>()
            .is_ok_and(|o| o.get().mesh == self.mesh)
    }

    fn __repr__(&self) -> String {
        format!(
            "<gradmesh.Mesh{}: {} points, {} faces, {}>",
            self.mesh
                .name
                .as_ref()
                .map(|n| format!(" {n:?}"))
                .unwrap_or_default(),
            self.mesh.points.len(),
            self.mesh.faces.len(),
            self.mesh.colour_space.name()
        )
    }
}

/// A picture: meshes drawn in order, the first at the bottom. Immutable: build a new one from
/// `layers` to change it.
#[pyclass(module = "gradmesh", frozen)]
pub struct Document {
    pub doc: gradmesh::Document,
}

#[pymethods]
impl Document {
    /// A document of the given meshes, the first at the bottom.
    #[new]
    fn new(layers: Vec<Bound<'_, Mesh>>) -> Document {
        let layers = layers.iter().map(|m| m.get().mesh.clone()).collect();
        Document {
            doc: gradmesh::Document::new(layers),
        }
    }

    /// A document from the native JSON format's text (docs/format.md).
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Document> {
        let doc = formats::read_str(text, Format::Json).map_err(error)?;
        Ok(Document { doc })
    }

    /// The document in the native JSON format.
    fn to_json(&self) -> String {
        formats::json::write_document(&self.doc)
    }

    /// Writes the document to `path` in the native JSON format (the only format that holds a
    /// whole document), atomically: a failed write leaves no partial file.
    fn write(&self, path: std::path::PathBuf) -> PyResult<()> {
        if Format::from_path(&path) != Some(Format::Json) {
            return Err(invalid(format!(
                "{}: documents are written as .json (the native format)",
                path.display()
            )));
        }
        let text = formats::json::write_document(&self.doc);
        formats::write_atomic(&path, text.as_bytes()).map_err(error)
    }

    /// The meshes, bottom first (copies: a document is immutable).
    #[getter]
    fn layers(&self) -> Vec<Mesh> {
        let layers = &self.doc.layers;
        layers.iter().map(|m| Mesh { mesh: m.clone() }).collect()
    }

    fn __len__(&self) -> usize {
        self.doc.layers.len()
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<Document>()
            .is_ok_and(|o| o.get().doc == self.doc)
    }

    fn __repr__(&self) -> String {
        format!("<gradmesh.Document: {} layers>", self.doc.layers.len())
    }
}

/// A tuple of Python objects (used by the functions that return several arrays).
pub fn tuple<'py>(py: Python<'py>, items: Vec<Bound<'py, PyAny>>) -> PyResult<Bound<'py, PyTuple>> {
    PyTuple::new(py, items)
}
