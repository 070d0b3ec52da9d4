//! Arrays in and out: Python objects taken as float64 or integer numpy arrays with their
//! shape and values checked (errors naming the argument and the element), and Rust vectors
//! handed to numpy without a copy.

use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyAnyMethods;

use crate::invalid;

/// A float64 array read from Python: its shape and its values in C order.
pub struct Floats {
    pub shape: Vec<usize>,
    pub data: Vec<f64>,
}

/// `obj` converted by `numpy.ascontiguousarray(obj, dtype=float64)`, named `name` in errors.
pub fn floats(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Floats> {
    let py = obj.py();
    let numpy = py.import("numpy")?;
    let converted = numpy
        .call_method1("ascontiguousarray", (obj, "float64"))
        .map_err(|e| {
            invalid(format!(
                "{name}: cannot be read as an array of numbers ({e})"
            ))
        })?;
    let array = converted
        .cast_into::<PyArrayDyn<f64>>()
        .map_err(|e| invalid(format!("{name}: {e}")))?;
    let read = array.readonly();
    let data = read
        .as_slice()
        .map_err(|e| invalid(format!("{name}: {e}")))?
        .to_vec();
    Ok(Floats {
        shape: read.shape().to_vec(),
        data,
    })
}

/// `obj` as an `(n, width)` array of finite numbers (`n` given when known): its rows.
pub fn rows(
    obj: &Bound<'_, PyAny>,
    name: &str,
    width: usize,
    n: Option<usize>,
) -> PyResult<Vec<f64>> {
    let a = floats(obj, name)?;
    let expected = match n {
        Some(n) => format!("({n}, {width})"),
        None => format!("(N, {width})"),
    };
    let fits = a.shape.len() == 2 && a.shape[1] == width && n.is_none_or(|n| a.shape[0] == n);
    if !fits {
        return Err(invalid(format!(
            "{name}: shape {:?}, expected {expected}",
            a.shape
        )));
    }
    check_finite(&a.data, name, width)?;
    Ok(a.data)
}

/// `obj` as a one-dimensional array of `n` finite numbers.
pub fn vector(obj: &Bound<'_, PyAny>, name: &str, n: usize) -> PyResult<Vec<f64>> {
    let a = floats(obj, name)?;
    if a.shape != [n] {
        return Err(invalid(format!(
            "{name}: shape {:?}, expected ({n},)",
            a.shape
        )));
    }
    check_finite(&a.data, name, 1)?;
    Ok(a.data)
}

/// Refuses NaN and infinities, naming the first one's place (`name[row, column]`).
fn check_finite(data: &[f64], name: &str, width: usize) -> PyResult<()> {
    match data.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) if width == 1 => Err(invalid(format!(
            "{name}[{i}] is {}: not a finite number",
            data[i]
        ))),
        Some(i) => Err(invalid(format!(
            "{name}[{}, {}] is {}: not a finite number",
            i / width,
            i % width,
            data[i]
        ))),
    }
}

/// Faces given as a sequence of sequences of point indices (or a 2-D integer array), checked
/// to be non-negative integers that fit 32 bits; `faces[f][c]` names a bad one.
pub fn faces(obj: &Bound<'_, PyAny>) -> PyResult<Vec<Vec<u32>>> {
    let mut out = Vec::new();
    let items = obj
        .try_iter()
        .map_err(|_| invalid("faces: expected a sequence of faces (sequences of point indices)"))?;
    for (f, item) in items.enumerate() {
        let face: Vec<i64> = item?
            .extract()
            .map_err(|e| invalid(format!("faces[{f}]: not a sequence of integers ({e})")))?;
        let mut corners = Vec::with_capacity(face.len());
        for (c, &i) in face.iter().enumerate() {
            let index = u32::try_from(i).map_err(|_| {
                invalid(format!(
                    "faces[{f}][{c}] is {i}: a point index must lie in 0..2^32"
                ))
            })?;
            corners.push(index);
        }
        out.push(corners);
    }
    Ok(out)
}

/// `data` as an `(n, width)` numpy array, without a copy.
pub fn to_rows<'py, T: numpy::Element>(
    py: Python<'py>,
    data: Vec<T>,
    width: usize,
) -> Bound<'py, PyAny> {
    let n = data.len() / width;
    Array2::from_shape_vec((n, width), data)
        .expect("whole rows")
        .into_pyarray(py)
        .into_any()
}

/// `data` as a one-dimensional numpy array, without a copy.
pub fn to_vector<'py, T: numpy::Element>(py: Python<'py>, data: Vec<T>) -> Bound<'py, PyAny> {
    Array1::from_vec(data).into_pyarray(py).into_any()
}

/// Faces as compressed rows: `offsets` (one more than the faces) into `points`.
pub fn face_csr(faces: &[Vec<u32>]) -> (Vec<i64>, Vec<i64>) {
    let mut offsets = Vec::with_capacity(faces.len() + 1);
    let mut points = Vec::new();
    offsets.push(0);
    for face in faces {
        points.extend(face.iter().map(|&v| i64::from(v)));
        offsets.push(points.len() as i64);
    }
    (offsets, points)
}
