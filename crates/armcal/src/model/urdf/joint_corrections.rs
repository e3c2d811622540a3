//! Per-joint corrections as a ROS 2 parameter file: for every joint of the nominal robot's
//! URDF (as [`super::to_urdf`] writes the nominal model), the correction of its origin
//! `dx, dy, dz` (m), `droll, dpitch, dyaw` (rad), and of its zero, `offset` (rad; m for a
//! prismatic joint):
//!
//! ```yaml
//! armcal_joint_corrections:
//!   ros__parameters:
//!     robot: ur10
//!     joints: [base_fixed, q1, …]
//!     corrections:
//!       q1: { dx: 0.0, dy: 0.0, dz: 0.0, droll: 0.0, dpitch: 0.0, dyaw: 0.0, offset: 0.0 }
//! ```
//!
//! The corrected origin is `O · T(dx, dy, dz) Rz(dyaw) Ry(dpitch) Rx(droll)` — the nominal
//! origin `O` composed on the right with the correction, in the joint's origin frame, as
//! robot_calibration's `update_urdf` composes its frame corrections — and the joint moves by
//! `q + offset` (the `<calibration rising>` of `super::calibration`). No public
//! specification of such a file exists: the layout is a ROS 2 parameter file
//! (`<node>: ros__parameters:`), the names the `dx … dyaw` of the issue, and the file says
//! how to apply it in its header. A joint the file does not name keeps its nominal origin.

use super::calibration::joint_offsets;
use super::export::urdf_robot;
use crate::input::field_line;
use crate::model::chain::ModelSpec;
use crate::model::pose::Pose;
use crate::model::tcp_shift::{without_nongeometric, NotHeld};
use crate::Error;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// The parameter file's node name.
pub const NODE: &str = "armcal_joint_corrections";

/// One joint's correction (m, rad; `offset` rad or m).
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Correction {
    dx: f64,
    dy: f64,
    dz: f64,
    droll: f64,
    dpitch: f64,
    dyaw: f64,
    #[serde(default)]
    offset: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Parameters {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    robot: Option<String>,
    #[serde(default)]
    joints: Vec<String>,
    corrections: BTreeMap<String, Correction>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Node {
    #[serde(rename = "ros__parameters")]
    ros_parameters: Parameters,
}

/// A joint-corrections file of a model.
#[derive(Clone, Debug)]
pub struct JointCorrectionsFile {
    /// The file's text (comments, then the YAML).
    pub text: String,
    /// What the file does not hold, each with the TCP shift its omission causes.
    pub not_held: Vec<NotHeld>,
}

/// The corrections that take `nominal` to `calibrated` (one chain at two parameter sets), as
/// a ROS 2 parameter file; `source` names where the model comes from, for the header.
pub fn to_joint_corrections(
    calibrated: &ModelSpec,
    nominal: &ModelSpec,
    source: &str,
) -> Result<JointCorrectionsFile, Error> {
    let (rigid, nongeometric) = without_nongeometric(calibrated)?;
    let (nominal, _) = without_nongeometric(nominal)?;
    let offsets = joint_offsets(&rigid, &nominal)?;
    let cal = urdf_robot(&rigid, &offsets)?;
    let nom = urdf_robot(&nominal, &[])?;
    let mut corrections = BTreeMap::new();
    let mut joints = Vec::new();
    for (c, n) in cal.joints.iter().zip(&nom.joints) {
        let origin = |j: &urdf_rs::Joint| Pose::from_xyz_rpy(j.origin.xyz.0, j.origin.rpy.0);
        let (d, r) = origin(n).inverse().compose(&origin(c)).to_xyz_rpy();
        joints.push(c.name.clone());
        corrections.insert(
            c.name.clone(),
            Correction {
                dx: d[0] + 0.0,
                dy: d[1] + 0.0,
                dz: d[2] + 0.0,
                droll: r[0] + 0.0,
                dpitch: r[1] + 0.0,
                dyaw: r[2] + 0.0,
                offset: c.calibration.as_ref().and_then(|c| c.rising).unwrap_or(0.0),
            },
        );
    }
    let file: BTreeMap<&str, Node> = [(
        NODE,
        Node {
            ros_parameters: Parameters {
                robot: Some(calibrated.name.clone()),
                joints,
                corrections,
            },
        },
    )]
    .into();
    let yaml = serde_norway::to_string(&file)
        .map_err(|e| Error::Model(format!("joint corrections of `{}`: {e}", calibrated.name)))?;
    let not_held: Vec<NotHeld> = nongeometric.into_iter().collect();
    let mut text = format!(
        "# Per-joint corrections of `{}` written by armcal from {source}.\n# For every joint \
         of the nominal URDF (`armcal export --format urdf` of the nominal model):\n# origin \
         := origin · T(dx, dy, dz) Rz(dyaw) Ry(dpitch) Rx(droll)  (m, rad), and the joint \
         moves by q + offset.\n",
        calibrated.name
    );
    for n in &not_held {
        text.push_str(&format!("# {}\n", n.sentence()));
    }
    text.push_str(&yaml);
    Ok(JointCorrectionsFile { text, not_held })
}

/// Reads a joint-corrections file and applies it to `nominal` (see the module
/// documentation); errors name the file, the line and the field.
pub fn read_joint_corrections(path: &Path, nominal: &ModelSpec) -> Result<ModelSpec, Error> {
    super::parse_file(path, "the joint corrections file", |text| {
        apply_joint_corrections(text, nominal)
    })
}

/// `nominal` with the corrections of the parameter file `text` applied: the chain as a URDF
/// with corrected joint origins and offsets, imported back.
pub fn apply_joint_corrections(text: &str, nominal: &ModelSpec) -> Result<ModelSpec, Error> {
    let parsed: BTreeMap<String, Node> = serde_norway::from_str(text).map_err(|e| {
        Error::Input(format!(
            "not a joint corrections file (`<node>: ros__parameters: corrections: <joint>: \
             {{dx, dy, dz, droll, dpitch, dyaw, offset}}`): {e}"
        ))
    })?;
    let mut nodes = parsed.into_values();
    let params = match (nodes.next(), nodes.next()) {
        (Some(n), None) => n.ros_parameters,
        _ => {
            return Err(Error::Input(
                "a joint corrections file has exactly one node (`armcal_joint_corrections:`)"
                    .into(),
            ))
        }
    };
    let mut robot = urdf_robot(nominal, &[])?;
    let known: Vec<String> = robot.joints.iter().map(|j| j.name.clone()).collect();
    for (name, c) in &params.corrections {
        let values = [c.dx, c.dy, c.dz, c.droll, c.dpitch, c.dyaw, c.offset];
        let fields = ["dx", "dy", "dz", "droll", "dpitch", "dyaw", "offset"];
        if let Some(k) = values.iter().position(|v| !v.is_finite()) {
            return Err(Error::Input(format!(
                "line {}: corrections.{name}.{} is {}, not a finite number; fix the file",
                field_line(text, name, fields[k]),
                fields[k],
                values[k]
            )));
        }
        let Some(joint) = robot.joints.iter_mut().find(|j| j.name == *name) else {
            return Err(Error::Input(format!(
                "line {}: corrections.{name}: the nominal robot `{}` has no joint `{name}` \
                 (joints: {})",
                field_line(text, name, ""),
                nominal.name,
                known.join(", ")
            )));
        };
        let o = Pose::from_xyz_rpy(joint.origin.xyz.0, joint.origin.rpy.0).compose(
            &Pose::from_xyz_rpy([c.dx, c.dy, c.dz], [c.droll, c.dpitch, c.dyaw]),
        );
        let (xyz, rpy) = o.to_xyz_rpy();
        joint.origin.xyz = urdf_rs::Vec3(xyz);
        joint.origin.rpy = urdf_rs::Vec3(rpy);
        if c.offset != 0.0 {
            if joint.joint_type == urdf_rs::JointType::Fixed {
                return Err(Error::Input(format!(
                    "line {}: corrections.{name}.offset: `{name}` is a fixed joint, it has no \
                     zero to offset",
                    field_line(text, name, "offset")
                )));
            }
            joint.calibration = Some(urdf_rs::Calibration {
                rising: Some(c.offset),
                falling: None,
            });
        }
    }
    // The chain ends in the link before the targets' fixed joints (super::export).
    let tip = robot.joints[robot.joints.len() - nominal.targets.len() - 1]
        .child
        .link
        .clone();
    let mut spec = super::import::from_urdf_robot(&robot, Some(&tip))?;
    spec.name = nominal.name.clone();
    Ok(spec)
}
