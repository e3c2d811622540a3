//! Exact derivatives of what an instrument measures.
//!
//! * identification Jacobian (w.r.t. model parameters) from the world twists of
//!   [`forward_kinematics`]: the column of parameter j is `±R_Iᵀ (ω_j × p + v_j)` for a
//!   position and `±R_Iᵀ ω_j` for an orientation (book §2.4–2.5 differential transforms,
//!   book eqs. 4.14–4.20); instrument parameters enter with the minus sign because the
//!   measurement is `T_I⁻¹ T_target` (paper eq. 3);
//! * joint (geometric) Jacobian w.r.t. q;
//! * the mixed derivative ∂/∂q of the identification Jacobian, by forward-mode dual numbers
//!   through the same generic code (for the pose-design gradients).

use crate::model::chain::Model;
use crate::model::kinematics::{forward_kinematics, Data};
use crate::model::pose::Pose;
use crate::model::registry::Segment;
use nalgebra::{DMatrix, Matrix3, RealField, Vector3};
use num_dual::Dual64;
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
fn influence(segment: Segment, obs: Observed) -> f64 {
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
/// velocity of its origin, rows 3–5 its angular velocity, one column per joint.
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
    j
}

/// Workspace for [`identification_jacobian_dq`]: dual-number buffers sized for a model and
/// a column set, reused across calls.
pub struct MixedWorkspace {
    data: Data<Dual64>,
    q: Vec<Dual64>,
    jac: DMatrix<Dual64>,
}

impl MixedWorkspace {
    pub fn new(model: &Model, rows: Rows, columns: usize) -> Self {
        MixedWorkspace {
            data: Data::new(model),
            q: vec![Dual64::from(0.0); model.dof()],
            jac: DMatrix::from_element(rows.count(), columns, Dual64::from(0.0)),
        }
    }
}

/// The identification Jacobian `J` (into `value`) and its derivatives `∂J/∂q_j` (into
/// `dq[j]`, one matrix per joint), by forward-mode dual numbers: one dual pass per joint
/// through the same code as [`identification_jacobian`].
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
    for (j, dqj) in dq.iter_mut().enumerate().take(model.dof()) {
        for (i, qi) in ws.q.iter_mut().enumerate() {
            *qi = Dual64::new(q[i], if i == j { 1.0 } else { 0.0 });
        }
        forward_kinematics(model, &mut ws.data, params, &ws.q);
        identification_jacobian(model, &ws.data, obs, rows, columns, &mut ws.jac, 0);
        for (d, x) in dqj.iter_mut().zip(ws.jac.iter()) {
            *d = x.eps;
        }
        if j == 0 {
            for (v, x) in value.iter_mut().zip(ws.jac.iter()) {
                *v = x.re;
            }
        }
    }
}
