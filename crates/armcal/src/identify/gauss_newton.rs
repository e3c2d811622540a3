//! Gauss–Newton as iterated linear least squares (book §4.3, eqs. 4.22–4.27): at each
//! iterate solve `J δ = −r` in the least-squares sense (column-scaled SVD) and step.
//! Undamped; it must reach the same estimate as Levenberg–Marquardt (book: "identical").

use super::problem::Problem;
use super::solver::{gradient_cosine, Iterate, Observer, Solution, Status, Tolerances};
use crate::Error;
use nalgebra::DVector;
use std::time::Instant;

pub fn gauss_newton(
    problem: &Problem,
    start: &[f64],
    tol: &Tolerances,
    observer: &mut dyn Observer,
) -> Result<Solution, Error> {
    let t0 = Instant::now();
    let n = problem.columns();
    let mut it = Iterate::start(problem, start)?;
    let mut cost = it.cost();
    let mut history = vec![cost];
    let mut status = Status::MaxIterations;
    let mut iterations = 0;
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
            .map_err(|e| Error::Input(format!("Gauss–Newton step: {e}")))?;
        let step = step_scaled.component_div(&scale);
        let x = problem.free_values(&it.params);
        problem.set_free(&mut it.params, &(&x + &step));
        it.update(problem);
        let new_cost = it.cost();
        observer.iteration(iterations, new_cost, 0.0);
        history.push(new_cost);
        if !new_cost.is_finite() || new_cost > 1e6 * cost.max(1.0) {
            status = Status::Diverged {
                reason: format!(
                    "the cost grew from {cost:.3e} to {new_cost:.3e}; undamped Gauss–Newton needs a start close to the solution (use LM)"
                ),
            };
            break;
        }
        let rel_step = step_scaled.norm() / (x.component_mul(&scale).norm() + tol.xtol);
        let reduction = (cost - new_cost).abs();
        cost = new_cost;
        if rel_step <= tol.xtol {
            status = Status::Converged {
                criterion: format!("relative step ≤ {:e}", tol.xtol),
            };
            break;
        }
        if reduction <= tol.ftol * cost.max(f64::MIN_POSITIVE) && iterations > 1 {
            status = Status::Converged {
                criterion: format!("relative cost change ≤ {:e}", tol.ftol),
            };
            break;
        }
    }
    Ok(it.into_solution(status, iterations, history, t0))
}
