//! Python bindings of gradmesh: the extension module `gradmesh._gradmesh`, which the Python
//! package `gradmesh` (in `python/gradmesh`) re-exports. A thin layer over the library's public
//! API: arrays in and out through numpy, the library's located errors as `gradmesh.Error`, its
//! warnings through Python's `warnings` module. `docs/python.md` describes the API.

mod arrays;
mod mesh;
mod picture;
mod pipeline;

use std::ffi::CString;

use pyo3::exceptions::{PyUserWarning, PyValueError};
use pyo3::prelude::*;

pyo3::create_exception!(
    gradmesh,
    Error,
    PyValueError,
    "An input gradmesh refuses (a bad file, mesh, array or option), with the place it lies."
);
pyo3::create_exception!(
    gradmesh,
    MeshWarning,
    PyUserWarning,
    "Legal but suspicious input (a point used by no face, a handle that may fold the surface)."
);

/// The library's error as a `gradmesh.Error` carrying its located message.
pub(crate) fn error(e: gradmesh::Error) -> PyErr {
    Error::new_err(e.to_string())
}

/// A `gradmesh.Error` with `message`.
pub(crate) fn invalid(message: impl Into<String>) -> PyErr {
    Error::new_err(message.into())
}

/// Issues the library's warnings as `gradmesh.MeshWarning`s, attributed to the caller.
pub(crate) fn warn(py: Python<'_>, warnings: &[gradmesh::Warning]) -> PyResult<()> {
    let category = py.get_type::<MeshWarning>();
    for w in warnings {
        let text = w.to_string().replace('\0', " ");
        let message = CString::new(text).expect("NUL bytes replaced");
        PyErr::warn(py, category.as_any(), &message, 1)?;
    }
    Ok(())
}

#[pymodule]
fn _gradmesh(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("Error", py.get_type::<Error>())?;
    m.add("MeshWarning", py.get_type::<MeshWarning>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<mesh::Mesh>()?;
    m.add_class::<mesh::Document>()?;
    m.add_function(wrap_pyfunction!(pipeline::read, m)?)?;
    m.add_function(wrap_pyfunction!(pipeline::refine, m)?)?;
    m.add_function(wrap_pyfunction!(pipeline::limit_matrix_arrays, m)?)?;
    m.add_function(wrap_pyfunction!(picture::render_picture, m)?)?;
    m.add_function(wrap_pyfunction!(picture::export_file, m)?)?;
    Ok(())
}
