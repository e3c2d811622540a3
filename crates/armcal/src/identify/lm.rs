//! Levenberg–Marquardt as a trust-region method (Moré 1978, "The Levenberg–Marquardt
//! algorithm: implementation and theory", the algorithm of MINPACK's `lmder`; book §4.3).
//!
//! Each iteration minimises the linear model ½‖r + Jδ‖² within the ellipsoid ‖Dδ‖ ≤ Δ,
//! whose solution is the Levenberg–Marquardt step `(JᵀJ + μ D²) δ = −Jᵀr` with the μ ≥ 0
//! that puts it on the boundary (μ = 0 when the Gauss–Newton step lies inside). `D` holds
//! the largest column norms of J seen so far (Moré's scaling, eq. 6.3), so mm and rad
//! columns compare. The radius Δ, not μ, is what the iteration adapts: doubled when the
//! actual cost reduction agrees with the predicted one (ratio ρ > 3/4), shrunk to a quarter
//! of the step when it does not (ρ < 1/4). The boundary step is found exactly on the
//! eigen-decomposition of the scaled `D⁻¹JᵀJD⁻¹` (the secular equation, Moré & Sorensen
//! 1983), which costs O(n²) per trial for the few dozen parameters of a calibration.
//!
//! Why a radius: on the real data sets (Motoman, `l1.beta ~ l1.a`, ρ = 0.993) the fit walks
//! a long curved valley whose flat direction makes `JᵀJ + μD²` nearly singular at small
//! μ; the step length then jumps by orders of magnitude between μ and μ/10, so
//! Marquardt's μ ← μ/10, μ ← 10μ rule alternated a rejected overshoot with an accepted
//! crawl for hundreds of iterations. Δ grows the step geometrically along the valley.
//! Measured in the commit that introduced it (iterations per seed before and after).
//!
//! **Geodesic acceleration** (Transtrum & Sethna 2012, "Improvements to the
//! Levenberg–Marquardt algorithm for nonlinear least-squares minimization",
//! arXiv:1201.5885, eqs. 13–15; Transtrum, Machta & Sethna 2011, Phys. Rev. E 83, 036701):
//! the step v is the velocity of a path through the valley; its second-order correction
//! `a = −(JᵀJ + μD²)⁻¹ Jᵀ r_vv`, with `r_vv ≈ (2/h) ((r(x + h v) − r(x)) / h − J v)` the
//! residual's second directional derivative by a finite difference (h = 0.1), bends the
//! step `v + a/2` along the valley. When the acceleration is large (`2‖Da‖ > α‖Dv‖`,
//! α = 0.75: no second-order correction, or rounding in r_vv at the last tiny steps) the
//! plain step v is tried. The ratio ρ compares the actual reduction
//! with the linear model's for v. Measured: the trust region alone still walked the real
//! data sets' curved valleys in short steps (Motoman non-geometric cells: first runs
//! 111–989 iterations, the cost still falling between iterations 50 and 400); with the
//! acceleration 26–38 and 21–182 (`real_data::solver_convergence`), the kinematic cells
//! 25–42 (before 55–87). It costs one more residual evaluation per trial.
//!
//! Written on nalgebra 0.35 rather than taken from the `levenberg-marquardt` crate: that
//! crate pins nalgebra 0.34 (two nalgebra versions in the tree and a copy of J at every
//! evaluation), and identification needs the Jacobian at the solution, the statistical
//! stopping rule below, explicit criteria and an observer, which are a few lines here.

use super::problem::Problem;
use super::solver::{
    gradient_cosine, no_decrease_status, Iterate, LeastSquares, SolverResult, ToleranceSettings,
};
use crate::progress::Observer;
use crate::solve::Status;
use crate::Error;
use nalgebra::{DMatrix, DVector, SymmetricEigen};
use std::time::Instant;

/// Settings of [`levenberg_marquardt`].
#[derive(Clone, Debug)]
pub struct LmSettings {
    /// Stopping rules.
    pub tolerances: ToleranceSettings,
    /// Initial trust radius relative to `‖D x₀‖` (MINPACK's `factor`, 100: the first step
    /// is the Gauss–Newton step unless it fails).
    pub initial_radius: f64,
}

impl Default for LmSettings {
    fn default() -> Self {
        LmSettings {
            tolerances: ToleranceSettings::default(),
            initial_radius: 100.0,
        }
    }
}

/// Step of the finite difference along the velocity for the geodesic acceleration
/// (Transtrum & Sethna 2012, §4: h = 0.1).
const GEODESIC_H: f64 = 0.1;
/// Largest ratio `2‖D a‖ / ‖D v‖` of acceleration to velocity for the acceleration to be
/// applied (Transtrum & Sethna 2012: α = 0.75).
const GEODESIC_ALPHA: f64 = 0.75;
/// Accept a step when the actual reduction is at least this fraction of the predicted one.
const ACCEPT: f64 = 1e-4;
/// Trials (residual evaluations) per iteration before the iteration gives up.
const TRIALS: usize = 60;

/// The scaled linear model of one iteration: `D⁻¹JᵀJD⁻¹ = Q Λ Qᵀ` and `b = Qᵀ D⁻¹ Jᵀr`,
/// so that the step of Levenberg parameter μ is `D δ = −Q (Λ + μ)⁻¹ b`.
struct ScaledModel {
    eigen: SymmetricEigen<f64, nalgebra::Dyn>,
    b: DVector<f64>,
}

impl ScaledModel {
    fn new(a: &DMatrix<f64>, g: &DVector<f64>, d: &DVector<f64>) -> ScaledModel {
        let scaled = DMatrix::from_fn(a.nrows(), a.ncols(), |i, k| a[(i, k)] / (d[i] * d[k]));
        let eigen = scaled.symmetric_eigen();
        let b = eigen.eigenvectors.tr_mul(&g.component_div(d));
        ScaledModel { eigen, b }
    }

    /// The scaled step `z = D δ` for the Levenberg parameter μ, in the eigenbasis.
    fn z(&self, mu: f64) -> DVector<f64> {
        self.solve(&self.b, mu)
    }

    /// `−(Λ + μ)⁻¹ c` for `c` in the eigenbasis.
    fn solve(&self, c: &DVector<f64>, mu: f64) -> DVector<f64> {
        c.zip_map(&self.eigen.eigenvalues, |c, l| -c / (l.max(0.0) + mu))
    }

    /// The scaled solution `z = D δ` (eigenbasis) of `(JᵀJ + μ D²) δ = −g` for another
    /// right-hand side `g` (the geodesic acceleration's `Jᵀ r_vv`).
    fn z_for(&self, g: &DVector<f64>, d: &DVector<f64>, mu: f64) -> DVector<f64> {
        self.solve(&self.eigen.eigenvectors.tr_mul(&g.component_div(d)), mu)
    }

    /// Whether the Gauss–Newton step exists (the scaled JᵀJ is not singular to rounding).
    fn regular(&self) -> bool {
        let l = &self.eigen.eigenvalues;
        l.min() > 1e-13 * l.max().max(f64::MIN_POSITIVE)
    }

    /// The Levenberg parameter μ ≥ 0 whose step has `‖z‖` within 10 % of `radius` (μ = 0
    /// if the Gauss–Newton step is that short): Newton's method on the secular equation
    /// `1/Δ − 1/‖z(μ)‖ = 0`, safeguarded by bisection (Moré & Sorensen 1983).
    fn levenberg_parameter(&self, radius: f64) -> f64 {
        if self.regular() && self.z(0.0).norm() <= 1.1 * radius {
            return 0.0;
        }
        let (mut lo, mut hi) = (0.0f64, self.b.norm() / radius);
        let mut mu = hi * 1e-3;
        for _ in 0..100 {
            let z = self.z(mu);
            let norm = z.norm();
            if (norm - radius).abs() <= 0.1 * radius {
                return mu;
            }
            if norm > radius {
                lo = mu;
            } else {
                hi = mu;
            }
            // d‖z‖/dμ = −Σ zᵢ² / (λᵢ + μ) / ‖z‖
            let dnorm = -z
                .iter()
                .zip(self.eigen.eigenvalues.iter())
                .map(|(zi, l)| zi * zi / (l.max(0.0) + mu))
                .sum::<f64>()
                / norm;
            let newton = mu - (norm - radius) / radius * norm / dnorm;
            mu = if newton > lo && newton < hi {
                newton
            } else if lo > 0.0 {
                (lo * hi).sqrt()
            } else {
                hi * 1e-3
            };
        }
        mu
    }

    /// `‖Jδ‖² = zᵀΛz` of the scaled step `z`.
    fn curvature(&self, z: &DVector<f64>) -> f64 {
        z.iter()
            .zip(self.eigen.eigenvalues.iter())
            .map(|(zi, l)| zi * zi * l.max(0.0))
            .sum()
    }

    /// The cost reduction the linear model predicts for the scaled step `z`:
    /// `−(bᵀz + ½ zᵀΛz)`.
    fn predicted(&self, z: &DVector<f64>) -> f64 {
        -(self.b.dot(z) + 0.5 * self.curvature(z))
    }
}

/// `min(1, σ̂₀)` with the a-posteriori `σ̂₀² = 2 cost / (m − n)`: the parameters scatter by
/// σ̂₀ σᵢ when the data's σ are off by σ̂₀, so a step rule in σᵢ never loosens below that.
fn noise_factor(cost: f64, m: usize, n: usize) -> f64 {
    if m > n {
        (2.0 * cost / (m - n) as f64).sqrt().min(1.0)
    } else {
        1.0
    }
}

/// Minimises ½‖r(p)‖² over the problem's free parameters, starting at `start` (full
/// parameter vector), by the trust-region Levenberg–Marquardt method of the module
/// documentation.
pub fn levenberg_marquardt(
    problem: &Problem,
    start: &[f64],
    settings: &LmSettings,
    observer: &mut dyn Observer,
) -> Result<SolverResult, Error> {
    minimise(problem, start, settings, observer)
}

/// [`levenberg_marquardt`] of any least-squares problem (a serial chain's or a tree's).
pub(crate) fn minimise<P: LeastSquares>(
    problem: &P,
    start: &[f64],
    settings: &LmSettings,
    observer: &mut dyn Observer,
) -> Result<SolverResult, Error> {
    let t0 = Instant::now();
    let (m, n) = (problem.rows(), problem.columns());
    let mut it = Iterate::start(problem, start)?;
    let tol = &settings.tolerances;
    observer.start("Levenberg–Marquardt", Some(tol.max_iterations));
    let mut cost = it.cost();
    let mut history = vec![cost];
    let mut trial_params = it.params.clone();
    let mut r_trial = DVector::zeros(m);
    let mut status = Status::IterationLimit;
    let mut iterations = 0;
    let mut d = DVector::<f64>::zeros(n);
    let mut radius = None;
    let mut previous_gn_step: Option<f64> = None;
    while iterations < tol.max_iterations {
        iterations += 1;
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
        let a = crate::linalg::gram(it.j.as_view());
        for k in 0..n {
            let norm = a[(k, k)].sqrt();
            d[k] = d[k].max(if norm > 0.0 { norm } else { 1.0 });
        }
        let g = it.j.tr_mul(&it.r);
        let model = ScaledModel::new(&a, &g, &d);
        let x = problem.free_values(&it.params);
        let scaled_x = x.component_mul(&d).norm();
        let mut delta = *radius.get_or_insert({
            settings.initial_radius * if scaled_x > 0.0 { scaled_x } else { 1.0 }
        });
        let mut accepted = false;
        for _ in 0..TRIALS {
            let mu = model.levenberg_parameter(delta);
            let z = model.z(mu);
            let scaled_step = z.norm();
            if mu == 0.0 && scaled_step <= tol.xtol * (scaled_x + tol.xtol) {
                // The model's minimum is x to rounding (noise-free data end here: no
                // step lowers a cost made of rounding errors).
                status = Status::Converged {
                    criterion: format!("relative step ≤ {:e}", tol.xtol),
                };
                accepted = true;
                break;
            }
            let mut step = (&model.eigen.eigenvectors * &z).component_div(&d);
            // geodesic acceleration: the second directional derivative of r along the
            // step by a finite difference, and the acceleration it asks for
            problem.set_free(&mut trial_params, &(&x + &step * GEODESIC_H));
            problem.evaluate(&mut it.ws, &trial_params, &mut r_trial, None);
            let r_vv = ((&r_trial - &it.r) / GEODESIC_H - &it.j * &step) * (2.0 / GEODESIC_H);
            let za = model.z_for(&it.j.tr_mul(&r_vv), &d, mu);
            // a larger acceleration is no second-order correction (the path bends too much
            // within this radius, or rounding dominates r_vv at the last tiny steps): the
            // plain step is tried
            if 2.0 * za.norm() <= GEODESIC_ALPHA * scaled_step {
                step += (&model.eigen.eigenvectors * &za).component_div(&d) * 0.5;
            }
            problem.set_free(&mut trial_params, &(&x + &step));
            problem.evaluate(&mut it.ws, &trial_params, &mut r_trial, None);
            let cost_new = 0.5 * r_trial.norm_squared();
            observer.iteration(iterations, cost_new, mu);
            let predicted = model.predicted(&z);
            let actual = cost - cost_new;
            let ratio = if predicted > 0.0 {
                actual / predicted
            } else {
                0.0
            };
            if !cost_new.is_finite() || ratio < 0.25 {
                delta = 0.25 * scaled_step.min(delta);
            } else if ratio > 0.75 {
                delta = delta.max(2.0 * scaled_step);
            }
            if !(cost_new.is_finite() && actual > 0.0 && ratio >= ACCEPT) {
                if delta <= f64::EPSILON * scaled_x {
                    break;
                }
                continue;
            }
            it.params.clone_from(&trial_params);
            it.update(problem);
            cost = it.cost();
            history.push(cost);
            accepted = true;
            // ‖Jδ‖ bounds the move of every parameter in its own σ: |δᵢ| ≤ σᵢ ‖Jδ‖ with
            // C_p = (JᵀJ)⁻¹ (Cauchy–Schwarz). A Gauss–Newton step (μ = 0) is the distance
            // to the model's minimum; contracting by c per iteration, what remains is at
            // most ‖Jδ‖ c / (1 − c).
            let j_step = model.curvature(&z).sqrt();
            let remaining = match (mu == 0.0, previous_gn_step) {
                (true, Some(prev)) if j_step < prev => j_step / (1.0 - j_step / prev),
                _ => f64::INFINITY,
            };
            previous_gn_step = (mu == 0.0).then_some(j_step);
            if remaining <= tol.sigma_step * noise_factor(cost, m, n) {
                status = Status::Converged {
                    criterion: format!("step ≤ {:e} σ of every parameter", tol.sigma_step),
                };
            } else if actual <= tol.ftol * cost_new.max(f64::MIN_POSITIVE)
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
        radius = Some(delta);
        if !accepted {
            // No step reduces the cost: at a minimum to machine precision, or stuck.
            status = no_decrease_status(
                &it,
                format!(
                    "no step reduces the cost (trust radius {delta:.1e} in scaled variables); the start may be too far from a solution or the model may not fit the data"
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

#[cfg(test)]
mod tests {
    use super::ScaledModel;
    use nalgebra::{DMatrix, DVector};

    /// The boundary step has `‖D δ‖` within 10 % of the radius and solves
    /// `(JᵀJ + μ D²) δ = −Jᵀr`; inside the radius it is the Gauss–Newton step (μ = 0);
    /// a singular JᵀJ still gets a finite boundary step.
    #[test]
    fn the_step_lies_on_the_trust_region_boundary() {
        let j = DMatrix::from_row_slice(
            4,
            3,
            &[
                1.0, 2.0, 0.0, 0.5, 1e3, 1.0, 2.0, 1999.0, 0.0, 1.0, 3.0, 1e-3,
            ],
        );
        let r = DVector::from_row_slice(&[1.0, -2.0, 0.5, 3.0]);
        let a = j.tr_mul(&j);
        let g = j.tr_mul(&r);
        let d = a.diagonal().map(f64::sqrt);
        let model = ScaledModel::new(&a, &g, &d);
        let gn = model.z(0.0).norm();
        assert_eq!(model.levenberg_parameter(2.0 * gn), 0.0);
        for radius in [gn * 0.5, gn * 1e-3, gn * 1e-8] {
            let mu = model.levenberg_parameter(radius);
            let z = model.z(mu);
            assert!(
                mu > 0.0 && (z.norm() / radius - 1.0).abs() <= 0.1,
                "{mu} {radius}"
            );
            let step = (&model.eigen.eigenvectors * &z).component_div(&d);
            let damped = &a + DMatrix::from_diagonal(&d.map(|x| mu * x * x));
            let res = (&damped * &step + &g).norm() / g.norm();
            assert!(res < 1e-9, "{res}");
            let predicted = -(g.dot(&step) + 0.5 * (&j * &step).norm_squared());
            assert!((model.predicted(&z) / predicted - 1.0).abs() < 1e-9);
        }
        let singular =
            DMatrix::from_row_slice(3, 3, &[1.0, 1.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 2.0]);
        let model = ScaledModel::new(
            &singular,
            &DVector::from_row_slice(&[1.0, 0.0, 1.0]),
            &DVector::from_element(3, 1.0),
        );
        assert!(!model.regular());
        let mu = model.levenberg_parameter(1e3);
        assert!(mu > 0.0 && model.z(mu).iter().all(|x| x.is_finite()));
    }
}
