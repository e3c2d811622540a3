//! TCP (tool-tip) calibration by pivoting: the robot touches one fixed point with the tool
//! tip from N flange orientations; the tip's offset in the flange frame and the point in the
//! world follow from the classic linear least-squares pivot problem
//!
//! ```text
//! [R_i  −I] [t; p] = −p_i,   i = 1 … N
//! ```
//!
//! (`R_i`, `p_i` the flange pose of pose i from the model's forward kinematics, `t` the tip
//! in the flange frame, `p` the fixed point in the world; e.g. Yaniv, "Which pivot
//! calibration?", SPIE Medical Imaging 2015, the algebraic one-step method). With the design
//! matrix `A` (3N × 6) and residual `r`: `σ̂² = ‖r‖² / (3N − 6)`, `Cov[t; p] = σ̂² (AᵀA)⁻¹`
//! (the residual scatter stands for everything that moves the tip between poses: the touch,
//! the robot's repeatability, the model's own errors). `A` is unit-free (rotations and
//! identities), so its condition number measures the orientation spread directly: poses
//! about one axis only leave `t` along that axis and the point along it inseparable (rank 5),
//! pure translations leave `t` undetermined (rank 3).
//!
//! The tool frame the result gives is the tip's position in the flange frame (the tool's
//! orientation is not observable from a point); its σ per axis is what the cell's
//! `[parameters] fixed_priors` for `tool.x/y/z` can state ([`crate::model::prior::FixedPrior`]).

use crate::model::{forward_kinematics, Data, Model};
use crate::Error;
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// Settings of [`pivot_calibration`].
#[derive(Clone, Debug)]
pub struct PivotSettings {
    /// Largest accepted condition number of the design matrix `[R_i −I]`: above it the
    /// orientations spread too little to separate the tip from the point. Default 100
    /// (tilts of about ±10° about two axes give ≈ 30).
    pub max_condition: f64,
}

impl Default for PivotSettings {
    fn default() -> Self {
        PivotSettings {
            max_condition: 100.0,
        }
    }
}

/// The result of a pivot calibration (`armcal pivot`'s record), mm and mm².
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PivotCalibration {
    /// The tool tip in the flange frame (mm): the tool frame's origin.
    pub tool_xyz_mm: [f64; 3],
    /// Its covariance (mm², flange frame), `σ̂² [(AᵀA)⁻¹]_tt`.
    pub tool_covariance: Matrix3<f64>,
    /// √diag of it (mm).
    pub tool_sigma_mm: [f64; 3],
    /// The touched point in the world (robot base) frame (mm).
    pub point_xyz_mm: [f64; 3],
    /// Its covariance (mm², world frame).
    pub point_covariance: Matrix3<f64>,
    /// σ̂ = √(‖r‖² / (3N − 6)) (mm): the scatter of the tip around the point per axis.
    pub residual_sigma_mm: f64,
    /// Each pose's distance of the computed tip from the point (mm), in input order.
    pub residuals_mm: Vec<f64>,
    /// Condition number of the design matrix (unit-free).
    pub condition_number: f64,
    /// Largest angle between two poses' flange orientations (deg).
    pub max_tilt_deg: f64,
    /// Number of poses.
    pub poses: usize,
}

impl PivotCalibration {
    /// The record as JSON (keys in alphabetical order, see `crate::json`).
    pub fn to_json(&self) -> Result<String, Error> {
        crate::json::sorted_pretty(self)
    }

    /// The σ (mm) the cell snippet states on each of `tool.x/y/z`: √λ_max of
    /// [`PivotCalibration::tool_covariance`]. A cell's `fixed_priors` are independent per
    /// parameter and cannot carry the covariance's correlations (the tip's σ along the
    /// tool's mean axis is typically several times its σ across, and the axes of the
    /// flange frame do not follow it); `λ_max I ⪰ C`, so the diagonal prior is never
    /// narrower than the pivot's covariance in any direction — conservative, where the
    /// per-axis √diag C alone would understate a correlated combination.
    pub fn prior_sigma_mm(&self) -> f64 {
        self.tool_covariance
            .symmetric_eigen()
            .eigenvalues
            .max()
            .max(0.0)
            .sqrt()
    }

    /// The cell-file lines that use the result: the tool frame and its σ as the fixed
    /// tool frame's prior, conservative ([`PivotCalibration::prior_sigma_mm`]).
    pub fn cell_snippet(&self) -> String {
        let [x, y, z] = self.tool_xyz_mm;
        let [sx, sy, sz] = [self.prior_sigma_mm(); 3];
        format!(
            "[tool]\nxyz_mm = [{x:.4}, {y:.4}, {z:.4}]\n\n# in [parameters]:\n\
             fixed_priors = {{ \"tool.x\" = {{ sigma_mm = {sx:.4} }}, \"tool.y\" = {{ sigma_mm = {sy:.4} }}, \"tool.z\" = {{ sigma_mm = {sz:.4} }} }}\n"
        )
    }
}

/// The flange's world pose in `data` after forward kinematics: the frame before the `tool`
/// link if the model has one, else the chain's end.
fn flange(model: &Model, data: &Data<f64>) -> (Matrix3<f64>, Vector3<f64>) {
    let pose = match model.link_index("tool") {
        Some(k) if k > 0 => &data.frames[k - 1],
        _ => data.tool(),
    };
    (pose.rot, pose.trans)
}

/// Pivot calibration (module notes) from the joint values `poses` (internal units) of
/// `model` at `params`: their flange poses by forward kinematics, then
/// [`pivot_from_flange_poses`]. Errors: a pose with the wrong number of joints, and those of
/// [`pivot_from_flange_poses`].
pub fn pivot_calibration(
    model: &Model,
    params: &[f64],
    poses: &[Vec<f64>],
    settings: &PivotSettings,
) -> Result<PivotCalibration, Error> {
    let mut data = Data::new(model);
    let mut flanges = Vec::with_capacity(poses.len());
    for (i, q) in poses.iter().enumerate() {
        if q.len() != model.dof() {
            return Err(Error::Input(format!(
                "pose {}: {} joint values, the robot has {}",
                i + 1,
                q.len(),
                model.dof()
            )));
        }
        forward_kinematics(model, &mut data, params, q);
        flanges.push(flange(model, &data));
    }
    pivot_from_flange_poses(&flanges, settings)
}

/// Pivot calibration (module notes) from the flange poses `(R_i, p_i)` (world frame, mm).
/// Errors: fewer than 3 poses, or orientations that spread too little (condition number
/// above [`PivotSettings::max_condition`], named with the largest tilt and what to do).
pub fn pivot_from_flange_poses(
    flanges: &[(Matrix3<f64>, Vector3<f64>)],
    settings: &PivotSettings,
) -> Result<PivotCalibration, Error> {
    let n = flanges.len();
    if n < 3 {
        return Err(Error::Input(format!(
            "a pivot calibration needs at least 3 poses touching the point ({n} given); \
             measure 6 or more with the tool tilted about two different axes"
        )));
    }
    let mut a = DMatrix::zeros(3 * n, 6);
    let mut b = DVector::zeros(3 * n);
    for (i, (r, p)) in flanges.iter().enumerate() {
        a.view_mut((3 * i, 0), (3, 3)).copy_from(r);
        a.view_mut((3 * i, 3), (3, 3))
            .copy_from(&(-Matrix3::identity()));
        b.rows_mut(3 * i, 3).copy_from(&(-p));
    }
    let rotations: Vec<&Matrix3<f64>> = flanges.iter().map(|(r, _)| r).collect();
    let max_tilt_deg = rotations
        .iter()
        .enumerate()
        .flat_map(|(i, ri)| rotations[i + 1..].iter().map(move |rj| (ri, rj)))
        .map(|(ri, rj)| {
            let c = (((ri.transpose() * *rj).trace() - 1.0) / 2.0).clamp(-1.0, 1.0);
            c.acos().to_degrees()
        })
        .fold(0.0, f64::max);
    let svd = a.clone().svd(true, true);
    let (smax, smin) = (svd.singular_values.max(), svd.singular_values.min());
    let condition_number = if smin > 0.0 {
        smax / smin
    } else {
        f64::INFINITY
    };
    if condition_number.is_nan() || condition_number > settings.max_condition {
        return Err(Error::Input(format!(
            "the {n} poses' flange orientations spread too little to separate the tool tip \
             from the touched point: condition number {condition_number:.3e} of [R_i −I] \
             (limit {}), largest tilt between two poses {max_tilt_deg:.1}°; touch the point \
             with the tool tilted by 20° or more about at least two different axes",
            settings.max_condition
        )));
    }
    let x = svd
        .solve(&b, 0.0)
        .map_err(|e| Error::Numerical(format!("pivot least squares: {e}")))?;
    let r = &a * &x - &b;
    let dof = 3 * n - 6;
    let s2 = if dof > 0 {
        r.norm_squared() / dof as f64
    } else {
        f64::NAN
    };
    let info_inv = (a.transpose() * &a)
        .try_inverse()
        .ok_or_else(|| Error::Numerical("pivot: AᵀA is singular".into()))?;
    let cov = info_inv * s2;
    let tool_covariance: Matrix3<f64> = cov.fixed_view::<3, 3>(0, 0).into_owned();
    Ok(PivotCalibration {
        tool_xyz_mm: [x[0], x[1], x[2]],
        tool_sigma_mm: [0, 1, 2].map(|k| tool_covariance[(k, k)].max(0.0).sqrt()),
        tool_covariance,
        point_xyz_mm: [x[3], x[4], x[5]],
        point_covariance: cov.fixed_view::<3, 3>(3, 3).into_owned(),
        residual_sigma_mm: s2.sqrt(),
        residuals_mm: (0..n).map(|i| r.rows(3 * i, 3).norm()).collect(),
        condition_number,
        max_tilt_deg,
        poses: n,
    })
}
