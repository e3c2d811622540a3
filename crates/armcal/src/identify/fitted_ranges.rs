//! The joint ranges an estimate was fitted on, and the warning for configurations outside
//! them: a calibration is proven only where it was measured, and its parameters (offsets,
//! compliance, gear harmonics) extrapolate with no data to check them beyond.

use crate::model::{Joint, JointKind, Model};
use serde::{Deserialize, Serialize};

/// The range of one joint over the configurations an estimate was fitted on (display units:
/// deg, mm for a prismatic joint).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FittedRange {
    /// The joint's name.
    pub joint: String,
    /// `deg` or `mm`.
    pub unit: String,
    /// Smallest value fitted on.
    pub lower: f64,
    /// Largest value fitted on.
    pub upper: f64,
}

/// A configuration is outside a fitted range when it passes an end by more than this share
/// of the range's width (or of 1°, 1 mm for a narrow one): the value a controller reports
/// and the next-to-extreme fitted pose differ by that much without extrapolating anything.
const SLACK: f64 = 1e-3;

impl FittedRange {
    /// The range of every joint of `model` over `configurations` (internal units); empty when
    /// there are none.
    pub fn of(model: &Model, configurations: &[Vec<f64>]) -> Vec<FittedRange> {
        if configurations.is_empty() {
            return Vec::new();
        }
        model
            .joints
            .iter()
            .enumerate()
            .map(|(j, joint)| {
                let f = joint.kind.unit().display_factor();
                let values = configurations.iter().map(|q| q[j] * f);
                FittedRange {
                    joint: joint.name.clone(),
                    unit: joint.kind.unit().display_name().to_string(),
                    lower: values.clone().fold(f64::INFINITY, f64::min),
                    upper: values.fold(f64::NEG_INFINITY, f64::max),
                }
            })
            .collect()
    }

    /// How far the display value `v` lies outside the range (0 inside or within the slack).
    /// A revolute joint (`turn` = 360°) is the same joint a turn further: every term of the
    /// model (the rotation, the gravity levers, the gear harmonics) is periodic in its angle,
    /// so `v` is compared in the turn nearest the range, and a range a full turn wide holds
    /// every angle.
    fn beyond(&self, v: f64, turn: Option<f64>) -> f64 {
        let slack = SLACK * (self.upper - self.lower).max(1.0);
        let outside = |v: f64| {
            if v < self.lower - slack {
                self.lower - v
            } else if v > self.upper + slack {
                v - self.upper
            } else {
                0.0
            }
        };
        match turn {
            Some(t) if self.upper - self.lower >= t => 0.0,
            Some(t) => {
                let middle = 0.5 * (self.lower + self.upper);
                outside(v - t * ((v - middle) / t).round())
            }
            None => outside(v),
        }
    }
}

/// The warning for the configurations `(id, q)` (internal units) of `joints` that lie
/// outside `ranges` (an estimate's [`FittedRange`]s, same joints by name): how many, and per
/// joint its fitted range and the farthest configuration beyond it. `None` when every
/// configuration is inside, or when the estimate records no ranges (an older file).
pub fn outside_warning(
    ranges: &[FittedRange],
    joints: &[Joint],
    configurations: &[(String, Vec<f64>)],
) -> Option<String> {
    let mut outside = vec![false; configurations.len()];
    let mut per_joint = Vec::new();
    for (j, joint) in joints.iter().enumerate() {
        let Some(range) = ranges.iter().find(|r| r.joint == joint.name) else {
            continue;
        };
        let f = joint.kind.unit().display_factor();
        let turn = (joint.kind == JointKind::Revolute).then_some(360.0);
        let worst = configurations
            .iter()
            .enumerate()
            .map(|(k, (id, q))| (k, id, range.beyond(q[j] * f, turn)))
            .filter(|(_, _, d)| *d > 0.0)
            .inspect(|(k, _, _)| outside[*k] = true)
            .max_by(|a, b| a.2.total_cmp(&b.2));
        if let Some((_, id, d)) = worst {
            per_joint.push(format!(
                "`{}` fitted on [{:.3}, {:.3}] {u}, up to {d:.3} {u} beyond at `{id}`",
                joint.name,
                range.lower,
                range.upper,
                u = range.unit
            ));
        }
    }
    let n = outside.iter().filter(|o| **o).count();
    (n > 0).then(|| {
        format!(
            "{n} of {} configurations lie outside the joint ranges the calibration was fitted on ({}); its accuracy there is extrapolated, not measured: measure poses that span them and identify again",
            configurations.len(),
            per_joint.join("; ")
        )
    })
}
