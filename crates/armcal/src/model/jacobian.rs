//! Exact derivatives of what an instrument measures.
//!
//! * identification Jacobian (w.r.t. model parameters) from the world twists of
//!   [`forward_kinematics`]: the column of parameter j is `±R_Iᵀ (ω_j × p + v_j)` for a
//!   position and `±R_Iᵀ ω_j` for an orientation (book §2.4–2.5 differential transforms,
//!   book eqs. 4.14–4.20); instrument parameters enter with the minus sign because the
//!   measurement is `T_I⁻¹ T_target` (paper eq. 3);
//! * joint (geometric) Jacobian w.r.t. q;
//! * the mixed derivative ∂/∂q of the identification Jacobian, analytic from the same
//!   twists (Lie brackets of joint and parameter twists), for the pose-design gradients.

use crate::model::chain::{Model, Step};
use crate::model::joint_correction::commanded_columns;
use crate::model::kinematics::{forward_kinematics, Data};
use crate::model::pose::Pose;
use crate::model::registry::Segment;
use nalgebra::{DMatrix, Matrix3, RealField, Vector3};
use serde::{Deserialize, Serialize};

/// The point or frame a measurement observes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Observed {
    /// Target `k` of the model (reflector, SMR, tooling-ball frame...).
    Target(usize),
    /// The tool frame (the TCP; the paper's KPI).
    Tool,
}

/// Which rows a measurement has.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Rows {
    /// Position, 3 rows (x, y, z in the instrument frame).
    Position,
    /// Position and a small rotation vector, 6 rows (book's 6-D pose residual).
    Pose,
}

impl Rows {
    /// Rows per observation: 3 for position, 6 for pose.
    pub fn count(self) -> usize {
        match self {
            Rows::Position => 3,
            Rows::Pose => 6,
        }
    }
}

/// World pose of the observed frame.
pub fn observed_world<T: RealField + Copy>(data: &Data<T>, obs: Observed) -> &Pose<T> {
    match obs {
        Observed::Target(k) => &data.targets[k],
        Observed::Tool => data.tool(),
    }
}

/// Pose of the observed frame in the instrument frame (what the instrument reports).
pub fn observed_pose<T: RealField + Copy>(data: &Data<T>, obs: Observed) -> Pose<T> {
    data.instrument.inverse().compose(observed_world(data, obs))
}

/// Position of the observed point in the instrument frame.
pub fn observed_position<T: RealField + Copy>(data: &Data<T>, obs: Observed) -> Vector3<T> {
    let w = observed_world(data, obs);
    data.instrument.rot.transpose() * (w.trans - data.instrument.trans)
}

/// Sign with which a parameter moves the observed frame (0 if it does not).
#[inline]
pub(crate) fn influence(segment: Segment, obs: Observed) -> f64 {
    match (segment, obs) {
        (Segment::Instrument, _) => -1.0,
        (Segment::Chain, _) => 1.0,
        (Segment::Target(k), Observed::Target(o)) if k == o => 1.0,
        _ => 0.0,
    }
}

/// Writes the identification Jacobian of the observed position (3 rows) or pose (6 rows)
/// into `out` at rows `row..row+rows`, one column per entry of `columns` (a parameter index
/// each). Requires `data` from [`forward_kinematics`]. Allocates nothing.
pub fn identification_jacobian<T: RealField + Copy>(
    model: &Model,
    data: &Data<T>,
    obs: Observed,
    rows: Rows,
    columns: &[usize],
    out: &mut DMatrix<T>,
    row: usize,
) {
    let p = observed_world(data, obs).trans;
    let rt: Matrix3<T> = data.instrument.rot.transpose();
    for (c, &j) in columns.iter().enumerate() {
        let s = influence(model.registry.get(j).segment, obs);
        if s == 0.0 {
            for r in 0..rows.count() {
                out[(row + r, c)] = T::zero();
            }
            continue;
        }
        let s: T = nalgebra::convert(s);
        let tw = &data.param_twists[j];
        let dp = rt * tw.point_velocity(&p) * s;
        out[(row, c)] = dp[0];
        out[(row + 1, c)] = dp[1];
        out[(row + 2, c)] = dp[2];
        if rows == Rows::Pose {
            let dw = rt * tw.w * s;
            out[(row + 3, c)] = dw[0];
            out[(row + 4, c)] = dw[1];
            out[(row + 5, c)] = dw[2];
        }
    }
}

/// Geometric joint Jacobian of the observed frame in the world frame: rows 0–2 the
/// velocity of its origin, rows 3–5 its angular velocity, one column per joint. With joint
/// corrections (compliance, periodic errors), w.r.t. the commanded joints: `J̃ ∂(q + Δq)/∂q`.
pub fn joint_jacobian<T: RealField + Copy>(data: &Data<T>, obs: Observed) -> DMatrix<T> {
    let p = observed_world(data, obs).trans;
    let n = data.joint_twists.len();
    let mut j = DMatrix::zeros(6, n);
    for (c, tw) in data.joint_twists.iter().enumerate() {
        let v = tw.point_velocity(&p);
        for r in 0..3 {
            j[(r, c)] = v[r];
            j[(r + 3, c)] = tw.w[r];
        }
    }
    if let Some(c) = &data.corrections {
        commanded_columns(c, &mut j);
    }
    j
}

/// Where every parameter and joint acts along the chain (what can move what): instrument
/// factors 0, chain factor i → i + 1, target factors `usize::MAX`; a joint correction θ_t
/// acts where its joint acts.
#[derive(Clone, Debug)]
pub struct ChainOrder {
    /// Per parameter.
    pub param: Vec<usize>,
    /// Per joint.
    pub joint: Vec<usize>,
}

impl ChainOrder {
    /// The chain positions of `model`'s parameters and joints.
    pub fn new(model: &Model) -> Self {
        let mut param = vec![0; model.param_count()];
        let mut joint = vec![0; model.dof()];
        let mut mark = |step: &Step, order: usize| {
            let (params, j) = match step {
                Step::Elementary { param, joint, .. } => (*param..*param + 1, *joint),
                Step::Screw { first, joint, .. } => (*first..*first + 7, *joint),
            };
            for p in params {
                param[p] = order;
            }
            if let Some(j) = j {
                joint[j] = order;
            }
        };
        for step in &model.instrument_steps {
            mark(step, 0);
        }
        for (i, step) in model.chain_steps.iter().enumerate() {
            mark(step, i + 1);
        }
        for step in model.target_steps.iter().flatten() {
            mark(step, usize::MAX);
        }
        // θ_t turns joint i: it acts where joint i acts, with no rate of its own
        for (p, j) in model.joint_corrections() {
            param[p] = joint[j];
        }
        ChainOrder { param, joint }
    }
}

/// Per joint, in the instrument frame: `R_Iᵀ ω_k` into `joint_w` and the velocity of the
/// point `p` (world), `R_Iᵀ ṗ = R_Iᵀ (ω_k × p + v_k)`, into `joint_p_dot`.
pub(crate) fn joint_motions(
    data: &Data<f64>,
    p: &Vector3<f64>,
    joint_w: &mut [Vector3<f64>],
    joint_p_dot: &mut [Vector3<f64>],
) {
    let rt: Matrix3<f64> = data.instrument.rot.transpose();
    for ((jk, w), p_dot) in data.joint_twists.iter().zip(joint_w).zip(joint_p_dot) {
        *w = rt * jk.w;
        *p_dot = rt * jk.point_velocity(p);
    }
}

/// Workspace for [`identification_jacobian_dq`]: kinematics buffers and, for every
/// parameter and joint, the position of its factor along the chain (what can move what).
pub struct MixedWorkspace {
    data: Data<f64>,
    order: ChainOrder,
    /// Per joint, in the instrument frame: `R_Iᵀ ω_k` and the point's velocity `R_Iᵀ ṗ`.
    joint_w: Vec<Vector3<f64>>,
    joint_p_dot: Vec<Vector3<f64>>,
    /// With joint corrections: per joint, its derivative matrix w.r.t. the corrected joint.
    deflected: Vec<DMatrix<f64>>,
}

impl MixedWorkspace {
    /// Buffers sized for `model`, with every parameter's and joint's chain position.
    pub fn new(model: &Model) -> Self {
        MixedWorkspace {
            data: Data::new(model),
            order: ChainOrder::new(model),
            joint_w: vec![Vector3::zeros(); model.dof()],
            joint_p_dot: vec![Vector3::zeros(); model.dof()],
            deflected: Vec::new(),
        }
    }
}

/// The identification Jacobian `J` (into `value`) and its derivatives `∂J/∂q_k` (into
/// `dq[k]`, one matrix per joint) in one forward-kinematics pass.
///
/// With `ξ_k = (ω_k, v_k)` the world twist of joint k, `ξ_j = (ω_j, v_j)` that of parameter
/// j and `c_j = ω_j × p + v_j` its world position column (the J column is `s R_Iᵀ c_j`):
/// * parameter j acts after joint k: everything beyond joint k turns rigidly with it, so
///   `ξ̇_j = [ξ_k, ξ_j] = (ω_k × ω_j, ω_k × v_j + v_k × ω_j)` (book §2.4–2.5) and, with
///   `ṗ = ω_k × p + v_k` and the Jacobi identity, `ċ_j = ω̇_j × p + ω_j × ṗ + v̇_j = ω_k × c_j`;
/// * parameter j acts before joint k: its twist is fixed and only the point moves,
///   `ċ_j = ω_j × ṗ`;
/// * both in one zero-reference screw: `ċ_j = ω̇_j × p + v̇_j + ω_j × ṗ` with `ξ̇_j` the
///   factor's own rate ([`Data::param_twist_rates`]).
///
/// Rotations commute with cross products, so in the instrument frame each entry is one
/// cross product: `∂J_j/∂q_k = (R_Iᵀω_k) × J_j` or `J^ω_j × (R_Iᵀ ṗ)` with
/// `J^ω_j = s R_Iᵀ ω_j` (the orientation column). Orientation rows: `(R_Iᵀω_k) × J^ω_j`
/// after joint k, the screw's `s R_Iᵀ ω̇_j`, zero before.
///
/// With joint corrections (`crate::model::joint_correction`: compliance, periodic errors)
/// the chain runs at `q̃ = q + Δq(q)`, so
/// `∂J/∂q_k = Σ_l ∂J/∂q̃_l (δ_lk + Σ_{t: joint l} θ_t ∂f_t/∂q_k)`, and the column of θ_t,
/// `f_t J̃_i` (joint i's column scaled by the basis), gains `(∂f_t/∂q_k) J̃_i`. Allocates
/// nothing after the first call with a given shape.
#[allow(clippy::too_many_arguments)]
pub fn identification_jacobian_dq(
    model: &Model,
    ws: &mut MixedWorkspace,
    params: &[f64],
    q: &[f64],
    obs: Observed,
    rows: Rows,
    columns: &[usize],
    value: &mut DMatrix<f64>,
    dq: &mut [DMatrix<f64>],
) {
    forward_kinematics(model, &mut ws.data, params, q);
    identification_jacobian(model, &ws.data, obs, rows, columns, value, 0);
    let data = &ws.data;
    let p = observed_world(data, obs).trans;
    let rt: Matrix3<f64> = data.instrument.rot.transpose();
    joint_motions(data, &p, &mut ws.joint_w, &mut ws.joint_p_dot);
    for (c, &j) in columns.iter().enumerate() {
        let s = influence(model.registry.get(j).segment, obs);
        let order_j = ws.order.param[j];
        let w_j = rt * data.param_twists[j].w * s;
        let col = Vector3::new(value[(0, c)], value[(1, c)], value[(2, c)]);
        for (k, out) in dq.iter_mut().enumerate().take(model.dof()) {
            let (w_k, p_dot) = (&ws.joint_w[k], &ws.joint_p_dot[k]);
            let order_k = ws.order.joint[k];
            let (d_pos, d_rot) = if s == 0.0 {
                (Vector3::zeros(), Vector3::zeros())
            } else if order_j > order_k {
                (w_k.cross(&col), w_k.cross(&w_j))
            } else if order_j == order_k {
                let rate = &data.param_twist_rates[j];
                (
                    rt * rate.point_velocity(&p) * s + w_j.cross(p_dot),
                    rt * rate.w * s,
                )
            } else {
                (w_j.cross(p_dot), Vector3::zeros())
            };
            out[(0, c)] = d_pos[0];
            out[(1, c)] = d_pos[1];
            out[(2, c)] = d_pos[2];
            if rows == Rows::Pose {
                out[(3, c)] = d_rot[0];
                out[(4, c)] = d_rot[1];
                out[(5, c)] = d_rot[2];
            }
        }
    }
    if let Some(state) = &data.corrections {
        let dof = model.dof();
        ws.deflected.resize(dof, DMatrix::zeros(0, 0));
        for (d, src) in ws.deflected.iter_mut().zip(dq.iter()) {
            d.clone_from(src);
        }
        for (_, joint, k, a) in state.rates() {
            dq[k] += &ws.deflected[joint] * a;
        }
        for (c, &j) in columns.iter().enumerate() {
            let Some((t, (_, joint))) = model
                .joint_corrections()
                .enumerate()
                .find(|(_, (param, _))| *param == j)
            else {
                continue;
            };
            let (w, p_dot) = (ws.joint_w[joint], ws.joint_p_dot[joint]);
            for (k, out) in dq.iter_mut().enumerate().take(dof) {
                let rate = state.basis_rate[t * dof + k];
                for r in 0..3 {
                    out[(r, c)] += p_dot[r] * rate;
                }
                if rows == Rows::Pose {
                    for r in 0..3 {
                        out[(3 + r, c)] += w[r] * rate;
                    }
                }
            }
        }
    }
}
