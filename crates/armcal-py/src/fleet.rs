//! A fleet: many robots, each calibrated the same way (issue 34 item 4). One robot's task
//! ([`robot`]): a virtual robot (the cell's nominal model perturbed, seeded), its KPI design
//! of `poses` poses, its campaign simulated with the cell's instrument noise, the
//! identification, and the check on held-out poses (random configurations within the joint
//! limits, seeded, measured with fresh noise, never fitted): the calibrated model's error
//! there and the drift check. `fleet_task` runs one robot (what a Ray task runs); `fleet` runs many in this
//! process over rayon's pool (`RAYON_NUM_THREADS`).

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::calls::write_whole;
use crate::progress::Progress;
use crate::records::{to_json, Cell};
use crate::ArmcalError;

/// What one robot's task does.
#[derive(Clone)]
struct Task {
    /// Poses of the KPI design.
    poses: usize,
    /// Whether the design keeps the cell's collision constraints.
    collisions: bool,
    /// Held-out poses of the check.
    check_poses: usize,
    /// Where to write the robot's design, estimate and report (`None`: nowhere).
    out: Option<PathBuf>,
}

/// One robot's row of the fleet table.
#[derive(Serialize)]
struct Row {
    /// The robot's name (`<cell>-<seed>`).
    robot: String,
    /// The seed of its perturbation, design and noise.
    seed: u64,
    /// The planner's criterion value (KPI, mm²).
    plan_value: f64,
    /// The identification's solver status.
    status: String,
    /// Whether the fit converged.
    converged: bool,
    /// The χ² verdict of the fit (`consistent`, …).
    chi2: String,
    /// The fitted data's RMS residual (mm).
    fit_rms_mm: f64,
    /// The largest predicted TCP σ over the working poses, √(max (1/3) tr C_s) (mm).
    tcp_sigma_mm: f64,
    /// RMS error of the calibrated model at the held-out poses (mm; the instrument noise
    /// included).
    check_rms_mm: f64,
    /// Largest error there (mm).
    check_max_mm: f64,
    /// RMS error of the nominal model at the same poses (mm), for comparison.
    nominal_rms_mm: f64,
    /// The parameter groups the drift check finds moved (`;`-separated; empty: none).
    check_moved: String,
    /// Wall time of the plan, the identification and the whole task (s).
    plan_s: f64,
    /// Wall time of the identification (s).
    identify_s: f64,
    /// Wall time of the task (s).
    total_s: f64,
    /// The robot's report (empty without `out`).
    report: String,
}

/// One robot's task with `seed` (see the module's doc).
fn robot(cell: &armcal::Cell, seed: u64, task: &Task) -> Result<Row, String> {
    let err = |e: armcal::Error| e.to_string();
    let start = Instant::now();
    let model = &cell.model;
    let truth = armcal::perturbed_truth(model, &armcal::Perturbation::default(), seed);
    let settings = armcal::PlanSettings {
        poses: task.poses,
        collisions: task.collisions,
        seed,
        ..Default::default()
    };
    let mut silent = armcal::Silent;
    let design = armcal::DesignRecord::planned(cell, None, "fleet", &settings, &[], &mut silent)
        .map_err(err)?;
    let plan_s = start.elapsed().as_secs_f64();
    let plan = design.plan.as_ref().ok_or("the plan made no design")?;
    let noise = cell.noise();
    let data = armcal::simulate(model, &truth, &plan.design, Some(&noise), seed).map_err(err)?;
    let t = Instant::now();
    let estimate = armcal::identify(
        cell,
        &data,
        &armcal::IdentifySettings::default(),
        &mut silent,
    )
    .map_err(err)?;
    let identify_s = t.elapsed().as_secs_f64();
    // Held out: random configurations, measured with noise of another seed, never fitted.
    let held = held_out_poses(model, task.check_poses, seed);
    let measured =
        armcal::simulate(model, &truth, &held, Some(&noise), seed ^ 0x5eed).map_err(err)?;
    let calibrated = estimate.params_for(model).map_err(err)?;
    let (check_rms_mm, check_max_mm) = held_out_error(cell, &calibrated, &measured)?;
    let (nominal_rms_mm, _) = held_out_error(cell, &model.nominal(), &measured)?;
    let drift = armcal::check(
        cell,
        &estimate,
        &measured,
        &armcal::CheckSettings::default(),
    )
    .map_err(err)?;
    let robot = format!("{}-{seed}", cell.name);
    let report = match &task.out {
        Some(dir) => write_robot(dir, &robot, &design, &estimate)?,
        None => String::new(),
    };
    let max_kpi = estimate.tcp.iter().map(|t| t.kpi).fold(0.0, f64::max);
    Ok(Row {
        robot,
        seed,
        plan_value: plan.value,
        status: estimate.solver.status.to_string(),
        converged: estimate.solver.status.is_converged(),
        chi2: estimate.uncertainty.verdict.clone(),
        fit_rms_mm: estimate.residuals.norm.rms,
        tcp_sigma_mm: max_kpi.sqrt(),
        check_rms_mm,
        check_max_mm,
        nominal_rms_mm,
        check_moved: drift.moved_groups().join(";"),
        plan_s,
        identify_s,
        total_s: start.elapsed().as_secs_f64(),
        report,
    })
}

/// `n` configurations uniform within the joint limits, seeded. (The library's own
/// `random_configurations` is not a root item of its front door; this is the same uniform
/// draw, with its own seed stream.)
fn held_out_poses(model: &armcal::Model, n: usize, seed: u64) -> Vec<Vec<f64>> {
    let (lower, upper) = model.joint_limits();
    let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_add(0xc4ec));
    (0..n)
        .map(|_| {
            lower
                .iter()
                .zip(&upper)
                .map(|(l, u)| rng.random_range(*l..=*u))
                .collect()
        })
        .collect()
}

/// RMS and largest distance between what the model with `params` predicts at the held-out
/// poses and what was measured there (mm).
fn held_out_error(
    cell: &armcal::Cell,
    params: &[f64],
    measured: &armcal::Dataset,
) -> Result<(f64, f64), String> {
    let poses: Vec<(String, Vec<f64>)> = measured
        .config_ids
        .iter()
        .cloned()
        .zip(measured.configurations.iter().cloned())
        .collect();
    let predicted = armcal::predict(&cell.model, params, &poses, None, cell.measurement)
        .map_err(|e| e.to_string())?;
    let json =
        |d: &armcal::Dataset| serde_json::to_value(&d.measurements).map_err(|e| e.to_string());
    let (p, m) = (json(&predicted)?, json(measured)?);
    let (p, m) = (
        p.as_array().cloned().unwrap_or_default(),
        m.as_array().cloned().unwrap_or_default(),
    );
    let point = |v: &serde_json::Value| -> Option<[f64; 3]> {
        let a = v["kind"]["value"].as_array()?;
        Some([
            a.first()?.as_f64()?,
            a.get(1)?.as_f64()?,
            a.get(2)?.as_f64()?,
        ])
    };
    let errors: Vec<f64> = p
        .iter()
        .zip(&m)
        .filter_map(|(a, b)| {
            let (a, b) = (point(a)?, point(b)?);
            Some(((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt())
        })
        .collect();
    if errors.is_empty() {
        return Err("the held-out data have no position measurements".into());
    }
    let rms = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
    Ok((rms, errors.iter().copied().fold(0.0, f64::max)))
}

/// Writes the robot's design, estimate and report into `dir/<robot>/`; returns the report.
fn write_robot(
    dir: &Path,
    robot: &str,
    design: &armcal::DesignRecord,
    estimate: &armcal::Estimate,
) -> Result<String, String> {
    let folder = dir.join(robot);
    let text = |e: PyErr| e.to_string();
    let design_path = folder.join("design.json");
    let estimate_path = folder.join("estimate.json");
    write_whole(&design_path, &to_json(design).map_err(text)?).map_err(text)?;
    write_whole(&estimate_path, &to_json(estimate).map_err(text)?).map_err(text)?;
    let acceptance = armcal::Acceptance {
        accepted: false,
        accept: "accept_unconverged=True",
        raise_iterations: "a larger iteration limit",
    };
    let page = armcal::files_report(&[design_path, estimate_path], robot, &acceptance)
        .map_err(|e| e.to_string())?;
    let path = folder.join("report.html");
    write_whole(&path, &page.page.render()).map_err(text)?;
    Ok(path.display().to_string())
}

/// A row as a dict, or the robot's error as a row with `error` set.
fn row_dict<'py>(
    py: Python<'py>,
    cell: &armcal::Cell,
    seed: u64,
    row: Result<Row, String>,
) -> PyResult<Bound<'py, PyAny>> {
    match row {
        Ok(row) => {
            let d = py
                .import("json")?
                .call_method1("loads", (to_json(&row)?,))?;
            d.set_item("error", py.None())?;
            Ok(d)
        }
        Err(e) => {
            let d = PyDict::new(py);
            d.set_item("robot", format!("{}-{seed}", cell.name))?;
            d.set_item("seed", seed)?;
            d.set_item("error", e)?;
            Ok(d.into_any())
        }
    }
}

/// One robot's calibration (what each Ray task of `examples/fleet_ray.py` runs): the
/// virtual robot `cell` perturbed with `seed`, its KPI design of `poses` poses (with the
/// cell's collision constraints if `collisions`), the simulated campaign, identification
/// and the check on `check_poses` held-out random poses. Returns the robot's row (a dict: plan value,
/// status, χ² verdict, fit RMS, TCP σ, held-out RMS and largest error of the calibrated
/// and RMS of the nominal model in mm, the drift check's moved groups, times in s);
/// a robot that fails has its message in `error`. With `out`, writes `out/<robot>/`
/// (design, estimate, report).
#[pyfunction]
#[pyo3(signature = (cell, seed, *, poses = 60, check_poses = 20, collisions = false, out = None))]
fn fleet_task<'py>(
    py: Python<'py>,
    cell: &Cell,
    seed: u64,
    poses: usize,
    check_poses: usize,
    collisions: bool,
    out: Option<PathBuf>,
) -> PyResult<Bound<'py, PyAny>> {
    let task = Task {
        poses,
        collisions,
        check_poses,
        out,
    };
    let c = &cell.cell;
    let row = py.detach(|| robot(c, seed, &task));
    row_dict(py, c, seed, row)
}

/// The fleet in this process: robot `i` is `cells[i]` with seed `seed + i`, each robot's
/// task as `fleet_task`, the robots in parallel over rayon's pool (`RAYON_NUM_THREADS`
/// threads; each robot's own planning runs inside it). Returns the rows in robot order;
/// `progress("step", {})` after each robot.
#[pyfunction]
#[pyo3(signature = (cells, *, seed = 1, poses = 60, check_poses = 20, collisions = false, out = None,
    progress = None))]
#[allow(clippy::too_many_arguments)]
fn fleet<'py>(
    py: Python<'py>,
    cells: &Bound<'py, PyList>,
    seed: u64,
    poses: usize,
    check_poses: usize,
    collisions: bool,
    out: Option<PathBuf>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyList>> {
    let cells: Vec<PyRef<'py, Cell>> = cells
        .iter()
        .enumerate()
        .map(|(i, c)| {
            c.extract()
                .map_err(|_| ArmcalError::new_err(format!("cells[{i}]: not a Cell")))
        })
        .collect::<PyResult<_>>()?;
    let robots: Vec<&armcal::Cell> = cells.iter().map(|c| &c.cell).collect();
    let task = Task {
        poses,
        collisions,
        check_poses,
        out,
    };
    let observer = std::sync::Mutex::new(Progress::new(progress));
    let rows: Vec<Result<Row, String>> = py.detach(|| {
        armcal::Observer::start(&mut *lock(&observer), "fleet", Some(robots.len()));
        let rows = robots
            .par_iter()
            .enumerate()
            .map(|(i, c)| {
                let row = robot(c, seed + i as u64, &task);
                armcal::Observer::step(&mut *lock(&observer));
                row
            })
            .collect();
        armcal::Observer::finish(&mut *lock(&observer));
        rows
    });
    let observer = observer
        .into_inner()
        .map_err(|_| ArmcalError::new_err("progress poisoned"))?;
    let list = PyList::empty(py);
    for (i, (row, c)) in rows.into_iter().zip(&robots).enumerate() {
        list.append(row_dict(py, c, seed + i as u64, row)?)?;
    }
    observer.finish_call(Ok(list))
}

/// The observer, even after a panic elsewhere (it holds no invariant).
fn lock(m: &std::sync::Mutex<Progress>) -> std::sync::MutexGuard<'_, Progress> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Adds the fleet functions to the module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(fleet_task, m)?)?;
    m.add_function(wrap_pyfunction!(fleet, m)?)?;
    Ok(())
}
