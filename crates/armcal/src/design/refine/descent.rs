//! Projected L-BFGS on the design (see the parent module): the working set's tangent
//! directions, the two-loop recursion, and the search along the projection arc.

use super::feasible_set::FeasibleSet;
use super::RefineSettings;
use crate::design::objective::{DesignObjective, ObjectiveWorkspace};
use crate::linalg::dot;
use crate::progress::Observer;
use crate::solve::Status;
use crate::Error;
use std::time::Instant;

/// Largest joint move (rad or mm) of a step without curvature information (the first one,
/// and after a restart).
const FIRST_MOVE: f64 = 0.05;
/// Armijo's sufficient-decrease fraction.
const ARMIJO: f64 = 1e-4;
/// Halvings of the step along the projection arc before the direction counts as failed.
const MAX_BACKTRACKS: usize = 30;

/// Projected L-BFGS on the objective scaled by `1/φ(u₀)`, with its buffers (allocated once).
pub(super) struct Descent<'a, 'b> {
    objective: &'a DesignObjective<'a>,
    set: &'a FeasibleSet<'b>,
    /// Gradient at `u` and at the trial point, the direction, the trial point.
    g: Vec<f64>,
    /// The gradient projected on the working set's tangent directions at `u`, and at the
    /// previous iterate; the last step.
    pg: Vec<f64>,
    pg_previous: Vec<f64>,
    last_step: Vec<f64>,
    g_trial: Vec<f64>,
    d: Vec<f64>,
    trial: Vec<f64>,
    /// Correction pairs `s = u⁺ − u`, `y = ∇φ(u⁺) − ∇φ(u)`, `ρ = 1/(yᵀs)`, newest at
    /// `(head + len − 1) % memory`.
    s: Vec<Vec<f64>>,
    y: Vec<Vec<f64>>,
    rho: Vec<f64>,
    alpha: Vec<f64>,
    head: usize,
    len: usize,
    /// φ after each iteration (unscaled).
    pub(super) history: Vec<f64>,
    /// Evaluations of φ and its gradient.
    pub(super) evaluations: usize,
}

impl<'a, 'b> Descent<'a, 'b> {
    pub(super) fn new(
        objective: &'a DesignObjective<'a>,
        set: &'a FeasibleSet<'b>,
        nu: usize,
        memory: usize,
    ) -> Self {
        let memory = memory.max(1);
        Descent {
            objective,
            set,
            g: vec![0.0; nu],
            pg: vec![0.0; nu],
            pg_previous: vec![0.0; nu],
            last_step: vec![0.0; nu],
            g_trial: vec![0.0; nu],
            d: vec![0.0; nu],
            trial: vec![0.0; nu],
            s: vec![vec![0.0; nu]; memory],
            y: vec![vec![0.0; nu]; memory],
            rho: vec![0.0; memory],
            alpha: vec![0.0; memory],
            head: 0,
            len: 0,
            history: Vec::new(),
            evaluations: 0,
        }
    }

    /// The L-BFGS direction `d = −P H P g`, P the projection onto the working set's
    /// tangent directions ([`FeasibleSet::tangent`]), by the two-loop recursion with a
    /// diagonal initial matrix (per-variable secant scaling, below).
    fn direction(&mut self) {
        let mem = self.s.len();
        for (d, g) in self.d.iter_mut().zip(&self.pg) {
            *d = -g;
        }
        for back in 0..self.len {
            let i = (self.head + self.len - 1 - back) % mem;
            let a = self.rho[i] * dot(&self.s[i], &self.d);
            self.alpha[i] = a;
            axpy(-a, &self.y[i], &mut self.d);
        }
        if self.len > 0 {
            // H₀ = diag(γ_j), γ_j = Σ s_j y_j / Σ y_j² over the pairs kept (the secant scaling
            // of each joint value on its own; `sᵀy/yᵀy` of the newest pair where a joint's
            // pairs show no positive curvature). The design's variables differ in scale (a
            // wrist joint moves the reflector far less than q1; a pose on the incidence
            // boundary far less freely than one inside): on the paper cell the diagonal
            // reaches 0.3350 in 240–290 iterations where the scalar needs 360 or more.
            let i = (self.head + self.len - 1) % mem;
            let gamma = 1.0 / (self.rho[i] * dot(&self.y[i], &self.y[i]));
            for (j, d) in self.d.iter_mut().enumerate() {
                let (mut sy, mut yy) = (0.0, 0.0);
                for b in 0..self.len {
                    let p = (self.head + b) % mem;
                    sy += self.s[p][j] * self.y[p][j];
                    yy += self.y[p][j] * self.y[p][j];
                }
                *d *= if sy > 0.0 && yy > 0.0 { sy / yy } else { gamma };
            }
        }
        for fwd in 0..self.len {
            let i = (self.head + fwd) % mem;
            let b = self.rho[i] * dot(&self.y[i], &self.d);
            axpy(self.alpha[i] - b, &self.s[i], &mut self.d);
        }
        self.set.tangent(&mut self.d);
    }

    /// Keeps the pair `s` = the last step, `y = P₊∇φ₊ − P∇φ` (the change of the gradient
    /// projected on the working set's tangent directions at each end, the secant of the
    /// reduced problem) if its curvature `sᵀy` is positive, dropping the oldest pair when
    /// the memory is full.
    fn remember(&mut self) {
        let mem = self.s.len();
        let slot = if self.len < mem {
            (self.head + self.len) % mem
        } else {
            let h = self.head;
            self.head = (self.head + 1) % mem;
            h
        };
        let (mut sy, mut ss, mut yy) = (0.0, 0.0, 0.0);
        for i in 0..self.pg.len() {
            let s = self.last_step[i];
            let y = self.pg[i] - self.pg_previous[i];
            self.s[slot][i] = s;
            self.y[slot][i] = y;
            sy += s * y;
            ss += s * s;
            yy += y * y;
        }
        if sy > 1e-10 * (ss * yy).sqrt() {
            self.rho[slot] = 1.0 / sy;
            self.len = (self.len + 1).min(mem);
        } else if self.len == mem {
            // The oldest pair was dropped for nothing: keep the memory one shorter.
            self.len -= 1;
        }
    }

    /// Descends from the feasible `u`; returns the status and the iterations run.
    pub(super) fn run(
        &mut self,
        ws: &mut ObjectiveWorkspace,
        u: &mut [f64],
        settings: &RefineSettings,
        t0: Instant,
        observer: &mut dyn Observer,
    ) -> Result<(Status, usize), Error> {
        let start = self.objective.value_and_gradient(ws, u, None)?;
        let scale = 1.0 / start.abs().max(1e-300);
        self.evaluations += 1;
        let mut f = scaled(self.objective, ws, u, Some(&mut self.g), scale);
        let window = settings.check_every.max(1);
        let mut iterations = 0;
        let mut values = vec![f];
        let mut pending = false;
        let status = loop {
            if iterations >= settings.max_iterations {
                break Status::IterationLimit;
            }
            if t0.elapsed() >= settings.max_duration {
                break Status::TimeLimit;
            }
            // The working set at u, the projected gradient, and the pair of the last step.
            self.set.active_normals(u, &self.g, false);
            self.pg.copy_from_slice(&self.g);
            self.set.tangent(&mut self.pg);
            if std::mem::take(&mut pending) {
                self.remember();
            }
            let largest = self.pg.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            if largest < settings.tolerance {
                break Status::Converged {
                    criterion: format!(
                        "projected gradient below {:e} of the start value per rad",
                        settings.tolerance
                    ),
                };
            }
            let Some(ft) = self.line_search(ws, u, f, scale) else {
                if self.len == 0 {
                    break Status::Stalled {
                        reason: "no further descent".into(),
                    };
                }
                // The quasi-Newton model misled the step: restart from the steepest descent.
                self.len = 0;
                continue;
            };
            for ((s, t), x) in self.last_step.iter_mut().zip(&self.trial).zip(u.iter()) {
                *s = t - x;
            }
            pending = true;
            std::mem::swap(&mut self.pg, &mut self.pg_previous);
            u.copy_from_slice(&self.trial);
            std::mem::swap(&mut self.g, &mut self.g_trial);
            f = ft;
            iterations += 1;
            values.push(f);
            self.history.push(f / scale);
            if iterations % 10 == 0 {
                observer.iteration(iterations, f / scale, largest);
            }
            if iterations >= window {
                let before = values[iterations - window];
                if before - f < settings.min_relative_improvement * before {
                    break Status::Converged {
                        criterion: format!(
                            "{window} iterations improved by less than {:e}",
                            settings.min_relative_improvement
                        ),
                    };
                }
            }
        };
        Ok((status, iterations))
    }

    /// Searches along the projection arc `Π(u + α d)` for a point with
    /// `φ ≤ φ(u) − 10⁻⁴ ∇φ·(u − Π(u + α d))`, halving α from 1 (from a largest move of
    /// [`FIRST_MOVE`] without curvature pairs). On success the point is in `trial`, its
    /// gradient in `g_trial`, and its (scaled) value is returned.
    fn line_search(
        &mut self,
        ws: &mut ObjectiveWorkspace,
        u: &[f64],
        f: f64,
        scale: f64,
    ) -> Option<f64> {
        self.direction();
        // Bounds and constraints the quasi-Newton direction would cross join the working set.
        self.set.active_normals(u, &self.d, true);
        self.set.tangent(&mut self.d);
        let mut slope: f64 = self.d.iter().zip(&self.g).map(|(d, g)| d * g).sum();
        if slope >= 0.0 {
            // Not a descent direction (curvature pairs bent by the projection): steepest
            // descent.
            self.len = 0;
            self.direction();
            slope = self.d.iter().zip(&self.g).map(|(d, g)| d * g).sum();
            if slope >= 0.0 {
                return None;
            }
        }
        let dmax = self.d.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let mut alpha = if self.len == 0 {
            FIRST_MOVE / dmax
        } else {
            1.0
        };
        for _ in 0..MAX_BACKTRACKS {
            for ((t, x), d) in self.trial.iter_mut().zip(u).zip(&self.d) {
                *t = x + alpha * d;
            }
            self.set.project(&mut self.trial);
            let decrease: f64 = self
                .g
                .iter()
                .zip(u)
                .zip(&self.trial)
                .map(|((g, x), t)| g * (x - t))
                .sum();
            if decrease > 0.0 {
                self.evaluations += 1;
                // The value first; the gradient (from the same kinematics) only for the point
                // accepted.
                let ft = scaled(self.objective, ws, &self.trial, None, scale);
                if ft <= f - ARMIJO * decrease && ft < f {
                    return Some(scaled(
                        self.objective,
                        ws,
                        &self.trial,
                        Some(&mut self.g_trial),
                        scale,
                    ));
                }
            }
            alpha *= 0.5;
        }
        None
    }
}

/// φ at `x` and, if asked, its gradient into `g`, both times `scale`; a singular design is
/// +∞.
fn scaled(
    objective: &DesignObjective,
    ws: &mut ObjectiveWorkspace,
    x: &[f64],
    mut g: Option<&mut [f64]>,
    scale: f64,
) -> f64 {
    match objective.value_and_gradient(ws, x, g.as_deref_mut()) {
        Ok(v) => {
            for gi in g.into_iter().flatten() {
                *gi *= scale;
            }
            v * scale
        }
        Err(_) => f64::INFINITY,
    }
}

/// `y += a x`.
fn axpy(a: f64, x: &[f64], y: &mut [f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += a * xi;
    }
}
