//! What an estimate says about its own fit (issue #10 item 4): did the solver converge, do
//! the residuals agree with the stated measurement σ (χ² test), and how many parameters
//! were identified of the count the measurement type gives in generic geometry. The
//! consumers of an estimate refuse one whose fit did not converge
//! ([`super::Estimate::check_usable`]).

use super::uncertainty::{Chi2Outcome, ParameterUncertainty};
use crate::model::identifiability::{expected_count, Measurement};
use crate::model::rank_deficit::RankDeficit;
use crate::model::Model;
use crate::solve::Status;
use serde::{Deserialize, Serialize};

/// The verdicts an estimate records.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Verdicts {
    /// How the solver ended.
    pub solver: Status,
    /// Whether the residuals agree with the stated σ.
    pub chi2: Chi2Verdict,
    /// How many parameters were identified of the generic count.
    pub identifiability: IdentifiabilityVerdict,
    /// Units, blunders, gross misfit, joint signs and zeros (`super::fit_checks`); empty
    /// in files of an older armcal.
    #[serde(default)]
    pub fit: super::FitChecks,
}

/// The χ² test of the a-posteriori variance factor σ̂₀² = rᵀr / (m − n) and what it means
/// for the reported σ's.
///
/// The reported parameter and TCP σ's come from `C_p = (F₁ᵀF₁)⁻¹` with the Jacobian
/// whitened by the *stated* σ: they are **not** scaled by σ̂₀². With the stated σ wrong by
/// a factor k (σ_true = k σ), E[σ̂₀²] = k² and the true covariance is k² C_p, so the
/// reported σ's are off by k ≈ √σ̂₀².
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Chi2Verdict {
    /// Result of the two-sided test at 5 %.
    pub outcome: Chi2Outcome,
    /// P(χ² ≥ rᵀr); `None` without redundancy.
    pub p_value: Option<f64>,
    /// σ̂₀²; `None` without redundancy.
    pub variance_factor: Option<f64>,
    /// √σ̂₀²: how many times larger the residuals are than the stated σ predicts.
    pub sigma_ratio: Option<f64>,
    /// Degrees of freedom m − n (rows minus free parameters).
    pub dof: usize,
    /// One sentence: what the verdict means for the reported σ's.
    pub meaning: String,
}

impl Chi2Verdict {
    /// A failing test (residuals too large for the stated σ) names the measurements with the
    /// largest residuals in its meaning.
    pub fn name_worst_rows(&mut self, rows: &[super::fit_checks::WorstRow]) {
        if self.outcome == Chi2Outcome::SigmaTooSmall && !rows.is_empty() {
            self.meaning.push_str(&format!(
                "; the largest residuals: {}",
                super::fit_checks::rows_words(rows)
            ));
        }
    }

    /// The verdict of the χ² test recorded in `u`.
    pub fn of(u: &ParameterUncertainty) -> Chi2Verdict {
        let outcome = Chi2Outcome::of(u.dof, u.p_value);
        let finite = |x: f64| Some(x).filter(|x| x.is_finite());
        let (p_value, variance_factor) = match outcome {
            Chi2Outcome::Untestable => (None, None),
            _ => (finite(u.p_value), finite(u.variance_factor)),
        };
        let sigma_ratio = variance_factor.map(f64::sqrt);
        let p = if u.p_value >= 1e-3 {
            format!("{:.3}", u.p_value)
        } else {
            format!("{:.1e}", u.p_value)
        };
        let test = format!("σ̂₀² = {:.3}, {} dof, p = {p}", u.variance_factor, u.dof);
        let k = sigma_ratio.unwrap_or(f64::NAN);
        let meaning = match outcome {
            Chi2Outcome::Consistent => format!(
                "the residuals agree with the stated σ ({test}): the reported σ's, which follow from it, stand"
            ),
            Chi2Outcome::SigmaTooSmall => format!(
                "the residuals are {k:.2}× what the stated σ predicts ({test}): the stated σ is too small (or the model misses an error, or there are outliers); the reported σ's assume the stated σ (C_p is not scaled by σ̂₀²) and are then about {k:.2}× too small — multiply them by √σ̂₀² = {k:.2}"
            ),
            Chi2Outcome::SigmaTooLarge => format!(
                "the residuals are only {k:.2}× what the stated σ predicts ({test}): the stated σ is too large; the reported σ's assume the stated σ (C_p is not scaled by σ̂₀²) and are then about {:.2}× too large — multiply them by √σ̂₀² = {k:.2}",
                1.0 / k
            ),
            Chi2Outcome::Untestable => "no redundancy (as many residuals as parameters): the residuals cannot test the stated σ, and the reported σ's rest on it alone".to_string(),
        };
        Chi2Verdict {
            outcome,
            p_value,
            variance_factor,
            sigma_ratio,
            dof: u.dof,
            meaning,
        }
    }
}

/// How many parameters were identified, against the count the measurement type identifies
/// in generic geometry (`expected_count`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct IdentifiabilityVerdict {
    /// The cell's measurement type (position, pose, distance).
    pub measurement: Measurement,
    /// Number of geometric parameters estimated (the non-geometric terms are counted
    /// apart, in `nongeometric`).
    pub identified: usize,
    /// The non-geometric terms estimated (joint compliance, periodic gear errors), which the
    /// generic count of geometric parameters does not include.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub nongeometric: Vec<String>,
    /// The generic count; `None` where it depends on the target layout (several points).
    pub expected: Option<usize>,
    /// Parameters left out with a reason (see the estimate's `fixed_reasons`).
    pub fixed: Vec<String>,
    /// One sentence: identified against expected, and why fewer if so.
    pub meaning: String,
}

impl IdentifiabilityVerdict {
    /// The verdict for the parameters `free` (registry indices of `model`) estimated from
    /// `measurement` data, with the parameters fixed for a reason and the rank deficit that
    /// explains a shortfall. The geometric parameters are compared with the generic count;
    /// the non-geometric terms are named as such.
    pub fn of(
        model: &Model,
        measurement: Measurement,
        free: &[usize],
        fixed_reasons: &[(String, String)],
        deficit: Option<&RankDeficit>,
    ) -> IdentifiabilityVerdict {
        let (terms, geometric): (Vec<usize>, Vec<usize>) =
            free.iter().partition(|&&i| model.is_joint_correction(i));
        let identified = geometric.len();
        let nongeometric: Vec<String> = terms
            .iter()
            .map(|&i| model.registry.get(i).name.clone())
            .collect();
        let expected = expected_count(model, measurement);
        let fixed: Vec<String> = fixed_reasons.iter().map(|(n, _)| n.clone()).collect();
        let what = measurement.words();
        let left_out = if fixed.is_empty() {
            String::new()
        } else {
            format!("; fixed with a reason: {}", fixed.join(", "))
        };
        let meaning = match expected {
            Some(e) if identified == e => format!(
                "all {e} parameters {what} measurements identify for this robot in generic geometry are estimated{left_out}"
            ),
            Some(e) if identified < e => format!(
                "{identified} of the {e} parameters {what} measurements identify for this robot in generic geometry are estimated, because {}{left_out}",
                deficit.map_or_else(
                    || "the cell's explicit free set leaves the others out".to_string(),
                    |d| d.causes.join("; ")
                )
            ),
            Some(e) => format!(
                "{identified} geometric parameters estimated, more than the {e} {what} measurements identify for this robot in generic geometry (priors, or a free set that is not minimal){left_out}"
            ),
            None => format!(
                "{identified} parameters estimated (the generic count for several targets depends on their layout){left_out}"
            ),
        };
        let meaning = if nongeometric.is_empty() {
            meaning
        } else {
            format!(
                "{meaning}; besides, {} non-geometric terms (joint compliance, periodic gear errors: {}), which the generic count of geometric parameters does not include",
                nongeometric.len(),
                nongeometric.join(", ")
            )
        };
        IdentifiabilityVerdict {
            measurement,
            identified,
            nongeometric,
            expected,
            fixed,
            meaning,
        }
    }

    /// Whether fewer parameters were estimated than the generic count.
    pub fn is_short(&self) -> bool {
        self.expected.is_some_and(|e| self.identified < e)
    }
}
