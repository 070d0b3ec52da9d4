//! Reading files, refining a mesh and its limit colours as a sparse matrix.

use gradmesh::{formats, refine_level, LevelPoints, Limits, VertexData};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::{to_rows, to_vector};
use crate::mesh::{parse_first_step, Document, Mesh};
use crate::{error, warn};

/// Reads a file: .json (the native format), .off (the paper authors' OFF), .obj or .svg (its
/// mesh gradients). Errors name the file and line.
#[pyfunction]
pub fn read(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Document> {
    let doc = py.detach(|| formats::read_path(&path)).map_err(error)?;
    Ok(Document { doc })
}

/// Level `levels` of the refinement of `mesh` (0 the mesh itself, 1 the first step, then
/// Catmull-Clark steps), its control points or, with `limit=True`, their limits: a dict of
/// "points" (V, 2), "colours" (V, 3), "opacity" (V,), "face_offsets" (F + 1,) and
/// "face_points". `interpolate_positions` and `first_step` override the mesh's options.
#[pyfunction]
#[pyo3(signature = (mesh, levels, limit=false, *, interpolate_positions=None, first_step=None))]
pub fn refine<'py>(
    py: Python<'py>,
    mesh: &Bound<'py, Mesh>,
    levels: usize,
    limit: bool,
    interpolate_positions: Option<bool>,
    first_step: Option<&str>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut m = mesh.get().mesh.clone();
    if let Some(i) = interpolate_positions {
        m.interpolate_positions = i;
    }
    if let Some(s) = first_step {
        m.first_step = parse_first_step(s)?;
    }
    let points = if limit {
        LevelPoints::Limit
    } else {
        LevelPoints::Control
    };
    let (level, warnings) = py
        .detach(|| refine_level(&m, levels, points, &Limits::DEFAULT))
        .map_err(error)?;
    warn(py, &warnings)?;
    let data = &level.data;
    let t = &level.topology;
    let mut offsets = vec![0i64];
    let mut corners = Vec::with_capacity(t.corner_count());
    for f in 0..t.face_count() {
        corners.extend(t.face_vertices(f).iter().map(|&v| i64::from(v)));
        offsets.push(corners.len() as i64);
    }
    let dict = PyDict::new(py);
    dict.set_item("points", to_rows(py, flat(data, |d| &d.position), 2))?;
    dict.set_item("colours", to_rows(py, flat(data, |d| &d.colour), 3))?;
    let opacity: Vec<f64> = data.iter().map(|d| d.opacity).collect();
    dict.set_item("opacity", to_vector(py, opacity))?;
    dict.set_item("face_offsets", to_vector(py, offsets))?;
    dict.set_item("face_points", to_vector(py, corners))?;
    Ok(dict)
}

/// The channels `field` picks of every vertex, one vertex after the other.
fn flat(data: &[VertexData], field: impl Fn(&VertexData) -> &[f64]) -> Vec<f64> {
    data.iter().flat_map(|d| field(d).iter().copied()).collect()
}

/// The limit colours of level `level`'s vertices as a sparse matrix of the points' colours
/// (see `gradmesh.limit_matrix`): `(data, indices, indptr, (rows, columns))`, the arrays of a
/// CSR matrix.
#[pyfunction]
#[pyo3(name = "limit_matrix_arrays")]
pub fn limit_matrix_arrays<'py>(
    py: Python<'py>,
    mesh: &Bound<'py, Mesh>,
    level: usize,
) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
    let m = &mesh.get().mesh;
    let (matrix, warnings) = py
        .detach(|| gradmesh::limit_matrix(m, level, &Limits::DEFAULT))
        .map_err(error)?;
    warn(py, &warnings)?;
    let indices: Vec<i64> = matrix.indices.iter().map(|&c| i64::from(c)).collect();
    let indptr: Vec<i64> = matrix.offsets.iter().map(|&o| o as i64).collect();
    let shape = (matrix.rows, matrix.columns).into_pyobject(py)?.into_any();
    crate::mesh::tuple(
        py,
        vec![
            to_vector(py, matrix.values),
            to_vector(py, indices),
            to_vector(py, indptr),
            shape,
        ],
    )
}
