//! The adaptive measurement campaign (paper §6: "an online approach of parameter estimation
//! and optimum experimental design … which monitors the current precision … the parameter
//! identification can be stopped when a certain level of TCP precision is reached"): plan a
//! first batch, measure it, identify (warm start from the previous estimate), compute the
//! TCP covariance at every working pose from what was measured, and either stop at the
//! target precision or plan the next batch given everything measured.
//!
//! [`start`] plans the first batch, [`step`] takes a measured batch; the state
//! ([`CampaignState`]) holds everything, so a campaign can be resumed at any time.
//! [`simulate`] runs the whole loop against a virtual robot and instrument; [`study`]
//! compares it with one-shot and random designs over seeded runs.

mod batch;
pub mod drift;
pub(crate) mod precision;
pub mod prior;
pub mod simulate;
pub(crate) mod state;
pub(crate) mod study;

pub use simulate::simulate;
pub use state::{
    CampaignPose, CampaignSettings, CampaignState, CampaignStep, Decision, FitSummary, Planner,
};

use crate::cell::Cell;
use crate::design::plan::{constraint_set, plan, CellConstraints, PlanSettings};
use crate::design::DesignModel;
use crate::identify::{identify, Estimate, IdentifySettings, ModelFingerprint};
use crate::measure::Dataset;
use crate::model::Segment;
use crate::progress::Observer;
use crate::Error;
use batch::check_batch;
pub use batch::{StepSettings, JOINT_TOLERANCE};
use precision::{poses_needed, predicted_sigmas, working_sigmas, WorkingSigma};

/// The fewest poses that identify the cell's free set: ⌈n_p / rows per pose⌉.
pub fn fewest_poses(cell: &Cell) -> Result<usize, Error> {
    let d = DesignModel::from_cell(cell)?;
    Ok(d.n().div_ceil(d.rows()))
}

/// Starts a campaign on `cell` (`cell_source`: its file or built-in name, kept in the
/// state): checks the settings and plans the first batch, the fewest poses that identify
/// the free set ([`fewest_poses`]), chosen by the settings' planner under every cell
/// constraint.
///
/// ```
/// use armcal::{campaign_start, campaign_step, CampaignDecision as Decision, CampaignSettings};
/// use armcal::Silent;
/// use armcal::{perturbed_truth, Perturbation};
///
/// # fn main() -> armcal::Result<()> {
/// let cell = armcal::cell::builtin::paper_cell()?;
/// let settings = CampaignSettings { target_sigma_mm: 0.6, ..CampaignSettings::default() };
/// let state = campaign_start(&cell, "paper-cell", &settings, &mut Silent)?;
/// assert_eq!(state.decision, Decision::Measure);
/// // Measure the poses it asks for (here on a virtual robot), keeping their ids, and step.
/// let truth = perturbed_truth(&cell.model, &Perturbation::default(), 1);
/// let qs: Vec<Vec<f64>> = state.next.iter().map(|p| p.q(&cell.model)).collect();
/// let mut batch = armcal::simulate(&cell.model, &truth, &qs, Some(&cell.noise()), 2)?;
/// batch.config_ids = state.next.iter().map(|p| p.id.clone()).collect();
/// let step = campaign_step(&cell, &state, &batch, &mut Silent)?;
/// assert_eq!(step.state.measured(), qs.len());
/// // Every working pose's TCP σ from the fit, and what to do next.
/// let last = step.state.steps.last().unwrap();
/// assert_eq!(last.working.len(), cell.working.len());
/// assert!(step.state.decision == Decision::Measure || step.state.decision == Decision::TargetReached);
/// # Ok(())
/// # }
/// ```
pub fn start(
    cell: &Cell,
    cell_source: &str,
    settings: &CampaignSettings,
    observer: &mut dyn Observer,
) -> Result<CampaignState, Error> {
    check_settings(cell, settings)?;
    if settings.prior.is_some() {
        return Err(Error::Input(
            "a campaign with a prior starts from the check poses that found the drift \
             (`start_after_check`)"
                .into(),
        ));
    }
    let first = fewest_poses(cell)?;
    if let Some(b) = settings.budget {
        if b < first {
            return Err(Error::Input(format!(
                "a budget of {b} poses cannot identify the {} free parameters of `{}`: the first batch alone needs {first} poses",
                DesignModel::from_cell(cell)?.n(),
                cell.name
            )));
        }
    }
    let qs = plan_batch(cell, settings, &[], first, 0, observer)?;
    let first_predicted_sigma_mm = predicted_sigmas(cell, &qs, 1.0)?;
    Ok(initial_state(
        cell,
        cell_source,
        settings,
        numbered(cell, &qs, 0),
        first_predicted_sigma_mm,
    ))
}

/// Starts a campaign from an earlier calibration after a drift check (issue 16 item 2):
/// `settings.prior` holds the old estimate as a prior ([`prior::CampaignPrior`]) and the
/// check measurements `check` are the first step, so the fit, the TCP precision and the
/// decision come at once; the next batch is planned given the check poses and the prior.
pub fn start_after_check(
    cell: &Cell,
    cell_source: &str,
    settings: &CampaignSettings,
    check: &Dataset,
    observer: &mut dyn Observer,
) -> Result<StepResult, Error> {
    check_settings(cell, settings)?;
    let Some(prior) = &settings.prior else {
        return Err(Error::Input(
            "a campaign after a drift check needs the old estimate as its prior".into(),
        ));
    };
    let at = prior.apply(cell)?;
    let poses: Vec<CampaignPose> = check
        .config_ids
        .iter()
        .zip(&check.configurations)
        .map(|(id, q)| CampaignPose::of(&cell.model, id.clone(), q))
        .collect();
    let predicted = predicted_sigmas(&at, &check.configurations, 1.0)?;
    let state = initial_state(cell, cell_source, settings, poses, predicted);
    step(cell, &state, check, observer)
}

/// The state of a campaign about to measure its first batch `next` (predicted σ
/// `first_predicted_sigma_mm` once measured).
fn initial_state(
    cell: &Cell,
    cell_source: &str,
    settings: &CampaignSettings,
    next: Vec<CampaignPose>,
    first_predicted_sigma_mm: Vec<f64>,
) -> CampaignState {
    CampaignState {
        campaign: "adaptive".into(),
        cell: cell.name.clone(),
        cell_source: cell_source.into(),
        fingerprint: ModelFingerprint::of(&cell.model),
        settings: settings.clone(),
        sigma_definition: precision::SIGMA_DEFINITION.into(),
        confidence: precision::CONFIDENCE,
        chi2_quantile: precision::chi2_quantile(),
        variance_rule: precision::VARIANCE_RULE.into(),
        first_batch: next.len(),
        first_predicted_sigma_mm,
        working: cell.working.iter().map(|w| w.name.clone()).collect(),
        steps: Vec::new(),
        next,
        decision: Decision::Measure,
        simulation_seed: None,
    }
}

/// Checks a campaign's settings against its cell: a positive target, a batch of at least
/// one pose, and a working pose to reach it at.
fn check_settings(cell: &Cell, settings: &CampaignSettings) -> Result<(), Error> {
    if !(settings.target_sigma_mm > 0.0 && settings.target_sigma_mm.is_finite()) {
        return Err(Error::Input(format!(
            "the target TCP σ must be a positive number of mm, not {}",
            settings.target_sigma_mm
        )));
    }
    if settings.batch == 0 {
        return Err(Error::Input(
            "a batch of 0 poses measures nothing; give at least 1".into(),
        ));
    }
    if cell.working.is_empty() {
        return Err(Error::Input(format!(
            "cell `{}` has no working pose ([[working]]): a campaign stops at a TCP precision at the working poses, so give at least one",
            cell.name
        )));
    }
    Ok(())
}

/// `cell` with the instrument and target frames of its model at `params` (every parameter
/// of the model, internal units), or `cell` itself without them; an instrument the fit
/// estimated is placed there ([`crate::cell::Instrument::placed`]). The links stay nominal:
/// the cell's capsules are drawn on the nominal links, and the estimate of a minimal set
/// may move a frame whose effect another parameter absorbs (a link offset traded against
/// the next link's), which would put the capsules where no link is.
fn cell_at<'a>(cell: &'a Cell, params: Option<&[f64]>) -> std::borrow::Cow<'a, Cell> {
    let Some(params) = params else {
        return std::borrow::Cow::Borrowed(cell);
    };
    let mut at = cell.clone();
    let mut placed = false;
    for (i, &v) in params.iter().enumerate() {
        let p = at.model.registry.get(i);
        placed |= p.segment == Segment::Instrument && p.status.is_free();
        if matches!(p.segment, Segment::Instrument | Segment::Target(_)) {
            at.model.registry.set_nominal(i, v);
        }
    }
    if let Some(instrument) = at.instrument.as_mut() {
        instrument.placed |= placed;
    }
    std::borrow::Cow::Owned(at)
}

/// The poses `qs` named `offset + 1`, `offset + 2`, ….
fn numbered(cell: &Cell, qs: &[Vec<f64>], offset: usize) -> Vec<CampaignPose> {
    qs.iter()
        .enumerate()
        .map(|(i, q)| CampaignPose::of(&cell.model, (offset + i + 1).to_string(), q))
        .collect()
}

/// `n` poses chosen by the settings' planner given the configurations `measured`, with the
/// seed of step `k`.
fn plan_batch(
    cell: &Cell,
    settings: &CampaignSettings,
    measured: &[Vec<f64>],
    n: usize,
    k: usize,
    observer: &mut dyn Observer,
) -> Result<Vec<Vec<f64>>, Error> {
    let seed = settings.seed.wrapping_add(k as u64);
    match settings.planner {
        Planner::Kpi => {
            let r = plan(
                cell,
                &PlanSettings {
                    poses: n,
                    seed,
                    ..PlanSettings::default()
                },
                measured,
                observer,
            )?;
            if !r.feasible {
                return Err(Error::Input(format!(
                    "no feasible batch of {n} poses for `{}`: its constraints block {}",
                    cell.name,
                    r.blocking
                        .iter()
                        .map(|(c, f)| format!("{c} ({:.0} % of draws)", 100.0 * f))
                        .collect::<Vec<_>>()
                        .join(", ")
                )));
            }
            Ok(r.design)
        }
        Planner::Random => {
            let set = constraint_set(cell, true)?;
            let params = cell.model.nominal();
            let cons = CellConstraints::new(&set, &params);
            let (qs, _) = crate::design::baselines::random_feasible(
                &cell.model,
                n,
                seed,
                PlanSettings::default().max_draws,
                |q| cons.feasible(q),
            )?;
            Ok(qs)
        }
    }
}

/// What a step made: the new state and the estimate of its fit (if any).
#[derive(Clone, Debug)]
pub struct StepResult {
    /// The state after the step.
    pub state: CampaignState,
    /// The fit on everything measured; `None` when it failed (the state says why).
    pub estimate: Option<Estimate>,
}

/// Takes the measured batch `batch` (the poses of `state.next`): identifies the free
/// parameters on everything measured (warm start from the last converged fit), computes
/// the TCP precision at every working pose (`precision`), and decides: stop when every
/// working pose's σ is at or below the target and the fit converged (an unconverged fit
/// never stops the campaign), stop when the budget is spent, or plan the next batch given
/// everything measured. `state` itself is not changed: a step that fails leaves it as it
/// was. `cell` must be the campaign's cell (its fingerprint is checked). The measured joint
/// values may differ from the planned ones by [`JOINT_TOLERANCE`].
pub fn step(
    cell: &Cell,
    state: &CampaignState,
    batch: &Dataset,
    observer: &mut dyn Observer,
) -> Result<StepResult, Error> {
    step_with(cell, state, batch, &StepSettings::default(), observer)
}

/// [`step`] with the joint tolerance and the unmeasurable poses of `settings`.
pub fn step_with(
    cell: &Cell,
    state: &CampaignState,
    batch: &Dataset,
    settings: &StepSettings,
    observer: &mut dyn Observer,
) -> Result<StepResult, Error> {
    let joint_tolerance = settings.joint_tolerance;
    if !(joint_tolerance.is_finite() && joint_tolerance >= 0.0) {
        return Err(Error::Input(format!(
            "joint tolerance {joint_tolerance}: give a number ≥ 0 (deg, mm for a prismatic joint)"
        )));
    }
    let differences = state.fingerprint.differences(&cell.model);
    if !differences.is_empty() {
        return Err(Error::Input(format!(
            "the cell `{}` differs from the one this campaign started with: {}; restore it, or start a new campaign",
            cell.name,
            differences.join("; ")
        )));
    }
    if state.decision != Decision::Measure {
        return Err(Error::Input(format!(
            "the campaign has stopped ({} after {} poses); start a new campaign to measure more",
            state.decision.words(),
            state.measured()
        )));
    }
    check_batch(cell, state, batch, settings)?;
    // a campaign from an earlier calibration fits the old free set with the old estimate
    // as prior (`prior`)
    let with_prior;
    let fit_cell = match &state.settings.prior {
        Some(p) => {
            with_prior = p.apply(cell)?;
            &with_prior
        }
        None => cell,
    };
    let mut data = state.data();
    data.append(batch);
    data.source = format!(
        "campaign, {} poses in {} steps",
        data.configurations.len(),
        state.steps.len() + 1
    );
    let warm = state
        .warm_start()
        .or(state.settings.prior.as_ref().map(|p| p.params.as_slice()))
        .map(<[f64]>::to_vec);
    let fit_settings = IdentifySettings {
        start: warm.clone(),
        ..IdentifySettings::default()
    };
    let (estimate, fit, fit_error, working) =
        match identify(fit_cell, &data, &fit_settings, observer) {
            Ok(mut e) => {
                // the estimate is of the campaign's cell, whatever prior the fit had
                e.fingerprint = Some(ModelFingerprint::of(&cell.model));
                let s = precision::scale(&e);
                let params = e.params_for(&cell.model)?;
                let fit = FitSummary {
                    status: e.solver.status.clone(),
                    iterations: e.solver.iterations,
                    warm_start: warm.is_some(),
                    free: e.free.len(),
                    variance_factor: Some(e.uncertainty.variance_factor).filter(|v| v.is_finite()),
                    dof: e.uncertainty.dof,
                    p_value: Some(e.uncertainty.p_value).filter(|v| v.is_finite()),
                    covariance_scale: s,
                    params,
                };
                let working = working_sigmas(&e, s);
                (Some(e), Some(fit), None, working)
            }
            Err(e) => (None, None, Some(e.to_string()), Vec::new()),
        };
    let mut next_state = state.clone();
    let measured = data.configurations.len();
    let target = state.settings.target_sigma_mm;
    let worst = largest_sigma(&working);
    let converged = fit.as_ref().is_some_and(|f| f.status.is_converged());
    let sigmas = || {
        working
            .iter()
            .map(|w| format!("`{}` {:.4} mm", w.name, w.sigma_mm))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let (decision, reason) = if converged && worst <= target {
        (
            Decision::TargetReached,
            format!("every working pose at or below {target} mm: {}", sigmas()),
        )
    } else if state.settings.budget.is_some_and(|b| measured >= b) {
        (
            Decision::BudgetExhausted,
            format!(
                "{measured} poses measured, the budget; target {target} mm not reached: {}",
                if working.is_empty() {
                    "no fit".to_string()
                } else {
                    sigmas()
                }
            ),
        )
    } else if let Some(e) = &fit_error {
        (Decision::Measure, format!("no fit ({e}); measuring more"))
    } else if !converged {
        (
            Decision::Measure,
            format!(
                "the fit did not converge ({}), so it cannot stop the campaign; measuring more",
                fit.as_ref()
                    .map(|f| f.status.to_string())
                    .unwrap_or_default()
            ),
        )
    } else {
        (
            Decision::Measure,
            format!("largest σ {worst:.4} mm > target {target} mm"),
        )
    };
    let k = state.steps.len() + 1;
    let (next, predicted, total) = if decision == Decision::Measure {
        let n = state.settings.budget.map_or(state.settings.batch, |b| {
            state.settings.batch.min(b - measured)
        });
        // Planned with the instrument and targets where the latest converged fit with
        // redundancy (this step's, else an earlier one's) puts them: the tracker's incidence,
        // line of sight and the TCP variance in its frame are evaluated there. Before such a
        // fit, where the cell puts them, with its `[design]` incidence and line-of-sight
        // margins to cover the placement error: a fit without redundancy (the first batch of
        // the fewest poses) interpolates its data exactly and can trade the tracker against
        // the links far from where it stands, and the links stay nominal here (the capsules
        // are drawn on them) — `campaign simulate --seed 3` on the paper cell with the
        // default margins: 446 mm and 6.5° about z, and a pose planned at 28° there met the
        // reflector at 32.4°. The predicted σ's use the latest converged fit (the nominal
        // before any).
        let converged = |f: &&FitSummary| f.status.is_converged();
        let latest = fit
            .as_ref()
            .filter(converged)
            .map(|f| f.params.as_slice())
            .or(state.warm_start());
        let placed = fit
            .iter()
            .chain(state.steps.iter().rev().filter_map(|s| s.fit.as_ref()))
            .find(|f| converged(f) && f.dof > 0)
            .map(|f| f.params.as_slice());
        let at = cell_at(fit_cell, latest);
        let qs = plan_batch(
            &cell_at(fit_cell, placed),
            &state.settings,
            &data.configurations,
            n,
            k,
            observer,
        )?;
        let mut all = data.configurations.clone();
        all.extend(qs.iter().cloned());
        let s = fit.as_ref().map_or(1.0, |f| f.covariance_scale);
        let predicted = predicted_sigmas(&at, &all, s)?;
        let largest = predicted.iter().copied().fold(0.0, f64::max);
        let total = poses_needed(all.len(), largest, target);
        // ids continue after every pose issued, the unmeasurable ones included
        let issued = measured
            + settings.unmeasurable.len()
            + state
                .steps
                .iter()
                .map(|s| s.unmeasurable.len())
                .sum::<usize>();
        (numbered(cell, &qs, issued), predicted, Some(total))
    } else {
        (Vec::new(), Vec::new(), None)
    };
    next_state.steps.push(CampaignStep {
        source: batch.source.clone(),
        poses: batch
            .config_ids
            .iter()
            .zip(&batch.configurations)
            .map(|(id, q)| CampaignPose::of(&cell.model, id.clone(), q))
            .collect(),
        data: batch.clone(),
        unmeasurable: state
            .next
            .iter()
            .filter(|p| settings.unmeasurable.contains(&p.id))
            .cloned()
            .collect(),
        measured,
        fit,
        fit_error,
        working,
        decision,
        reason,
        predicted_next_sigma_mm: predicted,
        predicted_total_poses: total,
    });
    next_state.next = next;
    next_state.decision = decision;
    Ok(StepResult {
        state: next_state,
        estimate,
    })
}

/// The largest σ over the working poses of a step (NaN without a fit).
pub fn largest_sigma(working: &[WorkingSigma]) -> f64 {
    if working.is_empty() {
        return f64::NAN;
    }
    working.iter().map(|w| w.sigma_mm).fold(0.0, f64::max)
}
