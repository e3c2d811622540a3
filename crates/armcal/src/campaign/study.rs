//! The campaign's simulation study (issue 16): for each target TCP σ and each of a number
//! of seeded virtual robots, the poses the adaptive campaign measured before it stopped,
//! against a one-shot KPI design sized beforehand to the same target (the fewest poses whose
//! predicted σ meets it) and against random measurable poses added batch by batch until
//! the fit meets the target; and the coverage of the stopping claim — the share of runs
//! whose true TCP error at the working pose lies in the stated 95 % ellipsoid.

use super::precision::{scale, tcp_position, working_sigmas, WorkingSigma};
use super::{largest_sigma, simulate, CampaignSettings, Decision, Planner};
use crate::cell::Cell;
use crate::design::plan::{plan, PlanSettings};
use crate::identify::{identify, IdentifySettings};
use crate::progress::{Observer, Silent};
use crate::sim::{perturbed_truth, Perturbation};
use crate::Error;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Settings of [`run`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StudySettings {
    /// Target TCP σ's (mm).
    pub targets: Vec<f64>,
    /// Seeded runs per target (virtual robots `first_seed`, `first_seed + 1`, …).
    pub runs: usize,
    /// Seed of the first virtual robot.
    pub first_seed: u64,
    /// Poses per batch of the adaptive and the random campaign.
    pub batch: usize,
    /// The most poses a run may measure.
    pub budget: usize,
    /// Perturb the virtual robots' fixed parameters by the cell's stated prior too
    /// ([`Perturbation::fixed`]): the coverage then tests the model floor.
    #[serde(default)]
    pub perturb_fixed: bool,
}

impl StudySettings {
    /// The virtual robots' perturbation.
    fn perturbation(&self, cell: &Cell) -> Perturbation {
        Perturbation {
            fixed: self.perturb_fixed.then(|| cell.fixed_prior.clone()),
            ..Perturbation::default()
        }
    }
}

impl Default for StudySettings {
    fn default() -> Self {
        StudySettings {
            targets: vec![0.7, 0.6, 0.5],
            runs: 20,
            first_seed: 1,
            batch: 5,
            budget: 400,
            perturb_fixed: false,
        }
    }
}

/// One run of one method on one virtual robot.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunOutcome {
    /// The virtual robot's seed.
    pub seed: u64,
    /// Poses measured.
    pub poses: usize,
    /// Whether the fit's largest σ met the target (for a campaign: it stopped there).
    pub reached: bool,
    /// The largest σ over the working poses at the end (mm).
    pub sigma_mm: f64,
    /// Whether the true TCP error lay in the stated 95 % ellipsoid at every working pose.
    pub inside_95: Option<bool>,
    /// The same for the ellipsoid of C_s + C_floor (the model floor).
    #[serde(default)]
    pub inside_95_with_floor: Option<bool>,
}

impl RunOutcome {
    fn of(seed: u64, poses: usize, target: f64, working: &[WorkingSigma]) -> RunOutcome {
        let sigma_mm = largest_sigma(working);
        RunOutcome {
            seed,
            poses,
            reached: sigma_mm <= target,
            sigma_mm,
            inside_95: all_inside(working, |w| w.true_error_inside_95),
            inside_95_with_floor: all_inside(working, |w| w.true_error_inside_95_with_floor),
        }
    }
}

/// Whether `inside` holds at every working pose (`None` if one does not know).
fn all_inside(
    working: &[WorkingSigma],
    inside: impl Fn(&WorkingSigma) -> Option<bool>,
) -> Option<bool> {
    working
        .iter()
        .map(inside)
        .collect::<Option<Vec<bool>>>()
        .map(|v| v.iter().all(|&b| b))
}

/// The methods at one target.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TargetRow {
    /// The target TCP σ (mm).
    pub target_sigma_mm: f64,
    /// The adaptive campaign (KPI batches), one run per seed.
    pub adaptive: Vec<RunOutcome>,
    /// Poses of the one-shot KPI design sized to the target: the fewest whose predicted σ
    /// (stated instrument σ, nominal model) is at or below it.
    pub one_shot_poses: usize,
    /// That design's predicted σ (mm).
    pub one_shot_predicted_sigma_mm: f64,
    /// The one-shot design measured on each virtual robot and identified.
    pub one_shot: Vec<RunOutcome>,
    /// Random measurable poses in batches until the fit meets the target, one run per seed.
    pub random: Vec<RunOutcome>,
}

/// Mean, smallest and largest poses of a method's runs.
pub fn poses_summary(runs: &[RunOutcome]) -> (f64, usize, usize) {
    let n = runs.len().max(1) as f64;
    let mean = runs.iter().map(|r| r.poses as f64).sum::<f64>() / n;
    let min = runs.iter().map(|r| r.poses).min().unwrap_or(0);
    let max = runs.iter().map(|r| r.poses).max().unwrap_or(0);
    (mean, min, max)
}

/// Share of runs whose true error lay in the 95 % ellipsoid (over runs that know it), and
/// how many runs that is.
pub fn coverage(runs: &[RunOutcome]) -> (f64, usize) {
    coverage_of(runs, |r| r.inside_95)
}

/// As [`coverage`], for the ellipsoid of C_s + C_floor.
pub fn coverage_with_floor(runs: &[RunOutcome]) -> (f64, usize) {
    coverage_of(runs, |r| r.inside_95_with_floor)
}

fn coverage_of(runs: &[RunOutcome], inside: impl Fn(&RunOutcome) -> Option<bool>) -> (f64, usize) {
    let known: Vec<bool> = runs.iter().filter_map(inside).collect();
    let inside = known.iter().filter(|&&b| b).count();
    (inside as f64 / known.len().max(1) as f64, known.len())
}

/// The study's record (`armcal campaign study --out`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CampaignStudyRecord {
    /// Marks the file: `"adaptive vs one-shot vs random"`.
    pub campaign_study: String,
    /// The cell's name.
    pub cell: String,
    /// The study's settings.
    pub settings: StudySettings,
    /// One row per target.
    pub rows: Vec<TargetRow>,
    /// Wall-clock time of the study (s).
    pub time_s: f64,
}

impl CampaignStudyRecord {
    /// The record as JSON (keys in alphabetical order, see `crate::json`).
    pub fn to_json(&self) -> Result<String, Error> {
        crate::json::sorted_pretty(self)
    }
}

/// The fewest poses of a one-shot KPI design whose predicted largest σ meets `target`, with
/// that σ: from a 30-pose design, N = ⌈30 σ₃₀² / target²⌉ (C_s ∝ 1/N), then up or down one
/// pose at a time until N is the fewest that meets it.
fn one_shot_size(cell: &Cell, target: f64) -> Result<(usize, f64, Vec<Vec<f64>>), Error> {
    let designed = |n: usize| -> Result<(f64, Vec<Vec<f64>>), Error> {
        let r = plan(
            cell,
            &PlanSettings {
                poses: n,
                ..PlanSettings::default()
            },
            &[],
            &mut Silent,
        )?;
        let sigma = super::precision::predicted_sigmas(cell, &r.design, 1.0)?
            .into_iter()
            .fold(0.0, f64::max);
        Ok((sigma, r.design))
    };
    let (s30, _) = designed(30)?;
    let mut n = super::precision::poses_needed(30, s30, target).max(super::fewest_poses(cell)?);
    let (mut sigma, mut design) = designed(n)?;
    while sigma > target {
        n += 1;
        (sigma, design) = designed(n)?;
    }
    while n > super::fewest_poses(cell)? {
        let (s, d) = designed(n - 1)?;
        if s > target {
            break;
        }
        (n, sigma, design) = (n - 1, s, d);
    }
    Ok((n, sigma, design))
}

/// The one-shot design measured on the virtual robot of `seed` and identified.
fn one_shot_run(
    cell: &Cell,
    settings: &StudySettings,
    design: &[Vec<f64>],
    seed: u64,
    target: f64,
) -> Result<RunOutcome, Error> {
    let model = &cell.model;
    let truth = perturbed_truth(model, &settings.perturbation(cell), seed);
    let data = crate::sim::simulate_measuring(
        model,
        &truth,
        design,
        &[],
        cell.measurement,
        Some(&cell.noise()),
        seed.wrapping_mul(1000).wrapping_add(999),
    )?;
    let e = identify(cell, &data, &IdentifySettings::default(), &mut Silent)?;
    let params = e.params_for(model)?;
    let working: Vec<WorkingSigma> = working_sigmas(&e, scale(&e))
        .into_iter()
        .zip(&cell.working)
        .map(|(w, wp)| {
            let err = tcp_position(model, &params, &wp.q) - tcp_position(model, &truth, &wp.q);
            w.with_true_error(err)
        })
        .collect();
    let mut r = RunOutcome::of(seed, design.len(), target, &working);
    r.reached &= e.solver.status.is_converged();
    Ok(r)
}

/// A campaign of `planner` on the virtual robot of `seed`.
fn campaign_run(
    cell: &Cell,
    settings: &StudySettings,
    planner: Planner,
    target: f64,
    seed: u64,
) -> Result<RunOutcome, Error> {
    let s = simulate(
        cell,
        &cell.name,
        &CampaignSettings {
            target_sigma_mm: target,
            batch: settings.batch,
            budget: Some(settings.budget),
            seed,
            planner,
            prior: None,
        },
        &settings.perturbation(cell),
        seed,
        &mut Silent,
    )?;
    let last = s.state.steps.last().expect("a simulated campaign measures");
    let mut r = RunOutcome::of(seed, last.measured, target, &last.working);
    r.reached = s.state.decision == Decision::TargetReached;
    Ok(r)
}

/// Runs the study on `cell`; `observer` gets one step per run.
pub fn run(
    cell: &Cell,
    settings: &StudySettings,
    observer: &mut dyn Observer,
) -> Result<CampaignStudyRecord, Error> {
    let t0 = Instant::now();
    let seeds: Vec<u64> = (0..settings.runs as u64)
        .map(|k| settings.first_seed + k)
        .collect();
    observer.start(
        "campaign study runs",
        Some(settings.targets.len() * (1 + 3 * seeds.len())),
    );
    let mut rows = Vec::new();
    for &target in &settings.targets {
        let (one_shot_poses, one_shot_predicted_sigma_mm, design) = one_shot_size(cell, target)?;
        observer.step();
        let mut row = TargetRow {
            target_sigma_mm: target,
            adaptive: Vec::new(),
            one_shot_poses,
            one_shot_predicted_sigma_mm,
            one_shot: Vec::new(),
            random: Vec::new(),
        };
        for &seed in &seeds {
            row.adaptive
                .push(campaign_run(cell, settings, Planner::Kpi, target, seed)?);
            observer.step();
            row.one_shot
                .push(one_shot_run(cell, settings, &design, seed, target)?);
            observer.step();
            row.random
                .push(campaign_run(cell, settings, Planner::Random, target, seed)?);
            observer.step();
        }
        rows.push(row);
    }
    observer.finish();
    Ok(CampaignStudyRecord {
        campaign_study: "adaptive vs one-shot vs random".into(),
        cell: cell.name.clone(),
        settings: settings.clone(),
        rows,
        time_s: t0.elapsed().as_secs_f64(),
    })
}
