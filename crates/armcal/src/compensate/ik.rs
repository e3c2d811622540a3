//! Calibrated inverse kinematics by damped least squares (book §5.2–5.3), seeded with the
//! nominal robot's closed-form solution where it has one ([`CalibratedIk`]).
//!
//! The book's optimal (LQR) compensator for one step is exactly damped least squares
//! (book eqs. 5.85–5.87, check 9): `Δq = (JᵀQJ + Γ)⁻¹ JᵀQ e`. armcal weights the task error
//! with `Q = diag(1, 1, 1, L², L², L²)` (position in mm, orientation in rad scaled by a
//! characteristic length L, the book's `k2/‖p‖²` form) and uses `Γ = γ² I` with γ chosen from
//! the smallest singular value σ_min of `J_w = Q^{1/2} J` (Maciejewski–Klein): γ = 0 while
//! σ_min ≥ ε, and `γ² = (1 − (σ_min/ε)²) γ_max²` below, so steps stay bounded near a
//! singularity instead of blowing up as they do with γ → 0 (book Table 5.7). γ_max² is
//! capped by the squared weighted error ‖e_w‖² (mm²), the Levenberg–Marquardt parameter of
//! Yamashita and Fukushima (2001), so that the last, small corrections near a singular
//! configuration converge quadratically instead of crawling under full damping; corrections
//! above γ_max (1 mm) get the full damping. Joint limits are enforced by clamping each step.
//!
//! At a singular configuration the error has no gradient along the singular direction (a
//! stretched elbow that must bend to shorten): a solve that stalls there with σ_min < ε
//! is restarted from the stalled joints moved ±2° along the right singular vector of
//! σ_min, and the better end is kept.
//!
//! The step is computed in task space, `Δq = J_wᵀ (J_w J_wᵀ + γ² I)⁻¹ e_w`, which equals the
//! joint-space form by the push-through identity and needs only a 6×6 (3×3 for position
//! targets) Cholesky factorisation on the stack whatever the number of joints. σ_min ≥ ε is
//! certified by the Cholesky factorisation of `J_w J_wᵀ − ε² I` succeeding; only when it
//! fails is σ_min computed (inverse iteration). One forward-kinematics evaluation per
//! iteration: the trial point of an accepted step is the next iterate. Nothing is allocated
//! inside the iterations.
//!
//! (Over 600 lines: one algorithm — the run, its singularity escape and the diagnosis of
//! why a solve ended — whose parts share the workspace and the run state; the step itself
//! is in [`super::damped_step`].)

use crate::compensate::closed_form::{NoClosedForm, SphericalWristIk};
pub use crate::compensate::damped_step::{damped_step, task_jacobian_columns};
use crate::compensate::damped_step::{normal_matrix, smallest_eigenvalue, step_from};
use crate::compensate::joint_change::{ChangeViolation, JointChangeLimit};
use crate::model::pose::rotation_log;
use crate::model::{forward_kinematics, Data, JointKind, Model, Pose};
use crate::solve::Status;
use nalgebra::{Cholesky, SMatrix, SVector, Vector3, Vector6};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// What the tool frame must reach (world frame, mm).
#[derive(Clone, Copy, Debug)]
pub enum IkTarget {
    /// Tool-frame origin only (mm); 3 task rows.
    Position(Vector3<f64>),
    /// Full tool-frame pose; 6 task rows, orientation weighted by L.
    Pose(Pose<f64>),
}

/// How an IK solve ended: the domain status of inverse kinematics, which tells a singular
/// configuration, a joint limit and an unreachable target apart (the compensated program's
/// status column), and maps onto the shared solver vocabulary with [`IkStatus::status`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum IkStatus {
    /// Within the position and orientation tolerances.
    Converged,
    /// Stopped near a singular configuration (σ_min < ε) above the tolerance.
    Singular,
    /// The target needs joint values beyond the limits ([`IkResult::limit`] names the joint).
    JointLimits,
    /// Out of reach: the nominal robot misses the target by more than the calibration moves
    /// the tool ([`CalibratedIk::solve`]), or the residual stopped decreasing away from a
    /// singularity.
    Unreachable,
    /// The iteration limit was reached first.
    #[serde(rename = "max-iterations")]
    IterationLimit,
    /// Compensation only ([`crate::compensate::joint_change`]): the exact solution changes a
    /// joint by more than [`IkSettings::joint_change_limit`] from the uncompensated joints;
    /// the row holds the position-priority solution within the limit
    /// ([`IkResult::change`] names the joint).
    JointChangeLimit,
}

impl IkStatus {
    /// The kebab-case name used in files (`converged`, `joint-limits`, …).
    pub fn name(self) -> &'static str {
        match self {
            IkStatus::Converged => "converged",
            IkStatus::Singular => "singular",
            IkStatus::JointLimits => "joint-limits",
            IkStatus::Unreachable => "unreachable",
            IkStatus::IterationLimit => "max-iterations",
            IkStatus::JointChangeLimit => "joint-change-limit",
        }
    }

    /// The status in the shared solver vocabulary: a singular stop is a stall, joint limits
    /// and an unreachable target make the problem infeasible.
    pub fn status(self) -> Status {
        match self {
            IkStatus::Converged => Status::Converged {
                criterion: "position and orientation within tolerance".into(),
            },
            IkStatus::Singular => Status::Stalled {
                reason: "near a singular configuration (σ_min < ε) above the tolerance".into(),
            },
            IkStatus::JointLimits => Status::Infeasible {
                reason: "the target needs joint values beyond the limits".into(),
            },
            IkStatus::Unreachable => Status::Infeasible {
                reason: "the target is out of reach".into(),
            },
            IkStatus::IterationLimit => Status::IterationLimit,
            IkStatus::JointChangeLimit => Status::Infeasible {
                reason: "the exact solution changes a joint by more than the compensation's \
                         joint-change limit"
                    .into(),
            },
        }
    }
}

/// Settings of [`calibrated_ik`].
#[derive(Clone, Debug)]
pub struct IkSettings {
    /// Damped least-squares iterations before [`IkStatus::IterationLimit`].
    pub max_iterations: usize,
    /// Position tolerance (mm).
    pub position_tolerance: f64,
    /// Orientation tolerance (rad).
    pub orientation_tolerance: f64,
    /// Characteristic length L (mm) weighting orientation against position.
    pub length: f64,
    /// Singular-value threshold ε of the weighted Jacobian `J_w` (mm per rad) below which
    /// damping starts.
    pub epsilon: f64,
    /// Largest damping γ_max (mm), reached at σ_min = 0; capped by ‖e_w‖.
    pub gamma_max: f64,
    /// The payload the robot carries at the targets (an index into
    /// [`Model::payloads`]; `None`: none): a compliant model deflects under its weight, and
    /// the solve includes that deflection ([`crate::identify::Estimate::payload_for`]).
    pub payload: Option<usize>,
    /// The largest change of each joint from the uncompensated joints that compensation
    /// accepts ([`crate::compensate::joint_change`]; not used by a bare IK solve, which has
    /// no uncompensated joints).
    pub joint_change_limit: JointChangeLimit,
}

impl Default for IkSettings {
    fn default() -> Self {
        IkSettings {
            max_iterations: 60,
            // 1000× below the 1 µm / 1 µrad the calibrated IK is required to reach.
            position_tolerance: 1e-6,
            orientation_tolerance: 1e-9,
            length: 1000.0,
            epsilon: 1.0,
            gamma_max: 1.0,
            payload: None,
            joint_change_limit: JointChangeLimit::default(),
        }
    }
}

/// A joint that the target needs beyond its limits: the value the unconstrained solution
/// takes (the representative modulo 2π nearest the limits, for a revolute joint) and the
/// limit it crosses (internal units).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LimitViolation {
    /// Joint index (0-based).
    pub joint: usize,
    /// Value the target needs (rad or mm).
    pub value: f64,
    /// The lower or upper limit it crosses (rad or mm).
    pub limit: f64,
}

/// Result of one solve.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct IkResult {
    /// Final joint values (rad or mm), within the limits.
    pub q: Vec<f64>,
    /// How the solve ended.
    pub status: IkStatus,
    /// Damped least-squares iterations, including those of a singularity restart.
    pub iterations: usize,
    /// Remaining position error (mm).
    pub position_error: f64,
    /// Remaining orientation error (rad; 0 for position targets).
    pub orientation_error: f64,
    /// Smallest singular value of the weighted Jacobian at the end, for a solve that did
    /// not converge (it tells a singular configuration from an unreachable target); `None`
    /// for a converged solve, where computing it would cost a sixth of the solve.
    pub sigma_min: Option<f64>,
    /// For [`IkStatus::JointLimits`]: the joint beyond its limits.
    pub limit: Option<LimitViolation>,
    /// For a compensation whose exact solution changes a joint by more than the limit (the
    /// row then holds the position-priority solution within it): the joint and its change.
    #[serde(default)]
    pub change: Option<ChangeViolation>,
    /// Whether the row holds the position-priority solution within the joint-change limit
    /// ([`CalibratedIk::solve_in_box`]) instead of the unlimited solve.
    #[serde(default)]
    pub position_priority: bool,
}

impl IkResult {
    /// One line for reports: `converged`; `joint-limits: q5 = 132.100 deg > 87.000 deg`;
    /// otherwise the status and the residual, e.g. `unreachable: residual 153.2 mm, 2.1 deg`.
    pub fn describe(&self, model: &Model) -> String {
        if let (IkStatus::JointLimits, Some(v)) = (self.status, self.limit) {
            if let Some(j) = model.joints.get(v.joint) {
                let unit = j.kind.unit();
                let f = unit.display_factor();
                return format!(
                    "joint-limits: {} = {:.3} {} {} {:.3} {}",
                    j.name,
                    v.value * f,
                    unit.display_name(),
                    if v.value > v.limit { ">" } else { "<" },
                    v.limit * f,
                    unit.display_name()
                );
            }
        }
        if let (IkStatus::JointChangeLimit, Some(c)) = (self.status, self.change) {
            if let Some(j) = model.joints.get(c.joint) {
                let unit = j.kind.unit();
                let f = unit.display_factor();
                return format!(
                    "joint-change-limit: {} needs {:+.3} {} (limit {:.3} {}){}; within the limit \
                     {:.6} mm, {:.4} deg",
                    j.name,
                    c.change * f,
                    unit.display_name(),
                    c.limit * f,
                    unit.display_name(),
                    if c.singular {
                        " near a singularity"
                    } else {
                        ""
                    },
                    self.position_error,
                    self.orientation_error.to_degrees()
                );
            }
        }
        if self.status == IkStatus::Converged {
            return self.status.name().to_string();
        }
        format!(
            "{}: residual {:.4} mm, {:.4} deg",
            self.status.name(),
            self.position_error,
            self.orientation_error.to_degrees()
        )
    }
}

/// Reusable buffers (sized for one model): kinematics, joint limits, iterate and trial
/// joints, Jacobian columns (and those w.r.t. the corrected joints), and the warm start of the σ_min inverse iteration.
pub struct IkWorkspace {
    data: Data<f64>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    revolute: Vec<bool>,
    q: Vec<f64>,
    trial: Vec<f64>,
    constrained: Vec<f64>,
    direction: Vec<f64>,
    best: Vec<f64>,
    columns: Vec<Vector6<f64>>,
    corrected: Vec<Vector6<f64>>,
    eigenvector: Vector6<f64>,
    /// Whether [`run_dls`] holds a joint at its bound when the error's gradient pushes it
    /// outward (an active set; [`CalibratedIk::solve_in_box`]), instead of only clamping.
    active_set: bool,
}

impl IkWorkspace {
    /// Buffers sized for `model`'s joints, with its joint limits.
    pub fn new(model: &Model) -> Self {
        let (lower, upper) = model.joint_limits();
        let n = model.dof();
        IkWorkspace {
            data: Data::new(model),
            lower,
            upper,
            revolute: model
                .joints
                .iter()
                .map(|j| j.kind == JointKind::Revolute)
                .collect(),
            q: vec![0.0; n],
            trial: vec![0.0; n],
            constrained: vec![0.0; n],
            direction: vec![0.0; n],
            best: vec![0.0; n],
            columns: vec![Vector6::zeros(); n],
            corrected: vec![Vector6::zeros(); n],
            eigenvector: Vector6::repeat(1.0 / 6f64.sqrt()),
            active_set: false,
        }
    }
}

/// Task error `e` (target minus tool; position rows, then for 6 rows the rotation vector of
/// `R_target R_toolᵀ` scaled by L), its position norm and its rotation angle.
fn weighted_error<const R: usize>(
    target: &IkTarget,
    tool: &Pose<f64>,
    length: f64,
) -> (SVector<f64, R>, f64, f64) {
    let (d, w) = match target {
        IkTarget::Position(p) => (p - tool.trans, Vector3::zeros()),
        IkTarget::Pose(t) => (
            t.trans - tool.trans,
            rotation_log(&(t.rot * tool.rot.transpose())),
        ),
    };
    let e = Vector6::new(d.x, d.y, d.z, w.x * length, w.y * length, w.z * length);
    (e.fixed_rows::<R>(0).into_owned(), d.norm(), w.norm())
}

/// How one damped-least-squares run ended (`ws.q` holds its joints, `ws.data` its
/// kinematics).
struct Run {
    converged: bool,
    iterations: usize,
    position_error: f64,
    orientation_error: f64,
    /// Not computed (NaN) for a converged run.
    sigma_min: f64,
    at_limit: bool,
    stalled: bool,
}

/// Damped least squares from `ws.q` (already set), R task rows; with `limits`, every step is
/// clamped to the joint limits.
fn run_dls<const R: usize>(
    model: &Model,
    params: &[f64],
    target: &IkTarget,
    settings: &IkSettings,
    ws: &mut IkWorkspace,
    limits: bool,
) -> Run {
    let eps2 = settings.epsilon * settings.epsilon;
    let length = settings.length;
    ws.data.payload = settings.payload;
    forward_kinematics(model, &mut ws.data, params, &ws.q);
    let mut best = f64::INFINITY;
    let mut stalls = 0;
    let mut at_limit = false;
    let mut iterations = 0;
    loop {
        let (e, pe, oe) = weighted_error::<R>(target, ws.data.tool(), length);
        if pe <= settings.position_tolerance && oe <= settings.orientation_tolerance {
            return Run {
                converged: true,
                iterations,
                position_error: pe,
                orientation_error: oe,
                sigma_min: f64::NAN,
                at_limit,
                stalled: false,
            };
        }
        task_jacobian_columns(&ws.data, length, &mut ws.columns, &mut ws.corrected);
        if ws.active_set {
            // A joint at a bound that the gradient JᵀQe pushes outward takes no part in the
            // step: the damped step of the remaining joints (projected Newton).
            for (k, c) in ws.columns.iter_mut().enumerate() {
                let g = c.fixed_rows::<R>(0).dot(&e);
                if (ws.q[k] <= ws.lower[k] && g < 0.0) || (ws.q[k] >= ws.upper[k] && g > 0.0) {
                    *c = Vector6::zeros();
                }
            }
        }
        let a = normal_matrix::<R>(&ws.columns);
        if iterations >= settings.max_iterations || stalls >= 5 {
            let sigma_min = smallest_eigenvalue(&a, &mut ws.eigenvector).sqrt();
            // Right singular vector of σ_min, v ∝ J_wᵀ u (u: the left one), in `ws.trial`.
            let u = ws.eigenvector.fixed_rows::<R>(0);
            for (t, c) in ws.trial.iter_mut().zip(&ws.columns) {
                *t = c.fixed_rows::<R>(0).dot(&u);
            }
            return Run {
                converged: false,
                iterations,
                position_error: pe,
                orientation_error: oe,
                sigma_min,
                at_limit,
                stalled: stalls >= 5,
            };
        }
        iterations += 1;
        let identity = SMatrix::<f64, R, R>::identity();
        let weighted = e.norm();
        let gamma2 = if Cholesky::new(a - identity * eps2).is_some() {
            0.0
        } else {
            let s2 = smallest_eigenvalue(&a, &mut ws.eigenvector);
            let cap = (settings.gamma_max * settings.gamma_max).min(weighted * weighted);
            (1.0 - s2 / eps2).max(0.0) * cap
        };
        // Damped step; if it does not reduce the weighted error, raise the damping (a
        // Levenberg–Marquardt safeguard, so that every accepted step is a descent step).
        let trace = a.trace();
        let mut g2 = gamma2;
        let mut accepted = false;
        for _ in 0..12 {
            if !step_from(&a, &ws.columns, &e, g2 + 1e-14 * trace, &mut ws.trial) {
                break;
            }
            let mut hits_limit = false;
            for k in 0..ws.q.len() {
                let v = ws.q[k] + ws.trial[k];
                if limits && (v < ws.lower[k] || v > ws.upper[k]) {
                    hits_limit = true;
                    ws.trial[k] = v.clamp(ws.lower[k], ws.upper[k]);
                } else {
                    ws.trial[k] = v;
                }
            }
            forward_kinematics(model, &mut ws.data, params, &ws.trial);
            let (et, _, _) = weighted_error::<R>(target, ws.data.tool(), length);
            if et.norm() < weighted {
                std::mem::swap(&mut ws.q, &mut ws.trial);
                at_limit = hits_limit;
                accepted = true;
                break;
            }
            g2 = (g2 * 10.0).max(1e-6 * trace);
        }
        if !accepted {
            // No descent step: a stationary point of the weighted error.
            forward_kinematics(model, &mut ws.data, params, &ws.q);
            stalls = 5;
            continue;
        }
        if weighted < best * (1.0 - 1e-3) {
            best = weighted;
            stalls = 0;
        } else {
            stalls += 1;
        }
    }
}

fn run_rows(
    model: &Model,
    params: &[f64],
    target: &IkTarget,
    settings: &IkSettings,
    ws: &mut IkWorkspace,
    limits: bool,
) -> Run {
    match target {
        IkTarget::Position(_) => run_dls::<3>(model, params, target, settings, ws, limits),
        IkTarget::Pose(_) => run_dls::<6>(model, params, target, settings, ws, limits),
    }
}

/// Joint step (rad or mm) of the restarts off a singular stall.
const ESCAPE_STEP: f64 = 0.035;

/// Restarts a solve that stalled at a singular configuration from the stalled joints moved
/// ±[`ESCAPE_STEP`] along the right singular vector of σ_min (left in `ws.trial` by
/// [`run_dls`]); returns the best of the three ends (converged first, then the smallest
/// weighted error), with its joints in `ws.q`.
fn escape_singular(
    model: &Model,
    params: &[f64],
    target: &IkTarget,
    settings: &IkSettings,
    ws: &mut IkWorkspace,
    stalled: Run,
) -> Run {
    let norm = ws.trial.iter().map(|v| v * v).sum::<f64>().sqrt();
    if !norm.is_finite() || norm <= 0.0 {
        return stalled;
    }
    // `constrained` keeps the stalled joints, `direction` the unit singular vector, `best`
    // the joints of the best end so far.
    ws.constrained.copy_from_slice(&ws.q);
    for (d, t) in ws.direction.iter_mut().zip(&ws.trial) {
        *d = t / norm;
    }
    ws.best.copy_from_slice(&ws.q);
    let score = |r: &Run| {
        (
            !r.converged,
            r.position_error + r.orientation_error * settings.length,
        )
    };
    let mut best = stalled;
    for sign in [1.0, -1.0] {
        for (k, q) in ws.q.iter_mut().enumerate() {
            *q = (ws.constrained[k] + sign * ESCAPE_STEP * ws.direction[k])
                .clamp(ws.lower[k], ws.upper[k]);
        }
        let mut run = run_rows(model, params, target, settings, ws, true);
        run.iterations += best.iterations;
        if score(&run) < score(&best) {
            best = run;
            ws.best.copy_from_slice(&ws.q);
            if best.converged {
                break;
            }
        }
    }
    ws.q.copy_from_slice(&ws.best);
    best
}

/// The representative of a revolute joint value modulo 2π nearest the interval [lo, hi]
/// (the value itself for a prismatic joint).
fn nearest_in_range(x: f64, lo: f64, hi: f64, revolute: bool) -> f64 {
    if !revolute || (lo..=hi).contains(&x) {
        return x;
    }
    let mid = 0.5 * (lo + hi);
    let y = x + 2.0 * PI * ((mid - x) / (2.0 * PI)).round();
    let outside = |v: f64| (lo - v).max(v - hi);
    [y - 2.0 * PI, y, y + 2.0 * PI]
        .into_iter()
        .min_by(|a, b| outside(*a).total_cmp(&outside(*b)))
        .unwrap_or(x)
}

/// Joint values that bring the tool frame of `model` with parameters `params` to `target`,
/// starting from `seed` (e.g. the nominal solution or the nominal program's joints).
///
/// If the limits stop the solve, the solve is repeated without them: when that one
/// converges, either every revolute joint can be shifted by whole turns into its limits
/// (the shifted solution is returned as converged) or the status is
/// [`IkStatus::JointLimits`] with the joint furthest beyond its limits.
pub fn calibrated_ik(
    model: &Model,
    params: &[f64],
    target: &IkTarget,
    seed: &[f64],
    settings: &IkSettings,
    ws: &mut IkWorkspace,
) -> IkResult {
    solve_with_diagnosis(model, params, target, seed, settings, ws)
}

fn solve_with_diagnosis(
    model: &Model,
    params: &[f64],
    target: &IkTarget,
    seed: &[f64],
    settings: &IkSettings,
    ws: &mut IkWorkspace,
) -> IkResult {
    for k in 0..ws.q.len() {
        let s = seed.get(k).copied().unwrap_or(0.0);
        ws.q[k] = s.clamp(ws.lower[k], ws.upper[k]);
    }
    let mut run = run_rows(model, params, target, settings, ws, true);
    if !run.converged && run.sigma_min < settings.epsilon {
        run = escape_singular(model, params, target, settings, ws, run);
    }
    let result = |ws: &IkWorkspace, run: &Run, status, limit| IkResult {
        q: ws.q.clone(),
        status,
        iterations: run.iterations,
        position_error: run.position_error,
        orientation_error: run.orientation_error,
        sigma_min: (!run.converged).then_some(run.sigma_min),
        limit,
        change: None,
        position_priority: false,
    };
    if run.converged {
        return result(ws, &run, IkStatus::Converged, None);
    }
    if run.at_limit {
        ws.constrained.copy_from_slice(&ws.q);
        for k in 0..ws.q.len() {
            ws.q[k] = seed.get(k).copied().unwrap_or(0.0);
        }
        let free = run_rows(model, params, target, settings, ws, false);
        if free.converged {
            let mut worst: Option<LimitViolation> = None;
            let mut excess = 0.0;
            for k in 0..ws.q.len() {
                let (lo, hi) = (ws.lower[k], ws.upper[k]);
                let x = nearest_in_range(ws.q[k], lo, hi, ws.revolute[k]);
                ws.q[k] = x;
                let beyond = (lo - x).max(x - hi);
                if beyond > 0.0 && beyond > excess {
                    excess = beyond;
                    worst = Some(LimitViolation {
                        joint: k,
                        value: x,
                        limit: if x > hi { hi } else { lo },
                    });
                }
            }
            if worst.is_none() {
                // Whole turns bring the unconstrained solution within the limits.
                return result(ws, &free, IkStatus::Converged, None);
            }
            ws.q.copy_from_slice(&ws.constrained);
            return result(ws, &run, IkStatus::JointLimits, worst);
        }
        ws.q.copy_from_slice(&ws.constrained);
    }
    let status = if run.sigma_min < settings.epsilon {
        IkStatus::Singular
    } else if run.stalled {
        IkStatus::Unreachable
    } else {
        IkStatus::IterationLimit
    };
    result(ws, &run, status, None)
}

/// Calibrated IK as book §5.2 describes it: the nominal robot's closed-form solution
/// ([`SphericalWristIk`]) seeds damped least squares on the calibrated model. Robots
/// without a closed form, and position-only targets, start from the caller's reference
/// joints instead.
pub struct CalibratedIk<'a> {
    model: &'a Model,
    nominal: Vec<f64>,
    calibrated: &'a [f64],
    settings: IkSettings,
    closed_form: Result<SphericalWristIk, NoClosedForm>,
    ws: IkWorkspace,
}

impl<'a> CalibratedIk<'a> {
    /// Detects the closed form on the nominal parameters `nominal`.
    pub fn new(
        model: &'a Model,
        nominal: &[f64],
        calibrated: &'a [f64],
        settings: IkSettings,
    ) -> Self {
        CalibratedIk {
            model,
            nominal: nominal.to_vec(),
            calibrated,
            settings,
            closed_form: SphericalWristIk::new(model, nominal),
            ws: IkWorkspace::new(model),
        }
    }

    /// The nominal closed-form solver, or why there is none.
    pub fn closed_form(&self) -> Result<&SphericalWristIk, &NoClosedForm> {
        self.closed_form.as_ref()
    }

    /// Solves for `target`. For a pose target with a closed form, the seed is the nominal
    /// branch nearest `reference` in joint space (exact and within the limits if any branch
    /// is, [`Branches::ordered`]); if the calibrated solve does not converge from it, the
    /// other branches are tried in order (near the workspace boundary or a joint limit the
    /// calibrated robot may reach a target in another branch only), and the first branch's
    /// result is returned if none converges. It is [`IkStatus::Unreachable`] when the
    /// nominal wrist centre misses the target by more than the calibration moves the tool
    /// there (`|FK_cal(q) − FK_nom(q)|`): then the calibrated robot cannot reach it either.
    /// Without a closed form, or for a position target, the seed is `reference` itself.
    ///
    /// [`Branches::ordered`]: crate::compensate::closed_form::Branches::ordered
    pub fn solve(&mut self, target: &IkTarget, reference: &[f64]) -> IkResult {
        if let (IkTarget::Pose(pose), Ok(cf)) = (target, &self.closed_form) {
            if reference.len() == 6 {
                let branches = cf.solve(pose, reference).ordered(reference);
                let mut first: Option<(IkResult, f64)> = None;
                for b in branches.as_slice() {
                    let r = solve_with_diagnosis(
                        self.model,
                        self.calibrated,
                        target,
                        &b.q,
                        &self.settings,
                        &mut self.ws,
                    );
                    if r.status == IkStatus::Converged {
                        return r;
                    }
                    first.get_or_insert((r, b.reach_miss));
                }
                if let Some((mut r, miss)) = first {
                    if miss > 0.0 && r.status != IkStatus::JointLimits {
                        // The calibration moves the tool by |FK_cal(q) − FK_nom(q)| here; a
                        // nominal miss beyond that is out of the calibrated robot's reach too.
                        forward_kinematics(self.model, &mut self.ws.data, &self.nominal, &r.q);
                        let nominal_tcp = self.ws.data.tool().trans;
                        forward_kinematics(self.model, &mut self.ws.data, self.calibrated, &r.q);
                        if miss > (self.ws.data.tool().trans - nominal_tcp).norm() {
                            r.status = IkStatus::Unreachable;
                        }
                    }
                    return r;
                }
            }
        }
        self.solve_from(target, reference)
    }

    /// Solves for `target` from the numerical seed `seed` (e.g. the previous program row's
    /// solution, or the nominal program's joints).
    pub fn solve_from(&mut self, target: &IkTarget, seed: &[f64]) -> IkResult {
        calibrated_ik(
            self.model,
            self.calibrated,
            target,
            seed,
            &self.settings,
            &mut self.ws,
        )
    }

    /// The settings of every solve.
    pub fn settings(&self) -> &IkSettings {
        &self.settings
    }

    /// The joints a controller that keeps the nominal model commands for `target`: the
    /// nominal closed-form branch nearest `reference` ([`Branches::ordered`]) where the robot
    /// has a closed form and the target is a pose, else the nominal model's damped
    /// least-squares solution from `reference`; `None` if that does not converge.
    ///
    /// [`Branches::ordered`]: crate::compensate::closed_form::Branches::ordered
    pub fn nominal_solution(&mut self, target: &IkTarget, reference: &[f64]) -> Option<Vec<f64>> {
        if let (IkTarget::Pose(pose), Ok(cf), 6) = (target, &self.closed_form, reference.len()) {
            let branches = cf.solve(pose, reference).ordered(reference);
            if let Some(b) = branches.as_slice().first() {
                return Some(b.q.to_vec());
            }
        }
        let r = calibrated_ik(
            self.model,
            &self.nominal,
            target,
            reference,
            &self.settings,
            &mut self.ws,
        );
        (r.status == IkStatus::Converged).then_some(r.q)
    }

    /// Damped least squares on the calibrated model within the joint box `[lower, upper]`
    /// (each bound within the joint limits), from `seed`, with position priority: the
    /// orientation rows are weighted by `PRIORITY_LENGTH` instead of L (and ε, γ_max
    /// scaled alike), so that a position error δ costs as much as an orientation error
    /// δ/`PRIORITY_LENGTH` rad — where the box leaves an orientation error ϑ, the position
    /// gives way by about `PRIORITY_LENGTH² ϑ / r` only (r ≈ the arm's reach, 10⁻⁵ mm for
    /// ϑ = 0.3°, r = 1 m). A joint at a bound that the error pushes outward is held there
    /// (active set). Converged if both tolerances are met; otherwise
    /// [`IkStatus::JointChangeLimit`] with what the box leaves. `sigma_min` is σ_min of
    /// the weighted Jacobian (weight L, all joints) at the result, for a result that did
    /// not converge: it tells a singularity apart from a limit that is simply too small.
    pub fn solve_in_box(
        &mut self,
        target: &IkTarget,
        seed: &[f64],
        mut lower: Vec<f64>,
        mut upper: Vec<f64>,
    ) -> IkResult {
        let ws = &mut self.ws;
        std::mem::swap(&mut ws.lower, &mut lower);
        std::mem::swap(&mut ws.upper, &mut upper);
        for k in 0..ws.q.len() {
            let s = seed.get(k).copied().unwrap_or(0.0);
            ws.q[k] = s.clamp(ws.lower[k], ws.upper[k]);
        }
        let scale = PRIORITY_LENGTH / self.settings.length;
        let priority = IkSettings {
            length: PRIORITY_LENGTH,
            epsilon: self.settings.epsilon * scale,
            gamma_max: self.settings.gamma_max * scale,
            ..self.settings.clone()
        };
        ws.active_set = true;
        let run = run_rows(self.model, self.calibrated, target, &priority, ws, true);
        ws.active_set = false;
        std::mem::swap(&mut ws.lower, &mut lower);
        std::mem::swap(&mut ws.upper, &mut upper);
        let sigma_min = (!run.converged).then(|| {
            let rows = match target {
                IkTarget::Position(_) => 3,
                IkTarget::Pose(_) => 6,
            };
            // `run_rows` left the kinematics of `ws.q` in `ws.data`.
            task_jacobian_columns(
                &ws.data,
                self.settings.length,
                &mut ws.columns,
                &mut ws.corrected,
            );
            let s2 = if rows == 3 {
                smallest_eigenvalue(&normal_matrix::<3>(&ws.columns), &mut ws.eigenvector)
            } else {
                smallest_eigenvalue(&normal_matrix::<6>(&ws.columns), &mut ws.eigenvector)
            };
            s2.sqrt()
        });
        IkResult {
            q: ws.q.clone(),
            status: if run.converged {
                IkStatus::Converged
            } else {
                IkStatus::JointChangeLimit
            },
            iterations: run.iterations,
            position_error: run.position_error,
            orientation_error: run.orientation_error,
            sigma_min,
            limit: None,
            change: None,
            position_priority: true,
        }
    }
}

/// Characteristic length (mm) that weights orientation against position in
/// [`CalibratedIk::solve_in_box`]: 1 mm, so that 1 mrad of orientation weighs as 1 µm of
/// position (position priority), 1000× below the compensation's own L.
pub const PRIORITY_LENGTH: f64 = 1.0;
