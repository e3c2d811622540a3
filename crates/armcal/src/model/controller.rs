//! Controller joint conventions: how a robot controller's axis value maps to the model's
//! joint variable.
//!
//! A controller counts its axes from its own zero and in its own direction (KUKA's A2 is
//! −90° with the upper arm vertical, a URDF may turn the other way); the model's joint
//! variable `q` is what its link convention adds to θ (or d). Per joint,
//!
//! ```text
//! q_model = sign · q_controller + offset        (sign = ±1; offset in rad or mm)
//! q_controller = sign · (q_model − offset)
//! ```
//!
//! so the map is its own kind of inverse and a negated axis round-trips exactly. The
//! identity (every sign +1, every offset 0) is "model angles", armcal's default.

use crate::model::{JointKind, Model};
use serde::{Deserialize, Serialize};

/// One joint's map from the controller's axis value to the model's joint variable.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct JointMap {
    /// +1 or −1: whether the controller turns (or slides) the joint the model's way.
    pub sign: f64,
    /// The model's joint variable at the controller's zero (rad, or mm for a prismatic joint).
    pub offset: f64,
}

impl JointMap {
    /// The identity: controller value = model value.
    pub const IDENTITY: JointMap = JointMap {
        sign: 1.0,
        offset: 0.0,
    };
}

/// The controller convention of every joint of a model, in the model's joint order.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ControllerConvention {
    /// One map per model joint.
    pub joints: Vec<JointMap>,
    /// Where the convention comes from, in words (`model angles`, a built-in robot's
    /// vendor convention with its source, or the cell's `[robot.controller]`).
    pub source: String,
}

impl ControllerConvention {
    /// Model angles: the identity for `dof` joints.
    pub fn model_angles(dof: usize) -> ControllerConvention {
        ControllerConvention {
            joints: vec![JointMap::IDENTITY; dof],
            source: "model angles".into(),
        }
    }

    /// Whether every joint maps to itself.
    pub fn is_identity(&self) -> bool {
        self.joints.iter().all(|m| *m == JointMap::IDENTITY)
    }

    /// The model's joint variables of the controller's axis values `c` (internal units).
    pub fn to_model(&self, c: &[f64]) -> Vec<f64> {
        c.iter()
            .zip(&self.joints)
            .map(|(c, m)| m.sign * c + m.offset)
            .collect()
    }

    /// The controller's axis values of the model's joint variables `q` (internal units).
    pub fn to_controller(&self, q: &[f64]) -> Vec<f64> {
        q.iter()
            .zip(&self.joints)
            .map(|(q, m)| m.sign * (q - m.offset))
            .collect()
    }

    /// Checks that the convention has one map per joint of `model` with a sign of ±1 and a
    /// finite offset; the message names the joint.
    pub fn check(&self, model: &Model) -> Result<(), String> {
        if self.joints.len() != model.dof() {
            return Err(format!(
                "the controller convention has {} joints, the model {}",
                self.joints.len(),
                model.dof()
            ));
        }
        for (m, j) in self.joints.iter().zip(&model.joints) {
            if m.sign != 1.0 && m.sign != -1.0 {
                return Err(format!("joint `{}`: sign must be 1 or -1", j.name));
            }
            if !m.offset.is_finite() {
                let unit = match j.kind {
                    JointKind::Revolute => "offset_deg",
                    JointKind::Prismatic => "offset_mm",
                };
                return Err(format!(
                    "joint `{}`: {unit} must be a finite number",
                    j.name
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_negated_offset_axis_round_trips() {
        let c = ControllerConvention {
            joints: vec![
                JointMap::IDENTITY,
                JointMap {
                    sign: -1.0,
                    offset: -90f64.to_radians(),
                },
                JointMap {
                    sign: -1.0,
                    offset: 0.3,
                },
            ],
            source: "test".into(),
        };
        let controller = [0.2, -1.4, 2.9];
        let q = c.to_model(&controller);
        assert_eq!(q[0], 0.2);
        assert!((q[1] - (1.4 - 90f64.to_radians())).abs() < 1e-15);
        let back = c.to_controller(&q);
        for (a, b) in back.iter().zip(controller) {
            assert!((a - b).abs() < 1e-15);
        }
        assert!(!c.is_identity());
        assert!(ControllerConvention::model_angles(3).is_identity());
    }
}
