//! Parameter identification with honest uncertainty (book ch. 4, paper eqs. 5–6, 13–19):
//! Levenberg–Marquardt, Gauss–Newton, recursive (Kalman) estimation, robust IRLS, priors
//! (MAP), parameter and TCP covariances, observability indices, held-out validation; joint
//! axes by circle point analysis.

pub mod circle_point;
pub(crate) mod estimate;
pub(crate) mod export;
pub(crate) mod fingerprint;
pub(crate) mod fit_checks;
pub mod fitted_ranges;
mod frames_first;
mod free_set;
pub(crate) mod gauss_newton;
pub mod held_out;
pub(crate) mod kalman;
pub(crate) mod lm;
pub mod model_floor;
pub(crate) mod nongeometric_choice;
pub(crate) mod nongeometric_gate;
pub(crate) mod pivot;
pub(crate) mod prediction_sigma;
pub(crate) mod problem;
pub(crate) mod refit;
pub mod residuals;
pub(crate) mod robust;
pub(crate) mod run;
pub(crate) mod settings;
pub(crate) mod sign_diagnosis;
pub(crate) mod solver;
mod split;
pub(crate) mod tree;
pub(crate) mod uncertainty;
pub(crate) mod unit_check;
pub(crate) mod verdicts;
mod weak_gain;

pub(crate) use estimate::{Acceptance, Estimate};
pub use estimate::{
    AxisErrors, HeldOutAxes, HeldOutOrientation, MeasurementResidual, ResidualReport, Usability,
    Validation,
};
pub(crate) use estimate::{ParameterEstimate, SolverReport};
pub use fingerprint::ModelFingerprint;
pub(crate) use fit_checks::FitChecks;
use frames_first::frames_model;
pub use frames_first::{
    frames_first_start, frames_only, frames_only_fit, is_frame_parameter, DETERMINED_VIF,
};
pub use gauss_newton::gauss_newton;
pub use kalman::{kalman_filter, KalmanSettings};
pub use lm::levenberg_marquardt;
pub(crate) use lm::LmSettings;
pub use pivot::pivot_from_flange_poses;
pub use problem::Problem;
pub(crate) use refit::FramesRefit;
pub use refit::RefitRecord;
pub(crate) use robust::Loss;
pub use robust::{robust_fit, Outlier};
pub(crate) use run::identify;
pub(crate) use settings::{IdentifySettings, Method};
pub use solver::SolverResult;
pub(crate) use solver::ToleranceSettings;
pub use uncertainty::{
    observability, parameter_uncertainty, tcp_covariance, tcp_covariance_constrained, tcp_jacobian,
    Chi2Outcome, Observability, ParameterUncertainty,
};
pub use verdicts::{Chi2Verdict, IdentifiabilityVerdict, Verdicts};

use crate::cell::Cell;
use crate::measure::{Dataset, MeasurementKind};
use crate::model::identifiability::{Identifiability, IdentifiabilitySettings, Measurement};
use crate::model::{Model, ParameterStatus};
use crate::progress::Observer;
use crate::Error;
use free_set::{fit_free_set, FreeSetFit};
pub(crate) use nongeometric_choice::{Candidate, NonGeometric, NonGeometricChoice};
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use split::Split;

/// The cell's model with its free set for `data`, decided at the parameters `at` (the
/// frames-first estimate or a fit, not the nominal: a target whose nominal offset is
/// unknown and written as `[0, 0, 0]` lies on the last joint axis there, where two
/// parameters of that joint have no effect), and the reason for every parameter left out.
/// A parameter the same analysis at the nominal leaves out is freed there only if the
/// data determine it (`weak_gain`: variance inflation at most [`DETERMINED_VIF`]), so
/// `plan`'s prediction at the nominal and the fit agree on a target on the last axis.
/// With `free = "auto"` the free set is the minimal identifiable set *at the data's
/// configurations*; parameters these data cannot identify although the cell could (e.g. a
/// joint that never moves, or all poses alike) are marked "from these data". Too few
/// residual rows for the cell's identifiable set is an error.
pub fn identifiable_model(
    cell: &Cell,
    data: &Dataset,
    at: &[f64],
) -> Result<(Model, Vec<(String, String)>), Error> {
    if !cell.auto_free {
        return Ok((cell.model.clone(), Vec::new()));
    }
    let generic = cell.identifiability(&cell.identifiability_settings())?;
    let (model, reasons, _) = identifiable_model_given(cell, data, at, &generic, &[])?;
    Ok((model, reasons))
}

/// [`identifiable_model`] of an `auto` cell with the cell's generic analysis (its declared
/// free set at the nominal, random configurations) already done, so that a fit deciding its
/// free set more than once does it once; `dropped` are parameters already left out (a
/// non-geometric term the gate found not separable), with their reasons; and the
/// parameters held as only weakly identifiable at `at` ([`weak_gain`]).
type FreeSet = (Model, Vec<(String, String)>, Vec<String>);
fn identifiable_model_given(
    cell: &Cell,
    data: &Dataset,
    at: &[f64],
    generic: &Identifiability,
    dropped: &[(usize, String)],
) -> Result<FreeSet, Error> {
    let rows = data.rows();
    if rows < generic.identifiable.len() {
        return Err(Error::Input(format!(
            "{rows} residual rows from {} measurements cannot determine the {} parameters cell `{}` identifies; measure at least {} configurations",
            data.measurements.len(),
            generic.identifiable.len(),
            cell.name,
            generic.identifiable.len().div_ceil(data.rows().max(1) / data.configurations.len().max(1))
        )));
    }
    let mut declared = cell.declared_model();
    for &(i, _) in dropped {
        declared.registry.set_status(i, ParameterStatus::Fixed);
    }
    let settings = IdentifiabilitySettings {
        stations: data.config_stations.clone(),
        payloads: Some(data.model_payloads(&declared)?),
        ..cell.identifiability_settings()
    };
    let (report, held) =
        weak_gain::analyze_holding_weak(&mut declared, at, &data.configurations, &settings)?;
    report.apply(&mut declared)?;
    let weak = held.iter().map(|(name, _)| name.clone()).collect();
    let generic_excluded: std::collections::HashSet<&str> =
        generic.excluded.iter().map(|e| e.name.as_str()).collect();
    let reasons = report
        .excluded
        .into_iter()
        .map(|e| {
            let reason = if generic_excluded.contains(e.name.as_str()) {
                e.reason
            } else {
                format!("from these data: {}", e.reason)
            };
            (e.name, reason)
        })
        .chain(held)
        .chain(
            dropped
                .iter()
                .map(|(i, why)| (declared.registry.get(*i).name.clone(), why.clone())),
        )
        .collect();
    Ok((declared, reasons, weak))
}

/// The measurement type of a data set for the identifiability analysis, from its first
/// measurement: pose, distance between poses, or (for every other kind) position.
fn data_measurement(data: &Dataset) -> Measurement {
    match data.measurements.first().map(|m| &m.kind) {
        Some(MeasurementKind::Pose { .. }) => Measurement::Pose,
        Some(MeasurementKind::Distance { .. }) => Measurement::Distance,
        _ => Measurement::Position,
    }
}

/// Runs one solver on a problem.
pub fn solve(
    problem: &mut Problem,
    start: &[f64],
    opts: &IdentifySettings,
    observer: &mut dyn Observer,
) -> Result<(SolverResult, Vec<Outlier>, Option<f64>), Error> {
    problem.check_determined()?;
    if let Some(loss) = opts.robust {
        let r = robust_fit(problem, start, loss, &opts.lm, observer)?;
        return Ok((r.solution, r.outliers, Some(r.scale)));
    }
    let s = match opts.method {
        Method::Lm => levenberg_marquardt(problem, start, &opts.lm, observer)?,
        Method::GaussNewton => gauss_newton(problem, start, &opts.lm.tolerances, observer)?,
        Method::Kalman => {
            kalman_filter(problem, start, &KalmanSettings::default(), observer)?.solution
        }
    };
    Ok((s, Vec::new(), None))
}

/// Splits configurations into (train, test) with a seeded shuffle.
pub fn holdout_split(n: usize, fraction: f64, seed: u64) -> (Vec<usize>, Vec<usize>) {
    let mut idx: Vec<usize> = (0..n).collect();
    idx.shuffle(&mut ChaCha8Rng::seed_from_u64(seed));
    let test = ((n as f64) * fraction).round() as usize;
    let (t, tr) = idx.split_at(test.min(n));
    let (mut train, mut test) = (tr.to_vec(), t.to_vec());
    train.sort();
    test.sort();
    (train, test)
}

/// The payload terms of `model` (`<joint>.compliance.payload`, [`crate::model::compliance`])
/// with the reason data that carry no payload leave them out.
pub(crate) fn payload_terms(model: &Model) -> impl Iterator<Item = (usize, String)> + '_ {
    model
        .compliance
        .iter()
        .flat_map(|c| &c.terms)
        .filter(|t| t.spec.is_payload())
        .map(|t| {
            (
                t.param,
                "no measurement carried a payload, so the joint's own compliance has no effect \
                 on these data: measure some poses with a [[payload]] (a `payload` column)"
                    .to_string(),
            )
        })
}

/// The payload states `data` carried in order of first appearance (`none` for rows without
/// a payload); empty when no row named one.
fn payload_states(data: &Dataset) -> Vec<String> {
    if !data.carries_payloads() {
        return Vec::new();
    }
    let mut states: Vec<String> = Vec::new();
    for c in 0..data.configurations.len() {
        let s = data.payload_of(c).unwrap_or("none");
        if !states.iter().any(|x| x == s) {
            states.push(s.to_string());
        }
    }
    states
}

/// The estimate of a fit: covariance, TCP covariance at the working configurations,
/// diagnostics, residuals and the held-out validation.
fn estimate_of_fit(
    cell: &Cell,
    data: &Dataset,
    opts: &IdentifySettings,
    split: &Split,
    fit: FreeSetFit,
    noise: &crate::measure::NoiseModel,
    observer: &mut dyn Observer,
) -> Result<Estimate, Error> {
    let train: &Dataset = &split.train;
    let (model, reasons) = (&fit.model, fit.reasons);
    let (sol, outliers, robust_scale) = (fit.solution, fit.outliers, fit.robust_scale);
    let mut problem = Problem::new(model, train, noise)?;
    problem.row_weights = fit.row_weights;
    let branch = crate::model::branch::nearest_branch(model, &sol.params);
    let sol = sol.in_branch(&branch, &problem.free);
    let names = problem.free_names();
    let kept = (0..model.param_count())
        .filter(|&i| !is_frame_parameter(model, i))
        .count();
    // the generic count is of geometric parameters: the non-geometric terms (compliance,
    // periodic errors) are counted apart
    let geometric =
        crate::model::identifiability::IdentifiableCount::of(model, problem.free.iter().copied())
            .geometric;
    // With a parameter held as only weakly identifiable at the fit (weak_gain), the deficit
    // is the nominal geometry's (a target on the last axis there), and it is explained there.
    let deficit_at = if fit.weak.is_empty() {
        sol.params.clone()
    } else {
        model.nominal()
    };
    let rank_deficit = if let Some(refit) = &opts.refit {
        refit::deficit(cell, refit, names.len(), kept)
    } else if cell.auto_free {
        let declared = cell.declared_model();
        crate::model::rank_deficit::rank_deficit(
            &declared,
            &deficit_at,
            geometric,
            cell.measurement,
            Some(&train.configurations),
        )?
    } else {
        None
    };
    // Covariance from the unweighted whitened Jacobian of the kept measurements (robust
    // weights only pick data).
    let unc = uncertainty::parameter_uncertainty(&sol.jacobian, &sol.residual, &names)?;
    let working: Vec<Vec<f64>> = cell.working.iter().map(|w| w.q.clone()).collect();
    let wnames: Vec<String> = cell.working.iter().map(|w| w.name.clone()).collect();
    // A frames refit holds the robot at an earlier calibration, not at a nominal with the
    // cell's prior: it states no floor. Without working poses the floor still holds what
    // `predict` needs at other configurations (its absorbed map).
    let model_floor = opts.refit.is_none().then(|| {
        model_floor::model_floor(
            &problem,
            &sol.params,
            &sol.jacobian,
            &unc.covariance,
            &cell.working,
            &cell.fixed_prior,
            &outliers,
        )
    });
    let (tcp, tcp_constrained) = if working.is_empty() {
        (Vec::new(), Vec::new())
    } else {
        let g = uncertainty::tcp_jacobian(model, &sol.params, &problem.free, &working);
        let cs = uncertainty::with_base_frame(
            uncertainty::tcp_covariance(&g, &unc.covariance, &wnames),
            &uncertainty::tcp_jacobian_world(model, &sol.params, &problem.free, &working),
            &unc.covariance,
        );
        let cc = uncertainty::tcp_covariance_constrained(&sol.jacobian, &g)?;
        let blocks = (0..working.len())
            .map(|i| cc.fixed_view::<3, 3>(3 * i, 3 * i).into_owned())
            .collect();
        (cs, blocks)
    };
    let data_rows = sol.jacobian.nrows() - problem.prior_rows.nrows();
    let nongeometric = nongeometric_gate::nongeometric_gate(
        model,
        &problem.free,
        &sol.jacobian.rows(0, data_rows).into_owned(),
        &unc.covariance,
        &sol.params,
    );
    let observability = uncertainty::observability(sol.jacobian.rows(0, data_rows));
    let residuals = residuals::residual_report(&problem, &sol.params, &split.train_configs);
    let validation = phase(observer, "held-out validation", || {
        split.validate(model, &sol.params, opts, noise)
    })?;
    let parameters = parameter_table(&model.registry, &sol.params, &problem.free, &unc.sigma);
    let strong = unc
        .strong_correlations
        .iter()
        .map(|&(a, b, rho)| (names[a].clone(), names[b].clone(), rho))
        .collect();
    Ok(Estimate {
        cell: cell.name.clone(),
        data: data.source.clone(),
        model: model.spec_at(&sol.params),
        parameters,
        payloads_measured: payload_states(train),
        nongeometric,
        nongeometric_choice: None,
        fixed_reasons: reasons.clone(),
        rank_deficit: rank_deficit.clone(),
        solver: SolverReport {
            method: opts.method,
            robust: opts.robust,
            status: sol.status.clone(),
            iterations: sol.iterations,
            time_ms: sol.time.as_secs_f64() * 1e3,
            history: sol.history.clone(),
        },
        verdicts: Some(Verdicts {
            solver: sol.status.clone(),
            chi2: Chi2Verdict::of(&unc),
            identifiability: IdentifiabilityVerdict::of(
                model,
                cell.measurement,
                &problem.free,
                &reasons,
                rank_deficit.as_ref(),
            ),
            fit: FitChecks::default(),
        }),
        fingerprint: None,
        free: names,
        strong_correlations: strong,
        uncertainty: unc,
        tcp,
        tcp_constrained,
        model_floor,
        observability,
        residuals,
        outliers,
        far_from_nominal: branch.far,
        robust_scale,
        validation,
        measurements: train.measurements.len(),
        configurations: train.configurations.len(),
        fitted_ranges: fitted_ranges::FittedRange::of(model, &train.configurations),
        refit: opts.refit.as_ref().map(|r| refit::record(r, kept)),
    })
}

/// Every parameter of `registry` in display units: nominal, the value in `params`, and for
/// the free ones (`free`, in covariance order) the σ of `sigma`.
pub(crate) fn parameter_table(
    registry: &crate::model::Registry,
    params: &[f64],
    free: &[usize],
    sigma: &[f64],
) -> Vec<ParameterEstimate> {
    let free_set: std::collections::HashSet<usize> = free.iter().copied().collect();
    (0..registry.len())
        .map(|i| {
            let p = registry.get(i);
            let f = p.unit.display_factor();
            let col = free.iter().position(|&c| c == i);
            ParameterEstimate {
                name: p.name.clone(),
                unit: p.unit.display_name().into(),
                nominal: p.nominal * f,
                estimate: params[i] * f,
                sigma: col.map(|c| sigma[c] * f),
                free: free_set.contains(&i),
            }
        })
        .collect()
}

/// Runs `f` as the task `task` of `observer` (a phase that reports no steps of its own).
fn phase<T>(observer: &mut dyn Observer, task: &str, f: impl FnOnce() -> T) -> T {
    observer.start(task, None);
    let result = f();
    observer.finish();
    result
}
