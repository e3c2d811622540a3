//! Continuous refinement of all N poses at once: minimise φ(q₁…q_N) within the joint
//! limits and subject to per-configuration constraints `g(q_i) ≥ 0` (incidence, collisions;
//! paper eq. 24b), with `optimization_engine` (OpEn): PANOC for the box-constrained problem,
//! its augmented-Lagrangian method (ALM) with `F₁(u) = −g(u) ∈ (−∞, 0]` when there are
//! constraints. Only `J_gᵀ d` products are needed, so thousands of constraints cost little.
//! The objective is divided by its value at the start so the tolerances are relative.

use crate::design::objective::DesignObjective;
use crate::Error;
use optimization_engine::{
    alm::*, constraints::Rectangle, core::ExitStatus, panoc::*, Problem, SolverError,
};
use std::cell::RefCell;
use std::time::{Duration, Instant};

/// Per-configuration constraints `g(q) ≥ 0` with their Jacobian (row-major `len × dof`).
pub trait ConfigurationConstraints {
    fn len(&self) -> usize;
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    fn evaluate(&self, q: &[f64], values: &mut [f64], jacobian: Option<&mut [f64]>);
}

/// Settings of [`refine`].
#[derive(Clone, Debug)]
pub struct RefineSettings {
    /// PANOC tolerance on the fixed-point residual (relative objective).
    pub tolerance: f64,
    /// ALM tolerance on the constraint violation (units of g: mm for distances).
    pub constraint_tolerance: f64,
    pub max_inner_iterations: usize,
    pub max_outer_iterations: usize,
    pub max_duration: Duration,
    pub lbfgs_memory: usize,
}

impl Default for RefineSettings {
    fn default() -> Self {
        RefineSettings {
            tolerance: 1e-5,
            constraint_tolerance: 1e-4,
            max_inner_iterations: 400,
            max_outer_iterations: 12,
            max_duration: Duration::from_secs(30),
            lbfgs_memory: 10,
        }
    }
}

/// Result of a refinement.
#[derive(Clone, Debug)]
pub struct RefineResult {
    pub q: Vec<Vec<f64>>,
    pub value: f64,
    pub start_value: f64,
    pub converged: bool,
    pub status: String,
    pub iterations: usize,
    pub time: Duration,
}

/// Refines the design `start` (N configurations).
pub fn refine(
    objective: &DesignObjective,
    start: &[Vec<f64>],
    lower: &[f64],
    upper: &[f64],
    constraints: Option<&dyn ConfigurationConstraints>,
    settings: &RefineSettings,
) -> Result<RefineResult, Error> {
    let t0 = Instant::now();
    let k = lower.len();
    let nconf = start.len();
    let nu = k * nconf;
    let mut u: Vec<f64> = start.concat();
    // Clamp the start into the box (PANOC projects anyway).
    for (i, x) in u.iter_mut().enumerate() {
        *x = x.clamp(lower[i % k], upper[i % k]);
    }
    let lo: Vec<f64> = (0..nu).map(|i| lower[i % k]).collect();
    let hi: Vec<f64> = (0..nu).map(|i| upper[i % k]).collect();
    let ws = RefCell::new(objective.workspace(nconf));
    let start_value = objective.value_and_gradient(&mut ws.borrow_mut(), &u, None)?;
    let scale = 1.0 / start_value.abs().max(1e-300);
    let cost = |x: &[f64], c: &mut f64| -> Result<(), SolverError> {
        let v = objective
            .value_and_gradient(&mut ws.borrow_mut(), x, None)
            .map_err(|_| SolverError::Cost("the design became singular"))?;
        *c = v * scale;
        Ok(())
    };
    let grad = |x: &[f64], g: &mut [f64]| -> Result<(), SolverError> {
        objective
            .value_and_gradient(&mut ws.borrow_mut(), x, Some(g))
            .map_err(|_| SolverError::Cost("the design became singular"))?;
        for v in g.iter_mut() {
            *v *= scale;
        }
        Ok(())
    };
    let bounds = Rectangle::new(Some(&lo), Some(&hi));
    let m = constraints.map(|c| c.len()).unwrap_or(0);
    let (converged, status, iterations) = if m == 0 {
        let problem = Problem::new(&bounds, grad, cost);
        let mut cache = PANOCCache::new(nu, settings.tolerance, settings.lbfgs_memory);
        let mut panoc = PANOCOptimizer::new(problem, &mut cache)
            .with_max_iter(settings.max_inner_iterations)
            .with_max_duration(settings.max_duration);
        let s = panoc
            .solve(&mut u)
            .map_err(|e| Error::Input(format!("pose refinement failed: {e}")))?;
        (
            s.exit_status() == ExitStatus::Converged,
            format!("{:?}", s.exit_status()),
            s.iterations(),
        )
    } else {
        let cons = constraints.expect("m > 0");
        let total = m * nconf;
        let cbuf = RefCell::new((vec![0.0; m], vec![0.0; m * k]));
        // F1(u) = −g(u) ≤ 0.
        let f1 = |x: &[f64], out: &mut [f64]| -> Result<(), SolverError> {
            let mut b = cbuf.borrow_mut();
            for i in 0..nconf {
                cons.evaluate(&x[i * k..(i + 1) * k], &mut b.0, None);
                for c in 0..m {
                    out[i * m + c] = -b.0[c];
                }
            }
            Ok(())
        };
        // J_F1(u)ᵀ d = −Σ_c d_c ∇g_c.
        let jf1t = |x: &[f64], d: &[f64], out: &mut [f64]| -> Result<(), SolverError> {
            let mut b = cbuf.borrow_mut();
            let (vals, jac) = &mut *b;
            out.fill(0.0);
            for i in 0..nconf {
                cons.evaluate(&x[i * k..(i + 1) * k], vals, Some(jac));
                for c in 0..m {
                    let dc = d[i * m + c];
                    if dc != 0.0 {
                        for j in 0..k {
                            out[i * k + j] -= dc * jac[c * k + j];
                        }
                    }
                }
            }
            Ok(())
        };
        let upper_c = vec![0.0; total];
        let set_c = Rectangle::new(None, Some(&upper_c));
        let factory = AlmFactory::new(
            cost,
            grad,
            Some(f1),
            Some(jf1t),
            NO_MAPPING,
            NO_JACOBIAN_MAPPING,
            Some(set_c),
            0,
        );
        let y_bound = optimization_engine::constraints::Ball2::new(None, 1e12);
        let problem = AlmProblem::new(
            bounds,
            Some(set_c),
            Some(y_bound),
            |x: &[f64], xi: &[f64], c: &mut f64| factory.psi(x, xi, c),
            |x: &[f64], xi: &[f64], g: &mut [f64]| factory.d_psi(x, xi, g),
            Some(f1),
            NO_MAPPING,
            total,
            0,
        );
        let mut cache = AlmCache::new(
            PANOCCache::new(nu, settings.tolerance, settings.lbfgs_memory),
            total,
            0,
        );
        let mut alm = AlmOptimizer::new(&mut cache, problem)
            .with_max_outer_iterations(settings.max_outer_iterations)
            .with_max_inner_iterations(settings.max_inner_iterations)
            .with_epsilon_tolerance(settings.tolerance)
            .with_delta_tolerance(settings.constraint_tolerance)
            .with_initial_penalty(10.0)
            .with_penalty_update_factor(5.0)
            .with_max_duration(settings.max_duration);
        let s = alm
            .solve(&mut u)
            .map_err(|e| Error::Input(format!("pose refinement failed: {e}")))?;
        (
            s.exit_status() == ExitStatus::Converged,
            format!("{:?}", s.exit_status()),
            s.num_inner_iterations(),
        )
    };
    let value = objective.value_and_gradient(&mut ws.borrow_mut(), &u, None)?;
    Ok(RefineResult {
        q: u.chunks(k).map(<[f64]>::to_vec).collect(),
        value,
        start_value,
        converged,
        status,
        iterations,
        time: t0.elapsed(),
    })
}
