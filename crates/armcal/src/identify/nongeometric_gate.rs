//! The identifiability gate of the non-geometric terms (issue 14 item 3): joint compliance
//! ([`crate::model::compliance`]) and periodic joint errors ([`crate::model::periodic`]). A
//! term can be as well determined as any parameter and still be the same function as the
//! geometry, or as another term, over the measured poses (a small arm, a narrow joint range;
//! the first harmonic of a shoulder and its compliance under an elbow mass). For each free
//! term, from the whitened Jacobian `F` of the fit and `C_p = (FᵀF)⁻¹`:
//!
//! * σ, √C_p of the term;
//! * its largest correlation |ρ| with another free parameter (geometric or not);
//! * the **unabsorbed share** `‖(I − P_O) f‖ / ‖f‖`, `f` the term's whitened column and `P_O`
//!   the projector on the span of every other free column: the part of its effect no change
//!   of the other parameters reproduces (1: orthogonal to them, 0: a combination of them);
//! * for a compliance, the sign: κ ≥ 0 is an arm sagging under gravity; an estimate below
//!   −2σ is an arm rising against it, a term that absorbs something other than compliance.
//!
//! A term is **separable** when its unabsorbed share is at least [`MIN_UNABSORBED`] and its
//! largest correlation below [`MAX_CORRELATION`] (the real arms where the terms
//! bought nothing had |ρ| ≥ 0.99). A fit with `free = "auto"` drops a term that is not
//! separable, names it and fits again ([`crate::identify::identify`]).

use crate::model::{Model, Registry, Unit};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// Smallest unabsorbed share of a separable term.
pub const MIN_UNABSORBED: f64 = 0.05;
/// Largest |ρ| with another free parameter of a separable term.
pub const MAX_CORRELATION: f64 = 0.99;

/// What the gate says of one non-geometric term.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TermVerdict {
    /// Parameter name (`j2.compliance.wrist`, `j1.periodic.sin1`).
    pub name: String,
    /// Display unit of the estimate and σ (`µrad/m`, `arcsec`).
    pub unit: String,
    /// The estimate (display unit).
    pub estimate: f64,
    /// σ of the estimate (display unit).
    pub sigma: f64,
    /// The free parameter it is most correlated with, and ρ.
    pub most_correlated: Option<(String, f64)>,
    /// `‖(I − P_O) f‖ / ‖f‖` (see the module notes).
    pub unabsorbed: f64,
    /// A compliance with κ < −2σ: the arm rises against gravity.
    pub wrong_sign: bool,
    /// Unabsorbed share ≥ `MIN_UNABSORBED` (5 %) and |ρ| < `MAX_CORRELATION` (0.99).
    pub separable: bool,
}

impl TermVerdict {
    /// Why a term that is not separable is dropped, for the fixed parameters' reasons.
    pub fn reason(&self) -> String {
        let with = self
            .most_correlated
            .as_ref()
            .map_or(String::new(), |(n, rho)| format!(", ρ = {rho:.3} with {n}"));
        format!(
            "`{}` is not separable from the other parameters on these data: {:.1} % of its \
             effect is not absorbed by them (separable: ≥ {:.0} %, |ρ| < {MAX_CORRELATION}){with}",
            self.name,
            100.0 * self.unabsorbed,
            100.0 * MIN_UNABSORBED
        )
    }
}

/// The verdicts of the free non-geometric terms of `model`: `free` the registry indices of
/// the columns of `jacobian` (whitened data rows), `covariance` C_p and `params` the
/// estimate.
pub fn nongeometric_gate(
    model: &Model,
    free: &[usize],
    jacobian: &DMatrix<f64>,
    covariance: &DMatrix<f64>,
    params: &[f64],
) -> Vec<TermVerdict> {
    gate(
        &model.registry,
        |i| model.is_joint_correction(i),
        free,
        jacobian,
        covariance,
        params,
    )
}

/// [`nongeometric_gate`] for the parameters of `registry` that `is_term` says are
/// non-geometric terms (a serial model's joint corrections, a tree's compliance).
pub(crate) fn gate(
    registry: &Registry,
    is_term: impl Fn(usize) -> bool,
    free: &[usize],
    jacobian: &DMatrix<f64>,
    covariance: &DMatrix<f64>,
    params: &[f64],
) -> Vec<TermVerdict> {
    (0..free.len())
        .filter(|&k| is_term(free[k]))
        .map(|k| {
            let others: Vec<usize> = (0..free.len()).filter(|&o| o != k).collect();
            let q = if others.is_empty() {
                DMatrix::zeros(jacobian.nrows(), 0)
            } else {
                jacobian.select_columns(&others).qr().q()
            };
            let col = jacobian.column(k).into_owned();
            let rest = &col - &q * (q.transpose() * &col);
            let sigma = covariance[(k, k)].sqrt();
            let most_correlated = others
                .iter()
                .map(|&o| (o, covariance[(k, o)] / (sigma * covariance[(o, o)].sqrt())))
                .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
                .map(|(o, rho)| (registry.get(free[o]).name.clone(), rho));
            let norm = col.norm();
            let unabsorbed = if norm > 0.0 { rest.norm() / norm } else { 0.0 };
            let p = registry.get(free[k]);
            let f = p.unit.display_factor();
            let value = params[free[k]];
            let rho = most_correlated.as_ref().map_or(0.0, |m| m.1.abs());
            TermVerdict {
                name: p.name.clone(),
                unit: p.unit.display_name().into(),
                estimate: value * f,
                sigma: sigma * f,
                most_correlated,
                unabsorbed,
                wrong_sign: matches!(p.unit, Unit::RadPerMm | Unit::RadPerNmm)
                    && value < -2.0 * sigma,
                separable: unabsorbed >= MIN_UNABSORBED && rho < MAX_CORRELATION,
            }
        })
        .collect()
}
