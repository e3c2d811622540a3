//! Gauss–Newton as iterated linear least squares (book §4.3, eqs. 4.22–4.27): at each
//! iterate solve `J δ = −r` in the least-squares sense (column-scaled SVD) and step by
//! `α δ`, with α the first of 1, ½, ¼, … that satisfies the Armijo condition
//! `F(x + α δ) ≤ F(x) + c α ∇Fᵀδ`, `c = 10⁻⁴` (step halving, the damped Gauss–Newton
//! method of Dennis & Schnabel 1983, §6.3 and §10.2). Near the solution α = 1 and the
//! iteration is the book's undamped Gauss–Newton, which reaches the same estimate as
//! Levenberg–Marquardt (book: "identical").
//!
//! Stopping uses LM's rules on the full Gauss–Newton step `δ`, never on a shortened `α δ`:
//! the relative step in column-scaled variables, or actual and predicted relative cost
//! reductions both ≤ ftol. A direction along which no step lowers the cost is convergence
//! only at rounding level; otherwise the status says the iteration stalled.

use super::problem::Problem;
use super::solver::{
    gradient_cosine, no_decrease_status, Iterate, LeastSquares, SolverResult, ToleranceSettings,
};
use crate::progress::Observer;
use crate::solve::Status;
use crate::Error;
use nalgebra::DVector;
use std::time::Instant;

/// Armijo's sufficient-decrease constant.
const ARMIJO: f64 = 1e-4;
/// Step halvings before the direction counts as giving no decrease (α ≥ 2⁻⁴⁰).
const HALVINGS: usize = 40;

/// Minimises ½‖r(p)‖² over the problem's free parameters by damped Gauss–Newton from
/// `start` (full parameter vector), stopping by `tol`.
pub fn gauss_newton(
    problem: &Problem,
    start: &[f64],
    tol: &ToleranceSettings,
    observer: &mut dyn Observer,
) -> Result<SolverResult, Error> {
    minimise(problem, start, tol, observer)
}

/// [`gauss_newton`] of any least-squares problem (a serial chain's or a tree's).
pub(crate) fn minimise<P: LeastSquares>(
    problem: &P,
    start: &[f64],
    tol: &ToleranceSettings,
    observer: &mut dyn Observer,
) -> Result<SolverResult, Error> {
    let t0 = Instant::now();
    let (m, n) = (problem.rows(), problem.columns());
    let mut it = Iterate::start(problem, start)?;
    observer.start("Gauss–Newton", Some(tol.max_iterations));
    let mut cost = it.cost();
    let mut history = vec![cost];
    let mut status = Status::IterationLimit;
    let mut iterations = 0;
    let mut trial_params = it.params.clone();
    let mut r_trial = DVector::zeros(m);
    while iterations < tol.max_iterations {
        if cost == 0.0 {
            status = Status::Converged {
                criterion: "zero residual".into(),
            };
            break;
        }
        if gradient_cosine(&it.j, &it.r) <= tol.gtol {
            status = Status::Converged {
                criterion: format!("gradient (cosine ≤ {:e})", tol.gtol),
            };
            break;
        }
        iterations += 1;
        // Column scaling so that mm and rad columns compare; then a rank-revealing solve.
        let scale: DVector<f64> =
            DVector::from_iterator(n, (0..n).map(|c| it.j.column(c).norm().max(1e-300)));
        let mut js = it.j.clone();
        for c in 0..n {
            js.column_mut(c).unscale_mut(scale[c]);
        }
        let svd = js.svd(true, true);
        let step_scaled = svd
            .solve(&(-&it.r), 1e-12)
            .map_err(|e| Error::Numerical(format!("Gauss–Newton step: {e}")))?;
        let step = step_scaled.component_div(&scale);
        // Directional derivative ∇Fᵀδ = (Jᵀr)ᵀδ and the decrease the linear model predicts.
        let slope = it.r.dot(&(&it.j * &step));
        let predicted = -(slope + 0.5 * (&it.j * &step).norm_squared());
        let x = problem.free_values(&it.params);
        let mut alpha = 1.0;
        let mut accepted = None;
        for _ in 0..=HALVINGS {
            problem.set_free(&mut trial_params, &(&x + &step * alpha));
            problem.evaluate(&mut it.ws, &trial_params, &mut r_trial, None);
            let trial_cost = 0.5 * r_trial.norm_squared();
            observer.iteration(iterations, trial_cost, 1.0 - alpha);
            if trial_cost.is_finite() && trial_cost <= cost + ARMIJO * alpha * slope {
                accepted = Some(trial_cost);
                break;
            }
            alpha *= 0.5;
        }
        let Some(new_cost) = accepted else {
            status = no_decrease_status(
                &it,
                "no step along the Gauss–Newton direction lowers the cost: Gauss–Newton stalled (use LM, or a start closer to the solution)".into(),
            );
            break;
        };
        it.params.clone_from(&trial_params);
        it.update(problem);
        let actual = cost - new_cost;
        cost = it.cost();
        history.push(cost);
        let rel_step = step_scaled.norm() / (x.component_mul(&scale).norm() + tol.xtol);
        if actual <= tol.ftol * cost.max(f64::MIN_POSITIVE)
            && predicted <= tol.ftol * cost.max(f64::MIN_POSITIVE)
        {
            status = Status::Converged {
                criterion: format!("relative cost reduction ≤ {:e}", tol.ftol),
            };
            break;
        }
        if rel_step <= tol.xtol {
            status = Status::Converged {
                criterion: format!("relative step ≤ {:e}", tol.xtol),
            };
            break;
        }
    }
    observer.finish();
    Ok(it.into_solution(status, iterations, history, t0))
}
