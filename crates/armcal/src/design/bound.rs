//! A lower bound on the best achievable criterion for N poses, and a design's efficiency.
//!
//! For a criterion φ convex in M (A, D, E, KPI, O1, O3 as implemented), every N-point
//! design has `M ∈ M₀ + N · conv{I(x)}` with `I(x) = J(x)ᵀWJ(x)` over the configuration
//! space (the approximate-design relaxation, Kiefer–Wolfowitz). The supporting hyperplane
//! at the current design M̂ with gradient Φ = ∂φ/∂M gives, for every design,
//! `φ(M) ≥ φ(M̂) − ⟨Φ, M̂ − M₀⟩ + N · min_x ⟨Φ, I(x)⟩`,
//! i.e. the equivalence-theorem bound with the sensitivity function `d(x) = −⟨Φ, I(x)⟩`
//! maximised over the feasible configurations (joint limits and the cell's constraints) by
//! multi-start gradient ascent from the best feasible pool points, accepting only feasible
//! steps. The bound is valid up to that global maximisation, which multi-start
//! approximates: a missed maximum would make the bound too high, never too low.

use crate::design::criteria::{evaluate, Criterion};
use crate::design::information::{DesignModel, InformationWorkspace};
use crate::design::objective::{triangular_factor, DesignObjective};
use crate::Error;
use nalgebra::DMatrix;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// The bound and what it says about a design.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct OptimalityBound {
    /// The design's criterion value.
    pub value: f64,
    /// Lower bound on the criterion of any N-pose design.
    pub lower_bound: f64,
    /// `lower_bound / value` (A, E, KPI: 1 is optimal); for log-scale criteria (D, O1, O3)
    /// `exp(lower_bound − value)` ([`efficiency`]). `None` when the bound says nothing: a
    /// criterion of positive values (A, E, KPI) with a bound ≤ 0.
    pub efficiency: Option<f64>,
    /// Largest sensitivity found and where.
    pub max_sensitivity: f64,
    /// The configuration (joint values, internal units: rad, mm) where `max_sensitivity` was
    /// found.
    pub argmax: Vec<f64>,
}

/// Whether the bound applies (criterion convex in M).
pub fn has_bound(c: Criterion) -> bool {
    matches!(
        c,
        Criterion::A
            | Criterion::D
            | Criterion::E
            | Criterion::Kpi
            | Criterion::KpiMax
            | Criterion::O1
            | Criterion::O3
    )
}

/// A design's efficiency against the lower bound `lower` of its criterion `c`: `lower / value`
/// for the criteria of positive values (A, E, KPI, KPI-max; `None` when `lower ≤ 0`, a bound that says
/// nothing), `exp(lower − value)` for the log-scale ones (D, O1, O3).
pub fn efficiency(c: Criterion, lower: f64, value: f64) -> Option<f64> {
    match c {
        Criterion::A | Criterion::E | Criterion::Kpi | Criterion::KpiMax => {
            (lower > 0.0).then(|| lower / value)
        }
        _ => Some((lower - value).exp()),
    }
}

/// Sensitivity `d(x) = −⟨Φ, I(x)⟩ = −tr(J Φ Jᵀ)` and its gradient w.r.t. x.
fn sensitivity(
    d: &DesignModel,
    ws: &mut InformationWorkspace,
    phi: &DMatrix<f64>,
    x: &[f64],
    grad: Option<&mut [f64]>,
) -> f64 {
    d.jacobian(ws, x);
    let b = &ws.jac * phi;
    if let Some(g) = grad {
        d.jacobian_dq_along(&ws.data, &mut ws.along, &b, g);
        g.iter_mut().for_each(|gj| *gj *= -2.0);
    }
    -b.dot(&ws.jac)
}

/// The bound for `design` (N configurations) under `objective`, maximising the sensitivity
/// from the `starts` best points of `pool` (plus the design's own points); the ascents run
/// in parallel, each with a feasibility test made by `make_feasible`.
pub fn optimality_bound<F: FnMut(&[f64]) -> bool>(
    objective: &DesignObjective,
    design: &[Vec<f64>],
    pool: &[Vec<f64>],
    starts: usize,
    make_feasible: impl Fn() -> F + Sync,
) -> Result<OptimalityBound, Error> {
    let d = objective.design;
    if !has_bound(objective.criterion) {
        return Err(Error::Input(format!(
            "no optimality bound for {:?}: the criterion is not convex in the information matrix",
            objective.criterion
        )));
    }
    let rows = d.rows();
    let np = objective.prior_rows.nrows();
    let mut a = DMatrix::zeros(np + rows * design.len(), d.n());
    a.rows_mut(0, np).copy_from(&objective.prior_rows);
    let mut ws = InformationWorkspace::new(d);
    for (i, q) in design.iter().enumerate() {
        d.jacobian(&mut ws, q);
        a.rows_mut(np + rows * i, rows).copy_from(&ws.jac);
    }
    let cv = evaluate(objective.criterion, &triangular_factor(a.clone()), d)?;
    let phi = &cv.gradient;
    let m_design = {
        let b = a.rows(np, a.nrows() - np);
        b.tr_mul(&b)
    };
    let inner = phi.dot(&m_design);
    // Multi-start: rank pool and design points by sensitivity, ascend from the best.
    let mut scored: Vec<(f64, Vec<f64>)> = pool
        .iter()
        .chain(design)
        .map(|x| (sensitivity(d, &mut ws, phi, x, None), x.clone()))
        .collect();
    scored.sort_by(|p, q| q.0.total_cmp(&p.0));
    let (lo, hi) = d.model.joint_limits();
    let k = lo.len();
    let ascents: Vec<(f64, Vec<f64>)> = scored[..starts.max(1).min(scored.len())]
        .par_iter()
        .map_init(
            || (InformationWorkspace::new(d), vec![0.0; k], make_feasible()),
            |(ws, g, feasible), (s0, x0)| {
                let (mut s, mut x) = (*s0, x0.clone());
                let mut step = 0.05;
                for _ in 0..200 {
                    sensitivity(d, ws, phi, &x, Some(g));
                    let gn = g.iter().map(|v| v * v).sum::<f64>().sqrt();
                    if gn == 0.0 {
                        break;
                    }
                    let trial: Vec<f64> = (0..k)
                        .map(|j| (x[j] + step * g[j] / gn).clamp(lo[j], hi[j]))
                        .collect();
                    let st = sensitivity(d, ws, phi, &trial, None);
                    if st > s && feasible(&trial) {
                        s = st;
                        x = trial;
                        step *= 1.5;
                    } else {
                        step *= 0.3;
                        if step < 1e-7 {
                            break;
                        }
                    }
                }
                (s, x)
            },
        )
        .collect();
    // The first of the largest, in the order of the starts (as a serial run would pick).
    let mut best = scored[0].clone();
    for (s, x) in ascents {
        if s > best.0 {
            best = (s, x);
        }
    }
    let n = design.len() as f64;
    let lower = cv.value - inner - n * best.0;
    Ok(OptimalityBound {
        value: cv.value,
        lower_bound: lower,
        efficiency: efficiency(objective.criterion, lower, cv.value),
        max_sensitivity: best.0,
        argmax: best.1,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bound_that_is_not_positive_gives_no_efficiency() {
        assert_eq!(efficiency(Criterion::Kpi, 0.3, 0.6), Some(0.5));
        assert_eq!(efficiency(Criterion::Kpi, -0.52, 0.6), None);
        assert_eq!(efficiency(Criterion::A, 0.0, 0.6), None);
        // Log-scale criteria: any real bound means something.
        let e = efficiency(Criterion::D, -3.0, -2.0).unwrap();
        assert!((e - (-1f64).exp()).abs() < 1e-15);
    }
}
