//! Continuous refinement of all N poses at once: minimise φ(q₁…q_N) over the set where
//! every configuration is within the joint limits and satisfies its constraints
//! `g(q_i) ≥ 0` (incidence, collisions; paper eq. 24b), with the PANOC solver of
//! `optimization_engine` (OpEn): a projected-gradient step and L-BFGS directions on the
//! forward–backward envelope. PANOC accepts a non-convex set if its projection can be
//! computed; here the set is a product of per-configuration sets, and each configuration
//! is projected on its own (see [`FeasibleSet`]). Every iterate is therefore feasible (up
//! to the projection's accuracy, checked strictly by the planner), and an early stop still
//! gives a usable design.
//!
//! PANOC runs in rounds of `check_every` iterations; the refinement stops when a round
//! improves φ by less than `min_relative_improvement` (relative), when PANOC's
//! fixed-point residual reaches `tolerance`, or at the iteration or time limit. The
//! objective is divided by its value at the start so the tolerances are relative.

use crate::design::objective::DesignObjective;
use crate::design::small_cholesky;
use crate::Error;
use optimization_engine::{
    constraints::Constraint, core::ExitStatus, panoc::*, FunctionCallResult, Problem, SolverError,
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
    /// Evaluates only the constraints in `rows`, writing their values (and Jacobian rows) at
    /// their own index of the full-length buffers; other entries may change. The default
    /// evaluates everything.
    fn evaluate_rows(
        &self,
        q: &[f64],
        rows: &[usize],
        values: &mut [f64],
        jacobian: Option<&mut [f64]>,
    ) {
        let _ = rows;
        self.evaluate(q, values, jacobian);
    }
}

/// Settings of [`refine`].
#[derive(Clone, Debug)]
pub struct RefineSettings {
    /// PANOC tolerance on the fixed-point residual (relative objective).
    pub tolerance: f64,
    /// PANOC iterations in all.
    pub max_iterations: usize,
    /// Iterations per round; the improvement is checked after each round.
    pub check_every: usize,
    /// Stop when a round lowers φ by less than this fraction.
    pub min_relative_improvement: f64,
    pub max_duration: Duration,
    pub lbfgs_memory: usize,
}

impl Default for RefineSettings {
    fn default() -> Self {
        RefineSettings {
            tolerance: 1e-5,
            max_iterations: 400,
            check_every: 50,
            min_relative_improvement: 1e-3,
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
    /// φ at the start and after each round.
    pub history: Vec<f64>,
    pub time: Duration,
}

/// Corrections per configuration and projection.
const MAX_CORRECTIONS: usize = 20;
/// Each correction aims this far beyond the boundary (as a multiple of the violation), so
/// that the linearisation error of a curved constraint rarely needs a second correction.
const OVERSHOOT: f64 = 1.05;
/// Safety factor on the observed gradient bounds (see [`FeasibleSet`]).
const LIPSCHITZ_SAFETY: f64 = 2.0;
/// A configuration farther than this (rad or mm, 1-norm) from its anchor is evaluated in full
/// and re-anchored; so is one with more than a third of its constraints possibly near.
const REANCHOR_DISTANCE: f64 = 0.2;

/// The feasible set of the design: a product over configurations of the joint box and
/// `{q : g(q) ≥ 0}`. Its projection (the proximal step of PANOC) clamps each configuration
/// into the box and then applies minimum-norm Gauss–Newton corrections on the violated
/// constraints `v`, `Δq = J_vᵀ (J_v J_vᵀ)⁻¹ (−g_v)` — the Euclidean projection to first
/// order — until none is violated. Allocates nothing per call.
///
/// PANOC projects every line-search trial, mostly after small moves, so each configuration
/// keeps an anchor `a` where all its constraints were last evaluated. By the mean-value
/// theorem `g_c(q) ≥ g_c(a) − L_c ‖q − a‖₁` with `L_c = sup ‖∇g_c‖_∞`; only the constraints
/// for which this bound does not prove `g_c(q) ≥ 0` are evaluated (none at all for a
/// configuration far from every boundary). `L_c` is estimated as [`LIPSCHITZ_SAFETY`] times
/// the largest `‖∇g_c‖_∞` over the start design, so the skip is a heuristic: the final
/// iterate is projected once more with every constraint evaluated ([`FeasibleSet::reset`]),
/// and the planner checks the result strictly.
struct FeasibleSet<'a> {
    lower: &'a [f64],
    upper: &'a [f64],
    constraints: Option<&'a dyn ConfigurationConstraints>,
    buffers: RefCell<ProjectionBuffers>,
}

struct ProjectionBuffers {
    values: Vec<f64>,
    jacobian: Vec<f64>,
    violated: Vec<usize>,
    near: Vec<usize>,
    /// `J_v J_vᵀ` (row-major, its Cholesky factor in place) and the right-hand side.
    normal: Vec<f64>,
    rhs: Vec<f64>,
    /// Per configuration: the anchor (`dof` values), the constraint values there (`m`), and
    /// whether it is set.
    anchors: Vec<f64>,
    anchor_values: Vec<f64>,
    anchored: Vec<bool>,
    /// `L_c` per constraint.
    lipschitz: Vec<f64>,
}

impl FeasibleSet<'_> {
    fn clamp(&self, q: &mut [f64]) {
        for ((x, lo), hi) in q.iter_mut().zip(self.lower).zip(self.upper) {
            *x = x.clamp(*lo, *hi);
        }
    }

    /// Forgets every anchor: the next projection evaluates every constraint.
    fn reset(&self) {
        self.buffers.borrow_mut().anchored.fill(false);
    }

    /// Sets `L_c` from the constraint gradients at the configurations of `x`.
    fn estimate_lipschitz(&self, x: &[f64]) {
        let Some(cons) = self.constraints else {
            return;
        };
        let k = self.lower.len();
        let b = &mut *self.buffers.borrow_mut();
        let m = b.values.len();
        b.lipschitz.fill(0.0);
        for q in x.chunks(k) {
            cons.evaluate(q, &mut b.values, Some(&mut b.jacobian));
            for c in 0..m {
                let g = b.jacobian[c * k..(c + 1) * k]
                    .iter()
                    .fold(0.0f64, |a, v| a.max(v.abs()));
                b.lipschitz[c] = b.lipschitz[c].max(LIPSCHITZ_SAFETY * g);
            }
        }
        // A constraint that did not move at any start configuration gets the largest bound.
        let largest = b.lipschitz.iter().cloned().fold(0.0, f64::max);
        for l in &mut b.lipschitz {
            if *l == 0.0 {
                *l = largest;
            }
        }
    }

    /// Projects configuration `index`.
    fn project_configuration(
        &self,
        cons: &dyn ConfigurationConstraints,
        index: usize,
        q: &mut [f64],
    ) {
        let k = q.len();
        let b = &mut *self.buffers.borrow_mut();
        let m = b.values.len();
        self.clamp(q);
        for _ in 0..MAX_CORRECTIONS {
            let anchor = &b.anchors[index * k..(index + 1) * k];
            let moved: f64 = if b.anchored[index] {
                q.iter().zip(anchor).map(|(x, a)| (x - a).abs()).sum()
            } else {
                f64::INFINITY
            };
            b.near.clear();
            if moved <= REANCHOR_DISTANCE {
                let av = &b.anchor_values[index * m..(index + 1) * m];
                b.near
                    .extend((0..m).filter(|&c| av[c] - b.lipschitz[c] * moved < 0.0));
                if b.near.is_empty() {
                    return;
                }
            }
            b.violated.clear();
            if moved > REANCHOR_DISTANCE || 3 * b.near.len() > m {
                cons.evaluate(q, &mut b.values, None);
                b.anchors[index * k..(index + 1) * k].copy_from_slice(q);
                b.anchor_values[index * m..(index + 1) * m].copy_from_slice(&b.values);
                b.anchored[index] = true;
                b.violated.extend((0..m).filter(|&c| b.values[c] < 0.0));
                if b.violated.is_empty() {
                    return;
                }
                cons.evaluate_rows(q, &b.violated, &mut b.values, Some(&mut b.jacobian));
            } else {
                // One forward kinematics for the values and gradients of the near ones.
                cons.evaluate_rows(q, &b.near, &mut b.values, Some(&mut b.jacobian));
                b.violated
                    .extend(b.near.iter().copied().filter(|&c| b.values[c] < 0.0));
                if b.violated.is_empty() {
                    return;
                }
            }
            let nv = b.violated.len();
            // Normal matrix J_v J_vᵀ, lightly regularised (dependent constraints).
            let mut trace = 0.0;
            for (r, &cr) in b.violated.iter().enumerate() {
                for (s, &cs) in b.violated.iter().enumerate().take(r + 1) {
                    let gr = &b.jacobian[cr * k..(cr + 1) * k];
                    let gs = &b.jacobian[cs * k..(cs + 1) * k];
                    let v: f64 = gr.iter().zip(gs).map(|(x, y)| x * y).sum();
                    b.normal[r * nv + s] = v;
                    b.normal[s * nv + r] = v;
                }
                trace += b.normal[r * nv + r];
                b.rhs[r] = -OVERSHOOT * b.values[cr];
            }
            if trace <= 0.0 {
                return; // no gradient to follow; the planner's check rejects the pose
            }
            for r in 0..nv {
                b.normal[r * nv + r] += 1e-10 * trace / nv as f64;
            }
            if !small_cholesky::factor(&mut b.normal[..nv * nv], nv) {
                return;
            }
            small_cholesky::solve(&b.normal[..nv * nv], &mut b.rhs[..nv], nv);
            for (r, &cr) in b.violated.iter().enumerate() {
                let y = b.rhs[r];
                for (x, g) in q.iter_mut().zip(&b.jacobian[cr * k..(cr + 1) * k]) {
                    *x += g * y;
                }
            }
            self.clamp(q);
        }
    }
}

impl Constraint for FeasibleSet<'_> {
    fn project(&self, x: &mut [f64]) -> FunctionCallResult {
        let k = self.lower.len();
        for (index, q) in x.chunks_mut(k).enumerate() {
            match self.constraints {
                Some(c) => self.project_configuration(c, index, q),
                None => self.clamp(q),
            }
        }
        Ok(())
    }

    fn is_convex(&self) -> bool {
        self.constraints.is_none()
    }
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
    let m = constraints.map_or(0, |c| c.len());
    let set = FeasibleSet {
        lower,
        upper,
        constraints: constraints.filter(|c| !c.is_empty()),
        buffers: RefCell::new(ProjectionBuffers {
            values: vec![0.0; m],
            jacobian: vec![0.0; m * k],
            violated: Vec::with_capacity(m),
            near: Vec::with_capacity(m),
            normal: vec![0.0; m * m],
            rhs: vec![0.0; m],
            anchors: vec![0.0; nu],
            anchor_values: vec![0.0; m * nconf],
            anchored: vec![false; nconf],
            lipschitz: vec![0.0; m],
        }),
    };
    let mut u: Vec<f64> = start.concat();
    set.project(&mut u)
        .map_err(|e| Error::Input(format!("pose refinement failed: {e:?}")))?;
    set.estimate_lipschitz(&u);
    let ws = RefCell::new(objective.workspace(nconf));
    let start_value = objective.value_and_gradient(&mut ws.borrow_mut(), &start.concat(), None)?;
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
    let mut value = objective.value_and_gradient(&mut ws.borrow_mut(), &u, None)?;
    let mut best_u = u.clone();
    let mut history = vec![start_value];
    let mut iterations = 0;
    let mut cache = PANOCCache::new(nu, settings.tolerance, settings.lbfgs_memory);
    let (converged, status) = loop {
        let remaining = settings.max_duration.saturating_sub(t0.elapsed());
        let round = settings
            .check_every
            .max(1)
            .min(settings.max_iterations - iterations);
        if round == 0 {
            break (false, "iteration limit".to_string());
        }
        if remaining.is_zero() {
            break (false, "time limit".to_string());
        }
        cache.reset();
        let problem = Problem::new(&set, grad, cost);
        let mut panoc = PANOCOptimizer::new(problem, &mut cache)
            .with_max_iter(round)
            .with_max_duration(remaining);
        let s = panoc
            .solve(&mut u)
            .map_err(|e| Error::Input(format!("pose refinement failed: {e}")))?;
        iterations += s.iterations();
        let previous = value;
        value = objective.value_and_gradient(&mut ws.borrow_mut(), &u, None)?;
        history.push(value);
        if value > previous {
            // PANOC descends on the envelope, not on φ itself: keep the better design.
            u.copy_from_slice(&best_u);
            value = previous;
            break (true, "converged (no further descent)".to_string());
        }
        best_u.copy_from_slice(&u);
        if s.exit_status() == ExitStatus::Converged {
            break (true, "converged".to_string());
        }
        if previous - value < settings.min_relative_improvement * previous.abs() {
            break (
                true,
                format!(
                    "converged (a round of {round} iterations improved by less than {:e})",
                    settings.min_relative_improvement
                ),
            );
        }
    };
    // The skipped evaluations rest on estimated bounds: project the result once more with
    // every constraint evaluated.
    set.reset();
    set.project(&mut u)
        .map_err(|e| Error::Input(format!("pose refinement failed: {e:?}")))?;
    if u != best_u {
        value = objective.value_and_gradient(&mut ws.borrow_mut(), &u, None)?;
    }
    Ok(RefineResult {
        q: u.chunks(k).map(<[f64]>::to_vec).collect(),
        value,
        start_value,
        converged,
        status,
        iterations,
        history,
        time: t0.elapsed(),
    })
}
