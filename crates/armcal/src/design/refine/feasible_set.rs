//! The feasible set of the refinement and its projection; the working set of bounds and
//! constraints a descent step would cross, and the projection onto its tangent directions.

use super::ConfigurationConstraints;
use crate::design::small_cholesky;
use std::cell::RefCell;

/// Corrections per configuration and projection.
const MAX_CORRECTIONS: usize = 6;
/// Each correction aims this far beyond the boundary (as a multiple of the violation), so
/// that the linearisation error of a curved constraint rarely needs a second correction.
const OVERSHOOT: f64 = 1.05;
/// Bisection steps of [`ProjectionBuffers::retreat`].
const RETREAT_STEPS: usize = 4;
/// Safety factor on the observed gradient bounds (see [`FeasibleSet`]).
const LIPSCHITZ_SAFETY: f64 = 2.0;
/// A configuration farther than this (rad or mm, 1-norm) from its anchor is evaluated in full
/// and re-anchored; so is one with more than a third of its constraints possibly near.
const REANCHOR_DISTANCE: f64 = 0.2;

/// The feasible set of the design: a product over configurations of each configuration's
/// joint box (the joint limits, or a smaller box around a pose of the user's pool) and
/// `{q : g(q) ≥ 0}`. Its projection (of every trial point of the descent) clamps each configuration
/// into the box and then applies minimum-norm Gauss–Newton corrections on the violated
/// constraints `v`, `Δq = J_vᵀ (J_v J_vᵀ)⁻¹ (−g_v)` — the Euclidean projection to first
/// order — until none is violated. Allocates nothing per call.
///
/// The descent projects every line-search trial, mostly after small moves, so each configuration
/// keeps an anchor `a` where all its constraints were last evaluated. By the mean-value
/// theorem `g_c(q) ≥ g_c(a) − L_c ‖q − a‖₁` with `L_c = sup ‖∇g_c‖_∞`; only the constraints
/// for which this bound does not prove `g_c(q) ≥ 0` are evaluated (none at all for a
/// configuration far from every boundary). `L_c` is estimated as [`LIPSCHITZ_SAFETY`] times
/// the largest `‖∇g_c‖_∞` over the start design, so the skip is a heuristic: the final
/// iterate is projected once more with every constraint evaluated ([`FeasibleSet::reset`]),
/// and the planner checks the result strictly.
pub(super) struct FeasibleSet<'a> {
    /// Joints per configuration.
    k: usize,
    /// Box of every configuration, configuration after configuration (N·k values each).
    pub(super) lower: &'a [f64],
    pub(super) upper: &'a [f64],
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
    /// Per configuration: an orthonormal basis (`k` vectors of `k` values at most) of the
    /// normals of the bounds and constraints a descent step would cross
    /// ([`FeasibleSet::active_normals`]), and how many vectors it has.
    basis: Vec<f64>,
    basis_len: Vec<usize>,
    /// The candidate normal being added to a basis.
    candidate: Vec<f64>,
    /// Per configuration: the constraint values and Jacobian at the iterate
    /// ([`FeasibleSet::active_normals`]), and the configuration they were evaluated at
    /// (`evaluated`, if `has_evaluated`): a projection's full evaluation at the point the
    /// descent then accepts is not repeated.
    active_values: Vec<f64>,
    active_jacobian: Vec<f64>,
    evaluated: Vec<f64>,
    has_evaluated: Vec<bool>,
}

impl<'a> FeasibleSet<'a> {
    /// The set of `nconf` configurations of `k` joints in the boxes `lower`, `upper` (N·k
    /// values each) under `constraints`, with its buffers.
    pub(super) fn new(
        k: usize,
        lower: &'a [f64],
        upper: &'a [f64],
        constraints: Option<&'a dyn ConfigurationConstraints>,
        nconf: usize,
    ) -> Self {
        let m = constraints.map_or(0, |c| c.len());
        let nu = k * nconf;
        FeasibleSet {
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
                basis: vec![0.0; nu * k],
                basis_len: vec![0; nconf],
                candidate: vec![0.0; k],
                active_values: vec![0.0; m * nconf],
                active_jacobian: vec![0.0; m * k * nconf],
                evaluated: vec![0.0; nu],
                has_evaluated: vec![false; nconf],
            }),
        }
    }

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
    pub(super) fn reset(&self) {
        self.buffers.borrow_mut().anchored.fill(false);
    }

    /// Sets `L_c` from the constraint gradients at the configurations of `x`.
    pub(super) fn estimate_lipschitz(&self, x: &[f64]) {
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
            // Values and Jacobian in one kinematics pass, kept for the working set
            // (`active_normals`) should the descent accept this configuration.
            cons.evaluate(q, &mut self.values, Some(&mut self.jacobian));
            self.active_values[index * m..(index + 1) * m].copy_from_slice(&self.values);
            self.active_jacobian[index * m * k..(index + 1) * m * k]
                .copy_from_slice(&self.jacobian);
            self.evaluated[index * k..(index + 1) * k].copy_from_slice(q);
            self.has_evaluated[index] = true;
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

impl FeasibleSet<'_> {
    /// For the feasible design `u` with gradient `g`: per configuration, the bounds and
    /// constraints the steepest descent `−g` would cross — a joint at its limit pushed
    /// outwards, a constraint within reach of a move of [`ACTIVE_MOVE`]
    /// (`g_c(q) ≤ ACTIVE_MOVE ‖∇g_c‖`) that `−g` decreases — collected one at a time (each
    /// tested against `−g` with the earlier ones projected out) into an orthonormal basis of
    /// their normals (modified Gram–Schmidt). [`FeasibleSet::tangent`] then projects onto
    /// the directions along all of them: the working set of a gradient-projection method.
    pub(super) fn active_normals(&self, u: &[f64], v: &[f64], extend: bool) {
        let k = self.k;
        let b = &mut *self.buffers.borrow_mut();
        let m = b.values.len();
        for (index, (q, vq)) in u.chunks(k).zip(v.chunks(k)).enumerate() {
            let values = &mut b.active_values[index * m..(index + 1) * m];
            let jacobian = &mut b.active_jacobian[index * m * k..(index + 1) * m * k];
            let evaluated = &mut b.evaluated[index * k..(index + 1) * k];
            if let (Some(cons), false) = (self.constraints, extend) {
                let same = evaluated
                    .iter()
                    .zip(q)
                    .all(|(a, x)| a.to_bits() == x.to_bits());
                if !(b.has_evaluated[index] && same) {
                    cons.evaluate(q, values, Some(jacobian));
                    evaluated.copy_from_slice(q);
                    b.has_evaluated[index] = true;
                }
            }
            let (lower, upper) = self.bounds(index);
            let basis = &mut b.basis[index * k * k..(index + 1) * k * k];
            let mut len = if extend { b.basis_len[index] } else { 0 };
            // The direction tested (−g, or d), with the normals found so far projected out.
            if extend {
                b.step.copy_from_slice(vq);
            } else {
                b.step.iter_mut().zip(vq).for_each(|(d, g)| *d = -g);
            }
            while len < k {
                // The first candidate normal `a` (pointing out of the set) with a·d > 0.
                let mut found = false;
                let normal = &mut b.candidate;
                for j in 0..k {
                    let out = if q[j] <= lower[j] {
                        -1.0
                    } else if q[j] >= upper[j] {
                        1.0
                    } else {
                        continue;
                    };
                    if out * b.step[j] > 0.0 && !in_span(basis, len, k, j) {
                        normal.fill(0.0);
                        normal[j] = out;
                        found = true;
                        break;
                    }
                }
                if !found {
                    for c in 0..m {
                        let grad = &jacobian[c * k..(c + 1) * k];
                        let norm = grad.iter().map(|v| v * v).sum::<f64>().sqrt();
                        let along: f64 = grad.iter().zip(&b.step).map(|(a, d)| a * d).sum();
                        if norm > 0.0 && values[c] <= ACTIVE_MOVE * norm && along < -1e-12 * norm {
                            normal.iter_mut().zip(grad).for_each(|(n, a)| *n = -a);
                            found = true;
                            break;
                        }
                    }
                }
                if !found {
                    break;
                }
                // Orthonormalise against the basis and project it out of d.
                for v in 0..len {
                    let bv = &basis[v * k..(v + 1) * k];
                    let p: f64 = bv.iter().zip(normal.iter()).map(|(x, y)| x * y).sum();
                    normal.iter_mut().zip(bv).for_each(|(n, x)| *n -= p * x);
                }
                let norm = normal.iter().map(|v| v * v).sum::<f64>().sqrt();
                if norm < 1e-9 {
                    break;
                }
                let bv = &mut basis[len * k..(len + 1) * k];
                bv.iter_mut()
                    .zip(normal.iter())
                    .for_each(|(x, n)| *x = n / norm);
                let p: f64 = bv.iter().zip(&b.step).map(|(x, d)| x * d).sum();
                b.step
                    .iter_mut()
                    .zip(bv.iter())
                    .for_each(|(d, x)| *d -= p * x);
                len += 1;
            }
            b.basis_len[index] = len;
        }
    }

    /// Projects `v` (N·k values) onto the directions along every normal of
    /// [`FeasibleSet::active_normals`]: `v_i ← v_i − Σ_b (b·v_i) b` per configuration.
    pub(super) fn tangent(&self, v: &mut [f64]) {
        let k = self.k;
        let b = self.buffers.borrow();
        for (index, vi) in v.chunks_mut(k).enumerate() {
            let basis = &b.basis[index * k * k..(index + 1) * k * k];
            for bv in basis.chunks(k).take(b.basis_len[index]) {
                let p: f64 = bv.iter().zip(vi.iter()).map(|(x, y)| x * y).sum();
                vi.iter_mut().zip(bv).for_each(|(y, x)| *y -= p * x);
            }
        }
    }

    /// Projects every configuration of `x` (N·k values) onto its set.
    pub(super) fn project(&self, x: &mut [f64]) {
        for (index, q) in x.chunks_mut(self.k).enumerate() {
            match self.constraints {
                Some(c) => self.project_configuration(c, index, q),
                None => self.clamp(index, q),
            }
        }
    }
}

/// A constraint within reach of a move this long (rad or mm) counts as active.
const ACTIVE_MOVE: f64 = 1e-3;

/// Whether joint `j`'s unit vector lies in the span of the first `len` basis vectors.
fn in_span(basis: &[f64], len: usize, k: usize, j: usize) -> bool {
    let rest: f64 = 1.0 - basis.chunks(k).take(len).map(|b| b[j] * b[j]).sum::<f64>();
    rest < 1e-12
}
