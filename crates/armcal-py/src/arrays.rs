//! numpy at the edges: an argument read as a float64 matrix (any array-like; copied out of
//! the read-only view before the GIL is released), results as new numpy arrays. A wrong
//! shape is an `ArmcalError` naming the argument, the expected and the actual shape.

use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{AllowTypeChange, IntoPyArray, PyArray1, PyArray2, PyArray3, PyArrayLikeDyn};
use pyo3::prelude::*;

use crate::ArmcalError;

/// The rows of `value`, a 2-D array-like of numbers, as owned rows; `width` is the number
/// of columns it must have (`None`: any, the same for every row); `what` says what a row
/// holds and in which unit, for the message.
pub(crate) fn rows(
    value: &Bound<'_, PyAny>,
    name: &str,
    width: Option<usize>,
    what: &str,
) -> PyResult<Vec<Vec<f64>>> {
    let shape_error = |got: String| {
        let cols = width.map_or("k".to_string(), |w| w.to_string());
        ArmcalError::new_err(format!(
            "{name}: expected an array of shape (n, {cols}) ({what}), got {got}"
        ))
    };
    let array: PyArrayLikeDyn<'_, f64, AllowTypeChange> =
        value.extract().map_err(|_| shape_error(type_name(value)))?;
    let view = array.as_array();
    if view.ndim() != 2 || width.is_some_and(|w| view.shape()[1] != w) {
        return Err(shape_error(format!("shape {:?}", view.shape())));
    }
    Ok(view
        .outer_iter()
        .map(|row| row.iter().copied().collect())
        .collect())
}

/// `value`, a 1-D array-like of numbers, as a vector of length `len` (`None`: any).
pub(crate) fn vector(
    value: &Bound<'_, PyAny>,
    name: &str,
    len: Option<usize>,
    what: &str,
) -> PyResult<Vec<f64>> {
    let shape_error = |got: String| {
        let n = len.map_or("n".to_string(), |l| l.to_string());
        ArmcalError::new_err(format!(
            "{name}: expected an array of shape ({n},) ({what}), got {got}"
        ))
    };
    let array: PyArrayLikeDyn<'_, f64, AllowTypeChange> =
        value.extract().map_err(|_| shape_error(type_name(value)))?;
    let view = array.as_array();
    if view.ndim() != 1 || len.is_some_and(|l| view.len() != l) {
        return Err(shape_error(format!("shape {:?}", view.shape())));
    }
    Ok(view.iter().copied().collect())
}

/// Equal-length rows as an (n, k) array; `k` is used for an empty list.
pub(crate) fn matrix<'py>(
    py: Python<'py>,
    rows: &[Vec<f64>],
    k: usize,
) -> Bound<'py, PyArray2<f64>> {
    let k = rows.first().map_or(k, Vec::len);
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    Array2::from_shape_vec((rows.len(), k), flat)
        .expect("rows of equal length")
        .into_pyarray(py)
}

/// Square matrices (`nalgebra`, column-major) as an (n, r, r) array, row-major per matrix.
pub(crate) fn stack<'py, const R: usize>(
    py: Python<'py>,
    mats: &[armcal::nalgebra::SMatrix<f64, R, R>],
) -> Bound<'py, PyArray3<f64>> {
    Array3::from_shape_fn((mats.len(), R, R), |(i, r, c)| mats[i][(r, c)]).into_pyarray(py)
}

/// A dynamic matrix (`nalgebra`) as a 2-D array.
pub(crate) fn dmatrix<'py>(
    py: Python<'py>,
    m: &armcal::nalgebra::DMatrix<f64>,
) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_fn((m.nrows(), m.ncols()), |(r, c)| m[(r, c)]).into_pyarray(py)
}

/// A vector as a 1-D array.
pub(crate) fn array1<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    Array1::from_vec(v).into_pyarray(py)
}

/// "a <type>" for a message.
fn type_name(value: &Bound<'_, PyAny>) -> String {
    let name = value.get_type().name().map(|n| n.to_string());
    format!("a {}", name.unwrap_or_else(|_| "?".into()))
}
