//! Whether the model can be the robot that made the data (issue 30 item 4): units
//! ([`super::unit_check`]), blunder rows, the gross-misfit verdict and, when it fires (or
//! on request), the joint sign and zero diagnosis ([`super::sign_diagnosis`]).
//!
//! **Plausible model error** ([`plausible_model_error`]): `2 mm + 1 % of the arm's length`
//! (capped at [`PLAUSIBLE_ARM_MM`]`.1`). An uncalibrated industrial robot's absolute
//! error is typically 1–10 mm over a reach of 1–3 m (ISO 9283 AP before calibration); a
//! fit adjusts every geometric parameter, so what it leaves — compliance, gear errors,
//! temperature — is smaller than the nominal model's error, not larger. A fitted residual
//! RMS above this bound is no model error.
//!
//! **Gross misfit** ([`GrossMisfit`]): the fitted position residual RMS (the measurements
//! a robust fit kept) above the plausible model error *and* √σ̂₀² > [`SIGMA_RATIO`]: the
//! residuals are more than 10 times what the stated σ predicts (no instrument's σ is
//! misstated by that much) and more than any model error. Then the model does not fit the
//! data: joint signs, zeros or units differ, and the estimate is refused unless accepted.
//!
//! **Far from the drawing** ([`FarFromDrawing`], issue 30 item 6): an angle of a link that
//! carries a joint (the robot proper, not the base, tool, instrument or target frames,
//! whose nominal placement may be rough) more than 90° from its nominal with no exactly
//! equivalent parameter set bringing it closer ([`crate::model::branch::FarAngle`] with
//! nothing in `blocked_by`). A real robot does not differ from its drawing by a quarter
//! turn; a fit that lands there found another robot that fits the data — with a joint
//! negated, the mirror image of the nominal (q → −q is conjugation by a half turn about an
//! axis normal to the joint's: the link's twist flips, e.g. `j1.alpha` −90° for +90°, and
//! the frame before it turns 180°), which fits to the noise, so no misfit shows. It is as
//! suspicious as a gross misfit: the sign and zero diagnosis runs and the estimate is
//! refused unless accepted. An angle an equivalent set would bring within 90° by changing
//! a fixed parameter is a branch the solver chose, not a different robot: it is not
//! counted.

use super::sign_diagnosis::{diagnose, SignDiagnosis};
use super::unit_check::{arm_length, data_scale, fitted_lengths, UnitFinding, PLAUSIBLE_ARM_MM};
use super::Estimate;
use crate::measure::{Dataset, NoiseModel};
use crate::model::branch::FarAngle;
use crate::model::{Model, Segment};
use crate::Error;
use serde::{Deserialize, Serialize};

/// A gross misfit needs residuals this many times what the stated σ predicts.
pub const SIGMA_RATIO: f64 = 10.0;
/// How many of the worst rows a verdict names.
pub const WORST: usize = 5;

/// The error (mm) a nominal model of an arm `arm_mm` long may plausibly have: 2 mm + 1 % of
/// the length, the length capped at 20 m (module doc).
pub fn plausible_model_error(arm_mm: f64) -> f64 {
    2.0 + 0.01 * arm_mm.min(PLAUSIBLE_ARM_MM.1)
}

/// One measurement, named by its data file line and pose, with its error.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WorstRow {
    /// Line in the data file (1-based, header = 1; 0 for synthetic data).
    pub line: usize,
    /// The configuration's `pose_id`.
    pub pose_id: String,
    /// Its error (mm): the fit's residual norm, or for a blunder the median discrepancy of
    /// its distances to the other measurements.
    pub error_mm: f64,
}

impl std::fmt::Display for WorstRow {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "line {} (pose `{}`) {:.4} mm",
            self.line, self.pose_id, self.error_mm
        )
    }
}

/// The rows joined for a sentence.
pub fn rows_words(rows: &[WorstRow]) -> String {
    rows.iter()
        .map(|r| r.to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// The gross-misfit verdict (module doc).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct GrossMisfit {
    /// Position residual RMS of the fit (mm).
    pub rms_mm: f64,
    /// √σ̂₀²: the residuals over what the stated σ predicts.
    pub sigma_ratio: f64,
    /// The plausible model error (mm).
    pub plausible_mm: f64,
    /// One sentence: the verdict, what to check, the worst rows.
    pub message: String,
}

/// The fitted robot differs from its drawing by a quarter turn or more (module doc).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FarFromDrawing {
    /// The robot's angles more than 90° from nominal that no equivalent set brings closer.
    pub angles: Vec<FarAngle>,
    /// One sentence: the angles, what the sign and zero diagnosis found, what to check.
    pub message: String,
}

/// The angles of `far` that belong to a link carrying a joint and that no exactly
/// equivalent parameter set brings within 90° of nominal (module doc).
pub fn robot_far_angles(model: &Model, far: &[FarAngle]) -> Vec<FarAngle> {
    let jointed = |i: usize| {
        model.registry.get(i).segment == Segment::Chain
            && model.links.iter().any(|l| {
                l.joint.is_some() && (l.first_param..l.first_param + l.param_count()).contains(&i)
            })
    };
    far.iter()
        .filter(|f| f.blocked_by.is_empty())
        .filter(|f| model.registry.index_of(&f.name).is_some_and(jointed))
        .cloned()
        .collect()
}

/// The far-from-drawing verdict on `angles` (non-empty) with the diagnosis's finding.
fn far_from_drawing(angles: Vec<FarAngle>, diagnosis: Option<&SignDiagnosis>) -> FarFromDrawing {
    let listed = angles
        .iter()
        .map(|a| {
            format!(
                "`{}` = {:.3}° is {:.1}° from its nominal {:.3}°",
                a.name,
                a.estimate_deg,
                (a.estimate_deg - a.nominal_deg).abs(),
                a.nominal_deg
            )
        })
        .collect::<Vec<_>>()
        .join(", ");
    let found = match diagnosis {
        Some(d) if d.explains => match &d.best {
            Some(b) => format!(
                "the data fit the nominal robot with {} ({:.3} mm RMS)",
                b.words, b.rms_mm
            ),
            None => String::new(),
        },
        _ => "no joint sign or zero hypothesis explains it; the nominal model's conventions may differ from the controller's".to_string(),
    };
    FarFromDrawing {
        message: format!(
            "the fitted robot is not the nominal one: {listed}, and no exactly equivalent parameter set brings it within 90° (a real robot does not differ from its drawing by a quarter turn); {found}: check joint signs, zeros and units"
        ),
        angles,
    }
}

/// What the checks found about the fit as a whole; empty for a fit of the right robot in
/// the right units.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct FitChecks {
    /// The arm's length at the nominal (mm, `arm_length`).
    #[serde(default)]
    pub arm_mm: f64,
    /// The plausible model error (mm, `plausible_model_error`).
    #[serde(default)]
    pub plausible_mm: f64,
    /// Units the data or the model likely hold where others are meant.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub units: Vec<UnitFinding>,
    /// Measurements far from every plausible model: blunders, worst first.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub blunders: Vec<WorstRow>,
    /// The fit's largest residuals (the measurements a robust fit kept), worst first.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub worst_rows: Vec<WorstRow>,
    /// Set when the model does not fit the data.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub misfit: Option<GrossMisfit>,
    /// Set when the fitted robot differs from its drawing by 90° or more.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub far: Option<FarFromDrawing>,
    /// The joint sign and zero diagnosis, when it ran.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diagnosis: Option<SignDiagnosis>,
    /// How the caller accepted a refused fit (its words, e.g. the CLI's flag); `None`: not
    /// accepted, or nothing refused.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub accepted: Option<String>,
}

impl FitChecks {
    /// The blunders in words (each row's line, pose id and error, joined for a sentence), as
    /// the refusal names them.
    pub fn blunder_rows(&self) -> String {
        rows_words(&self.blunders)
    }

    /// Whether the fit is refused: a gross misfit, a robot far from its drawing or a unit
    /// mistake.
    pub fn refuses(&self) -> bool {
        self.misfit.is_some() || self.far.is_some() || !self.units.is_empty()
    }

    /// Why the fit is refused, one sentence per finding; empty when it is not.
    pub fn reasons(&self) -> Vec<String> {
        let units = self.units.iter().map(|u| format!("units: {}", u.message));
        let blunders = (!self.blunders.is_empty()).then(|| {
            format!(
                "blunders: {} lie farther from the other measurements than the model allows, by more than the plausible model error ({:.1} mm): remove them, or fit robustly",
                rows_words(&self.blunders),
                self.plausible_mm
            )
        });
        let misfit = self.misfit.iter().map(|m| m.message.clone());
        let far = self.far.iter().map(|f| f.message.clone());
        let diagnosis = self
            .diagnosis
            .iter()
            .map(|d| format!("sign and zero diagnosis: {}", d.message));
        units
            .chain(blunders)
            .chain(misfit)
            .chain(far)
            .chain(diagnosis)
            .collect()
    }
}

/// The checks of the fit `estimate` of `model` (the cell's model with the data's stations)
/// to `data` (the fitted part): the diagnosis runs when the misfit or the far-from-drawing
/// verdict fires unexplained by a unit or a blunder, or when `diagnose_signs`; `accepted`
/// is recorded when the fit is refused.
pub fn check(
    model: &Model,
    data: &Dataset,
    noise: &NoiseModel,
    estimate: &Estimate,
    diagnose_signs: bool,
    accepted: Option<&str>,
) -> Result<FitChecks, Error> {
    let nominal = model.nominal();
    let arm_mm = arm_length(model, &nominal);
    let plausible_mm = plausible_model_error(arm_mm);
    let scale = data_scale(model, &nominal, data, plausible_mm);
    let row = |i: usize, error_mm: f64| {
        let m = &data.measurements[i];
        WorstRow {
            line: m.line,
            pose_id: data.config_ids.get(m.config).cloned().unwrap_or_default(),
            error_mm,
        }
    };
    // a unit named by the data's scale explains every length; else a single length fitted a
    // unit factor from its nominal is the likelier cause of an unexplained scale
    let named = scale.findings.iter().any(|f| !f.likely_unit.is_empty());
    let fitted = fitted_lengths(model, &estimate.parameters);
    let units = if named || fitted.is_empty() {
        scale.findings
    } else {
        fitted
    };
    let blunders: Vec<WorstRow> = scale
        .blunders
        .iter()
        .take(WORST)
        .map(|&(i, e)| row(i, e))
        .collect();
    let outliers: std::collections::HashSet<usize> =
        estimate.outliers.iter().map(|o| o.line).collect();
    let mut kept: Vec<(usize, f64)> = estimate
        .residuals
        .per_measurement
        .iter()
        .enumerate()
        .filter(|(i, _)| {
            let line = data.measurements[*i].line;
            line == 0 || !outliers.contains(&line)
        })
        .map(|(i, r)| (i, r.norm))
        .collect();
    let rms_mm = (kept.iter().map(|(_, e)| e * e).sum::<f64>() / kept.len().max(1) as f64).sqrt();
    kept.sort_by(|a, b| b.1.total_cmp(&a.1));
    let worst_rows: Vec<WorstRow> = kept.iter().take(WORST).map(|&(i, e)| row(i, e)).collect();
    let sigma_ratio = estimate
        .verdicts
        .as_ref()
        .and_then(|v| v.chi2.sigma_ratio)
        .unwrap_or(f64::NAN);
    let misfit = (rms_mm > plausible_mm && sigma_ratio > SIGMA_RATIO).then(|| GrossMisfit {
        rms_mm,
        sigma_ratio,
        plausible_mm,
        message: format!(
            "the model does not fit the data: check joint signs, zeros and units. The residual RMS {rms_mm:.3} mm is {sigma_ratio:.1}× what the stated σ predicts (more than {SIGMA_RATIO}×) and above the {plausible_mm:.1} mm any plausible model error leaves (2 mm + 1 % of the {arm_mm:.0} mm from the base through every joint to the farthest target at q = 0); the worst rows: {}",
            rows_words(&worst_rows)
        ),
    });
    let far_angles = robot_far_angles(model, &estimate.far_from_nominal);
    let suspicious = misfit.is_some() || !far_angles.is_empty();
    let unexplained = suspicious && units.is_empty() && blunders.is_empty();
    let diagnosis = if unexplained || diagnose_signs {
        // a fit far from the drawing fits another robot: its RMS is no baseline for the
        // hypotheses, which keep the drawing
        let near = far_angles.is_empty().then_some(rms_mm);
        Some(diagnose(model, data, noise, plausible_mm, near)?)
    } else {
        None
    };
    let far = (!far_angles.is_empty()).then(|| far_from_drawing(far_angles, diagnosis.as_ref()));
    let mut checks = FitChecks {
        arm_mm,
        plausible_mm,
        units,
        blunders,
        worst_rows,
        misfit,
        far,
        diagnosis,
        accepted: None,
    };
    if checks.refuses() {
        checks.accepted = accepted.map(str::to_string);
    }
    Ok(checks)
}
