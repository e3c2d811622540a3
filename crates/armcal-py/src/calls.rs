//! The functions: each reads its arrays (copies), releases the GIL for the library's root
//! call and wraps the result. Units: joint values rad (mm for a prismatic joint), lengths
//! mm, angles rad — the library's internal units.

use std::path::{Path, PathBuf};

use numpy::PyArray3;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::arrays::{array1, matrix, rows, vector};
use crate::progress::Progress;
use crate::records::{
    from_json, named, to_json, CampaignState, Cell, Dataset, Design, DriftCheck, Estimate,
};
use crate::{armcal_error, ArmcalError};

/// What `q` holds, for the messages.
const JOINTS: &str = "joint values, rad; mm for a prismatic joint";

/// The joint rows `q` of `cell`'s model.
fn joint_rows(cell: &Cell, q: &Bound<'_, PyAny>) -> PyResult<Vec<Vec<f64>>> {
    rows(q, "q", Some(cell.cell.model.dof()), JOINTS)
}

/// Parameters given as `None` (the nominal), an `Estimate` or an array (registry order).
fn parameters(cell: &Cell, params: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<f64>> {
    let model = &cell.cell.model;
    match params {
        None => Ok(model.nominal()),
        Some(p) => match p.cast::<Estimate>() {
            Ok(est) => {
                let est = &est.get().inner;
                est.check_model(model).map_err(armcal_error)?;
                est.params_for(model).map_err(armcal_error)
            }
            Err(_) => vector(
                p,
                "params",
                Some(model.registry.len()),
                "every model parameter, registry order, mm and rad",
            ),
        },
    }
}

/// A data set from arrays (checked by `Dataset::from_arrays`), with per-axis σ (mm) set on
/// every position measurement if given: a number, shape (3,) or shape (m, 3).
fn data_from_arrays(
    cell: &Cell,
    q: &Bound<'_, PyAny>,
    measured: &Bound<'_, PyAny>,
    sigma: Option<&Bound<'_, PyAny>>,
    ids: Vec<String>,
) -> PyResult<armcal::Dataset> {
    let joints = joint_rows(cell, q)?;
    let measured = rows(
        measured,
        "measured",
        Some(3),
        "x, y, z mm of the observed point, instrument frame",
    )?;
    let sigma = match sigma {
        None => None,
        Some(s) => Some(sigma_rows(s, measured.len())?),
    };
    let arrays = armcal::DataArrays {
        joints,
        measured,
        kind: armcal::RowKind::Position,
        ids,
        ..Default::default()
    };
    let data = armcal::Dataset::from_arrays(&cell.cell.model, &arrays).map_err(armcal_error)?;
    match sigma {
        None => Ok(data),
        Some(sigma) => with_sigma(cell, data, &sigma),
    }
}

/// σ as one (3,) row per measurement.
fn sigma_rows(s: &Bound<'_, PyAny>, m: usize) -> PyResult<Vec<[f64; 3]>> {
    let what = "σ of x, y, z, mm: a number, shape (3,) or shape (m, 3)";
    let rows: Vec<Vec<f64>> = if let Ok(x) = s.extract::<f64>() {
        vec![vec![x; 3]; m]
    } else if let Ok(v) = vector(s, "sigma", Some(3), what) {
        vec![v; m]
    } else {
        let r = rows(s, "sigma", Some(3), what)?;
        if r.len() != m {
            return Err(ArmcalError::new_err(format!(
                "sigma: {} rows for {m} measurements",
                r.len()
            )));
        }
        r
    };
    rows.into_iter()
        .enumerate()
        .map(|(i, r)| {
            if r.iter().all(|x| x.is_finite() && *x > 0.0) {
                Ok([r[0], r[1], r[2]])
            } else {
                Err(ArmcalError::new_err(format!(
                    "sigma: row {}: every σ must be a positive number (mm), got {r:?}",
                    i + 1
                )))
            }
        })
        .collect()
}

/// `data` with the σ of its i-th (position) measurement `sigma[i]`, for a cell whose noise
/// model weights each row by its own σ (`per-measurement`); for another cell an error
/// (its noise model would not use them). The measurement kind's serde form (`{"kind":
/// "position", "value": …, "sigma": …}`) is edited, so that the binding names only root
/// items of the library.
fn with_sigma(cell: &Cell, data: armcal::Dataset, sigma: &[[f64; 3]]) -> PyResult<armcal::Dataset> {
    let json = |e: serde_json::Error| ArmcalError::new_err(e.to_string());
    let mut value = serde_json::to_value(&data).map_err(json)?;
    if let Some(ms) = value["measurements"].as_array_mut() {
        for (m, s) in ms.iter_mut().zip(sigma) {
            m["kind"]["sigma"] = serde_json::json!(s);
        }
    }
    let data: armcal::Dataset = serde_json::from_value(value).map_err(json)?;
    match cell.cell.noise().unused_sigmas(&data) {
        Some(why) => Err(ArmcalError::new_err(format!("sigma: {why}"))),
        None => Ok(data),
    }
}

/// The data of `identify`, `check` and `campaign_step`: a `Dataset`, or joint rows with
/// their measured positions.
fn data_argument(
    cell: &Cell,
    q: &Bound<'_, PyAny>,
    measured: Option<&Bound<'_, PyAny>>,
    sigma: Option<&Bound<'_, PyAny>>,
) -> PyResult<armcal::Dataset> {
    match (q.cast::<Dataset>(), measured) {
        (Ok(d), None) => match sigma {
            None => Ok(d.get().inner.clone()),
            Some(s) => {
                let data = d.get().inner.clone();
                let sigma = sigma_rows(s, data.measurements.len())?;
                with_sigma(cell, data, &sigma)
            }
        },
        (Ok(_), Some(_)) => Err(ArmcalError::new_err(
            "measured: give either a Dataset or q and measured, not both",
        )),
        (Err(_), Some(m)) => data_from_arrays(cell, q, m, sigma, Vec::new()),
        (Err(_), None) => Err(ArmcalError::new_err(
            "measured: missing (give q and measured, or a Dataset)",
        )),
    }
}

/// The tool frame's world pose at each configuration, shape (n, 4, 4) (mm): forward
/// kinematics of `cell`'s model with `params` (`None`: the nominal; an `Estimate`; or an
/// array of every parameter, registry order, mm and rad). `q`: shape (n, dof), rad (mm for
/// a prismatic joint).
#[pyfunction]
#[pyo3(signature = (cell, q, params = None))]
fn fk<'py>(
    py: Python<'py>,
    cell: &Cell,
    q: &Bound<'py, PyAny>,
    params: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let configurations = joint_rows(cell, q)?;
    let params = parameters(cell, params)?;
    let model = &cell.cell.model;
    let poses = py
        .detach(|| armcal::fk(model, &params, &configurations))
        .map_err(armcal_error)?;
    Ok(crate::arrays::stack(py, &poses))
}

/// A virtual robot's true parameters: the nominal perturbed at random (the library's
/// default perturbation: the scale of a real robot's errors), seeded; shape (p,), mm, rad.
#[pyfunction]
#[pyo3(signature = (cell, seed = 1))]
fn perturbed_truth<'py>(
    py: Python<'py>,
    cell: &Cell,
    seed: u64,
) -> Bound<'py, numpy::PyArray1<f64>> {
    let model = &cell.cell.model;
    array1(
        py,
        armcal::perturbed_truth(model, &armcal::Perturbation::default(), seed),
    )
}

/// What the cell's instrument measures at `q` (shape (n, dof), rad) on a robot with the
/// parameters `truth` (`None`: the nominal; an array, registry order, mm and rad), with the
/// cell's instrument noise if `noise` (seeded: same seed, same data); `ids` name the rows
/// (default `1`, `2`, …). Returns a `Dataset`.
#[pyfunction]
#[pyo3(signature = (cell, q, truth = None, noise = true, seed = 1, ids = None))]
fn simulate(
    py: Python<'_>,
    cell: &Cell,
    q: &Bound<'_, PyAny>,
    truth: Option<&Bound<'_, PyAny>>,
    noise: bool,
    seed: u64,
    ids: Option<Vec<String>>,
) -> PyResult<Dataset> {
    let configurations = joint_rows(cell, q)?;
    let ids = ids
        .map(|ids| checked_ids(ids, configurations.len()))
        .transpose()?;
    let truth = parameters(cell, truth)?;
    let cell = &cell.cell;
    let data = py
        .detach(|| {
            let noise = noise.then(|| cell.noise());
            armcal::simulate(&cell.model, &truth, &configurations, noise.as_ref(), seed)
        })
        .map_err(armcal_error)?;
    Ok(Dataset::wrap(match ids {
        Some(ids) => armcal::Dataset {
            config_ids: ids,
            ..data
        },
        None => data,
    }))
}

/// `ids`, one per row of `q`.
fn checked_ids(ids: Vec<String>, n: usize) -> PyResult<Vec<String>> {
    if ids.len() == n {
        Ok(ids)
    } else {
        Err(ArmcalError::new_err(format!(
            "ids: {} ids for {n} rows of q",
            ids.len()
        )))
    }
}

/// What the instrument measures at `q` (shape (n, dof), rad), noise-free, on the robot with
/// `params` (`None`: the nominal; an `Estimate`; an array). Returns a `Dataset`.
#[pyfunction]
#[pyo3(signature = (cell, q, params = None))]
fn predict(
    py: Python<'_>,
    cell: &Cell,
    q: &Bound<'_, PyAny>,
    params: Option<&Bound<'_, PyAny>>,
) -> PyResult<Dataset> {
    let poses: Vec<(String, Vec<f64>)> = joint_rows(cell, q)?
        .into_iter()
        .enumerate()
        .map(|(i, q)| ((i + 1).to_string(), q))
        .collect();
    let params = parameters(cell, params)?;
    let cell = &cell.cell;
    let data = py
        .detach(|| armcal::predict(&cell.model, &params, &poses, None, cell.measurement))
        .map_err(armcal_error)?;
    Ok(Dataset::wrap(data))
}

/// A data set from arrays: joint rows `q` (shape (n, dof), rad) and the measured positions
/// (shape (n, 3), mm, instrument frame), checked row by row (shape, non-finite values,
/// joints past their limits: the message names the row and field); `sigma` (mm; a number,
/// (3,) or (n, 3)) is each row's σ, for a cell with the `per-measurement` noise model; `ids` name the rows (default `1`,
/// `2`, …; a campaign step's batch has the ids of `state.next_ids`).
#[pyfunction]
#[pyo3(signature = (cell, q, measured, sigma = None, ids = None))]
fn dataset(
    cell: &Cell,
    q: &Bound<'_, PyAny>,
    measured: &Bound<'_, PyAny>,
    sigma: Option<&Bound<'_, PyAny>>,
    ids: Option<Vec<String>>,
) -> PyResult<Dataset> {
    let ids = ids.unwrap_or_default();
    Ok(Dataset::wrap(data_from_arrays(
        cell, q, measured, sigma, ids,
    )?))
}

/// Identifies the cell's free parameters from measured positions (`armcal identify`): `q`
/// shape (n, dof) rad and `measured` shape (n, 3) mm, or a `Dataset` as `q`. `sigma`: the
/// measurements' σ (mm), for a cell whose instrument noise model is `per-measurement` (an
/// error for another: its noise model weights every row by its own σ); `method`: `lm`, `gauss-newton` or
/// `kalman`; `robust`: `None`, `huber` or `cauchy`; `holdout`: the fraction of
/// configurations held out for validation (seeded by `seed`); `progress(event, info)`:
/// see the package's docs. Returns an `Estimate`; a fit that did not converge is returned
/// with its status (`estimate.converged` is False): no calibration.
#[pyfunction]
#[pyo3(signature = (cell, q, measured = None, *, sigma = None, method = "lm", robust = None,
    holdout = 0.0, seed = 1, progress = None))]
#[allow(clippy::too_many_arguments)]
fn identify(
    py: Python<'_>,
    cell: &Cell,
    q: &Bound<'_, PyAny>,
    measured: Option<&Bound<'_, PyAny>>,
    sigma: Option<&Bound<'_, PyAny>>,
    method: &str,
    robust: Option<&str>,
    holdout: f64,
    seed: u64,
    progress: Option<Py<PyAny>>,
) -> PyResult<Estimate> {
    let data = data_argument(cell, q, measured, sigma)?;
    if !(0.0..1.0).contains(&holdout) {
        return Err(ArmcalError::new_err(format!(
            "holdout: a fraction in [0, 1), got {holdout}"
        )));
    }
    let settings = armcal::IdentifySettings {
        method: named(method, "method")?,
        robust: robust.map(|r| named(r, "robust")).transpose()?,
        holdout,
        seed,
        ..Default::default()
    };
    let cell = &cell.cell;
    let mut observer = Progress::new(progress);
    let result = py.detach(|| armcal::identify(cell, &data, &settings, &mut observer));
    observer.finish_call(result.map(Estimate::wrap).map_err(armcal_error))
}

/// Plans `n` measurement poses (`armcal plan`): `criterion` (`kpi`, `d`, `a`, …, paper eqs.
/// 5–6, 19, 24), under the cell's collision constraints if `collisions`, from `starts`
/// seeded starts; with `pool` (shape (k, dof), rad) the poses are chosen from those
/// joint rows instead (`armcal plan --pool`). Returns a `Design`.
#[pyfunction]
#[pyo3(signature = (cell, n = 60, *, criterion = "kpi", collisions = true, pool = None, seed = 1,
    starts = 2, progress = None))]
#[allow(clippy::too_many_arguments)]
fn plan(
    py: Python<'_>,
    cell: &Cell,
    n: usize,
    criterion: &str,
    collisions: bool,
    pool: Option<&Bound<'_, PyAny>>,
    seed: u64,
    starts: usize,
    progress: Option<Py<PyAny>>,
) -> PyResult<Design> {
    let criterion = armcal::Criterion::from_name(criterion).ok_or_else(|| {
        let names: Vec<&str> = armcal::Criterion::ALL.iter().map(|c| c.name()).collect();
        ArmcalError::new_err(format!(
            "criterion: unknown `{criterion}`, expected one of {}",
            names.join(", ")
        ))
    })?;
    let pool = pool.map(|p| joint_rows(cell, p)).transpose()?;
    let cell = &cell.cell;
    let mut observer = Progress::new(progress);
    let result = py.detach(|| match pool {
        None => {
            let settings = armcal::PlanSettings {
                poses: n,
                criterion,
                collisions,
                seed,
                starts,
                ..Default::default()
            };
            armcal::DesignRecord::planned(cell, None, "plan", &settings, &[], &mut observer)
        }
        Some(pool) => {
            let settings = armcal::PoolSettings {
                poses: n,
                criterion,
                collisions,
                ..Default::default()
            };
            let chosen = armcal::plan_pool(cell, &pool, &settings, &mut observer)?;
            let design = chosen.plan.design.clone();
            let mut record = armcal::DesignRecord::new(
                cell,
                None,
                "pool",
                &design,
                Some(chosen.plan),
                collisions,
            )?;
            record.pool = Some(chosen.pool);
            Ok(record)
        }
    });
    observer.finish_call(result.map(Design::wrap).map_err(armcal_error))
}

/// The predicted precision of any design `q` (shape (n, dof), rad; paper eqs. 5–6, 19):
/// C_p, σ, the TCP covariances and every criterion, as a dict (`armcal assess`).
#[pyfunction]
fn assess<'py>(py: Python<'py>, cell: &Cell, q: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    let design = joint_rows(cell, q)?;
    let cell = &cell.cell;
    let a = py
        .detach(|| armcal::assess(cell, &design))
        .map_err(armcal_error)?;
    py.import("json")?.call_method1("loads", (to_json(&a)?,))
}

/// Compensates a joint program (`armcal compensate`): the joints `q` (shape (n, dof), rad)
/// taught with the nominal model, or with `targets` (shape (n, 4, 4), world tool poses, mm)
/// the Cartesian targets solved from the reference joints `q`. Each row is solved by the
/// calibrated inverse kinematics of `estimate`. Returns a dict: `q` (n, dof) the joints to
/// send, `status` per row (`converged`, …), `position_error` (n,) mm, and `rows` (every
/// row's record).
#[pyfunction]
#[pyo3(signature = (cell, estimate, q, targets = None))]
fn compensate<'py>(
    py: Python<'py>,
    cell: &Cell,
    estimate: &Estimate,
    q: &Bound<'py, PyAny>,
    targets: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let joints = joint_rows(cell, q)?;
    let ids: Vec<String> = (1..=joints.len()).map(|i| i.to_string()).collect();
    let program = match targets {
        None => armcal::Program::Joints {
            rows: ids.into_iter().zip(joints).collect(),
        },
        Some(t) => {
            let poses = target_poses(t, joints.len())?;
            armcal::Program::Targets {
                rows: ids
                    .into_iter()
                    .zip(poses)
                    .zip(joints)
                    .map(|((id, pose), q)| (id, pose, q))
                    .collect(),
            }
        }
    };
    let model = &cell.cell.model;
    // As the command line: the estimate's parameters for the cell's model, checked to be
    // identified on it.
    let calibrated = estimate.inner.params_for(model).map_err(armcal_error)?;
    let rows = py.detach(|| {
        armcal::compensate(
            model,
            &calibrated,
            &program,
            &armcal::IkSettings::default(),
            None,
        )
    });
    let out = PyDict::new(py);
    let q_out: Vec<Vec<f64>> = rows.iter().map(|r| r.result.q.clone()).collect();
    out.set_item("q", matrix(py, &q_out, model.dof()))?;
    let status: Vec<&str> = rows.iter().map(|r| r.result.status.name()).collect();
    out.set_item("status", status)?;
    let errors: Vec<f64> = rows.iter().map(|r| r.result.position_error).collect();
    out.set_item("position_error", array1(py, errors))?;
    out.set_item(
        "rows",
        py.import("json")?
            .call_method1("loads", (to_json(&rows)?,))?,
    )?;
    Ok(out)
}

/// `targets` (shape (n, 4, 4), homogeneous, mm) as the library's poses, through their serde
/// form `{"rot": [column-major 3 × 3], "trans": [x, y, z]}` (a root item names no pose type).
fn target_poses<T: serde::de::DeserializeOwned>(
    t: &Bound<'_, PyAny>,
    n: usize,
) -> PyResult<Vec<T>> {
    let flat = rows(
        t.call_method1("reshape", (-1, 16))?.as_any(),
        "targets",
        Some(16),
        "4 × 4 world poses, mm",
    )?;
    if flat.len() != n {
        return Err(ArmcalError::new_err(format!(
            "targets: {} poses for {n} rows of q",
            flat.len()
        )));
    }
    flat.iter()
        .map(|m| {
            let rot: Vec<f64> = (0..3)
                .flat_map(|c| (0..3).map(move |r| m[4 * r + c]))
                .collect();
            let value = serde_json::json!({ "rot": rot, "trans": [m[3], m[7], m[11]] });
            serde_json::from_value(value).map_err(|e| ArmcalError::new_err(format!("targets: {e}")))
        })
        .collect()
}

/// Starts an adaptive campaign (`armcal campaign start`): batches of `batch` KPI poses until
/// every working pose's TCP σ is at most `target_sigma_mm` (or `budget` poses). Returns the
/// `CampaignState` whose `next_q(cell)` are the poses to measure.
#[pyfunction]
#[pyo3(signature = (cell, *, target_sigma_mm = 0.5, batch = 5, budget = None, seed = 1, progress = None))]
fn campaign_start(
    py: Python<'_>,
    cell: &Cell,
    target_sigma_mm: f64,
    batch: usize,
    budget: Option<usize>,
    seed: u64,
    progress: Option<Py<PyAny>>,
) -> PyResult<CampaignState> {
    let settings = armcal::CampaignSettings {
        target_sigma_mm,
        batch,
        budget,
        seed,
        ..Default::default()
    };
    let source = cell.source();
    let cell = &cell.cell;
    let mut observer = Progress::new(progress);
    let result = py.detach(|| armcal::campaign_start(cell, &source, &settings, &mut observer));
    observer.finish_call(result.map(CampaignState::wrap).map_err(armcal_error))
}

/// One campaign step (`armcal campaign step`): the measured batch (`q` and `measured`, or a
/// `Dataset`) → `(state, estimate)`: the next state and the estimate on everything
/// measured so far (`None` until the data determine the parameters).
#[pyfunction]
#[pyo3(signature = (cell, state, q, measured = None, *, progress = None))]
fn campaign_step(
    py: Python<'_>,
    cell: &Cell,
    state: &CampaignState,
    q: &Bound<'_, PyAny>,
    measured: Option<&Bound<'_, PyAny>>,
    progress: Option<Py<PyAny>>,
) -> PyResult<(CampaignState, Option<Estimate>)> {
    let batch = data_argument(cell, q, measured, None)?;
    let (cell, state) = (&cell.cell, &state.inner);
    let mut observer = Progress::new(progress);
    let result = py.detach(|| armcal::campaign_step(cell, state, &batch, &mut observer));
    let step = observer.finish_call(result.map_err(armcal_error))?;
    Ok((
        CampaignState::wrap(step.state),
        step.estimate.map(Estimate::wrap),
    ))
}

/// The drift check (`armcal check`): poses measured after a calibration (`q` and
/// `measured`, or a `Dataset`) tested against `estimate` (χ², and a score test per
/// parameter group at level `alpha`). Returns a `DriftCheck`.
#[pyfunction]
#[pyo3(signature = (cell, estimate, q, measured = None, *, alpha = 0.05))]
fn check(
    py: Python<'_>,
    cell: &Cell,
    estimate: &Estimate,
    q: &Bound<'_, PyAny>,
    measured: Option<&Bound<'_, PyAny>>,
    alpha: f64,
) -> PyResult<DriftCheck> {
    let data = data_argument(cell, q, measured, None)?;
    let (cell, estimate) = (&cell.cell, &estimate.inner);
    let settings = armcal::CheckSettings { alpha };
    py.detach(|| armcal::check(cell, estimate, &data, &settings))
        .map(DriftCheck::wrap)
        .map_err(armcal_error)
}

/// The HTML report of records (`armcal report`): `records` are `Estimate`, `Design`,
/// `DriftCheck` or `CampaignState` objects or paths of record files armcal wrote; the
/// self-contained page is written to `out` (a `.html` file, or `out/report.html` for a
/// folder), complete or not at all. An estimate whose fit did not converge is refused
/// unless `accept_unconverged`. Returns the page's path.
#[pyfunction]
#[pyo3(signature = (records, out, *, title = "armcal report", accept_unconverged = false))]
fn report(
    py: Python<'_>,
    records: &Bound<'_, PyList>,
    out: PathBuf,
    title: &str,
    accept_unconverged: bool,
) -> PyResult<String> {
    let scratch = Scratch::new()?;
    let mut files = Vec::new();
    for (i, r) in records.iter().enumerate() {
        if let Ok(path) = r.extract::<PathBuf>() {
            files.push(path);
            continue;
        }
        let (text, kind) = record_json(&r).map_err(|_| {
            ArmcalError::new_err(format!(
                "records[{i}]: an Estimate, Design, DriftCheck, CampaignState or a file path, got a {}",
                r.get_type().name().map(|n| n.to_string()).unwrap_or_default()
            ))
        })?;
        let path = scratch.0.join(format!("{}-{kind}.json", i + 1));
        std::fs::write(&path, text).map_err(|e| ArmcalError::new_err(e.to_string()))?;
        files.push(path);
    }
    let acceptance = armcal::Acceptance {
        accepted: accept_unconverged,
        accept: "accept_unconverged=True",
        raise_iterations: "a larger iteration limit",
    };
    let html = py
        .detach(|| armcal::files_report(&files, title, &acceptance).map(|r| r.page.render()))
        .map_err(armcal_error)?;
    let path = if out.extension().is_some_and(|e| e == "html") {
        out
    } else {
        out.join("report.html")
    };
    write_whole(&path, &html)?;
    Ok(path.display().to_string())
}

/// A record object's JSON and kind, for `report`.
fn record_json(r: &Bound<'_, PyAny>) -> PyResult<(String, &'static str)> {
    if let Ok(e) = r.cast::<Estimate>() {
        return Ok((to_json(&e.get().inner)?, "estimate"));
    }
    if let Ok(d) = r.cast::<Design>() {
        return Ok((to_json(&d.get().inner)?, "design"));
    }
    if let Ok(c) = r.cast::<DriftCheck>() {
        return Ok((to_json(&c.get().inner)?, "check"));
    }
    let s = r.cast::<CampaignState>()?;
    Ok((to_json(&s.get().inner)?, "campaign"))
}

/// A scratch folder for one call, removed at its end.
struct Scratch(PathBuf);

impl Scratch {
    fn new() -> PyResult<Scratch> {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        let dir = std::env::temp_dir().join(format!("armcal-py-{}-{nanos}", std::process::id()));
        std::fs::create_dir_all(&dir)
            .map_err(|e| ArmcalError::new_err(format!("{}: {e}", dir.display())))?;
        Ok(Scratch(dir))
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Writes `text` to `path` whole or not at all (a sibling temporary file, renamed).
pub(crate) fn write_whole(path: &Path, text: &str) -> PyResult<()> {
    let fail = |e: std::io::Error| ArmcalError::new_err(format!("{}: {e}", path.display()));
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(fail)?;
    }
    let tmp = path.with_extension("partial");
    std::fs::write(&tmp, text).map_err(fail)?;
    std::fs::rename(&tmp, path).map_err(fail)
}

/// A record read from a file armcal wrote, by kind: `estimate`, `design`, `check` or
/// `campaign`.
#[pyfunction]
fn read_record(py: Python<'_>, path: PathBuf) -> PyResult<Py<PyAny>> {
    let text = std::fs::read_to_string(&path)
        .map_err(|e| ArmcalError::new_err(format!("{}: {e}", path.display())))?;
    let value: serde_json::Value = from_json(&text, "armcal")?;
    let field = |k: &str| value.get(k).is_some();
    Ok(if field("uncertainty") {
        Py::new(py, Estimate::wrap(from_json(&text, "estimate")?))?.into_any()
    } else if field("assessment") {
        Py::new(py, Design::wrap(from_json(&text, "design")?))?.into_any()
    } else if field("decision") {
        Py::new(py, CampaignState::wrap(from_json(&text, "campaign state")?))?.into_any()
    } else {
        Py::new(py, DriftCheck::wrap(from_json(&text, "drift check")?))?.into_any()
    })
}

/// Adds the functions to the module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(fk, m)?)?;
    m.add_function(wrap_pyfunction!(perturbed_truth, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(predict, m)?)?;
    m.add_function(wrap_pyfunction!(dataset, m)?)?;
    m.add_function(wrap_pyfunction!(identify, m)?)?;
    m.add_function(wrap_pyfunction!(plan, m)?)?;
    m.add_function(wrap_pyfunction!(assess, m)?)?;
    m.add_function(wrap_pyfunction!(compensate, m)?)?;
    m.add_function(wrap_pyfunction!(campaign_start, m)?)?;
    m.add_function(wrap_pyfunction!(campaign_step, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(report, m)?)?;
    m.add_function(wrap_pyfunction!(read_record, m)?)?;
    Ok(())
}
