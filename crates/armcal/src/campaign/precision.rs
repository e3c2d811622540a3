//! The TCP precision a campaign has reached: C_s at every working pose from the fit on
//! everything measured, scaled by the variance factor, its σ and 95 % ellipsoid; and the
//! precision predicted for poses not yet measured.

use crate::cell::Cell;
use crate::identify::Estimate;
use crate::model::{forward_kinematics, observed_position, Data, Model, Observed};
use crate::Error;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// Confidence of the ellipsoids a campaign states.
pub const CONFIDENCE: f64 = 0.95;

/// What "TCP σ" means in a campaign.
pub const SIGMA_DEFINITION: &str = "σ = √((1/3) tr C_s) (mm), the RMS of the three axis σ's of the TCP position (tool origin in the instrument frame) at the working pose: the square root of the paper's KPI φ_A(C_s); C_s = s·G C_p Gᵀ with s the variance-factor scale.";

/// How σ̂₀² enters C_s.
pub const VARIANCE_RULE: &str = "C_s is scaled by s = max(1, σ̂₀²) (s = 1 without redundancy): residuals larger than the stated instrument σ widen C_s, smaller ones never narrow it — σ̂₀² from a few dozen degrees of freedom scatters by ±√(2/dof) (±26 % at 30 dof), and a campaign that stopped on a low draw of σ̂₀² would claim more precision than it has.";

/// χ²₃ quantile at [`CONFIDENCE`]: the 95 % ellipsoid of a 3-D Gaussian error e with
/// covariance C is eᵀ C⁻¹ e ≤ 7.815.
pub fn chi2_quantile() -> f64 {
    ChiSquared::new(3.0)
        .expect("3 degrees of freedom")
        .inverse_cdf(CONFIDENCE)
}

/// The precision at one working pose.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WorkingSigma {
    /// The working pose's name.
    pub name: String,
    /// σ = √((1/3) tr C_s) (mm, `SIGMA_DEFINITION`).
    pub sigma_mm: f64,
    /// σ of each instrument axis, √diag C_s (mm).
    pub axes_mm: [f64; 3],
    /// Semi-axes of the 95 % ellipsoid eᵀ C_s⁻¹ e ≤ χ²₃(0.95), largest first (mm).
    pub ellipsoid_95_mm: [f64; 3],
    /// C_s (mm², instrument frame), scaled.
    pub covariance: Matrix3<f64>,
    /// Simulated campaigns only: the true TCP error, estimated − true TCP position (mm).
    pub true_error_mm: Option<[f64; 3]>,
    /// Simulated campaigns only: whether the true error lies in the 95 % ellipsoid.
    pub true_error_inside_95: Option<bool>,
    /// The model floor C_floor at the working pose (mm², instrument frame, not scaled:
    /// it comes from the fixed parameters' stated prior, not from the residuals;
    /// [`crate::identify::model_floor`]); `None`: the estimate states none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub floor_covariance: Option<Matrix3<f64>>,
    /// √((1/3) tr C_floor) (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub floor_sigma_mm: Option<f64>,
    /// Simulated campaigns only: whether the true error lies in the 95 % ellipsoid of
    /// C_s + C_floor.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub true_error_inside_95_with_floor: Option<bool>,
}

impl WorkingSigma {
    /// The precision of C_s (mm², already scaled) at the working pose `name`.
    pub fn of(name: &str, covariance: Matrix3<f64>) -> WorkingSigma {
        let k = chi2_quantile();
        let mut eig: Vec<f64> = covariance
            .symmetric_eigen()
            .eigenvalues
            .iter()
            .map(|l| (k * l.max(0.0)).sqrt())
            .collect();
        eig.sort_by(|a, b| b.total_cmp(a));
        WorkingSigma {
            name: name.into(),
            sigma_mm: (covariance.trace() / 3.0).max(0.0).sqrt(),
            axes_mm: [0, 1, 2].map(|i| covariance[(i, i)].max(0.0).sqrt()),
            ellipsoid_95_mm: [eig[0], eig[1], eig[2]],
            covariance,
            true_error_mm: None,
            true_error_inside_95: None,
            floor_covariance: None,
            floor_sigma_mm: None,
            true_error_inside_95_with_floor: None,
        }
    }

    /// Sets the model floor `floor` (mm²).
    pub fn with_floor(mut self, floor: Matrix3<f64>) -> WorkingSigma {
        self.floor_sigma_mm = Some((floor.trace() / 3.0).max(0.0).sqrt());
        self.floor_covariance = Some(floor);
        self
    }

    /// Sets the true error `e` (mm) and whether eᵀ C_s⁻¹ e ≤ χ²₃(0.95) (and, with a floor,
    /// eᵀ (C_s + C_floor)⁻¹ e ≤ χ²₃(0.95)).
    pub fn with_true_error(mut self, e: Vector3<f64>) -> WorkingSigma {
        let inside = |c: Matrix3<f64>| {
            c.try_inverse()
                .map(|inv| (e.transpose() * inv * e)[(0, 0)] <= chi2_quantile())
        };
        self.true_error_mm = Some([e[0], e[1], e[2]]);
        self.true_error_inside_95 = inside(self.covariance);
        self.true_error_inside_95_with_floor = self
            .floor_covariance
            .and_then(|f| inside(self.covariance + f));
        self
    }
}

/// The factor C_s is scaled by ([`VARIANCE_RULE`]): max(1, σ̂₀²), or 1 without redundancy.
pub fn scale(estimate: &Estimate) -> f64 {
    let u = &estimate.uncertainty;
    if u.dof > 0 && u.variance_factor.is_finite() {
        u.variance_factor.max(1.0)
    } else {
        1.0
    }
}

/// The precision at every working pose of an estimate, C_s scaled by `scale`, with the
/// estimate's model floor beside it (the target is on C_s: the floor does not shrink with
/// more poses).
pub fn working_sigmas(estimate: &Estimate, scale: f64) -> Vec<WorkingSigma> {
    estimate
        .tcp
        .iter()
        .map(|t| {
            let w = WorkingSigma::of(&t.name, t.covariance * scale);
            match estimate.model_floor.as_ref().and_then(|f| f.at(&t.name)) {
                Some(f) => w.with_floor(f.covariance),
                None => w,
            }
        })
        .collect()
}

/// The TCP position (tool origin in the instrument frame, mm) of `model` with `params` at `q`.
pub fn tcp_position(model: &Model, params: &[f64], q: &[f64]) -> Vector3<f64> {
    let mut d = Data::new(model);
    forward_kinematics(model, &mut d, params, q);
    observed_position(&d, Observed::Tool)
}

/// The σ (mm) predicted at every working pose of `cell` once the configurations `poses`
/// (internal units) are measured, from the design's C_s at the nominal model and the
/// stated instrument σ ([`crate::design::assess::assess`]), scaled by `scale`.
pub fn predicted_sigmas(cell: &Cell, poses: &[Vec<f64>], scale: f64) -> Result<Vec<f64>, Error> {
    let a = crate::design::assess::assess(cell, poses)?;
    Ok(a.tcp.iter().map(|t| (scale * t.kpi).sqrt()).collect())
}

/// Poses in all that the target `target_mm` needs, from the largest σ `sigma_mm` predicted
/// for `poses` poses: C_s of further batches of like quality shrinks as 1/N, so
/// N = ⌈poses · σ² / target²⌉ (at least `poses`).
pub fn poses_needed(poses: usize, sigma_mm: f64, target_mm: f64) -> usize {
    let n = (poses as f64 * (sigma_mm / target_mm).powi(2)).ceil();
    (n as usize).max(poses)
}
