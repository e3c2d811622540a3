//! Joint-space corrections: the non-geometric terms of issue 14 — joint compliance under
//! gravity ([`crate::model::compliance`]) and periodic joint errors
//! ([`crate::model::periodic`]) — share one form,
//!
//! `q̃ = q + Δq(q)`, `Δq_i = Σ_{t: joint i} θ_t f_t(q)`,
//!
//! a parameter `θ_t` times a known function `f_t` of the commanded joints (a compliance's
//! lever, a harmonic). The chain is evaluated at `q̃`; the identification column of `θ_t` is
//! `f_t` times joint `i`'s column (its world twist `f_t ξ_i`), the joint Jacobian w.r.t. the
//! commanded joints is `J̃ (I + Σ_t θ_t e_i ∇f_tᵀ)` and the mixed derivative gains the chain
//! rule through `q̃` ([`crate::model::identification_jacobian_dq`]). This module holds the
//! per-evaluation state every term fills, and the chain rule.

use crate::model::chain::Model;
use crate::model::compliance::ComplianceData;
use crate::model::link::{Joint, JointKind};
use crate::model::pose::Twist;
use nalgebra::{convert, DMatrix, RealField};

/// The per-evaluation state of a model's joint corrections ([`crate::model::Data`]); terms
/// in registry order (compliance, then periodic: [`Model::joint_corrections`]).
#[derive(Clone, Debug)]
pub struct CorrectionData<T: RealField + Copy> {
    /// The compliance's lever pass; `None` without compliance.
    pub compliance: Option<ComplianceData<T>>,
    /// The corrected joints `q + Δq` at which the chain is evaluated.
    pub q: Vec<T>,
    /// Per term, `f_t(q)` (a lever in mm, a harmonic).
    pub basis: Vec<T>,
    /// Per term and joint (row-major, `term · dof + k`), `∂f_t/∂q_k`.
    pub basis_rate: Vec<T>,
    /// Per term, `θ_t` and the index of the joint it turns.
    pub value: Vec<(T, usize)>,
}

impl<T: RealField + Copy> CorrectionData<T> {
    /// Buffers for `model`; `None` for a model without joint corrections.
    pub(crate) fn new(model: &Model) -> Option<Self> {
        let n = model.joint_corrections().count();
        (n > 0).then(|| CorrectionData {
            compliance: model
                .compliance
                .as_ref()
                .map(|c| ComplianceData::new(model, c)),
            q: vec![T::zero(); model.dof()],
            basis: vec![T::zero(); n],
            basis_rate: vec![T::zero(); n * model.dof()],
            value: vec![(T::zero(), 0); n],
        })
    }

    /// Every term's basis, its q-derivatives and value at `q` with `payload` carried (an
    /// index into [`Model::payloads`]), and the corrected joints.
    pub(crate) fn evaluate(
        &mut self,
        model: &Model,
        params: &[f64],
        q: &[T],
        payload: Option<usize>,
    ) {
        let dof = model.dof();
        let mut t = 0;
        if let (Some(c), Some(state)) = (&model.compliance, &mut self.compliance) {
            let n = c.terms.len();
            state.evaluate(
                model,
                c,
                q,
                payload,
                &mut self.basis[..n],
                &mut self.basis_rate[..n * dof],
            );
            t = n;
        }
        for term in &model.periodic {
            let (f, rate) = term.basis(q);
            self.basis[t] = f;
            let row = &mut self.basis_rate[t * dof..(t + 1) * dof];
            row.iter_mut().for_each(|x| *x = T::zero());
            row[term.joint] = rate;
            t += 1;
        }
        self.q.copy_from_slice(q);
        for (t, (param, joint)) in model.joint_corrections().enumerate() {
            let theta: T = convert(params[param]);
            self.value[t] = (theta, joint);
            self.q[joint] += theta * self.basis[t];
        }
    }

    /// Writes the correction parameters' twists into `data` (after the corrected pass): a
    /// unit change of θ_t turns joint i by f_t, so its twist is `f_t ξ_i`, and it has no
    /// rate of its own.
    pub(crate) fn set_twists(
        &self,
        model: &Model,
        data_twists: &mut [Twist<T>],
        joints: &[Twist<T>],
        rates: &mut [Twist<T>],
    ) {
        for (t, (param, joint)) in model.joint_corrections().enumerate() {
            let j = joints[joint];
            data_twists[param] = Twist {
                w: j.w * self.basis[t],
                v: j.v * self.basis[t],
            };
            rates[param] = Twist::zero();
        }
    }

    /// `θ_t ∂f_t/∂q_k` for every term `t` (with its joint) and joint `k`: the entries of
    /// `∂q̃/∂q − I`.
    pub(crate) fn rates(&self) -> impl Iterator<Item = (usize, usize, usize, T)> + '_ {
        let dof = self.q.len();
        self.value
            .iter()
            .enumerate()
            .flat_map(move |(t, &(theta, joint))| {
                (0..dof).map(move |k| (t, joint, k, theta * self.basis_rate[t * dof + k]))
            })
    }
}

/// `J_q = J̃ ∂q̃/∂q`: the derivative w.r.t. the commanded joints of columns `jac` given w.r.t.
/// the corrected joints (one column per joint), in place.
pub(crate) fn commanded_columns<T: RealField + Copy>(c: &CorrectionData<T>, jac: &mut DMatrix<T>) {
    let corrected = jac.clone_owned();
    for (_, joint, k, a) in c.rates() {
        for r in 0..jac.nrows() {
            jac[(r, k)] += corrected[(r, joint)] * a;
        }
    }
}

/// The indices of the joints `names` in chain order, for a correction `what` (`compliance`,
/// `periodic errors are`) modelled for revolute joints only; the error names an unknown,
/// prismatic or twice-listed joint.
pub(crate) fn revolute_joints(
    joints: &[Joint],
    names: &[String],
    what: &str,
) -> Result<Vec<usize>, String> {
    let known: Vec<&str> = joints.iter().map(|j| j.name.as_str()).collect();
    let mut index = Vec::new();
    for name in names {
        let i = known.iter().position(|n| n == name).ok_or_else(|| {
            format!(
                "unknown joint `{name}` (the robot's joints: {})",
                known.join(", ")
            )
        })?;
        if joints[i].kind == JointKind::Prismatic {
            return Err(format!(
                "joint `{name}` is prismatic; {what} modelled for revolute joints only"
            ));
        }
        if index.contains(&i) {
            return Err(format!("joint `{name}` is listed twice"));
        }
        index.push(i);
    }
    index.sort_unstable();
    Ok(index)
}
