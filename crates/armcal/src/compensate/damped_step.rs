//! The damped least-squares step of calibrated IK ([`super::ik`]) in task space: the
//! weighted task Jacobian's columns, the step `Δq = J_wᵀ (J_w J_wᵀ + γ² I)⁻¹ e_w` (book eqs.
//! 5.85–5.87, one stage), and σ_min² of `J_w` by inverse iteration for the damping. Fixed-size
//! (R = 3 or 6 rows) stack matrices: nothing is allocated.

use crate::model::Data;
use nalgebra::{Cholesky, SMatrix, SVector, Vector6};

/// Columns of the weighted task Jacobian `Q^{1/2} J` of the tool frame, one per commanded
/// joint, from evaluated kinematics: joint j's world twist (ω, v) moves the tool origin p
/// with `ω × p + v` (rows 0–2) and turns it with ω, scaled by L (rows 3–5). With joint
/// corrections (compliance, periodic errors; `crate::model::joint_correction`) the twists
/// are those of the corrected joints `q̃ = q + Δq(q)` and the columns w.r.t. the commanded
/// joints follow by the chain rule, `J = J̃ ∂q̃/∂q`; `corrected` (one column per joint) then
/// holds `J̃` and is otherwise untouched.
pub fn task_jacobian_columns(
    data: &Data<f64>,
    length: f64,
    columns: &mut [Vector6<f64>],
    corrected: &mut [Vector6<f64>],
) {
    let p = data.tool().trans;
    for (col, tw) in columns.iter_mut().zip(&data.joint_twists) {
        let v = tw.point_velocity(&p);
        *col = Vector6::new(
            v.x,
            v.y,
            v.z,
            tw.w.x * length,
            tw.w.y * length,
            tw.w.z * length,
        );
    }
    if let Some(c) = &data.corrections {
        corrected.copy_from_slice(columns);
        for (_, joint, k, a) in c.rates() {
            columns[k] += corrected[joint] * a;
        }
    }
}

/// `J_w J_wᵀ` over the first R rows.
pub(super) fn normal_matrix<const R: usize>(columns: &[Vector6<f64>]) -> SMatrix<f64, R, R> {
    let mut a = SMatrix::<f64, R, R>::zeros();
    for c in columns {
        let j = c.fixed_rows::<R>(0);
        a += j * j.transpose();
    }
    a
}

/// `Δq = J_wᵀ (A + γ² I)⁻¹ e` with `A = J_w J_wᵀ` into `step`; `false` if `A + γ² I` is
/// not positive definite.
pub(super) fn step_from<const R: usize>(
    a: &SMatrix<f64, R, R>,
    columns: &[Vector6<f64>],
    e: &SVector<f64, R>,
    gamma2: f64,
    step: &mut [f64],
) -> bool {
    let Some(ch) = Cholesky::new(a + SMatrix::<f64, R, R>::identity() * gamma2) else {
        return false;
    };
    let y = ch.solve(e);
    for (s, c) in step.iter_mut().zip(columns) {
        *s = c.fixed_rows::<R>(0).dot(&y);
    }
    true
}

/// The one-step optimal compensator (book eqs. 5.85–5.87 with one stage), in task-space
/// form: `Δq = J_wᵀ (J_w J_wᵀ + γ² I)⁻¹ e_w = (J_wᵀJ_w + γ² I)⁻¹ J_wᵀ e_w`, from the columns
/// of the weighted Jacobian (first R rows) and the weighted error. Writes `step` (one
/// value per column); `false` if the damped matrix is not positive definite (γ = 0 at an
/// exact singularity).
pub fn damped_step<const R: usize>(
    columns: &[Vector6<f64>],
    e: &SVector<f64, R>,
    gamma2: f64,
    step: &mut [f64],
) -> bool {
    step_from(&normal_matrix::<R>(columns), columns, e, gamma2, step)
}

/// Smallest eigenvalue of the symmetric positive semi-definite `a` (σ_min² of J_w) by
/// inverse iteration from the warm start `v` (updated), to 1e-3 relative (the Rayleigh
/// quotient, whose error is quadratic in that of the vector; enough for the damping and
/// the report).
pub(super) fn smallest_eigenvalue<const R: usize>(
    a: &SMatrix<f64, R, R>,
    v: &mut Vector6<f64>,
) -> f64 {
    // A shift of rounding size keeps the factorisation defined at an exact singularity.
    let shift = 1e-13 * a.trace().max(f64::MIN_POSITIVE);
    let Some(ch) = Cholesky::new(a + SMatrix::<f64, R, R>::identity() * shift) else {
        return 0.0;
    };
    let mut x: SVector<f64, R> = v.fixed_rows::<R>(0).into_owned();
    if !x.iter().all(|c| c.is_finite()) || x.norm() <= 1e-3 {
        x = SVector::repeat(1.0);
    }
    x.normalize_mut();
    let mut mu = 0.0;
    for _ in 0..30 {
        let y = ch.solve(&x);
        let next = x.dot(&y);
        let n = y.norm();
        x = y / n;
        let done = (next - mu).abs() <= 1e-3 * next;
        mu = next;
        if done {
            break;
        }
    }
    v.fixed_rows_mut::<R>(0).copy_from(&x);
    (1.0 / mu - shift).max(0.0)
}
