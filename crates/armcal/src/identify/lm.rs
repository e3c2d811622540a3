//! Levenberg–Marquardt with Marquardt's diagonal scaling (book §4.3; Marquardt 1963:
//! μ₀ = 0.01, factor v = 10, book check 10).
//!
//! Written on nalgebra 0.35 rather than taken from the `levenberg-marquardt` crate: that
//! crate pins nalgebra 0.34 (two nalgebra versions in the tree and a copy of J at every
//! evaluation), and identification needs the Jacobian at the solution, Marquardt scaling,
//! explicit criteria and an observer, which are a few lines here.

use super::problem::Problem;
use super::solver::{
    gradient_cosine, no_decrease_status, Iterate, SolverResult, Status, ToleranceSettings,
};
use crate::progress::Observer;
use crate::Error;
use nalgebra::DVector;
use std::time::Instant;

/// Settings of [`levenberg_marquardt`].
#[derive(Clone, Debug)]
pub struct LmSettings {
    /// Stopping rules.
    pub tolerances: ToleranceSettings,
    /// Initial damping relative to the scaling (Marquardt's λ₀).
    pub mu0: f64,
    /// Damping increase / decrease factor.
    pub factor: f64,
}

impl Default for LmSettings {
    fn default() -> Self {
        LmSettings {
            tolerances: ToleranceSettings::default(),
            mu0: 0.01,
            factor: 10.0,
        }
    }
}

/// Minimises ½‖r(p)‖² over the problem's free parameters, starting at `start` (full
/// parameter vector). Step: `(JᵀJ + μ D) δ = −Jᵀr` with `D = diag(JᵀJ)`.
pub fn levenberg_marquardt(
    problem: &Problem,
    start: &[f64],
    settings: &LmSettings,
    observer: &mut dyn Observer,
) -> Result<SolverResult, Error> {
    let t0 = Instant::now();
    let (m, n) = (problem.rows(), problem.columns());
    let mut it = Iterate::start(problem, start)?;
    observer.start(
        "Levenberg–Marquardt",
        Some(settings.tolerances.max_iterations),
    );
    let mut cost = it.cost();
    let mut history = vec![cost];
    let mut mu = settings.mu0;
    let mut trial_params = it.params.clone();
    let mut r_trial = DVector::zeros(m);
    let tol = &settings.tolerances;
    let mut status = Status::IterationLimit;
    let mut iterations = 0;
    while iterations < tol.max_iterations {
        iterations += 1;
        if cost == 0.0 {
            status = Status::Converged {
                criterion: "zero residual".into(),
            };
            break;
        }
        let g = it.j.tr_mul(&it.r);
        if gradient_cosine(&it.j, &it.r) <= tol.gtol {
            status = Status::Converged {
                criterion: format!("gradient (cosine ≤ {:e})", tol.gtol),
            };
            break;
        }
        let a = crate::linalg::gram(it.j.as_view());
        let d: DVector<f64> = a.diagonal().map(|x| x.max(1e-300));
        let x = problem.free_values(&it.params);
        let mut accepted = false;
        // Inner loop: raise μ until the step reduces the cost.
        for _ in 0..60 {
            let mut damped = a.clone();
            for k in 0..n {
                damped[(k, k)] += mu * d[k];
            }
            let step = match damped.cholesky() {
                Some(ch) => ch.solve(&(-&g)),
                None => {
                    mu *= settings.factor;
                    continue;
                }
            };
            let x_new = &x + &step;
            problem.set_free(&mut trial_params, &x_new);
            problem.evaluate(&mut it.ws, &trial_params, &mut r_trial, None);
            let cost_new = 0.5 * r_trial.norm_squared();
            // Predicted reduction of the linear model.
            let jstep = &it.j * &step;
            let predicted = -(g.dot(&step) + 0.5 * jstep.norm_squared());
            observer.iteration(iterations, cost_new, mu);
            if cost_new.is_finite() && cost_new < cost {
                let scaled_step = step.zip_map(&d, |s, dk| s * dk.sqrt()).norm();
                let scaled_x = x.zip_map(&d, |xk, dk| xk * dk.sqrt()).norm();
                let actual = cost - cost_new;
                it.params.clone_from(&trial_params);
                it.update(problem);
                cost = it.cost();
                history.push(cost);
                mu = (mu / settings.factor).max(1e-15);
                accepted = true;
                if actual <= tol.ftol * cost_new.max(f64::MIN_POSITIVE)
                    && predicted <= tol.ftol * cost
                {
                    status = Status::Converged {
                        criterion: format!("relative cost reduction ≤ {:e}", tol.ftol),
                    };
                } else if scaled_step <= tol.xtol * (scaled_x + tol.xtol) {
                    status = Status::Converged {
                        criterion: format!("relative step ≤ {:e}", tol.xtol),
                    };
                }
                break;
            }
            mu *= settings.factor;
            if mu > 1e30 {
                break;
            }
        }
        if !accepted {
            // No step reduces the cost: at a minimum to machine precision, or stuck.
            status = no_decrease_status(
                &it,
                format!(
                    "no step reduces the cost (damping μ = {mu:.1e}); the start may be too far from a solution or the model may not fit the data"
                ),
            );
            break;
        }
        if status.is_converged() {
            break;
        }
    }
    observer.finish();
    Ok(it.into_solution(status, iterations, history, t0))
}
