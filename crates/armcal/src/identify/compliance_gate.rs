//! The identifiability gate of the compliance terms ([`crate::model::compliance`], issue 14
//! item 3): a lumped term can be as well determined as any parameter and still be the same
//! function as the geometry over the measured poses (a small arm, a narrow joint range). For
//! each free term, from the whitened Jacobian `F` of the fit and `C_p = (FᵀF)⁻¹`:
//!
//! * σ, √C_p of the term;
//! * its largest correlation |ρ| with a geometric (non-compliance) free parameter;
//! * the **unabsorbed share** `‖(I − P_G) f‖ / ‖f‖`, `f` the term's whitened column and `P_G`
//!   the projector on the span of the geometric columns: the part of its effect no change of
//!   the geometry reproduces (1: orthogonal to the geometry, 0: a combination of it);
//! * the sign: κ ≥ 0 is an arm sagging under gravity; an estimate below −2σ is an arm rising
//!   against it, a term that absorbs something other than compliance.
//!
//! A term is **separable** when its unabsorbed share is at least [`MIN_UNABSORBED`] and its
//! largest correlation below [`MAX_CORRELATION`] (the real arms where the terms
//! bought nothing had |ρ| ≥ 0.99).

use crate::model::Model;
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// Smallest unabsorbed share of a separable term.
pub const MIN_UNABSORBED: f64 = 0.05;
/// Largest |ρ| with a geometric parameter of a separable term.
pub const MAX_CORRELATION: f64 = 0.99;

/// What the gate says of one compliance term.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ComplianceVerdict {
    /// Parameter name (`q2.compliance.wrist`).
    pub name: String,
    /// Estimate κ (µrad/m).
    pub estimate_urad_per_m: f64,
    /// σ of κ (µrad/m).
    pub sigma_urad_per_m: f64,
    /// The geometric free parameter it is most correlated with, and ρ.
    pub most_correlated: Option<(String, f64)>,
    /// `‖(I − P_G) f‖ / ‖f‖` (see the module notes).
    pub unabsorbed: f64,
    /// κ < −2σ: the arm rises against gravity.
    pub wrong_sign: bool,
    /// Unabsorbed share ≥ [`MIN_UNABSORBED`] and |ρ| < [`MAX_CORRELATION`].
    pub separable: bool,
}

/// The verdicts of the free compliance terms of `model`: `free` the registry indices of the
/// columns of `jacobian` (whitened data rows), `covariance` C_p and `params` the estimate.
pub fn compliance_gate(
    model: &Model,
    free: &[usize],
    jacobian: &DMatrix<f64>,
    covariance: &DMatrix<f64>,
    params: &[f64],
) -> Vec<ComplianceVerdict> {
    let Some(c) = &model.compliance else {
        return Vec::new();
    };
    let (terms, geometric): (Vec<usize>, Vec<usize>) =
        (0..free.len()).partition(|&k| c.is_term(free[k]));
    if terms.is_empty() {
        return Vec::new();
    }
    let g = jacobian.select_columns(&geometric);
    let q = if geometric.is_empty() {
        DMatrix::zeros(jacobian.nrows(), 0)
    } else {
        g.qr().q()
    };
    let f = model.registry.get(free[terms[0]]).unit.display_factor();
    terms
        .iter()
        .map(|&k| {
            let col = jacobian.column(k).into_owned();
            let rest = &col - &q * (q.transpose() * &col);
            let sigma = covariance[(k, k)].sqrt();
            let most_correlated = geometric
                .iter()
                .map(|&o| (o, covariance[(k, o)] / (sigma * covariance[(o, o)].sqrt())))
                .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
                .map(|(o, rho)| (model.registry.get(free[o]).name.clone(), rho));
            let unabsorbed = rest.norm() / col.norm();
            let kappa = params[free[k]];
            let rho = most_correlated.as_ref().map_or(0.0, |m| m.1.abs());
            ComplianceVerdict {
                name: model.registry.get(free[k]).name.clone(),
                estimate_urad_per_m: kappa * f,
                sigma_urad_per_m: sigma * f,
                most_correlated,
                unabsorbed,
                wrong_sign: kappa < -2.0 * sigma,
                separable: unabsorbed >= MIN_UNABSORBED && rho < MAX_CORRELATION,
            }
        })
        .collect()
}
