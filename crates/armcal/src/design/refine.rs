//! Continuous refinement of all N poses at once: minimise φ(q₁…q_N) over the set where
//! every configuration is within the joint limits and satisfies its constraints
//! `g(q_i) ≥ 0` (incidence, collisions; paper eq. 24b), with the PANOC solver of
//! `optimization_engine` (OpEn): a projected-gradient step and L-BFGS directions on the
//! forward–backward envelope. PANOC accepts a non-convex set if its projection can be
//! computed; here the set is a product of per-configuration sets, and each configuration
//! is projected on its own (see `FeasibleSet`). Every iterate is therefore feasible (up
//! to the projection's accuracy, checked strictly by the planner), and an early stop still
//! gives a usable design.
//!
//! PANOC runs in rounds of `check_every` iterations; the refinement stops when a round
//! improves φ by less than `min_relative_improvement` (relative, scaled by the round's
//! length), when PANOC's fixed-point residual reaches `tolerance`, or at the iteration or
//! time limit. A round that ends worse than it started is retried from the best design
//! with a third of its length; when even the shortest round does, PANOC has stalled (with
//! many poses on curved constraint boundaries its envelope line search fails) and
//! projected-gradient steps with an Armijo test on φ use the remaining iterations
//! (`projected_gradient`). The objective is divided by its value at the start so the
//! tolerances are relative.
//!
//! (Over 600 lines because the projection (`FeasibleSet`, with its anchors and
//! bounds) and the two descents that use it are one algorithm sharing private buffers.)

use crate::design::objective::DesignObjective;
use crate::design::small_cholesky;
use crate::progress::Observer;
use crate::solve::Status;
use crate::Error;
use optimization_engine::{
    constraints::Constraint, core::ExitStatus, panoc::*, FunctionCallResult, Problem, SolverError,
};
use std::cell::RefCell;
use std::time::{Duration, Instant};

/// Per-configuration constraints `g(q) ≥ 0` with their Jacobian (row-major `len × dof`).
pub trait ConfigurationConstraints {
    /// Number of constraints.
    fn len(&self) -> usize;
    /// Whether there are none.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Values `g(q)` of all constraints into `values` and, if asked, their Jacobian w.r.t. q
    /// into `jacobian` (row-major `len × dof`).
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
    /// PANOC iterations and projected-gradient steps in all.
    pub max_iterations: usize,
    /// Iterations per round; the improvement is checked after each round.
    pub check_every: usize,
    /// Stop when a round lowers φ by less than this fraction.
    pub min_relative_improvement: f64,
    /// Wall-clock limit of the whole refinement.
    pub max_duration: Duration,
    /// L-BFGS memory of PANOC (correction pairs kept).
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
    /// The refined design, one configuration per pose (internal units: rad, mm).
    pub q: Vec<Vec<f64>>,
    /// φ of the refined design.
    pub value: f64,
    /// φ of the start design.
    pub start_value: f64,
    /// How the PANOC rounds ended: a convergence criterion, the iteration or time limit, or
    /// a stall (no further descent), after which projected-gradient steps continue.
    pub status: Status,
    /// The projected-gradient steps after a stall (`None`: they did not run, no stall or
    /// no iterations left).
    pub projected_gradient_steps: Option<usize>,
    /// PANOC iterations and projected-gradient steps run.
    pub iterations: usize,
    /// φ at the start and after each round.
    pub history: Vec<f64>,
    /// Wall-clock time of the refinement.
    pub time: Duration,
}

impl RefineResult {
    /// The status in the design record's words: `converged`, `converged (a round of …)`,
    /// `iteration limit`, `time limit`; a stall reads `converged (no further descent)` (the
    /// best design so far is kept, and no step lowers φ) and is followed by
    /// `; then N projected-gradient steps` when those ran.
    pub fn describe(&self) -> String {
        let status = match &self.status {
            Status::IterationLimit => "iteration limit".to_string(),
            Status::TimeLimit => "time limit".to_string(),
            Status::Stalled { reason } => format!("converged ({reason})"),
            other => other.to_string(),
        };
        match self.projected_gradient_steps {
            Some(n) => format!("{status}; then {n} projected-gradient steps"),
            None => status,
        }
    }
}

/// Corrections per configuration and projection.
const MAX_CORRECTIONS: usize = 6;
/// Each correction aims this far beyond the boundary (as a multiple of the violation), so
/// that the linearisation error of a curved constraint rarely needs a second correction.
const OVERSHOOT: f64 = 1.05;
/// Bisection steps of [`ProjectionBuffers::retreat`].
const RETREAT_STEPS: usize = 4;
/// Shortest PANOC round (iterations) after rounds that ended worse than they started.
const MIN_ROUND: usize = 5;
/// Safety factor on the observed gradient bounds (see [`FeasibleSet`]).
const LIPSCHITZ_SAFETY: f64 = 2.0;
/// A configuration farther than this (rad or mm, 1-norm) from its anchor is evaluated in full
/// and re-anchored; so is one with more than a third of its constraints possibly near.
const REANCHOR_DISTANCE: f64 = 0.2;

/// The feasible set of the design: a product over configurations of each configuration's
/// joint box (the joint limits, or a smaller box around a pose of the user's pool) and
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
    /// Joints per configuration.
    k: usize,
    /// Box of every configuration, configuration after configuration (N·k values each).
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
    /// Per configuration: the last configuration that passed a full evaluation.
    safe: Vec<f64>,
    has_safe: Vec<bool>,
    /// Joints free in a correction, and the correction.
    free: Vec<bool>,
    step: Vec<f64>,
}

impl FeasibleSet<'_> {
    /// The box of configuration `index`.
    fn bounds(&self, index: usize) -> (&[f64], &[f64]) {
        let r = index * self.k..(index + 1) * self.k;
        (&self.lower[r.clone()], &self.upper[r])
    }

    fn clamp(&self, index: usize, q: &mut [f64]) {
        let (lower, upper) = self.bounds(index);
        for ((x, lo), hi) in q.iter_mut().zip(lower).zip(upper) {
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
        let k = self.k;
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

    /// Projects configuration `index`. If the corrections do not reach the set (joint limits
    /// and constraints pulling against each other), the configuration returns to the last
    /// one that passed a full evaluation, so every iterate stays feasible.
    fn project_configuration(
        &self,
        cons: &dyn ConfigurationConstraints,
        index: usize,
        q: &mut [f64],
    ) {
        let b = &mut *self.buffers.borrow_mut();
        let (lower, upper) = self.bounds(index);
        self.clamp(index, q);
        for _ in 0..MAX_CORRECTIONS {
            if !b.violated_at(cons, index, q) {
                return;
            }
            if !b.correct(q, lower, upper) {
                break;
            }
            self.clamp(index, q);
        }
        if b.has_safe[index] {
            b.retreat(cons, index, q);
        }
    }
}

impl ProjectionBuffers {
    /// Moves `q`, which the corrections could not make feasible, back along the segment to
    /// the last fully checked feasible configuration `s` of `index`: to the farthest point
    /// `s + t (q − s)`, `t ∈ {1/2, 1/4, …}`, that passes a full evaluation (`s` itself if
    /// none does). Bisection keeps the projection continuous in `q` far more than a jump
    /// back to `s` would.
    fn retreat(&mut self, cons: &dyn ConfigurationConstraints, index: usize, q: &mut [f64]) {
        let k = q.len();
        let m = self.values.len();
        self.step.copy_from_slice(q);
        q.copy_from_slice(&self.safe[index * k..(index + 1) * k]);
        let mut t = 1.0;
        for _ in 0..RETREAT_STEPS {
            t *= 0.5;
            let safe = &self.safe[index * k..(index + 1) * k];
            for ((x, s), target) in q.iter_mut().zip(safe).zip(&self.step) {
                *x = s + t * (target - s);
            }
            cons.evaluate(q, &mut self.values, None);
            if self.values.iter().all(|&v| v >= 0.0) {
                self.safe[index * k..(index + 1) * k].copy_from_slice(q);
                self.anchors[index * k..(index + 1) * k].copy_from_slice(q);
                self.anchor_values[index * m..(index + 1) * m].copy_from_slice(&self.values);
                self.anchored[index] = true;
                return;
            }
        }
        q.copy_from_slice(&self.safe[index * k..(index + 1) * k]);
    }

    /// Fills `violated` with the constraints violated at `q` (and their values and gradients
    /// in `values`, `jacobian`); whether there are any. Evaluates only the constraints the
    /// anchor's bound does not clear, or everything (and re-anchors) when the configuration
    /// moved far or many are near.
    fn violated_at(
        &mut self,
        cons: &dyn ConfigurationConstraints,
        index: usize,
        q: &[f64],
    ) -> bool {
        let k = q.len();
        let m = self.values.len();
        let moved: f64 = if self.anchored[index] {
            let anchor = &self.anchors[index * k..(index + 1) * k];
            q.iter().zip(anchor).map(|(x, a)| (x - a).abs()).sum()
        } else {
            f64::INFINITY
        };
        self.near.clear();
        if moved <= REANCHOR_DISTANCE {
            let av = &self.anchor_values[index * m..(index + 1) * m];
            let l = &self.lipschitz;
            self.near
                .extend((0..m).filter(|&c| av[c] - l[c] * moved < 0.0));
            if self.near.is_empty() {
                return false;
            }
        }
        self.violated.clear();
        if moved > REANCHOR_DISTANCE || 3 * self.near.len() > m {
            cons.evaluate(q, &mut self.values, None);
            self.anchors[index * k..(index + 1) * k].copy_from_slice(q);
            self.anchor_values[index * m..(index + 1) * m].copy_from_slice(&self.values);
            self.anchored[index] = true;
            let values = &self.values;
            self.violated.extend((0..m).filter(|&c| values[c] < 0.0));
            if self.violated.is_empty() {
                self.safe[index * k..(index + 1) * k].copy_from_slice(q);
                self.has_safe[index] = true;
                return false;
            }
            cons.evaluate_rows(
                q,
                &self.violated,
                &mut self.values,
                Some(&mut self.jacobian),
            );
        } else {
            // One forward kinematics for the values and gradients of the near ones.
            cons.evaluate_rows(q, &self.near, &mut self.values, Some(&mut self.jacobian));
            let values = &self.values;
            self.violated
                .extend(self.near.iter().copied().filter(|&c| values[c] < 0.0));
        }
        !self.violated.is_empty()
    }

    /// One minimum-norm correction of `q` on the `violated` constraints, with the joints that
    /// sit at a limit and would be pushed beyond it held fixed (their Jacobian columns left
    /// out, the projection onto the box and the linearised constraints); false if there is no
    /// direction to follow.
    fn correct(&mut self, q: &mut [f64], lower: &[f64], upper: &[f64]) -> bool {
        let k = q.len();
        let nv = self.violated.len();
        self.free.fill(true);
        for _ in 0..=k {
            // Normal matrix J_v J_vᵀ over the free joints, lightly regularised (dependent
            // constraints).
            let mut trace = 0.0;
            for (r, &cr) in self.violated.iter().enumerate() {
                for (s, &cs) in self.violated.iter().enumerate().take(r + 1) {
                    let gr = &self.jacobian[cr * k..(cr + 1) * k];
                    let gs = &self.jacobian[cs * k..(cs + 1) * k];
                    let v: f64 = (0..k)
                        .filter(|&j| self.free[j])
                        .map(|j| gr[j] * gs[j])
                        .sum();
                    self.normal[r * nv + s] = v;
                    self.normal[s * nv + r] = v;
                }
                trace += self.normal[r * nv + r];
                self.rhs[r] = -OVERSHOOT * self.values[cr];
            }
            if trace <= 0.0 {
                return false;
            }
            for r in 0..nv {
                self.normal[r * nv + r] += 1e-10 * trace / nv as f64;
            }
            if !small_cholesky::factor(&mut self.normal[..nv * nv], nv) {
                return false;
            }
            small_cholesky::solve(&self.normal[..nv * nv], &mut self.rhs[..nv], nv);
            self.step.fill(0.0);
            for (r, &cr) in self.violated.iter().enumerate() {
                let y = self.rhs[r];
                for (d, g) in self
                    .step
                    .iter_mut()
                    .zip(&self.jacobian[cr * k..(cr + 1) * k])
                {
                    *d += g * y;
                }
            }
            let mut blocked = false;
            for j in 0..k {
                let x = q[j] + self.step[j];
                if self.free[j]
                    && ((x < lower[j] && q[j] <= lower[j]) || (x > upper[j] && q[j] >= upper[j]))
                {
                    self.free[j] = false;
                    blocked = true;
                }
            }
            if !blocked {
                for ((x, d), free) in q.iter_mut().zip(&self.step).zip(&self.free) {
                    if *free {
                        *x += d;
                    }
                }
                return true;
            }
        }
        false
    }
}

impl Constraint for FeasibleSet<'_> {
    fn project(&self, x: &mut [f64]) -> FunctionCallResult {
        for (index, q) in x.chunks_mut(self.k).enumerate() {
            match self.constraints {
                Some(c) => self.project_configuration(c, index, q),
                None => self.clamp(index, q),
            }
        }
        Ok(())
    }

    fn is_convex(&self) -> bool {
        self.constraints.is_none()
    }
}

/// Refines the design `start` (N configurations) within the joint limits `lower`, `upper`
/// (one value per joint).
pub fn refine(
    objective: &DesignObjective,
    start: &[Vec<f64>],
    lower: &[f64],
    upper: &[f64],
    constraints: Option<&dyn ConfigurationConstraints>,
    settings: &RefineSettings,
    observer: &mut dyn Observer,
) -> Result<RefineResult, Error> {
    let n = start.len();
    refine_in_boxes(
        objective,
        start,
        &lower.repeat(n),
        &upper.repeat(n),
        constraints,
        settings,
        observer,
    )
}

/// Refines the design `start` (N configurations of k joints) with configuration `i` kept in
/// its own box `lower[i·k..(i+1)·k]`, `upper[i·k..(i+1)·k]` (N·k values each; e.g. the joint
/// limits intersected with a radius around a pool pose). Every start configuration should
/// lie in its box (it is clamped into it first).
pub fn refine_in_boxes(
    objective: &DesignObjective,
    start: &[Vec<f64>],
    lower: &[f64],
    upper: &[f64],
    constraints: Option<&dyn ConfigurationConstraints>,
    settings: &RefineSettings,
    observer: &mut dyn Observer,
) -> Result<RefineResult, Error> {
    let t0 = Instant::now();
    let k = objective.design.dof();
    let nconf = start.len();
    let nu = k * nconf;
    if lower.len() != nu || upper.len() != nu {
        return Err(Error::Input(format!(
            "pose refinement: {nconf} configurations of {k} joints need {nu} bounds each, got {} and {}",
            lower.len(),
            upper.len()
        )));
    }
    let m = constraints.map_or(0, |c| c.len());
    let set = FeasibleSet {
        k,
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
            safe: vec![0.0; nu],
            has_safe: vec![false; nconf],
            free: vec![true; k],
            step: vec![0.0; k],
        }),
    };
    let mut u: Vec<f64> = start.concat();
    set.project(&mut u)
        .map_err(|e| Error::Numerical(format!("pose refinement failed: {e:?}")))?;
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
    // PANOC descends on its envelope, not on φ itself, and with a non-convex set a round can
    // end worse than it started: then the round restarts from the best design with a third
    // of its length, down to MIN_ROUND iterations.
    let mut round_length = settings.check_every.max(1);
    observer.start("pose refinement", Some(settings.max_iterations));
    let status = loop {
        let remaining = settings.max_duration.saturating_sub(t0.elapsed());
        let round = round_length.min(settings.max_iterations - iterations);
        if round == 0 {
            break Status::IterationLimit;
        }
        if remaining.is_zero() {
            break Status::TimeLimit;
        }
        cache.reset();
        let problem = Problem::new(&set, grad, cost);
        let mut panoc = PANOCOptimizer::new(problem, &mut cache)
            .with_max_iter(round)
            .with_max_duration(remaining);
        let s = panoc
            .solve(&mut u)
            .map_err(|e| Error::Numerical(format!("pose refinement failed: {e}")))?;
        iterations += s.iterations();
        let previous = value;
        value = objective.value_and_gradient(&mut ws.borrow_mut(), &u, None)?;
        history.push(value);
        observer.iteration(iterations, value, 0.0);
        if value > previous {
            u.copy_from_slice(&best_u);
            value = previous;
            if round_length <= MIN_ROUND {
                break Status::Stalled {
                    reason: "no further descent".into(),
                };
            }
            round_length = (round_length / 3).max(MIN_ROUND);
            continue;
        }
        best_u.copy_from_slice(&u);
        if s.exit_status() == ExitStatus::Converged {
            // PANOC's own fixed-point tolerance: nothing more to say.
            break Status::Converged {
                criterion: String::new(),
            };
        }
        let expected =
            settings.min_relative_improvement * round as f64 / settings.check_every.max(1) as f64;
        if previous - value < expected * previous.abs() {
            break Status::Converged {
                criterion: format!(
                    "a round of {round} iterations improved by less than {:e}",
                    expected
                ),
            };
        }
    };
    // Where PANOC stalls (its line search on the envelope fails when many configurations sit
    // on curved constraint boundaries), projected gradient steps with an Armijo test on φ
    // itself continue monotonically, within the remaining iteration budget.
    let stalled = matches!(status, Status::Stalled { .. });
    let projected_gradient_steps = if stalled && iterations < settings.max_iterations {
        let budget = settings.max_iterations - iterations;
        let (v, n) = projected_gradient(
            objective,
            &mut ws.borrow_mut(),
            &set,
            &mut u,
            value,
            budget,
            settings.max_duration.saturating_sub(t0.elapsed()),
        )?;
        iterations += n;
        value = v;
        history.push(value);
        best_u.copy_from_slice(&u);
        observer.iteration(iterations, value, 0.0);
        Some(n)
    } else {
        None
    };
    observer.finish();
    // The skipped evaluations rest on estimated bounds: project the result once more with
    // every constraint evaluated.
    set.reset();
    set.project(&mut u)
        .map_err(|e| Error::Numerical(format!("pose refinement failed: {e:?}")))?;
    if u != best_u {
        value = objective.value_and_gradient(&mut ws.borrow_mut(), &u, None)?;
    }
    Ok(RefineResult {
        q: u.chunks(k).map(<[f64]>::to_vec).collect(),
        value,
        start_value,
        status,
        projected_gradient_steps,
        iterations,
        history,
        time: t0.elapsed(),
    })
}

/// Projected gradient descent on φ with an Armijo test, from the feasible design `u` with
/// value `value`: `u⁺ = Π(u − α ∇φ)`, accepted if `φ(u⁺) ≤ φ(u) − 10⁻⁴ ∇φ·(u − u⁺)`; α
/// grows by 1.5 after an accepted step and shrinks by 0.3 after a rejected one, starting
/// with a largest joint move of 0.05 rad. Returns the value and the accepted steps.
fn projected_gradient(
    objective: &DesignObjective,
    ws: &mut crate::design::ObjectiveWorkspace,
    set: &FeasibleSet,
    u: &mut [f64],
    mut value: f64,
    max_steps: usize,
    max_duration: Duration,
) -> Result<(f64, usize), Error> {
    let t0 = Instant::now();
    let mut g = vec![0.0; u.len()];
    let mut trial = u.to_vec();
    objective.value_and_gradient(ws, u, Some(&mut g))?;
    let gmax = g.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    if gmax == 0.0 {
        return Ok((value, 0));
    }
    let mut alpha = 0.05 / gmax;
    let mut steps = 0;
    let mut trials = 0;
    while steps < max_steps && trials < 4 * max_steps && t0.elapsed() < max_duration {
        trials += 1;
        for ((t, x), gi) in trial.iter_mut().zip(u.iter()).zip(&g) {
            *t = x - alpha * gi;
        }
        set.project(&mut trial)
            .map_err(|e| Error::Numerical(format!("pose refinement failed: {e:?}")))?;
        let decrease: f64 = g
            .iter()
            .zip(u.iter())
            .zip(&trial)
            .map(|((gi, x), t)| gi * (x - t))
            .sum();
        // A singular trial design counts as no descent.
        let v = objective
            .value_and_gradient(ws, &trial, None)
            .unwrap_or(f64::INFINITY);
        if v <= value - 1e-4 * decrease && v < value {
            u.copy_from_slice(&trial);
            value = v;
            steps += 1;
            alpha *= 1.5;
            objective.value_and_gradient(ws, u, Some(&mut g))?;
        } else {
            alpha *= 0.3;
            if alpha * gmax < 1e-8 {
                break;
            }
        }
    }
    Ok((value, steps))
}
