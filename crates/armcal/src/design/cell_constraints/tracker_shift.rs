//! Which poses stay measurable when the instrument stands up to `D` mm from where the cell
//! puts it, in any direction (`armcal evaluate --tracker-shift-mm D`).
//!
//! Only the instrument's origin `t` enters a constraint (incidence and line of sight; the
//! robot's own constraints do not move with it), so a displacement is a vector `δ`,
//! `|δ| ≤ D`. For each pose and each constraint the worst `δ` is found exactly, not sampled:
//!
//! - **Incidence.** `β` is the angle between the reflector's z axis and `t − p` (paper
//!   eq. 4). The vectors `t + δ − p` fill a ball of radius `D` about `t − p`, which subtends a
//!   half-angle `α = asin(D / |t − p|)` seen from `p` (every direction when `D ≥ |t − p|`):
//!   the worst angle is `min(β + α, 180°)`, attained by moving the tracker perpendicular to
//!   the beam, away from the reflector's axis.
//! - **Line of sight.** The beams `p → t + δ` fill the convex hull of `p` and the ball
//!   `B(t, D)`; the worst clearance of a capsule is its axis' distance to that hull
//!   ([`segment_cone_distance`], exact to rounding) less the radii.
//!
//! A pose is counted measurable when every constraint keeps `g ≥ 0` at its own worst `δ`.
//! That is exactly "measurable for every tracker position in the ball" (a pose fails for some
//! `δ` if and only if some constraint fails for some `δ`); for the design as a whole it is
//! conservative, since one misplaced tracker has a single `δ` for every pose while each pose's
//! worst `δ` differs. The robot is at the nominal parameters, as for
//! [`unmeasurable_poses`](super::unmeasurable_poses).

use super::measurable::violations;
use super::*;
use crate::geometry::segment_cone_distance;
use serde::{Deserialize, Serialize};

/// A design checked against an instrument displaced by up to [`TrackerShift::shift_mm`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrackerShift {
    /// The largest displacement of the instrument's origin (mm), any direction.
    pub shift_mm: f64,
    /// Number of poses checked.
    pub poses: usize,
    /// Poses measurable wherever the instrument stands within `shift_mm`.
    pub measurable: usize,
    /// The smallest incidence margin `β_max − β` (deg) at the worst displacement over the
    /// poses, and its pose (1-based); none without an incidence limit.
    pub incidence_margin_deg: Option<(f64, usize)>,
    /// The smallest beam clearance (mm) at the worst displacement over the poses, and its
    /// pose (1-based); none without line-of-sight constraints.
    pub line_of_sight_mm: Option<(f64, usize)>,
    /// Every pose some displacement makes unmeasurable, with each constraint it violates at
    /// that constraint's worst displacement (`pose 7: incidence 31.2° > 30°`).
    pub unmeasurable: Vec<String>,
}

impl ConstraintSet {
    /// Every constraint's smallest value at `params`, `q` over every instrument origin
    /// within `shift` (mm) of the one the parameters place (see the module documentation);
    /// constraints that do not depend on the instrument keep their value.
    ///
    /// # Panics
    /// If a length is wrong, or `shift` is negative.
    pub fn evaluate_shifted(
        &self,
        ws: &mut ConstraintWorkspace,
        params: &[f64],
        q: &[f64],
        shift: f64,
        values: &mut [f64],
    ) {
        assert!(shift >= 0.0, "shift must be ≥ 0");
        self.evaluate(ws, params, q, values, None);
        let data = &ws.data;
        let p = match self.reflector {
            Reflector::Target(k) => data.targets[k].trans,
            Reflector::Tool => data.tool().trans,
        };
        let t = data.instrument.trans;
        for (value, item) in values.iter_mut().zip(&self.items) {
            *value = match *item {
                Item::Incidence => {
                    let beta = self.incidence_angle(*value);
                    let len = (t - p).norm();
                    let alpha = if shift < len {
                        (shift / len).asin()
                    } else {
                        std::f64::consts::PI
                    };
                    (beta + alpha).min(std::f64::consts::PI).cos() - self.cos_max
                }
                Item::BeamRobot { i } => {
                    let [a, b] = ws.ends[i];
                    segment_cone_distance(&p, &t, shift, &a, &b).0
                        - self.beam_radius
                        - self.capsules[i].radius
                }
                Item::BeamObstacle { o } => {
                    let ob = &self.obstacles[o];
                    segment_cone_distance(&p, &t, shift, &ob.a, &ob.b).0
                        - self.beam_radius
                        - ob.radius
                }
                _ => *value,
            };
        }
    }
}

/// Checks the poses `design` (internal units) of `cell` against an instrument up to
/// `shift_mm` from where the cell puts it (see the module documentation): the physical limits
/// (no clearance, no margin), every constraint of the cell, the nominal robot.
pub fn tracker_shift(
    cell: &Cell,
    design: &[Vec<f64>],
    shift_mm: f64,
) -> Result<TrackerShift, Error> {
    if !(shift_mm.is_finite() && shift_mm >= 0.0) {
        return Err(Error::Input(format!(
            "the tracker shift must be a finite distance ≥ 0 mm, got {shift_mm}"
        )));
    }
    let set = ConstraintSet::new(cell, &ConstraintSettings::default())?;
    let params = cell.model.nominal();
    let mut ws = set.workspace();
    let mut values = vec![0.0; set.len()];
    let max_incidence = set.max_incidence();
    let mut out = TrackerShift {
        shift_mm,
        poses: design.len(),
        measurable: 0,
        incidence_margin_deg: None,
        line_of_sight_mm: None,
        unmeasurable: Vec::new(),
    };
    let least = |best: &mut Option<(f64, usize)>, v: f64, pose: usize| {
        if best.is_none_or(|b| v < b.0) {
            *best = Some((v, pose));
        }
    };
    for (k, q) in design.iter().enumerate() {
        cell.model
            .check_joints(q)
            .map_err(|e| Error::Input(format!("pose {}: {e}", k + 1)))?;
        set.evaluate_shifted(&mut ws, &params, q, shift_mm, &mut values);
        for (i, v) in values.iter().enumerate() {
            match (set.kind(i), max_incidence) {
                (ConstraintKind::Incidence, Some(m)) => least(
                    &mut out.incidence_margin_deg,
                    (m - set.incidence_angle(*v)).to_degrees(),
                    k + 1,
                ),
                (ConstraintKind::LineOfSight, _) => least(&mut out.line_of_sight_mm, *v, k + 1),
                _ => {}
            }
        }
        let violations = violations(&set, &values);
        if violations.is_empty() {
            out.measurable += 1;
        } else {
            out.unmeasurable.push(
                Unmeasurable {
                    id: (k + 1).to_string(),
                    violations,
                }
                .to_string(),
            );
        }
    }
    Ok(out)
}
