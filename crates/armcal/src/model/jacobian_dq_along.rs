//! The derivative w.r.t. the joints of a weighted sum of the identification Jacobian's
//! entries, `∂/∂q_k ⟨Ω, J(q)⟩ = Σ_{r,c} Ω_rc ∂J_rc/∂q_k`, for a fixed weight Ω: what every
//! pose-design gradient needs (`∂φ/∂q_k = −2 ⟨J Φ, ∂J/∂q_k⟩`, Ω = J Φ), in one pass over
//! the columns instead of the k full matrices of [`identification_jacobian_dq`].
//!
//! With the entries of [`identification_jacobian_dq`] (`J_j` the position column of
//! parameter j, `J^ω_j = s R_Iᵀ ω_j` its orientation column, `w_k = R_Iᵀ ω_k`,
//! `ṗ_k = R_Iᵀ ṗ` for joint k, all in the instrument frame) and Ω's position and orientation
//! rows `o_j`, `o'_j` of column j, the triple product `a·(b × c) = b·(c × a)` moves the joint
//! out of every sum:
//! * parameters after joint k: `Σ_j o_j·(w_k × J_j) + o'_j·(w_k × J^ω_j)
//!   = w_k · Σ_j (J_j × o_j + J^ω_j × o'_j)`;
//! * parameters before joint k: `Σ_j o_j·(J^ω_j × ṗ_k) = ṗ_k · Σ_j (o_j × J^ω_j)`;
//! * parameters in joint k's own screw: the entry itself, `o_j·(s R_Iᵀ ċ_j + J^ω_j × ṗ_k) +
//!   o'_j·(s R_Iᵀ ω̇_j)`.
//!
//! So each column costs two cross products and each joint two dot products, O(n_p + k)
//! vector work where the matrices cost O(n_p·k) cross products and stores. Joint
//! corrections (compliance, periodic errors) enter by the same chain rule as in
//! [`identification_jacobian_dq`], applied to the weighted sums.

use crate::model::chain::Model;
use crate::model::jacobian::{
    influence, joint_motions, observed_world, ChainOrder, Observed, Rows,
};
use crate::model::kinematics::Data;
use nalgebra::{DMatrix, Matrix3, Vector3};

#[cfg(doc)]
use crate::model::jacobian::identification_jacobian_dq;

/// Buffers for [`identification_jacobian_dq_along`], sized for one model, with where each
/// parameter sits among the joints.
pub struct AlongWorkspace {
    /// Per joint: how many joints act before it.
    joint_rank: Vec<usize>,
    /// Per parameter: how many joints act strictly before it, how many before or with it,
    /// and the joint acting in its own factor (if any).
    joints_before: Vec<usize>,
    joints_up_to: Vec<usize>,
    same_joint: Vec<Option<usize>>,
    joint_w: Vec<Vector3<f64>>,
    joint_p_dot: Vec<Vector3<f64>>,
    /// Per count m of joints before a parameter: `Σ (J_j × o_j + J^ω_j × o'_j)` over the
    /// parameters with `joints_before = m` and `Σ o_j × J^ω_j` over those with
    /// `joints_up_to = m`; then summed into per-rank totals (suffix and prefix sums).
    after: Vec<Vector3<f64>>,
    before: Vec<Vector3<f64>>,
    /// Per joint: the derivative before the joint corrections' chain rule.
    uncorrected: Vec<f64>,
}

impl AlongWorkspace {
    /// Buffers for `model`.
    pub fn new(model: &Model) -> Self {
        let dof = model.dof();
        let order = ChainOrder::new(model);
        let count = |keep: &dyn Fn(usize) -> bool| order.joint.iter().filter(|&&o| keep(o)).count();
        AlongWorkspace {
            joint_rank: order.joint.iter().map(|&o| count(&|x| x < o)).collect(),
            joints_before: order.param.iter().map(|&o| count(&|x| x < o)).collect(),
            joints_up_to: order.param.iter().map(|&o| count(&|x| x <= o)).collect(),
            same_joint: order
                .param
                .iter()
                .map(|&o| order.joint.iter().position(|&x| x == o))
                .collect(),
            joint_w: vec![Vector3::zeros(); dof],
            joint_p_dot: vec![Vector3::zeros(); dof],
            after: vec![Vector3::zeros(); dof + 1],
            before: vec![Vector3::zeros(); dof + 1],
            uncorrected: vec![0.0; dof],
        }
    }
}

/// Adds `Σ_{r,c} Ω_{row+r, c} ∂J_rc/∂q_k` to `out[k]` for every joint k, where `J` is the
/// identification Jacobian of `obs` (`rows`, one column per entry of `columns`, as
/// [`crate::model::identification_jacobian`] writes it) and Ω is `weight`'s rows
/// `row..row + rows.count()`. Requires `data` from [`crate::model::forward_kinematics`] at
/// the configuration; allocates nothing.
#[allow(clippy::too_many_arguments)]
pub fn identification_jacobian_dq_along(
    model: &Model,
    ws: &mut AlongWorkspace,
    data: &Data<f64>,
    obs: Observed,
    rows: Rows,
    columns: &[usize],
    weight: &DMatrix<f64>,
    row: usize,
    out: &mut [f64],
) {
    let dof = model.dof();
    let p = observed_world(data, obs).trans;
    let rt: Matrix3<f64> = data.instrument.rot.transpose();
    joint_motions(data, &p, &mut ws.joint_w, &mut ws.joint_p_dot);
    ws.after.fill(Vector3::zeros());
    ws.before.fill(Vector3::zeros());
    ws.uncorrected.fill(0.0);
    let weights_of = |c: usize| {
        let o = Vector3::new(weight[(row, c)], weight[(row + 1, c)], weight[(row + 2, c)]);
        let o_rot = if rows == Rows::Pose {
            Vector3::new(
                weight[(row + 3, c)],
                weight[(row + 4, c)],
                weight[(row + 5, c)],
            )
        } else {
            Vector3::zeros()
        };
        (o, o_rot)
    };
    for (c, &j) in columns.iter().enumerate() {
        let s = influence(model.registry.get(j).segment, obs);
        if s == 0.0 {
            continue;
        }
        let (o, o_rot) = weights_of(c);
        let twist = &data.param_twists[j];
        let col = rt * twist.point_velocity(&p) * s;
        let col_w = rt * twist.w * s;
        let after = col.cross(&o) + col_w.cross(&o_rot);
        let before = o.cross(&col_w);
        // Joint k acts before parameter j when rank_k < joints_before[j], after it when
        // rank_k ≥ joints_up_to[j].
        ws.after[ws.joints_before[j]] += after;
        ws.before[ws.joints_up_to[j]] += before;
        if let Some(k) = ws.same_joint[j] {
            let rate = &data.param_twist_rates[j];
            let d_pos = rt * rate.point_velocity(&p) * s + col_w.cross(&ws.joint_p_dot[k]);
            ws.uncorrected[k] += o.dot(&d_pos) + o_rot.dot(&(rt * rate.w * s));
        }
    }
    for m in (0..dof).rev() {
        let later = ws.after[m + 1];
        ws.after[m] += later;
    }
    for m in 1..=dof {
        let earlier = ws.before[m - 1];
        ws.before[m] += earlier;
    }
    for (k, (x, &rank)) in out.iter_mut().zip(&ws.joint_rank).enumerate() {
        ws.uncorrected[k] +=
            ws.joint_w[k].dot(&ws.after[rank + 1]) + ws.joint_p_dot[k].dot(&ws.before[rank]);
        *x += ws.uncorrected[k];
    }
    let Some(state) = &data.corrections else {
        return;
    };
    // ∂J/∂q_k gains Σ_l θ_t ∂f_t/∂q_k ∂J/∂q̃_l (the uncorrected sums), and the column of
    // θ_t gains (∂f_t/∂q_k) J̃_i, joint i's column.
    for (_, joint, k, a) in state.rates() {
        out[k] += a * ws.uncorrected[joint];
    }
    for (t, (param, joint)) in model.joint_corrections().enumerate() {
        let Some(c) = columns.iter().position(|&j| j == param) else {
            continue;
        };
        let (o, o_rot) = weights_of(c);
        let along = o.dot(&ws.joint_p_dot[joint]) + o_rot.dot(&ws.joint_w[joint]);
        for (k, x) in out.iter_mut().enumerate().take(dof) {
            *x += state.basis_rate[t * dof + k] * along;
        }
    }
}
