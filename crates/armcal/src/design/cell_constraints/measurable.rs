//! Which poses the cell's instrument can measure: every constraint of the cell (the
//! reflector's incidence, paper eq. 4; the beam's line of sight; the robot clear of its
//! obstacles, half-spaces and of itself) evaluated at each pose at the nominal parameters,
//! with clearance 0 — the physical limits, not the planner's safety clearance. A pose the
//! robot cannot take without touching itself or an obstacle is not measurable either, so
//! self collision counts. Joint limits are checked where the poses are read.

use super::*;
use std::fmt;

/// A constraint a pose violates, with its value in display units.
#[derive(Clone, Debug, PartialEq)]
pub struct Violation {
    /// The constraint's name ([`ConstraintSet::names`]), e.g. `beam / car-roof`.
    pub constraint: String,
    /// What it guards against.
    pub kind: ConstraintKind,
    /// The incidence angle β (deg) for the incidence; the distance (mm, negative: the
    /// capsules overlap by that much) for the others.
    pub value: f64,
    /// The limit: β_max (deg) for the incidence, 0 mm for a distance.
    pub limit: f64,
}

impl fmt::Display for Violation {
    /// `incidence 41.2° > 30°`, `beam / car-roof: -12.3 mm (line of sight blocked)`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let what = match self.kind {
            ConstraintKind::Incidence => {
                return write!(f, "incidence {:.1}° > {}°", self.value, self.limit);
            }
            ConstraintKind::SelfCollision => "self collision",
            ConstraintKind::Obstacle => "collision with an obstacle",
            ConstraintKind::HalfSpace => "beyond a half-space",
            ConstraintKind::LineOfSight => "line of sight blocked",
        };
        write!(f, "{}: {:.1} mm ({what})", self.constraint, self.value)
    }
}

/// A pose the instrument cannot measure and why.
#[derive(Clone, Debug, PartialEq)]
pub struct Unmeasurable {
    /// The pose's id as its file gives it (`pose_id`).
    pub id: String,
    /// Every constraint it violates, in the set's order (incidence first).
    pub violations: Vec<Violation>,
}

impl fmt::Display for Unmeasurable {
    /// `pose 7: incidence 41.2° > 30°; beam / car-roof: -12.3 mm (line of sight blocked)`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "pose {}: ", self.id)?;
        for (k, v) in self.violations.iter().enumerate() {
            if k > 0 {
                f.write_str("; ")?;
            }
            write!(f, "{v}")?;
        }
        Ok(())
    }
}

/// The poses `(id, q)` (internal units) of `cell` that violate a constraint of the cell (see
/// the module documentation), each with every constraint it violates; empty when every pose
/// is measurable.
pub fn unmeasurable_poses(
    cell: &Cell,
    poses: &[(String, Vec<f64>)],
) -> Result<Vec<Unmeasurable>, Error> {
    unmeasurable_poses_at(cell, &cell.model.nominal(), poses)
}

/// As [`unmeasurable_poses`], with the robot and the instrument where the parameters
/// `params` (internal units, the model's full vector) put them: what a virtual instrument
/// can measure on a simulated robot.
pub fn unmeasurable_poses_at(
    cell: &Cell,
    params: &[f64],
    poses: &[(String, Vec<f64>)],
) -> Result<Vec<Unmeasurable>, Error> {
    let set = ConstraintSet::new(cell, &ConstraintSettings::default())?;
    let mut ws = set.workspace();
    let mut values = vec![0.0; set.len()];
    let mut out = Vec::new();
    for (id, q) in poses {
        cell.model
            .check_joints(q)
            .map_err(|e| Error::Input(format!("pose {id}: {e}")))?;
        set.evaluate(&mut ws, params, q, &mut values, None);
        let violations = violations(&set, &values);
        if !violations.is_empty() {
            out.push(Unmeasurable {
                id: id.clone(),
                violations,
            });
        }
    }
    Ok(out)
}

/// The constraints of `set` whose `values` are negative, in display units.
pub(super) fn violations(set: &ConstraintSet, values: &[f64]) -> Vec<Violation> {
    // β_max in degrees as the cell gave it (30, not 30.000000000000004).
    let beta_max = set
        .max_incidence()
        .map_or(0.0, |b| (b.to_degrees() * 1e9).round() / 1e9);
    values
        .iter()
        .enumerate()
        .filter(|(_, v)| **v < 0.0)
        .map(|(i, v)| {
            let kind = set.kind(i);
            let (value, limit) = if kind == ConstraintKind::Incidence {
                (set.incidence_angle(*v).to_degrees(), beta_max)
            } else {
                (*v, 0.0)
            };
            Violation {
                constraint: set.name(i).to_string(),
                kind,
                value,
                limit,
            }
        })
        .collect()
}
