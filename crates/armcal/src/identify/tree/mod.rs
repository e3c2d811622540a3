//! Identification of a kinematic tree ([`crate::model::tree`], issue 32): one least-squares
//! problem over the stacked rows of every branch.
//!
//! Each measurement row names the tree target it saw; its residual is that target's
//! branch's (the branch's forward kinematics at the branch joints `q_b = offset + C_b q`,
//! through the couplings), and its Jacobian row the branch's identification Jacobian
//! scattered into the tree registry's columns (a parameter not on the branch: zero), so a
//! shared link (the torso) and the instrument frame are one set of columns fed by every
//! branch (paper eqs. 5–6 over the union of the branches' rows). The free set is the minimal
//! identifiable set of the tree at the data's rows
//! ([`crate::model::tree::identifiability`]); the solvers, the covariance `C_p = σ̂₀² (JᵀJ)⁻¹`
//! (book eq. 5.23) and the robust reweighting are the serial fit's ([`super::solver`]).
//!
//! Joint and lateral (bending) compliance over the tree ([`crate::model::tree::compliance`],
//! [`crate::model::tree::bending`]) is fitted with the geometry: its κ and κ⊥ are tree
//! parameters like any other (their columns exact, their σ from the same covariance), and
//! the serial identifiability gate
//! ([`crate::identify::nongeometric_gate`]) judges each: a term that is not separable from
//! the others on these data is dropped, named with its reason, and the tree fitted again.
//!
//! `--nongeometric auto` cross-validates the kinematic tree against the compliant one as a
//! serial fit's candidates are ([`fit`]). What a tree fit does not have yet (the serial
//! fit's): periodic joint errors, priors, instrument stations, payloads, distance measurements, the
//! Kalman filter, the model floor and the fit checks; each is refused by name.

use super::lm::minimise;
use super::nongeometric_gate::TermVerdict;
use super::robust::Outlier;
use super::solver::LeastSquares;
use super::uncertainty::{parameter_uncertainty, ParameterUncertainty};
use super::{holdout_split, Acceptance, IdentifySettings, Method, ParameterEstimate, SolverReport};
use super::{Candidate, NonGeometric, NonGeometricChoice};
use crate::accuracy::ErrorStats;
use crate::cell::tree::TreeCell;
use crate::measure::{Dataset, MeasurementKind};
use crate::model::identifiability::{Identifiability, IdentifiabilitySettings, Measurement};
use crate::model::jacobian::Rows;
use crate::model::registry::Segment;
use crate::model::tree::identifiability::analyze_tree_measured;
use crate::model::tree::kinematics::{branch_kinematics, tree_identification_jacobian, TreeData};
use crate::model::tree::{Tree, TreeSpec};
use crate::model::Observed;
use crate::progress::Observer;
use crate::Error;
use nalgebra::{DMatrix, Matrix3};
use serde::{Deserialize, Serialize};

mod export;
mod fit;
mod problem;
pub use export::export_tree_estimate;
use fit::{choose_tree, fit_tree_free_set, TreeFit};
pub(crate) use problem::TreeProblem;

/// The fit of one target (one branch's reflector) in a tree estimate: how well the model
/// explains its rows, fitted and held out.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TreeTargetFit {
    /// The target's name.
    pub target: String,
    /// The links from the root to the link it hangs from.
    pub branch: Vec<String>,
    /// Position error (mm) of its fitted measurements at the estimate.
    pub fitted: ErrorStats,
    /// Position error (mm) of its held-out measurements at the estimate (`count` 0: none).
    pub held_out: ErrorStats,
    /// Position error (mm) of its held-out measurements with the nominal robot and the
    /// instrument and target frames fitted to the training data (what calibrating only the
    /// frames would give).
    pub held_out_frames_only: ErrorStats,
}

/// The estimate of a tree (`armcal identify` of a tree cell, `estimate.json`): the tree at
/// its estimated parameters, every parameter with its σ, the covariance, the solver and the
/// fit per target. `armcal export` writes it as a URDF or a tree cell
/// ([`export_tree_estimate`]); `predict`, `report`, `compensate`, `accuracy` and the others
/// take a serial estimate and refuse this one by name.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TreeEstimate {
    /// Always `tree-estimate` (what the other commands recognise and refuse).
    pub kind: String,
    /// The cell's name.
    pub cell: String,
    /// The data fitted (file names).
    pub data: String,
    /// The tree at the estimate (nominal values replaced by the estimated ones).
    pub tree: TreeSpec,
    /// Every tree parameter: nominal, estimate, σ (free ones), display units.
    pub parameters: Vec<ParameterEstimate>,
    /// The estimated parameters, in covariance order.
    pub free: Vec<String>,
    /// Every parameter left at its nominal value, with the reason.
    pub fixed_reasons: Vec<(String, String)>,
    /// How the solver ended.
    pub solver: SolverReport,
    /// Covariance, σ, correlations and the χ² test of the fit (book eq. 5.23).
    pub uncertainty: ParameterUncertainty,
    /// Measurements a robust fit found to be outliers.
    pub outliers: Vec<Outlier>,
    /// The identifiability gate of the compliance terms fitted (empty for a rigid tree).
    #[serde(default)]
    pub nongeometric: Vec<TermVerdict>,
    /// `--nongeometric auto`: every candidate's cross-validated score and the choice.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nongeometric_choice: Option<NonGeometricChoice>,
    /// The fit per target.
    pub targets: Vec<TreeTargetFit>,
    /// What held-out validation was done (empty: none).
    pub validation: String,
    /// Measurements fitted.
    pub measurements: usize,
    /// Configurations fitted.
    pub configurations: usize,
}

impl TreeEstimate {
    /// Whether the estimate may be used (exported, reported): a fit that did not converge is
    /// refused unless `acceptance` accepts it, and then the returned note says so.
    pub fn check_usable(&self, acceptance: &Acceptance) -> Result<Option<String>, Error> {
        if self.solver.status.is_converged() {
            return Ok(None);
        }
        if !acceptance.accepted {
            return Err(Error::Input(format!(
                "the fit of tree `{}` did not converge ({}): its estimate is no calibration; \
                 refit (raise the iteration limit with {}), or pass {} to use it anyway",
                self.cell, self.solver.status, acceptance.raise_iterations, acceptance.accept
            )));
        }
        Ok(Some(format!(
            "the fit did not converge ({}); used because {} was given",
            self.solver.status, acceptance.accept
        )))
    }

    /// The record as JSON (keys in alphabetical order, `crate::json`).
    pub fn to_json(&self) -> Result<String, Error> {
        crate::json::sorted_pretty(self)
    }

    /// Reads the estimate at `path` if it is a tree's (`kind` `tree-estimate`); `None` for
    /// any other JSON (a serial estimate, read by [`crate::Estimate::from_file`]). Errors
    /// name the file.
    pub fn read_if_tree(path: &std::path::Path) -> Result<Option<TreeEstimate>, Error> {
        let file = |message: String| Error::File {
            file: path.display().to_string(),
            message,
        };
        let text = crate::input::read_capped(path, crate::input::TEXT_CAP)
            .map_err(|e| file(e.to_string()))?;
        if tree_estimate_refusal(&text).is_none() {
            return Ok(None);
        }
        serde_json::from_str(&text)
            .map(Some)
            .map_err(|e| file(format!("not a readable tree estimate: {e}")))
    }

    /// The tree parameter vector of the estimate (internal units), in `cell`'s registry
    /// order; an error if the estimate is of another tree.
    pub fn params_for(&self, tree: &Tree) -> Result<Vec<f64>, Error> {
        if self.parameters.len() != tree.param_count() {
            return Err(Error::Input(format!(
                "the estimate of `{}` has {} parameters, tree `{}` {}",
                self.cell,
                self.parameters.len(),
                tree.name,
                tree.param_count()
            )));
        }
        self.parameters
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let reg = tree.registry.get(i);
                if reg.name != p.name {
                    return Err(Error::Input(format!(
                        "parameter {i} of the estimate is `{}`, of tree `{}` `{}`",
                        p.name, tree.name, reg.name
                    )));
                }
                Ok(p.estimate / reg.unit.display_factor())
            })
            .collect()
    }
}

impl TreeEstimate {
    /// The 3 × 3 covariance (mm²) of the position of the target named `target` at the tree
    /// joints `q` (internal units) from the estimate's parameter covariance: `G C_p Gᵀ` with
    /// `G` the position rows of the target's identification Jacobian over the free
    /// parameters (paper eq. 19, through the target's branch).
    pub fn tcp_covariance(
        &self,
        tree: &Tree,
        target: &str,
        q: &[f64],
    ) -> Result<Matrix3<f64>, Error> {
        let params = self.params_for(tree)?;
        let t = tree
            .targets
            .iter()
            .position(|t| t.0 == target)
            .ok_or_else(|| {
                Error::Input(format!("tree `{}` has no target `{target}`", tree.name))
            })?;
        if q.len() != tree.dof() {
            return Err(Error::Input(format!(
                "tree `{}` has {} joints, not {}",
                tree.name,
                tree.dof(),
                q.len()
            )));
        }
        let free = self
            .free
            .iter()
            .map(|n| tree.registry.require(n))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(tree_tcp_covariance(
            tree,
            &params,
            &free,
            &self.uncertainty.covariance,
            t,
            q,
        ))
    }
}

/// What a command that takes a serial chain's estimate says of the JSON `text` when it is a
/// tree's ([`TreeEstimate`]); `None` when it is not.
pub(crate) fn tree_estimate_refusal(text: &str) -> Option<String> {
    let value: serde_json::Value = serde_json::from_str(text).ok()?;
    (value.get("kind")?.as_str()? == "tree-estimate").then(|| {
        "the estimate of a kinematic tree (`armcal identify` of a tree cell): `armcal \
         export` writes it as a URDF or a tree cell and `armcal report` shows it; predict, \
         compensate, accuracy and the other commands that read an estimate take a serial \
         chain's for now (issue 32); the tree's parameters, σ and per-target fit are in this \
         file"
            .to_string()
    })
}

/// The targets each configuration of `data` measures.
fn measured_targets(data: &Dataset) -> Vec<Vec<usize>> {
    let mut seen = vec![Vec::new(); data.configurations.len()];
    for m in &data.measurements {
        if let Observed::Target(t) = m.observed {
            if !seen[m.config].contains(&t) {
                seen[m.config].push(t);
            }
        }
    }
    seen
}

/// The identifiable set of `tree` at `params` from the rows of `data` (each configuration
/// measuring the targets it names), among the tree parameters `candidates` allows.
fn identifiable_at(
    tree: &Tree,
    params: &[f64],
    data: &Dataset,
    measurement: Measurement,
    candidates: impl Fn(usize) -> bool,
) -> Result<(Vec<usize>, Identifiability), Error> {
    let mut t = tree.clone();
    for i in 0..t.param_count() {
        if !candidates(i) {
            t.registry
                .set_status(i, crate::model::registry::ParameterStatus::Fixed);
        }
    }
    let opts = IdentifiabilitySettings {
        measurement,
        poses: data.configurations.len(),
        ..Default::default()
    };
    let report = analyze_tree_measured(
        &t,
        params,
        &data.configurations,
        Some(&measured_targets(data)),
        &opts,
    )?;
    let free = report
        .identifiable
        .iter()
        .map(|n| tree.registry.require(n))
        .collect::<Result<_, _>>()?;
    Ok((free, report))
}

/// The measurement type of a tree's data: pose if its first row is a pose, else position.
fn data_measurement(data: &Dataset) -> Measurement {
    match data.measurements.first().map(|m| &m.kind) {
        Some(MeasurementKind::Pose { .. }) => Measurement::Pose,
        _ => Measurement::Position,
    }
}

/// Identifies the tree of `cell` from `data` (every row naming its target): a frames-first
/// fit (the instrument frame, the robot nominal), then the tree's identifiable set
/// at the data's rows decided there and fitted by the settings' solver (Levenberg–Marquardt,
/// Gauss–Newton, or robust IRLS); its covariance `C_p = σ̂₀² (JᵀJ)⁻¹` (book eq. 5.23), and
/// the position errors per target, fitted and held out (`opts.holdout` of the configurations
/// at random, seeded, or `opts.test`). A fit that did not converge says so in its status.
///
/// With the cell's joint compliance and bending (`--nongeometric` as the cell, or
/// `compliance`: both kinds) the κ and κ⊥ are fitted with the geometry and gated
/// (`crate::identify::nongeometric_gate`): while a term is not separable, the least
/// separable is dropped (its reason kept) and the tree fitted again; `--nongeometric none`
/// fits the rigid tree.
///
/// Settings a tree fit does not take yet are refused by name: `method` Kalman, a `refit`, a
/// warm `start`, periodic terms (`--nongeometric periodic`, `both`),
/// the sign diagnosis.
pub fn identify_tree(
    cell: &TreeCell,
    data: &Dataset,
    opts: &IdentifySettings,
    observer: &mut dyn Observer,
) -> Result<TreeEstimate, Error> {
    let refused = [
        (
            "the Kalman filter (--method kalman)",
            opts.method == Method::Kalman,
        ),
        ("a frames refit (--refit)", opts.refit.is_some()),
        ("a warm start", opts.start.is_some()),
        (
            "periodic joint errors (--nongeometric periodic or both)",
            matches!(
                opts.nongeometric,
                NonGeometric::Only(Candidate::Periodic | Candidate::Both)
            ),
        ),
        (
            "the joint sign diagnosis (--diagnose-signs)",
            opts.diagnose_signs,
        ),
    ];
    if let Some((what, _)) = refused.iter().find(|(_, asked)| *asked) {
        return Err(Error::Input(format!(
            "cell `{}` is a tree: a tree fit does not take {what} yet (issue 32)",
            cell.name
        )));
    }
    let tree = &cell.tree;
    let (train, test, validation) = split(data, opts)?;
    let measurement = data_measurement(&train);
    let nominal = tree.nominal();
    let lm = &opts.lm;
    // 1. the instrument frame, the robot and its targets nominal (a target's offset the
    // data see only together with the placement would wander off here: the serial
    // frames-first start holds such offsets too, `frames_first`)
    observer.start("frames-first fit", None);
    let is_frame = |i: usize| {
        let p = tree.registry.get(i);
        p.status.is_free() && p.segment == Segment::Instrument
    };
    let (frames, _) = identifiable_at(tree, &nominal, &train, measurement, is_frame)?;
    let frames_fit = {
        let problem = TreeProblem::new(tree, &train, &cell.noise, frames)?;
        check_determined(&problem)?;
        minimise(&problem, &nominal, lm, observer)?
    };
    observer.finish();
    // 2. the non-geometric model (the cell's, none, or cross-validated), then the tree's
    // identifiable set at the frames-first estimate fitted with it
    let (rigid, nongeometric_choice) = match opts.nongeometric {
        NonGeometric::Auto { folds } => {
            let choice = choose_tree(
                cell,
                &train,
                &frames_fit.params,
                measurement,
                opts,
                folds,
                observer,
            )?;
            (choice.chosen == Candidate::Kinematic, Some(choice))
        }
        NonGeometric::Only(Candidate::Kinematic) => (true, None),
        _ => (false, None),
    };
    let TreeFit {
        problem,
        solution: sol,
        outliers,
        report,
        verdicts: nongeometric,
        dropped,
    } = fit_tree_free_set(
        cell,
        &train,
        &frames_fit.params,
        measurement,
        rigid,
        opts,
        observer,
    )?;
    let names = problem.free_names();
    let unc = parameter_uncertainty(&sol.jacobian, &sol.residual, &names)?;
    // fit per target: the fitted rows, and the held-out rows with the estimate and with the
    // frames-only fit
    let fitted = problem.position_errors(&sol.params);
    let held_out = match &test {
        Some(test) => {
            let errors = TreeProblem::new(tree, test, &cell.noise, Vec::new())?;
            Some((
                errors.position_errors(&sol.params),
                errors.position_errors(&frames_fit.params),
            ))
        }
        None => None,
    };
    let per_target = |d: &Dataset, errors: &[f64], t: usize| -> ErrorStats {
        let e: Vec<f64> = d
            .measurements
            .iter()
            .zip(errors)
            .filter(|(m, _)| m.observed == Observed::Target(t))
            .map(|(_, &e)| e)
            .collect();
        ErrorStats::of(&e)
    };
    let targets = (0..tree.targets.len())
        .map(|t| {
            let (name, b, _) = &tree.targets[t];
            let (held_out, frames_only) = match (&test, &held_out) {
                (Some(d), Some((fit, frames))) => (per_target(d, fit, t), per_target(d, frames, t)),
                _ => (ErrorStats::default(), ErrorStats::default()),
            };
            TreeTargetFit {
                target: name.clone(),
                branch: tree.branches[*b]
                    .model
                    .links
                    .iter()
                    .map(|l| l.spec.name.clone())
                    .collect(),
                fitted: per_target(&train, &fitted, t),
                held_out,
                held_out_frames_only: frames_only,
            }
        })
        .collect();
    let parameters = super::parameter_table(&tree.registry, &sol.params, &problem.free, &unc.sigma);
    Ok(TreeEstimate {
        kind: "tree-estimate".into(),
        cell: cell.name.clone(),
        data: data.source.clone(),
        tree: tree.spec_at(&sol.params),
        parameters,
        free: names,
        fixed_reasons: report
            .excluded
            .into_iter()
            .map(|e| (e.name, e.reason))
            .chain(
                dropped
                    .into_iter()
                    .map(|(i, reason)| (tree.registry.get(i).name.clone(), reason)),
            )
            .collect(),
        solver: SolverReport {
            method: opts.method,
            robust: opts.robust,
            status: sol.status.clone(),
            iterations: sol.iterations,
            time_ms: sol.time.as_secs_f64() * 1e3,
            history: sol.history.clone(),
        },
        uncertainty: unc,
        outliers,
        nongeometric,
        nongeometric_choice,
        targets,
        validation,
        measurements: train.measurements.len(),
        configurations: train.configurations.len(),
    })
}

/// At least one free parameter and no fewer rows than free parameters.
fn check_determined(problem: &TreeProblem) -> Result<(), Error> {
    if problem.free.is_empty() {
        return Err(Error::Input("no free parameters to identify".into()));
    }
    if problem.rows() < problem.free.len() {
        return Err(Error::Input(format!(
            "{} residual rows from {} measurements cannot determine the {} identifiable \
             parameters of tree `{}`; measure more poses",
            problem.rows(),
            problem.data.measurements.len(),
            problem.free.len(),
            problem.tree.name
        )));
    }
    Ok(())
}

/// The training data, the validation data and what the validation is: `opts.holdout` of
/// the configurations held out at random (seeded; [`holdout_split`]), or `opts.test`.
fn split(
    data: &Dataset,
    opts: &IdentifySettings,
) -> Result<(Dataset, Option<Dataset>, String), Error> {
    let h = opts.holdout;
    if !(0.0..1.0).contains(&h) {
        return Err(Error::Input(format!(
            "the holdout fraction {h} must be in [0, 1) (0: no held-out validation)"
        )));
    }
    match (&opts.test, h > 0.0) {
        (Some(_), true) => Err(Error::Input(
            "give either a holdout fraction or test data for validation, not both".into(),
        )),
        (Some(test), false) => Ok((data.clone(), Some(test.clone()), test.source.clone())),
        (None, true) => {
            // each group of configurations that measure the same targets (a file of one
            // arm's poses) is split as a fit of that group alone would split it
            let seen = measured_targets(data);
            let mut groups: Vec<(Vec<usize>, Vec<usize>)> = Vec::new();
            for (c, targets) in seen.iter().enumerate() {
                let mut key = targets.clone();
                key.sort_unstable();
                match groups.iter_mut().find(|(k, _)| *k == key) {
                    Some((_, configs)) => configs.push(c),
                    None => groups.push((key, vec![c])),
                }
            }
            let (mut train, mut test) = (Vec::new(), Vec::new());
            for (_, configs) in &groups {
                let (tr, te) = holdout_split(configs.len(), h, opts.seed);
                train.extend(tr.into_iter().map(|i| configs[i]));
                test.extend(te.into_iter().map(|i| configs[i]));
            }
            train.sort_unstable();
            test.sort_unstable();
            if test.is_empty() {
                return Err(Error::Input(format!(
                    "the holdout fraction {h} of {} configurations holds out none; hold out a \
                     larger fraction",
                    data.configurations.len()
                )));
            }
            let what = format!(
                "{} of the {} configurations of {} held out at random (seed {}), each set of \
                 configurations measuring the same targets split on its own",
                test.len(),
                data.configurations.len(),
                data.source,
                opts.seed
            );
            Ok((data.subset(&train), Some(data.subset(&test)), what))
        }
        (None, false) => Ok((data.clone(), None, String::new())),
    }
}

/// The 3 × 3 covariance (mm²) of the position of tree target `target` at the tree joints
/// `q` from the covariance of the free parameters `free` at `params`: `G C_p Gᵀ` with `G`
/// the position rows of the target's identification Jacobian (paper eq. 19, per branch).
fn tree_tcp_covariance(
    tree: &Tree,
    params: &[f64],
    free: &[usize],
    covariance: &DMatrix<f64>,
    target: usize,
    q: &[f64],
) -> Matrix3<f64> {
    let mut data = TreeData::new(tree);
    branch_kinematics(tree, &mut data, tree.targets[target].1, params, q);
    let mut g = DMatrix::zeros(3, free.len());
    tree_identification_jacobian(tree, &mut data, target, Rows::Position, free, &mut g, 0);
    let c = &g * covariance * g.transpose();
    Matrix3::from_fn(|r, k| c[(r, k)])
}
