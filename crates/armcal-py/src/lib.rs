//! armcal from Python (issue 34): the native module `armcal._armcal`, re-exported by the
//! package `armcal` (`python/armcal/__init__.py`).
//!
//! The binding calls only the library's front door (root items `armcal::X`, see
//! `docs/src/reference/library.md`): numpy arrays in, numpy arrays and record objects out.
//! Units are the library's: joint values in rad (mm for a prismatic joint), lengths in mm,
//! angles in rad. Every call that computes copies its inputs out of the read-only arrays,
//! then releases the GIL (`Python::detach`) for the computation, so other Python threads run
//! while armcal works; rayon's pool honours `RAYON_NUM_THREADS`. armcal's errors are raised
//! as `armcal.ArmcalError` (a `ValueError`) with armcal's message, which names the file,
//! line or row and field.
//!
//! - [`arrays`]: numpy in and out, with messages that name the argument and its shape.
//! - [`progress`]: a Python callable as armcal's `Observer`.
//! - [`records`]: the Python classes (`Cell`, `Dataset`, `Estimate`, `Design`, …); every
//!   record pickles through its serde JSON, so it crosses process and machine boundaries.
//! - [`calls`]: the functions (`fk`, `simulate`, `identify`, `plan`, …).
//! - [`fleet`]: one robot's calibration task and the in-process fleet over rayon.

use pyo3::prelude::*;

mod arrays;
mod calls;
mod fleet;
mod progress;
mod records;

pyo3::create_exception!(
    _armcal,
    ArmcalError,
    pyo3::exceptions::PyValueError,
    "An error armcal reports: bad input (its message names the file, line or row, and the \
     field) or a computation that cannot be done. A subclass of ValueError."
);

/// armcal's error as an [`ArmcalError`] with armcal's message.
pub(crate) fn armcal_error(e: armcal::Error) -> PyErr {
    ArmcalError::new_err(e.to_string())
}

/// The native module: classes and functions; `armcal/__init__.py` re-exports them.
#[pymodule]
fn _armcal(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("ArmcalError", m.py().get_type::<ArmcalError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    records::register(m)?;
    calls::register(m)?;
    fleet::register(m)?;
    Ok(())
}
