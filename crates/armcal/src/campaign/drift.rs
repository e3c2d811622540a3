//! The drift check (issue 16 item 2): a handful of check poses measured after the
//! calibration are tested against the calibrated model's prediction, and a score test per
//! parameter group says which parameters most likely moved.
//!
//! With the whitened residual `r` of the check rows (the identification's residual blocks
//! divided by the instrument σ of each row, so the instrument covariance is `R = I`), the
//! whitened Jacobian `J` w.r.t. the estimate's free parameters and the estimate's parameter
//! covariance `C_p`, the check residual is, without drift, `r ~ N(0, S)` with
//!
//! ```text
//! S = J C_p Jᵀ + I          (prediction covariance plus instrument noise)
//! χ² = rᵀ S⁻¹ r  ~  χ²(m)   (m: residual components of the check rows)
//! ```
//!
//! and the check says "drifted" when `P(χ²(m) ≥ χ²) < α`. For a parameter group `G` (the
//! columns `J_G` of one joint, the instrument or the tool frame) the score
//! (Lagrange-multiplier) test of "the group moved by δ" at δ = 0 is
//!
//! ```text
//! g = J_Gᵀ S⁻¹ r,   I_G = J_Gᵀ S⁻¹ J_G,   T_G = gᵀ I_G⁺ g  ~  χ²(rank I_G)
//! ```
//!
//! (`I_G⁺` the pseudo-inverse: on a few check poses a group may be only partly observable).
//! The group with the smallest p-value explains the residual best.

use crate::cell::Cell;
use crate::identify::{Estimate, Problem};
use crate::measure::Dataset;
use crate::model::ParameterStatus;
use crate::Error;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// How the estimate's parameter covariance enters `S`, in words (the record says it).
pub const COVARIANCE_RULE: &str = "C_p as stated by the instrument σ (not scaled by the calibration's variance factor σ̂₀²): R is the stated instrument covariance too, so S stays one model of the noise; a calibration whose σ̂₀² was far from 1 is flagged by its own χ² verdict";

/// Settings of [`check`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CheckSettings {
    /// Significance level of the χ² test, in (0, 1): "drifted" when p < α.
    pub alpha: f64,
}

impl Default for CheckSettings {
    fn default() -> Self {
        CheckSettings { alpha: 0.05 }
    }
}

/// The check's outcome.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DriftVerdict {
    /// p ≥ α: the check poses agree with the calibrated model.
    Consistent,
    /// p < α: the robot or the cell has changed since the calibration.
    Drifted,
}

impl DriftVerdict {
    /// The verdict in words: `consistent` or `drifted`.
    pub fn words(self) -> &'static str {
        match self {
            DriftVerdict::Consistent => "consistent",
            DriftVerdict::Drifted => "drifted",
        }
    }
}

/// The score test of one parameter group.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GroupScore {
    /// The group: the parameters' common name prefix (`j2`, `base`, `tool`, a target).
    pub group: String,
    /// Its free parameters.
    pub parameters: Vec<String>,
    /// Degrees of freedom: the rank of `J_Gᵀ S⁻¹ J_G` on the check poses.
    pub rank: usize,
    /// `T_G = gᵀ (J_Gᵀ S⁻¹ J_G)⁺ g`.
    pub statistic: f64,
    /// `P(χ²(rank) ≥ T_G)`; 1 for a group the check poses do not see (rank 0).
    pub p_value: f64,
}

/// The drift check record (`check.json`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DriftCheck {
    /// The cell's name.
    pub cell: String,
    /// The estimate's data (what was calibrated on).
    pub calibrated_on: String,
    /// The check data file.
    pub data: String,
    /// Check poses.
    pub poses: usize,
    /// Residual components m: the χ² test's degrees of freedom.
    pub dof: usize,
    /// `χ² = rᵀ S⁻¹ r`.
    pub chi2: f64,
    /// `P(χ²(m) ≥ χ²)`.
    pub p_value: f64,
    /// The significance level.
    pub alpha: f64,
    /// `drifted` when p < α.
    pub verdict: DriftVerdict,
    /// RMS of the position residuals (mm), for scale.
    pub rms_position_mm: f64,
    /// The same χ² with the prediction covariance left out (`S = I`): how much of the
    /// tolerance is the calibration's own uncertainty.
    pub chi2_without_prediction: f64,
    /// How `C_p` enters `S` (`COVARIANCE_RULE`).
    pub covariance_rule: String,
    /// The calibration's variance factor σ̂₀² (`None` without redundancy).
    pub calibration_variance_factor: Option<f64>,
    /// Every group's score test, smallest p-value first.
    pub groups: Vec<GroupScore>,
}

impl DriftCheck {
    /// The groups that most likely moved: the groups whose score test rejects "did not
    /// move" by Holm's step-down procedure at the check's α (Holm 1979, "A simple sequentially
    /// rejective multiple test procedure": the k-th smallest of the G tested groups' p-values,
    /// k = 0, 1, …, rejects at α/(G − k) while every smaller one has), and at least the first
    /// when the check says "drifted" (the groups a campaign after the check releases from the
    /// old estimate's prior, `crate::campaign::prior`). Empty for a consistent check without
    /// such a group. Testing each of a robot's 8 or so groups at α on its own would name a
    /// group on an unmoved robot far more often than α; Holm's procedure keeps the chance of
    /// naming any group of an unmoved robot at most α.
    pub fn moved_groups(&self) -> Vec<String> {
        let tested = self.groups.iter().filter(|g| g.rank > 0).count();
        let mut moved: Vec<String> = self
            .groups
            .iter()
            .enumerate()
            .take_while(|(k, g)| g.rank > 0 && g.p_value < self.alpha / (tested - k) as f64)
            .map(|(_, g)| g.group.clone())
            .collect();
        if moved.is_empty() && self.verdict == DriftVerdict::Drifted {
            moved.extend(self.groups.first().map(|g| g.group.clone()));
        }
        moved
    }

    /// The record as JSON (keys in alphabetical order, see `crate::json`).
    pub fn to_json(&self) -> Result<String, Error> {
        crate::json::sorted_pretty(self)
    }
}

/// The group of a parameter: its name before the first `.` (`j2.theta` → `j2`).
pub fn group_of(name: &str) -> &str {
    name.split('.').next().unwrap_or(name)
}

/// Tests the check measurements `data` against `estimate` of `cell` (module docs): the χ²
/// of the whitened residual under `S = J C_p Jᵀ + I` and a score test per parameter group.
///
/// ```
/// use armcal::model::random_configurations;
/// use armcal::{check, identify, perturbed_truth, simulate, CheckSettings, DriftVerdict};
/// use armcal::{IdentifySettings, Perturbation, Silent};
///
/// # fn main() -> armcal::Result<()> {
/// let cell = armcal::cell::builtin::paper_cell()?;
/// let model = &cell.model;
/// let truth = perturbed_truth(model, &Perturbation::default(), 5);
/// let poses = random_configurations(model, 30, 2);
/// let data = simulate(model, &truth, &poses, Some(&cell.noise()), 3)?;
/// let estimate = identify(&cell, &data, &IdentifySettings::default(), &mut Silent)?;
/// // Ten check poses after the tracker moved 5 mm along x: drifted, the tracker first.
/// let mut moved = truth.clone();
/// moved[model.registry.index_of("tracker.x").expect("the tracker's x")] += 5.0;
/// let again = random_configurations(model, 10, 9);
/// let after = simulate(model, &moved, &again, Some(&cell.noise()), 4)?;
/// let c = check(&cell, &estimate, &after, &CheckSettings::default())?;
/// assert_eq!(c.verdict, DriftVerdict::Drifted);
/// assert_eq!(c.groups[0].group, "tracker");
/// # Ok(())
/// # }
/// ```
pub fn check(
    cell: &Cell,
    estimate: &Estimate,
    data: &Dataset,
    settings: &CheckSettings,
) -> Result<DriftCheck, Error> {
    if !(settings.alpha > 0.0 && settings.alpha < 1.0) {
        return Err(Error::Input(format!(
            "the significance level must lie strictly between 0 and 1, not {}",
            settings.alpha
        )));
    }
    if data.measurements.is_empty() {
        return Err(Error::Input(format!(
            "{}: no measurements to check",
            data.source
        )));
    }
    estimate.check_consistent()?;
    let params = estimate.params_for(&cell.model)?;
    // The estimate's free set, all plainly free: a prior's rows belong to the calibration,
    // not to the check.
    let mut model = cell.model.clone();
    for i in 0..model.registry.len() {
        let name = model.registry.get(i).name.clone();
        let status = if estimate.free.contains(&name) {
            ParameterStatus::Free
        } else {
            ParameterStatus::Fixed
        };
        model.registry.set_status(i, status);
    }
    let problem = Problem::new(&model, data, &cell.noise())?;
    let names = problem.free_names();
    let column_of: Vec<usize> = names
        .iter()
        .map(|n| {
            estimate.free.iter().position(|f| f == n).ok_or_else(|| {
                Error::Model(format!(
                    "free parameter `{n}` has no covariance in the estimate"
                ))
            })
        })
        .collect::<Result<_, _>>()?;
    let cov = &estimate.uncertainty.covariance;
    let n = names.len();
    let cp = DMatrix::from_fn(n, n, |a, b| cov[(column_of[a], column_of[b])]);
    let (r_all, j_all) = problem.residual_and_jacobian(&params);
    let m = problem.data_rows();
    let r = r_all.rows(0, m).into_owned();
    let j = j_all.rows(0, m).into_owned();
    let s = &j * &cp * j.transpose() + DMatrix::identity(m, m);
    let chol = s.clone().cholesky().ok_or_else(|| {
        Error::Numerical("the check's covariance S = J C_p Jᵀ + I is not positive definite".into())
    })?;
    let s_inv_r = chol.solve(&r);
    let chi2 = r.dot(&s_inv_r);
    let p_value = upper_tail(chi2, m)?;
    let verdict = if p_value < settings.alpha {
        DriftVerdict::Drifted
    } else {
        DriftVerdict::Consistent
    };
    let groups = group_scores(&names, &j, &chol.solve(&j), &s_inv_r)?;
    Ok(DriftCheck {
        cell: cell.name.clone(),
        calibrated_on: estimate.data.clone(),
        data: data.source.clone(),
        poses: data.configurations.len(),
        dof: m,
        chi2,
        p_value,
        alpha: settings.alpha,
        verdict,
        rms_position_mm: rms_position(&problem, &r),
        chi2_without_prediction: r.norm_squared(),
        covariance_rule: COVARIANCE_RULE.into(),
        calibration_variance_factor: Some(estimate.uncertainty.variance_factor)
            .filter(|v| v.is_finite()),
        groups,
    })
}

/// `P(χ²(dof) ≥ x)`.
fn upper_tail(x: f64, dof: usize) -> Result<f64, Error> {
    let d = ChiSquared::new(dof as f64).map_err(|e| Error::Numerical(e.to_string()))?;
    Ok(1.0 - d.cdf(x))
}

/// The score test of every group (module docs), smallest p-value first; `s_inv_j = S⁻¹ J`,
/// `s_inv_r = S⁻¹ r`.
fn group_scores(
    names: &[String],
    j: &DMatrix<f64>,
    s_inv_j: &DMatrix<f64>,
    s_inv_r: &DVector<f64>,
) -> Result<Vec<GroupScore>, Error> {
    let mut order: Vec<&str> = Vec::new();
    for n in names {
        if !order.contains(&group_of(n)) {
            order.push(group_of(n));
        }
    }
    let mut out = Vec::with_capacity(order.len());
    for g in order {
        let cols: Vec<usize> = (0..names.len())
            .filter(|&c| group_of(&names[c]) == g)
            .collect();
        let jg = j.select_columns(&cols);
        let score = jg.transpose() * s_inv_r;
        let info = jg.transpose() * s_inv_j.select_columns(&cols);
        let svd = info.symmetric_eigen();
        let largest = svd.eigenvalues.iter().copied().fold(0.0, f64::max);
        let tol = largest * 1e-10 * cols.len() as f64;
        let mut statistic = 0.0;
        let mut rank = 0;
        for (k, &l) in svd.eigenvalues.iter().enumerate() {
            if l > tol && l > 0.0 {
                rank += 1;
                statistic += svd.eigenvectors.column(k).dot(&score).powi(2) / l;
            }
        }
        let p_value = if rank == 0 {
            1.0
        } else {
            upper_tail(statistic, rank)?
        };
        out.push(GroupScore {
            group: g.to_string(),
            parameters: cols.iter().map(|&c| names[c].clone()).collect(),
            rank,
            statistic,
            p_value,
        });
    }
    out.sort_by(|a, b| {
        a.p_value
            .total_cmp(&b.p_value)
            .then(wilson_hilferty(b).total_cmp(&wilson_hilferty(a)))
    });
    Ok(out)
}

/// The Wilson–Hilferty normal score of a group's statistic, `z = ((T/k)^{1/3} − (1 − 2/(9k)))
/// / √(2/(9k))`: monotone in the p-value, so it orders the groups whose p-values underflow
/// to 0.
fn wilson_hilferty(g: &GroupScore) -> f64 {
    if g.rank == 0 {
        return f64::NEG_INFINITY;
    }
    let k = g.rank as f64;
    let v = 2.0 / (9.0 * k);
    ((g.statistic / k).cbrt() - (1.0 - v)) / v.sqrt()
}

/// RMS over the check's position rows of the residual in mm (whitened residual × σ).
fn rms_position(problem: &Problem, r: &DVector<f64>) -> f64 {
    let mut sum = 0.0;
    let mut count = 0usize;
    for (k, meas) in problem.data.measurements.iter().enumerate() {
        if meas.kind.rows() < 3 {
            continue;
        }
        let row = problem.row_of[k];
        for a in 0..3 {
            sum += (r[row + a] * problem.sigmas[row + a]).powi(2);
        }
        count += 3;
    }
    if count == 0 {
        return f64::NAN;
    }
    (sum / count as f64).sqrt()
}
