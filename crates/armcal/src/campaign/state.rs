//! The campaign's state file (`campaign.json`): everything the campaign measured and
//! decided, step by step, so that a campaign can be resumed at any time and `report` can
//! draw its σ-vs-poses curve.

use crate::campaign::precision::WorkingSigma;
use crate::campaign::prior::CampaignPrior;
use crate::identify::ModelFingerprint;
use crate::measure::Dataset;
use crate::model::Model;
use crate::solve::Status;
use crate::Error;
use serde::{Deserialize, Serialize};

/// How the next batch of poses is chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Planner {
    /// The KPI criterion (paper eq. 24) under every cell constraint, given every pose
    /// measured so far (design augmentation, [`crate::design::plan::plan`]).
    Kpi,
    /// Uniform random measurable poses (the paper's heuristic), for comparison.
    Random,
}

/// What a campaign aims at and how it proceeds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CampaignSettings {
    /// The TCP σ (mm, [`WorkingSigma::sigma_mm`]) every working pose must reach.
    pub target_sigma_mm: f64,
    /// Poses per batch after the first.
    pub batch: usize,
    /// The most poses the campaign may measure in all; `None`: no limit.
    pub budget: Option<usize>,
    /// Seed of the planner's candidate pools (step `k` plans with `seed + k`).
    pub seed: u64,
    /// How batches are chosen.
    pub planner: Planner,
    /// The earlier calibration the campaign starts from, as a prior (a campaign after a
    /// drift check, `crate::campaign::prior`); `None`: from the cell's nominal model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prior: Option<CampaignPrior>,
}

impl Default for CampaignSettings {
    fn default() -> Self {
        CampaignSettings {
            target_sigma_mm: 0.5,
            batch: 5,
            budget: None,
            seed: 1,
            planner: Planner::Kpi,
            prior: None,
        }
    }
}

/// What the campaign decided after a step (or at its start).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Decision {
    /// Measure the poses of `next` and step again.
    Measure,
    /// Every working pose's TCP σ is at or below the target, from a converged fit: stop.
    TargetReached,
    /// The budget is spent and the target was not reached: stop.
    BudgetExhausted,
}

impl Decision {
    /// The decision in words.
    pub fn words(self) -> &'static str {
        match self {
            Decision::Measure => "measure the next batch",
            Decision::TargetReached => "stop: target reached",
            Decision::BudgetExhausted => "stop: budget exhausted, target not reached",
        }
    }
}

/// A pose to measure or measured: its id and joint values (display units: deg, mm).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CampaignPose {
    /// The `pose_id` of `next.csv` and of the data file.
    pub id: String,
    /// Joint values, deg (mm for a prismatic joint).
    pub joints: Vec<f64>,
}

impl CampaignPose {
    /// The pose `q` (internal units) of `model` named `id`.
    pub fn of(model: &Model, id: String, q: &[f64]) -> CampaignPose {
        CampaignPose {
            id,
            joints: q
                .iter()
                .zip(&model.joints)
                .map(|(v, j)| crate::measure::csv::joint_display(j, *v))
                .collect(),
        }
    }

    /// Its joint values in internal units (rad, mm).
    pub fn q(&self, model: &Model) -> Vec<f64> {
        self.joints
            .iter()
            .zip(&model.joints)
            .map(|(v, j)| v / j.kind.unit().display_factor())
            .collect()
    }
}

/// The fit of one step, in short.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FitSummary {
    /// The solver's status; only a converged fit can stop the campaign.
    pub status: Status,
    /// Solver iterations.
    pub iterations: usize,
    /// Whether it started from the previous step's estimate (warm start) or from the
    /// frames-first start.
    pub warm_start: bool,
    /// Free parameters estimated.
    pub free: usize,
    /// A-posteriori variance factor σ̂₀² = rᵀr / dof (`None` without redundancy).
    pub variance_factor: Option<f64>,
    /// Degrees of freedom (rows − free parameters).
    pub dof: usize,
    /// The χ² test's p-value P(χ² ≥ rᵀr) (`None` without redundancy).
    pub p_value: Option<f64>,
    /// The factor C_s was scaled by (`crate::campaign::precision::scale`).
    pub covariance_scale: f64,
    /// Every parameter of the model at the fit (internal units), the next step's warm start.
    pub params: Vec<f64>,
}

/// One step: the batch measured, the fit, the precision reached and what was decided.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CampaignStep {
    /// The data file the batch was read from.
    pub source: String,
    /// The batch's poses as measured (ids and joints from the data file).
    pub poses: Vec<CampaignPose>,
    /// The batch's measurements, as read (internal units); every step's data together are
    /// what the campaign has measured.
    pub data: Dataset,
    /// The poses of the batch the instrument could not measure (planned ids and joints;
    /// [`super::StepSettings::unmeasurable`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub unmeasurable: Vec<CampaignPose>,
    /// Poses measured in all, this batch included.
    pub measured: usize,
    /// The fit on everything measured; `None` when it failed (`fit_error`).
    pub fit: Option<FitSummary>,
    /// Why there is no fit.
    pub fit_error: Option<String>,
    /// The TCP precision at every working pose from this fit (empty without a fit).
    pub working: Vec<WorkingSigma>,
    /// What was decided.
    pub decision: Decision,
    /// The decision's reason in words (the σ's against the target, or the budget).
    pub reason: String,
    /// Predicted σ at every working pose once `next` is measured too (mm, scaled as the fit's
    /// C_s; `crate::campaign::precision::predicted_sigmas`); empty when stopped. `next`
    /// was planned, and this predicted, with the instrument and target frames at the latest
    /// converged fit (this step's `fit.params`, else an earlier step's; the nominal before
    /// any) and the links nominal.
    pub predicted_next_sigma_mm: Vec<f64>,
    /// Predicted poses in all the target needs (C_s ∝ 1/N beyond the next batch), when
    /// continuing.
    pub predicted_total_poses: Option<usize>,
}

/// The state of an adaptive measurement campaign (paper §6): `armcal campaign start`
/// writes it, every `armcal campaign step` rewrites it whole.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CampaignState {
    /// Marks the file as a campaign state: `"adaptive"`.
    pub campaign: String,
    /// The cell's name.
    pub cell: String,
    /// Where the cell came from: its file (absolute path) or a built-in name; `step` reads it
    /// again.
    pub cell_source: String,
    /// The cell's model at the start; a step with a cell that differs is refused.
    pub fingerprint: ModelFingerprint,
    /// Target, batch, budget and planner.
    pub settings: CampaignSettings,
    /// What "TCP σ" means here.
    pub sigma_definition: String,
    /// Confidence of the stated ellipsoids (0.95).
    pub confidence: f64,
    /// χ²₃ quantile at `confidence` (7.815): the ellipsoid is eᵀ C⁻¹ e ≤ this.
    pub chi2_quantile: f64,
    /// How the variance factor σ̂₀² enters the TCP covariance.
    pub variance_rule: String,
    /// Poses of the first batch: the fewest that identify the free set.
    pub first_batch: usize,
    /// Predicted σ at every working pose after the first batch (mm, stated instrument σ).
    pub first_predicted_sigma_mm: Vec<f64>,
    /// Names of the working poses, the order of every σ list.
    pub working: Vec<String>,
    /// Every step so far.
    pub steps: Vec<CampaignStep>,
    /// The poses to measure next (`next.csv`); empty once stopped.
    pub next: Vec<CampaignPose>,
    /// The current decision (the last step's, or `measure` at the start).
    pub decision: Decision,
    /// For a simulated campaign (`campaign simulate`): the virtual robot's seed.
    pub simulation_seed: Option<u64>,
}

impl CampaignState {
    /// Poses measured so far.
    pub fn measured(&self) -> usize {
        self.steps.last().map_or(0, |s| s.measured)
    }

    /// Everything measured so far, one dataset.
    pub fn data(&self) -> Dataset {
        let mut all = Dataset {
            source: format!("campaign ({} steps)", self.steps.len()),
            ..Default::default()
        };
        for s in &self.steps {
            all.append(&s.data);
        }
        all
    }

    /// The last converged fit's parameters: the warm start of the next step.
    pub fn warm_start(&self) -> Option<&[f64]> {
        self.steps
            .iter()
            .rev()
            .filter_map(|s| s.fit.as_ref())
            .find(|f| f.status.is_converged())
            .map(|f| f.params.as_slice())
    }

    /// The state as JSON (keys in alphabetical order, see `crate::json`).
    pub fn to_json(&self) -> Result<String, Error> {
        crate::json::sorted_pretty(self)
    }

    /// Reads a `campaign.json`; `file` names it in errors.
    pub fn from_json(text: &str, file: &str) -> Result<CampaignState, Error> {
        serde_json::from_str(text).map_err(|e| Error::File {
            file: file.into(),
            message: format!("not an armcal campaign state: {e}"),
        })
    }
}
