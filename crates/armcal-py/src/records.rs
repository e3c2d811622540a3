//! The Python classes: a [`Cell`] and the records armcal's calls return ([`Dataset`],
//! [`Estimate`], [`Design`], [`CampaignState`], [`DriftCheck`]). Each record holds the
//! library's serde record unchanged, shows the numbers a user works with as numpy arrays
//! (internal units: mm, rad), and has `to_json()` (the same JSON the command line writes),
//! `from_json(text)`, `to_dict()` and pickling by its JSON (`__reduce__`), so it crosses
//! process and machine boundaries (Ray, multiprocessing).

use numpy::{PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyType};
use serde::de::DeserializeOwned;
use serde::Serialize;

use crate::arrays::{array1, dmatrix, matrix, stack};
use crate::{armcal_error, ArmcalError};

/// `value` as JSON text (pretty, as the command line writes its files).
pub(crate) fn to_json<T: Serialize>(value: &T) -> PyResult<String> {
    serde_json::to_string_pretty(value).map_err(|e| ArmcalError::new_err(e.to_string()))
}

/// `text` read as the record `kind` (for the message).
pub(crate) fn from_json<T: DeserializeOwned>(text: &str, kind: &str) -> PyResult<T> {
    serde_json::from_str(text)
        .map_err(|e| ArmcalError::new_err(format!("not a JSON {kind} record: {e}")))
}

/// `value` as plain Python objects (dicts, lists, numbers, strings), through its JSON.
fn to_python<'py, T: Serialize>(py: Python<'py>, value: &T) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(|e| ArmcalError::new_err(e.to_string()))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// A name (`"lm"`, `"kpi"`, `"huber"`) as the library's enum of that field, through the
/// enum's serde name: the binding names only root items of the library, and these
/// enums' own names are not at its root. A wrong name is an error listing the valid ones.
pub(crate) fn named<T: DeserializeOwned>(name: &str, field: &str) -> PyResult<T> {
    serde_json::from_value(serde_json::Value::String(name.to_string()))
        .map_err(|e| ArmcalError::new_err(format!("{field}: {e}")))
}

/// The shared methods of a record class wrapping the serde record in field `inner`.
/// (PyO3 allows one `#[pymethods]` block per class without its `multiple-pymethods`
/// feature, so the class's own methods are passed in.)
macro_rules! record_methods {
    ($py_type:ident, $kind:literal, { $($own:tt)* }) => {
        #[pymethods]
        impl $py_type {
            $($own)*

            /// The record as JSON text (what the command line writes to its file).
            fn to_json(&self) -> PyResult<String> {
                to_json(&self.inner)
            }

            /// The record read from JSON text (`to_json`, or the command line's file).
            #[classmethod]
            fn from_json(_cls: &Bound<'_, PyType>, text: &str) -> PyResult<Self> {
                Ok(Self::wrap(from_json(text, $kind)?))
            }

            /// The record as plain Python objects (dicts, lists, numbers; file units).
            fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
                to_python(py, &self.inner)
            }

            /// Pickling: the record's JSON, read back by `from_json`.
            fn __reduce__<'py>(
                slf: &Bound<'py, Self>,
            ) -> PyResult<(Bound<'py, PyAny>, (String,))> {
                let from_json = slf.get_type().getattr("from_json")?;
                Ok((from_json, (slf.borrow().to_json()?,)))
            }
        }
    };
}

/// A robot cell: robot, instrument, targets, working poses, obstacles, and its model.
#[pyclass(module = "armcal._armcal", frozen)]
pub(crate) struct Cell {
    pub(crate) cell: armcal::Cell,
    /// How it was made, for pickling: (`"load"`, name or path) or (`"toml"`, text).
    origin: (String, String),
}

impl Cell {
    /// The cell's source as the campaign records it (its path or built-in name; a TOML
    /// text's cell name).
    pub(crate) fn source(&self) -> String {
        match self.origin.0.as_str() {
            "load" => self.origin.1.clone(),
            _ => self.cell.name.clone(),
        }
    }

    fn restore(kind: &str, arg: &str) -> PyResult<Cell> {
        let cell = match kind {
            "load" => armcal::Cell::load(arg),
            "toml" => armcal::Cell::from_toml(arg, "<text>", std::path::Path::new(".")),
            _ => {
                return Err(ArmcalError::new_err(format!(
                    "unknown cell origin `{kind}`"
                )))
            }
        }
        .map_err(armcal_error)?;
        Ok(Cell {
            cell,
            origin: (kind.to_string(), arg.to_string()),
        })
    }
}

#[pymethods]
impl Cell {
    /// A cell file (`.toml`) or a built-in robot's name (`kr15`, `paper-650-600`, …).
    /// A pickled cell loads the same path or name again where it is unpickled.
    #[classmethod]
    fn load(_cls: &Bound<'_, PyType>, name_or_path: &str) -> PyResult<Cell> {
        Cell::restore("load", name_or_path)
    }

    /// A cell from its TOML text (files it names are relative to the working directory).
    #[classmethod]
    fn from_toml(_cls: &Bound<'_, PyType>, text: &str) -> PyResult<Cell> {
        Cell::restore("toml", text)
    }

    /// The cell's name.
    #[getter]
    fn name(&self) -> String {
        self.cell.name.clone()
    }

    /// Number of joints.
    #[getter]
    fn dof(&self) -> usize {
        self.cell.model.dof()
    }

    /// The joints' names.
    #[getter]
    fn joints(&self) -> Vec<String> {
        self.cell
            .model
            .joints
            .iter()
            .map(|j| j.name.clone())
            .collect()
    }

    /// The joint limits `(lower, upper)`, each of shape (dof,) (rad; mm for a prismatic
    /// joint).
    fn joint_limits<'py>(
        &self,
        py: Python<'py>,
    ) -> (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>) {
        let (lower, upper) = self.cell.model.joint_limits();
        (array1(py, lower), array1(py, upper))
    }

    /// The nominal parameters, shape (p,), registry order (internal units: mm, rad).
    fn nominal<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.cell.model.nominal())
    }

    /// The cell's working poses (what `plan`'s KPI criterion and `Estimate.tcp_cov` are
    /// about), shape (w, dof) (rad, mm).
    fn working_poses<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let rows: Vec<Vec<f64>> = self.cell.working.iter().map(|w| w.q.clone()).collect();
        matrix(py, &rows, self.cell.model.dof())
    }

    /// Every model parameter, in registry order, as a dict: `name`, `unit` (display unit:
    /// `mm`, `deg`, …), `nominal` (internal units: mm, rad), `nominal_display` (in `unit`),
    /// `status` (`free`, `fixed` or `prior`), `prior_sigma` (internal units, for a prior),
    /// and `reason`: why the identifiability analysis of the cell's declared free set
    /// (the cell's measurement, its random poses) leaves it out, or `None`.
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let cell = &self.cell;
        let analysis = py
            .detach(|| cell.identifiability(&cell.identifiability_settings()))
            .map_err(armcal_error)?;
        let list = PyList::empty(py);
        for p in cell.model.registry.iter() {
            let d = PyDict::new(py);
            d.set_item("name", &p.name)?;
            d.set_item("unit", p.unit.display_name())?;
            d.set_item("nominal", p.nominal)?;
            d.set_item("nominal_display", p.nominal * p.unit.display_factor())?;
            // The status's serde form: {"status": "free" | "fixed" | "prior", "sigma": …}.
            let status =
                serde_json::to_value(p.status).map_err(|e| ArmcalError::new_err(e.to_string()))?;
            d.set_item("status", status["status"].as_str())?;
            d.set_item("prior_sigma", status.get("sigma").and_then(|s| s.as_f64()))?;
            let reason = analysis.excluded.iter().find(|e| e.name == p.name);
            d.set_item("reason", reason.map(|e| e.reason.clone()))?;
            list.append(d)?;
        }
        Ok(list)
    }

    fn __repr__(&self) -> String {
        format!(
            "Cell({:?}, {} joints, {} parameters)",
            self.cell.name,
            self.cell.model.dof(),
            self.cell.model.registry.len()
        )
    }

    /// Pickling: the cell is made again from its origin (path or name, or TOML text).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (String, String))> {
        let restore = slf.get_type().getattr("_restore")?;
        let cell = slf.borrow();
        Ok((restore, (cell.origin.0.clone(), cell.origin.1.clone())))
    }

    /// The cell made again from `(kind, arg)` (pickling).
    #[classmethod]
    fn _restore(_cls: &Bound<'_, PyType>, kind: &str, arg: &str) -> PyResult<Cell> {
        Cell::restore(kind, arg)
    }
}

/// Joint configurations and the measurements taken at them (a data file's content).
#[pyclass(module = "armcal._armcal", frozen)]
pub(crate) struct Dataset {
    pub(crate) inner: armcal::Dataset,
}

impl Dataset {
    pub(crate) fn wrap(inner: armcal::Dataset) -> Dataset {
        Dataset { inner }
    }
}

record_methods!(Dataset, "data set", {
    /// The configurations, shape (n, dof) (rad; mm for a prismatic joint).
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix(py, &self.inner.configurations, 0)
    }

    /// The configurations' ids (`pose_id`).
    #[getter]
    fn ids(&self) -> Vec<String> {
        self.inner.config_ids.clone()
    }

    /// The measured positions, one row per measurement, shape (m, 3) (x, y, z mm,
    /// instrument frame); an error for data of other kinds (poses, distances: `to_dict()`).
    #[getter]
    fn measured<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let rows = self
            .inner
            .measurements
            .iter()
            .map(|m| measured_row(&m.kind))
            .collect::<PyResult<Vec<_>>>()?;
        Ok(matrix(py, &rows, 3))
    }

    /// The configuration index of each measurement, shape (m,).
    #[getter]
    fn config(&self) -> Vec<usize> {
        self.inner.measurements.iter().map(|m| m.config).collect()
    }

    fn __len__(&self) -> usize {
        self.inner.configurations.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "Dataset({} configurations, {} measurements, source {:?})",
            self.inner.configurations.len(),
            self.inner.measurements.len(),
            self.inner.source
        )
    }
});

/// One position measurement's x, y, z (mm). The kind's serde form (`{"kind": "position",
/// "value": [x, y, z], …}`) is read, so that only root items of the library are named.
fn measured_row<T: Serialize>(kind: &T) -> PyResult<Vec<f64>> {
    let v = serde_json::to_value(kind).map_err(|e| ArmcalError::new_err(e.to_string()))?;
    let row: Option<Vec<f64>> = match v["kind"].as_str() {
        Some("position") => v["value"]
            .as_array()
            .and_then(|a| a.iter().map(|n| n.as_f64()).collect()),
        _ => None,
    };
    row.ok_or_else(|| {
        ArmcalError::new_err(format!(
            "measured: a {} measurement is not a position; use to_dict()",
            v["kind"].as_str().unwrap_or("?")
        ))
    })
}

/// An identification's result: parameters with their uncertainty, residuals, the solver's
/// status (what `armcal identify` writes).
#[pyclass(module = "armcal._armcal", frozen)]
pub(crate) struct Estimate {
    pub(crate) inner: armcal::Estimate,
}

impl Estimate {
    pub(crate) fn wrap(inner: armcal::Estimate) -> Estimate {
        Estimate { inner }
    }

    /// The identified parameters, registry order (mm, rad): the nominal values of the
    /// identified model the estimate holds (`Estimate::model`), in internal units as fitted.
    pub(crate) fn params_vec(&self) -> PyResult<Vec<f64>> {
        let model = armcal::Model::from_spec(&self.inner.model).map_err(armcal_error)?;
        Ok(model.nominal())
    }
}

record_methods!(Estimate, "estimate", {
    /// Every parameter of the model at the solution, shape (p,), registry order (internal
    /// units: mm, rad); `names` gives the order.
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(array1(py, self.params_vec()?))
    }

    /// The names of `params`, registry order.
    #[getter]
    fn names(&self) -> Vec<String> {
        self.inner
            .parameters
            .iter()
            .map(|p| p.name.clone())
            .collect()
    }

    /// The free (estimated) parameters' names: the order of `sigma` and `cov`.
    #[getter]
    fn free(&self) -> Vec<String> {
        self.inner.free.clone()
    }

    /// σ of the free parameters, shape (f,) (internal units: mm, rad), √diag(C_p).
    #[getter]
    fn sigma<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.inner.uncertainty.sigma.clone())
    }

    /// C_p, the covariance of the free parameters, shape (f, f) (mm, rad; paper §1.1).
    #[getter]
    fn cov<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        dmatrix(py, &self.inner.uncertainty.covariance)
    }

    /// C_s = G C_p Gᵀ at each of the cell's working poses, shape (w, 3, 3) (mm²,
    /// instrument frame).
    #[getter]
    fn tcp_cov<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        let mats: Vec<_> = self.inner.tcp.iter().map(|t| t.covariance).collect();
        stack(py, &mats)
    }

    /// The solver's status (`converged`, …).
    #[getter]
    fn status(&self) -> String {
        self.inner.solver.status.to_string()
    }

    /// Whether the fit converged (an estimate that did not is no calibration).
    #[getter]
    fn converged(&self) -> bool {
        self.inner.solver.status.is_converged()
    }

    /// The fitted data's residuals `model − measured`: the x, y, z of each position
    /// measurement (mm, instrument frame), shape (m, 3) (NaN for a measurement without a
    /// position row, e.g. a distance).
    #[getter]
    fn residuals<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let rows: Vec<Vec<f64>> = self
            .inner
            .residuals
            .per_measurement
            .iter()
            .map(|r| r.xyz.map_or(vec![f64::NAN; 3], |x| x.to_vec()))
            .collect();
        matrix(py, &rows, 3)
    }

    /// The held-out validation (RMS and largest error of the nominal, frames-only and
    /// calibrated models, mm), or `None` without held-out data.
    #[getter]
    fn validation<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.inner
            .validation
            .as_ref()
            .map(|v| to_python(py, v))
            .transpose()
    }

    fn __repr__(&self) -> String {
        format!(
            "Estimate(cell {:?}, {} free parameters, {}, χ² {})",
            self.inner.cell,
            self.inner.free.len(),
            self.inner.solver.status,
            self.inner.uncertainty.verdict
        )
    }
});

/// Degrees per radian, the library's display factor of an angle (`Unit::display_factor`).
const DEG_PER_RAD: f64 = 180.0 / std::f64::consts::PI;

/// A measurement design: the poses to measure and what they predict (what `armcal plan`
/// writes).
#[pyclass(module = "armcal._armcal", frozen)]
pub(crate) struct Design {
    pub(crate) inner: armcal::DesignRecord,
}

impl Design {
    pub(crate) fn wrap(inner: armcal::DesignRecord) -> Design {
        Design { inner }
    }
}

record_methods!(Design, "design", {
    /// The poses, shape (n, dof) (rad; mm for a prismatic joint).
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let rows: Vec<Vec<f64>> = self
            .inner
            .poses
            .iter()
            .map(|row| {
                row.iter()
                    .zip(&self.inner.joints)
                    // As `DesignRecord::design_for`: display value / display factor.
                    .map(|(v, j)| if j.unit == "deg" { v / DEG_PER_RAD } else { *v })
                    .collect()
            })
            .collect();
        matrix(py, &rows, self.inner.joints.len())
    }

    /// The planner's criterion value (`None` for a design that was not planned).
    #[getter]
    fn value(&self) -> Option<f64> {
        self.inner.plan.as_ref().map(|p| p.value)
    }

    /// The planner's status (`converged`, …; `None` for a design that was not planned).
    #[getter]
    fn status(&self) -> Option<String> {
        self.inner.plan.as_ref().map(|p| p.status.to_string())
    }

    /// The predicted σ of the free parameters at this design (mm, rad).
    #[getter]
    fn sigma<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.inner.assessment.sigma.clone())
    }

    /// The predicted C_s at each working pose, shape (w, 3, 3) (mm²).
    #[getter]
    fn tcp_cov<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        let mats: Vec<_> = self
            .inner
            .assessment
            .tcp
            .iter()
            .map(|t| t.covariance)
            .collect();
        stack(py, &mats)
    }

    fn __repr__(&self) -> String {
        format!(
            "Design(cell {:?}, {} poses, method {:?})",
            self.inner.cell,
            self.inner.poses.len(),
            self.inner.method
        )
    }
});

/// An adaptive campaign's state: the poses to measure next and the decision (what
/// `armcal campaign` keeps in its state file).
#[pyclass(module = "armcal._armcal", frozen)]
pub(crate) struct CampaignState {
    pub(crate) inner: armcal::CampaignState,
}

impl CampaignState {
    pub(crate) fn wrap(inner: armcal::CampaignState) -> CampaignState {
        CampaignState { inner }
    }
}

record_methods!(CampaignState, "campaign state", {
    /// The next batch's poses for `cell`'s model, shape (b, dof) (rad; mm for a prismatic
    /// joint; the state keeps them in display units); empty once the campaign stops.
    fn next_q<'py>(&self, py: Python<'py>, cell: &Cell) -> Bound<'py, PyArray2<f64>> {
        let joints = &cell.cell.model.joints;
        let rows: Vec<Vec<f64>> = self
            .inner
            .next
            .iter()
            .map(|p| {
                p.joints
                    .iter()
                    .zip(joints)
                    .map(|(v, j)| v / j.kind.unit().display_factor())
                    .collect()
            })
            .collect();
        matrix(py, &rows, joints.len())
    }

    /// The next batch's pose ids.
    #[getter]
    fn next_ids(&self) -> Vec<String> {
        self.inner.next.iter().map(|p| p.id.clone()).collect()
    }

    /// The decision in words (`measure the next batch`, `stop: target reached`, …).
    #[getter]
    fn decision(&self) -> String {
        self.inner.decision.words().to_string()
    }

    /// Number of poses measured so far.
    #[getter]
    fn measured(&self) -> usize {
        self.inner.measured()
    }

    fn __repr__(&self) -> String {
        format!(
            "CampaignState({} measured, {} next, {})",
            self.inner.measured(),
            self.inner.next.len(),
            self.inner.decision.words()
        )
    }
});

/// A drift check: did the robot move since its calibration? (what `armcal check` writes).
#[pyclass(module = "armcal._armcal", frozen)]
pub(crate) struct DriftCheck {
    pub(crate) inner: armcal::DriftCheck,
}

impl DriftCheck {
    pub(crate) fn wrap(inner: armcal::DriftCheck) -> DriftCheck {
        DriftCheck { inner }
    }
}

record_methods!(DriftCheck, "drift check", {
    /// The parameter groups the score test finds moved (empty: none).
    fn moved_groups(&self) -> Vec<String> {
        self.inner.moved_groups()
    }

    fn __repr__(&self) -> String {
        format!("DriftCheck(moved: {:?})", self.inner.moved_groups())
    }
});

/// Adds the classes to the module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Cell>()?;
    m.add_class::<Dataset>()?;
    m.add_class::<Estimate>()?;
    m.add_class::<Design>()?;
    m.add_class::<CampaignState>()?;
    m.add_class::<DriftCheck>()?;
    Ok(())
}
