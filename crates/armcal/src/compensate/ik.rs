//! Calibrated inverse kinematics by damped least squares (book §5.2–5.3).
//!
//! The book's optimal (LQR) compensator for one step is exactly damped least squares
//! (book eqs. 5.85–5.87, check 9): `Δq = (JᵀQJ + Γ)⁻¹ JᵀQ e`. armcal weights the task error
//! with `Q = diag(1, 1, 1, L², L², L²)` (position in mm, orientation in rad scaled by a
//! characteristic length L, the book's `k2/‖p‖²` form) and uses `Γ = γ² I` with γ chosen from
//! the smallest singular value σ_min of `Q^{1/2} J` (Maciejewski–Klein): γ = 0 while
//! σ_min ≥ ε, and `γ² = (1 − (σ_min/ε)²) γ_max²` below, so steps stay bounded near a
//! singularity instead of blowing up as they do with γ → 0 (book Table 5.7). Joint limits
//! are enforced by clamping each step.

use crate::model::pose::rotation_log;
use crate::model::{forward_kinematics, joint_jacobian, Data, Model, Observed, Pose};
use nalgebra::{DMatrix, DVector, Vector3};
use serde::{Deserialize, Serialize};

/// What the tool frame must reach (world frame, mm).
#[derive(Clone, Copy, Debug)]
pub enum IkTarget {
    Position(Vector3<f64>),
    Pose(Pose<f64>),
}

/// How an IK solve ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum IkStatus {
    Converged,
    /// Stopped near a singular configuration (σ_min < ε) above the tolerance.
    Singular,
    /// The target needs joint values beyond the limits.
    JointLimits,
    /// The residual stopped decreasing far from the target (out of reach).
    Unreachable,
    MaxIterations,
}

/// Settings of [`calibrated_ik`].
#[derive(Clone, Debug)]
pub struct IkSettings {
    pub max_iterations: usize,
    /// Position tolerance (mm).
    pub position_tolerance: f64,
    /// Orientation tolerance (rad).
    pub orientation_tolerance: f64,
    /// Characteristic length L (mm) weighting orientation against position.
    pub length: f64,
    /// Singular-value threshold ε and largest damping γ_max (of the weighted Jacobian).
    pub epsilon: f64,
    pub gamma_max: f64,
}

impl Default for IkSettings {
    fn default() -> Self {
        IkSettings {
            max_iterations: 60,
            position_tolerance: 1e-7,
            orientation_tolerance: 1e-10,
            length: 1000.0,
            epsilon: 1.0,
            gamma_max: 1.0,
        }
    }
}

/// Result of one solve.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct IkResult {
    pub q: Vec<f64>,
    pub status: IkStatus,
    pub iterations: usize,
    /// Remaining position error (mm) and orientation error (rad; 0 for position targets).
    pub position_error: f64,
    pub orientation_error: f64,
    /// Smallest singular value of the weighted Jacobian at the end.
    pub sigma_min: f64,
}

/// Reusable buffers.
pub struct IkWorkspace {
    data: Data<f64>,
}

impl IkWorkspace {
    pub fn new(model: &Model) -> Self {
        IkWorkspace {
            data: Data::new(model),
        }
    }
}

fn error(target: &IkTarget, tool: &Pose<f64>) -> (DVector<f64>, f64, f64) {
    match target {
        IkTarget::Position(p) => {
            let e = p - tool.trans;
            (DVector::from_column_slice(e.as_slice()), e.norm(), 0.0)
        }
        IkTarget::Pose(t) => {
            let e = t.trans - tool.trans;
            let w = rotation_log(&(t.rot * tool.rot.transpose()));
            (
                DVector::from_iterator(6, e.iter().chain(w.iter()).copied()),
                e.norm(),
                w.norm(),
            )
        }
    }
}

/// The weighted task Jacobian `Q^{1/2} J` of the tool frame (position rows, then, for 6
/// rows, orientation rows scaled by the characteristic length), from evaluated kinematics.
pub fn task_jacobian(data: &Data<f64>, rows: usize, length: f64) -> DMatrix<f64> {
    let j6 = joint_jacobian(data, Observed::Tool);
    let mut j: DMatrix<f64> = j6.rows(0, rows).into_owned();
    for r in 3..rows {
        j.row_mut(r).scale_mut(length);
    }
    j
}

/// The one-step optimal compensator (book eqs. 5.85–5.87 with one stage):
/// `Δq = (JᵀQJ + γ² I)⁻¹ JᵀQ e`, given `JᵀQJ` and `JᵀQe`. `None` if the damped matrix is
/// not positive definite (γ = 0 at an exact singularity).
pub fn damped_step(jtj: &DMatrix<f64>, jte: &DVector<f64>, gamma2: f64) -> Option<DVector<f64>> {
    let mut a = jtj.clone();
    for k in 0..a.nrows() {
        a[(k, k)] += gamma2;
    }
    a.cholesky().map(|ch| ch.solve(jte))
}

/// Joint values that bring the tool frame of `model` with parameters `params` to `target`,
/// starting from `seed` (e.g. the nominal solution or the nominal program's joints).
pub fn calibrated_ik(
    model: &Model,
    params: &[f64],
    target: &IkTarget,
    seed: &[f64],
    settings: &IkSettings,
    ws: &mut IkWorkspace,
) -> IkResult {
    let (lo, hi) = model.joint_limits();
    let mut q: Vec<f64> = seed
        .iter()
        .zip(lo.iter().zip(&hi))
        .map(|(x, (a, b))| x.clamp(*a, *b))
        .collect();
    let rows = match target {
        IkTarget::Position(_) => 3,
        IkTarget::Pose(_) => 6,
    };
    let mut best_err = f64::INFINITY;
    let mut stalled = 0;
    let mut sigma_min = f64::INFINITY;
    let mut at_limit = false;
    // `ws.data` holds the kinematics at `q` after an accepted step; evaluate only otherwise.
    let mut evaluated = false;
    for it in 0..=settings.max_iterations {
        if !evaluated {
            forward_kinematics(model, &mut ws.data, params, &q);
        }
        evaluated = false;
        let (e, pe, oe) = error(target, ws.data.tool());
        if pe <= settings.position_tolerance && oe <= settings.orientation_tolerance {
            return IkResult {
                q,
                status: IkStatus::Converged,
                iterations: it,
                position_error: pe,
                orientation_error: oe,
                sigma_min,
            };
        }
        let j = task_jacobian(&ws.data, rows, settings.length);
        let mut ew = e.clone();
        for r in 3..rows {
            ew[r] *= settings.length;
        }
        let weighted = ew.norm();
        let svd = j.clone().svd(false, false);
        sigma_min = svd.singular_values.min();
        let gamma2 = if sigma_min >= settings.epsilon {
            0.0
        } else {
            (1.0 - (sigma_min / settings.epsilon).powi(2)) * settings.gamma_max.powi(2)
        };
        // Damped step; if it does not reduce the weighted error, raise the damping (a
        // Levenberg–Marquardt safeguard, so that every accepted step is a descent step).
        let jtj = j.tr_mul(&j);
        let jte = j.tr_mul(&ew);
        let smax = svd.singular_values.max();
        let mut g2 = gamma2;
        let mut accepted = false;
        for _ in 0..12 {
            let Some(step) = damped_step(&jtj, &jte, g2 + 1e-14 * smax * smax) else {
                break;
            };
            let mut trial = q.clone();
            let mut hits_limit = false;
            for (k, st) in step.iter().enumerate() {
                let v = q[k] + st;
                if v < lo[k] || v > hi[k] {
                    hits_limit = true;
                }
                trial[k] = v.clamp(lo[k], hi[k]);
            }
            forward_kinematics(model, &mut ws.data, params, &trial);
            let (mut et, _, _) = error(target, ws.data.tool());
            if rows == 6 {
                for r in 3..6 {
                    et[r] *= settings.length;
                }
            }
            if et.norm() < weighted {
                q = trial;
                at_limit = hits_limit;
                accepted = true;
                evaluated = true;
                break;
            }
            g2 = (g2 * 10.0).max(1e-6 * smax * smax);
        }
        if !accepted {
            break;
        }
        if weighted < best_err * (1.0 - 1e-3) {
            best_err = weighted;
            stalled = 0;
        } else {
            stalled += 1;
            if stalled >= 5 {
                break;
            }
        }
    }
    forward_kinematics(model, &mut ws.data, params, &q);
    let (_, pe, oe) = error(target, ws.data.tool());
    let status = if pe <= settings.position_tolerance && oe <= settings.orientation_tolerance {
        IkStatus::Converged
    } else if at_limit {
        IkStatus::JointLimits
    } else if sigma_min < settings.epsilon {
        IkStatus::Singular
    } else if stalled >= 5 {
        IkStatus::Unreachable
    } else {
        IkStatus::MaxIterations
    };
    IkResult {
        q,
        status,
        iterations: settings.max_iterations,
        position_error: pe,
        orientation_error: oe,
        sigma_min,
    }
}
