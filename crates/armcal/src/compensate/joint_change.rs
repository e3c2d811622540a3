//! Compensation within a joint-change limit: a compensated row may change each joint by no
//! more than a stated limit from the uncompensated row (the nominal program's joints, or
//! the nominal model's solution of a Cartesian target).
//!
//! A calibration moves the tool by a millimetre or so and corrects each joint by a fraction
//! of a degree; an exact calibrated solution that changes a joint by more than that is not a
//! correction but a branch change or, near a singularity, a whip: where two joint axes
//! align (a wrist at q5 ≈ 0) the Jacobian loses a direction, and an orientation error δ
//! along it needs joint changes of order δ/σ_min — 30–180° of q4 and q6 for a few tenths of
//! a degree. So a row whose exact solution ([`CalibratedIk::solve_from`]) changes a joint
//! beyond the limit is solved again within the box `q₀ ± limit` (and the joint limits) by
//! damped least squares with position priority ([`CalibratedIk::solve_in_box`]: the book's
//! damped compensator, §5.3, with an active set at the box and σ_min-scheduled damping),
//! started from `q₀` plus the previous row's correction (so the correction stays continuous
//! along a program where the limit allows it) and from the exact solution clamped into the
//! box, the better end kept. It is converged if the box holds a solution
//! within the tolerances, [`IkStatus::JointChangeLimit`] otherwise, with what it reached
//! (position and orientation miss) and the joint that needed more ([`ChangeViolation`]).
//! The singularity is recognised from the Jacobian's conditioning (σ_min of the weighted
//! Jacobian below ε), never from a joint's value, so this holds for any chain.

use crate::compensate::ik::{CalibratedIk, IkResult, IkStatus, IkTarget, PRIORITY_LENGTH};
use crate::model::{JointKind, Model};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The largest change of each joint from the uncompensated joints that compensation accepts
/// (internal units).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct JointChangeLimit {
    /// For a revolute joint (rad).
    pub revolute: f64,
    /// For a prismatic joint (mm).
    pub prismatic: f64,
}

impl Default for JointChangeLimit {
    /// 5° and 5 mm: ten times the corrections a calibration makes away from singularities
    /// (joint offsets and link errors of a fraction of a degree or millimetre; the demo's
    /// are hundredths of a degree), and far below a branch change (a wrist flip is 180°).
    fn default() -> Self {
        JointChangeLimit {
            revolute: 5f64.to_radians(),
            prismatic: 5.0,
        }
    }
}

impl JointChangeLimit {
    /// The limit for a joint of `kind` (rad or mm).
    pub fn of(&self, kind: JointKind) -> f64 {
        match kind {
            JointKind::Revolute => self.revolute,
            JointKind::Prismatic => self.prismatic,
        }
    }
}

/// A row whose exact compensation changes a joint by more than the limit.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ChangeViolation {
    /// Joint index (0-based): the one whose change exceeds its limit by the largest factor.
    pub joint: usize,
    /// The change the exact solution needs (rad or mm).
    pub change: f64,
    /// The joint's limit (rad or mm).
    pub limit: f64,
    /// Whether the weighted Jacobian at the limited solution is near singular (σ_min < ε).
    pub singular: bool,
}

/// The change of a joint of `kind` from `from` to `to`: the difference, for a revolute joint
/// taken modulo a whole turn into (−π, π] (a whole turn is the same pose, e.g. a program
/// value outside the limits whose solution is shifted into them).
pub fn joint_change(kind: JointKind, from: f64, to: f64) -> f64 {
    let d = to - from;
    match kind {
        JointKind::Revolute => d - 2.0 * PI * (d / (2.0 * PI)).round(),
        JointKind::Prismatic => d,
    }
}

/// The joint of `q` whose change from `q0` exceeds its limit by the largest factor, if any.
fn largest_violation(
    model: &Model,
    limit: &JointChangeLimit,
    q0: &[f64],
    q: &[f64],
) -> Option<ChangeViolation> {
    let mut worst: Option<(f64, ChangeViolation)> = None;
    for (k, ((j, a), b)) in model.joints.iter().zip(q0).zip(q).enumerate() {
        let change = joint_change(j.kind, *a, *b);
        let lim = limit.of(j.kind);
        let factor = change.abs() / lim;
        // A non-finite change is a violation too.
        if (factor.is_nan() || factor > 1.0) && worst.as_ref().is_none_or(|(f, _)| factor > *f) {
            worst = Some((
                factor,
                ChangeViolation {
                    joint: k,
                    change,
                    limit: lim,
                    singular: false,
                },
            ));
        }
    }
    worst.map(|(_, v)| v)
}

/// The compensation of one row within the joint-change limit of `ik`'s settings: `exact` is
/// the unlimited solve for `target` (e.g. [`CalibratedIk::solve_from`] seeded with the
/// row), `uncompensated` the row's uncompensated joints, `previous` the previous row's
/// correction (compensated − uncompensated joints) if it has one.
///
/// `exact` is returned as it is when it changes no joint beyond the limit, or when the
/// uncompensated joints lie further than the limit outside the joint limits (there is no
/// box to solve in). Otherwise the position-priority solution within the box is returned:
/// converged, or not with [`IkResult::change`] set and the status
/// [`IkStatus::JointChangeLimit`] — [`IkStatus::JointLimits`] or [`IkStatus::Unreachable`]
/// if `exact` had it (the robot cannot reach the target at all: that diagnosis stands).
pub fn within_joint_change_limit(
    ik: &mut CalibratedIk,
    model: &Model,
    target: &IkTarget,
    exact: IkResult,
    uncompensated: &[f64],
    previous: Option<&[f64]>,
) -> IkResult {
    let limit = ik.settings().joint_change_limit;
    let Some(mut violation) = largest_violation(model, &limit, uncompensated, &exact.q) else {
        return exact;
    };
    let (joint_lower, joint_upper) = model.joint_limits();
    let (mut lower, mut upper) = (Vec::new(), Vec::new());
    let (mut continuing, mut clamped) = (Vec::new(), Vec::new());
    for (k, j) in model.joints.iter().enumerate() {
        let (lo, hi) = (joint_lower[k], joint_upper[k]);
        let mut centre = uncompensated[k];
        if j.kind == JointKind::Revolute && !(lo..=hi).contains(&centre) {
            // The same angle by whole turns, nearest the joint range.
            let mid = 0.5 * (lo + hi);
            centre += 2.0 * PI * ((mid - centre) / (2.0 * PI)).round();
        }
        let lim = limit.of(j.kind);
        let (a, b) = ((centre - lim).max(lo), (centre + lim).min(hi));
        if a.is_nan() || b.is_nan() || a > b {
            return exact;
        }
        lower.push(a);
        upper.push(b);
        let carried = previous.and_then(|p| p.get(k)).copied().unwrap_or(0.0);
        continuing.push((centre + carried).clamp(a, b));
        clamped.push((centre + joint_change(j.kind, centre, exact.q[k])).clamp(a, b));
    }
    // Two starts: the previous row's correction carried over (continuity along the
    // program), and the exact solution clamped into the box (its direction: near a
    // singularity the box's best corner flips with the side of it, and a start on the wrong
    // corner can stall there). The better end in the position-priority cost is kept, the
    // continuing one on a tie.
    let cost = |r: &IkResult| {
        r.position_error
            .hypot(PRIORITY_LENGTH * r.orientation_error)
    };
    let mut limited = ik.solve_in_box(target, &continuing, lower.clone(), upper.clone());
    if limited.status != IkStatus::Converged && clamped != continuing {
        let other = ik.solve_in_box(target, &clamped, lower, upper);
        if cost(&other) < cost(&limited) * (1.0 - 1e-9) {
            limited = IkResult {
                iterations: limited.iterations + other.iterations,
                ..other
            };
        } else {
            limited.iterations += other.iterations;
        }
    }
    if limited.status != IkStatus::Converged {
        violation.singular = limited.sigma_min.is_some_and(|s| s < ik.settings().epsilon);
        limited.change = Some(violation);
        if matches!(exact.status, IkStatus::JointLimits | IkStatus::Unreachable) {
            // The robot cannot reach the target at all: that diagnosis stands.
            limited.status = exact.status;
            limited.limit = exact.limit;
        }
    }
    limited
}

/// The correction `q − q0` of a row (revolute joints modulo a whole turn), the `previous`
/// argument of [`within_joint_change_limit`] for the next row.
pub fn correction(model: &Model, q0: &[f64], q: &[f64]) -> Vec<f64> {
    model
        .joints
        .iter()
        .zip(q0.iter().zip(q))
        .map(|(j, (a, b))| joint_change(j.kind, *a, *b))
        .collect()
}
