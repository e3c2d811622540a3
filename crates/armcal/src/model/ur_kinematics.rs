//! Universal Robots kinematics YAML: the robot-specific file `ur_calibration` extracts from a
//! controller's factory calibration, and `ur_description` (Universal_Robots_ROS2_Description,
//! `config/<type>/default_kinematics.yaml`, read by `urdf/inc/ur_common.xacro` as
//! `kinematics_parameters_file`) builds the URDF from:
//!
//! ```yaml
//! kinematics:
//!   shoulder:  { x: …, y: …, z: …, roll: …, pitch: …, yaw: … }   # m, rad
//!   upper_arm: { … }
//!   forearm:   { … }
//!   wrist_1:   { … }
//!   wrist_2:   { … }
//!   wrist_3:   { … }
//!   hash: calib_…        # the controller's calibration checksum
//! ```
//!
//! **The chain** (`urdf/ur_macro.xacro`): joint `shoulder_pan_joint` has origin `shoulder`
//! (`T(x, y, z) Rz(yaw) Ry(pitch) Rx(roll)`, URDF) from `base_link_inertia` — the controller's
//! base frame `base`, both `base_link` turned by π about z — and turns about its z axis;
//! `shoulder_lift_joint` … `wrist_3_joint` follow with origins `upper_arm` … `wrist_3`, every
//! axis z. `wrist_3_link → flange` is `rpy (0, −π/2, −π/2)` and `flange → tool0` is
//! `rpy (π/2, 0, π/2)`: their product is the identity, so `tool0`, the controller's flange
//! frame, is `wrist_3_link`. armcal's model of the file is therefore `base` (identity), six
//! [`Convention::Urdf`] links with axis z and offset 0 named after the joints, and an
//! identity `tool`; joint values are the controller's.
//!
//! **Writing** a calibrated chain: every link is split at its joint, `T_i(q) = A_i J(q) B_i`
//! (`super::urdf::export`), with `R_i` turning z onto the joint axis; the origin of joint
//! `i` is `P_i A_i R_i Tz(d_i)`, where `P_i = Tz(−d_{i−1}) R_{i−1}ᵀ B_{i−1}` (the base frame
//! for joint 1) and `d_i` is the z component of `R_iᵀ B_i`'s shift, which commutes with the
//! joint's rotation. For the built-in UR10's DH parameters this gives exactly Universal
//! Robots' `default_kinematics.yaml` (shoulder z = d1, upper_arm roll = α1, forearm x = a2,
//! wrist_1 x = a3 and z = d4, wrist_2 y = −d5, wrist_3 y = d6). After the last joint, the
//! rest `M` of the chain up to the flange is split as `Tz(d) Rz(φ) · E`: `Tz(d) Rz(φ)` goes
//! into `wrist_3`, and `E` (an offset across or a tilt of the last axis) has no place in the
//! file. Neither has the tool frame, the instrument, the targets or a non-geometric term: the
//! writer lists what it leaves out with the TCP shift each one causes.
//!
//! **The hash** is the controller's checksum of its own calibration; it cannot be computed
//! for another model. The writer puts `armcal_` and a hash of the file's numbers there, and
//! says so in the file: the UR driver then warns that the file does not match the
//! controller's calibration, which is true.

use crate::input::field_line;
use crate::model::chain::{LinkSpec, Model, ModelSpec};
use crate::model::link::{Convention, Joint, JointKind, LinkGeometry};
use crate::model::pose::{rot_z, Pose};
use crate::model::tcp_shift::{spec_shift, without_nongeometric, NotHeld};
use crate::model::urdf::export::{fixed_pose, split_at_joint};
use crate::model::urdf::CONTINUOUS_RANGE;
use crate::Error;
use nalgebra::{Matrix3, Rotation3, Vector3};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The six frames of the file and the joints they place, in chain order.
pub const UR_FRAMES: [(&str, &str); 6] = [
    ("shoulder", "shoulder_pan_joint"),
    ("upper_arm", "shoulder_lift_joint"),
    ("forearm", "elbow_joint"),
    ("wrist_1", "wrist_1_joint"),
    ("wrist_2", "wrist_2_joint"),
    ("wrist_3", "wrist_3_joint"),
];

const MM_PER_M: f64 = 1000.0;

/// One frame of the file (m, rad).
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Frame {
    x: f64,
    y: f64,
    z: f64,
    roll: f64,
    pitch: f64,
    yaw: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Kinematics {
    shoulder: Frame,
    upper_arm: Frame,
    forearm: Frame,
    wrist_1: Frame,
    wrist_2: Frame,
    wrist_3: Frame,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    hash: Option<String>,
}

impl Kinematics {
    fn frames(&self) -> [&Frame; 6] {
        [
            &self.shoulder,
            &self.upper_arm,
            &self.forearm,
            &self.wrist_1,
            &self.wrist_2,
            &self.wrist_3,
        ]
    }
}

#[derive(Clone, Debug, Serialize, Deserialize)]
struct File {
    kinematics: Kinematics,
}

/// Reads a UR kinematics YAML file as a model (see the module documentation); errors name
/// the file, the line and the field.
pub fn read_ur_kinematics(path: &Path) -> Result<ModelSpec, Error> {
    crate::model::urdf::parse_file(path, "the UR kinematics file", from_ur_kinematics_str)
}

/// Parses UR kinematics YAML text as a model named `ur` (see the module documentation).
pub fn from_ur_kinematics_str(text: &str) -> Result<ModelSpec, Error> {
    let parsed: File = serde_norway::from_str(text).map_err(|e| {
        Error::Input(format!(
            "not a UR kinematics file (`kinematics:` with shoulder, upper_arm, forearm, \
             wrist_1, wrist_2, wrist_3, each x, y, z in m and roll, pitch, yaw in rad): {e}"
        ))
    })?;
    let mut links = vec![identity("base")];
    for ((key, joint), f) in UR_FRAMES.iter().zip(parsed.kinematics.frames()) {
        let values = [f.x, f.y, f.z, f.roll, f.pitch, f.yaw];
        let names = ["x", "y", "z", "roll", "pitch", "yaw"];
        if let Some(k) = values.iter().position(|v| !v.is_finite()) {
            return Err(Error::Input(format!(
                "line {}: kinematics.{key}.{} is {}, not a finite number; fix the file",
                field_line(text, key, names[k]),
                names[k],
                values[k]
            )));
        }
        links.push(LinkSpec {
            name: joint.to_string(),
            geometry: LinkGeometry {
                convention: Convention::Urdf,
                values: vec![
                    f.x * MM_PER_M,
                    f.y * MM_PER_M,
                    f.z * MM_PER_M,
                    f.roll,
                    f.pitch,
                    f.yaw,
                    0.0,
                ],
                axis: Some([0.0, 0.0, 1.0]),
            },
            joint: Some(Joint {
                name: joint.to_string(),
                kind: JointKind::Revolute,
                lower: -CONTINUOUS_RANGE,
                upper: CONTINUOUS_RANGE,
            }),
        });
    }
    links.push(identity("tool"));
    Ok(ModelSpec {
        name: "ur".into(),
        instrument: None,
        links,
        targets: Vec::new(),
        compliance: None,
        periodic: None,
        payloads: Vec::new(),
    })
}

fn identity(name: &str) -> LinkSpec {
    LinkSpec {
        name: name.into(),
        geometry: LinkGeometry::frame6([0.0; 3], [0.0; 3]),
        joint: None,
    }
}

/// The rotation taking z onto the unit vector `e`.
fn z_onto(e: &Vector3<f64>) -> Matrix3<f64> {
    Rotation3::rotation_between(&Vector3::z(), e)
        .map(|r| r.into_inner())
        // antiparallel: a half turn about x
        .unwrap_or_else(|| Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, -1.0)))
}

fn rotation(rot: Matrix3<f64>) -> Pose<f64> {
    Pose {
        rot,
        trans: Vector3::zeros(),
    }
}

fn shift_z(d: f64) -> Pose<f64> {
    Pose {
        rot: Matrix3::identity(),
        trans: Vector3::new(0.0, 0.0, d),
    }
}

/// A UR kinematics file of a model.
#[derive(Clone, Debug)]
pub struct UrKinematicsFile {
    /// The file's text (comments, then the YAML).
    pub text: String,
    /// What the file does not hold, each with the TCP shift its omission causes.
    pub not_held: Vec<NotHeld>,
}

/// Writes `spec` (six revolute joints; any conventions) as a UR kinematics file (see the
/// module documentation); `source` names where the model comes from, for the file's header.
pub fn to_ur_kinematics(spec: &ModelSpec, source: &str) -> Result<UrKinematicsFile, Error> {
    let (rigid, nongeometric) = without_nongeometric(spec)?;
    let model = Model::from_spec(&rigid)?;
    if model.dof() != 6 || model.joints.iter().any(|j| j.kind != JointKind::Revolute) {
        return Err(Error::Model(format!(
            "a UR kinematics file holds six revolute joints; `{}` has {} joints{}",
            spec.name,
            model.dof(),
            if model.joints.iter().any(|j| j.kind == JointKind::Prismatic) {
                " (some prismatic)"
            } else {
                ""
            }
        )));
    }
    let tool_index = rigid.links.len() - 1;
    let tool = &rigid.links[tool_index];
    let has_tool = tool.joint.is_none();
    let arm_end = if has_tool {
        tool_index
    } else {
        rigid.links.len()
    };
    let mut origins: Vec<Pose<f64>> = Vec::new();
    let mut pending = Pose::identity();
    for link in &rigid.links[..arm_end] {
        match &link.joint {
            None => pending = pending.compose(&fixed_pose(&link.geometry)),
            Some(j) => {
                let (a, axis, b) = split_at_joint(&link.geometry, j.kind);
                let r = z_onto(&axis);
                let rest = rotation(r.transpose()).compose(&b);
                let d = rest.trans.z;
                origins.push(
                    pending
                        .compose(&a)
                        .compose(&rotation(r))
                        .compose(&shift_z(d)),
                );
                pending = shift_z(-d).compose(&rest);
            }
        }
    }
    // The rest after the last joint: Tz(d) Rz(φ) goes into wrist_3, the remainder is lost.
    let phi = pending.rot[(1, 0)].atan2(pending.rot[(0, 0)]);
    let c = shift_z(pending.trans.z).compose(&rotation(rot_z(phi)));
    let remainder = c.inverse().compose(&pending);
    let last = origins.last_mut().expect("six joints");
    *last = last.compose(&c);

    let frame = |p: &Pose<f64>| {
        let (xyz, rpy) = p.to_xyz_rpy();
        // `+ 0.0` turns −0 into 0 in the text
        Frame {
            x: xyz[0] / MM_PER_M + 0.0,
            y: xyz[1] / MM_PER_M + 0.0,
            z: xyz[2] / MM_PER_M + 0.0,
            roll: rpy[0] + 0.0,
            pitch: rpy[1] + 0.0,
            yaw: rpy[2] + 0.0,
        }
    };
    let f: Vec<Frame> = origins.iter().map(frame).collect();
    let mut kinematics = Kinematics {
        shoulder: f[0],
        upper_arm: f[1],
        forearm: f[2],
        wrist_1: f[3],
        wrist_2: f[4],
        wrist_3: f[5],
        hash: None,
    };
    kinematics.hash = Some(format!("armcal_{:016x}", fnv1a(&kinematics)));
    let yaml = serde_norway::to_string(&File { kinematics })
        .map_err(|e| Error::Model(format!("UR kinematics file of `{}`: {e}", spec.name)))?;

    // What the file leaves out, each with its cost, measured on the file read back.
    let read_back = from_ur_kinematics_str(&yaml)?;
    let mut not_held: Vec<NotHeld> = nongeometric.into_iter().collect();
    let mut arm = rigid.clone();
    if has_tool {
        arm.links[tool_index].geometry = LinkGeometry::frame6([0.0; 3], [0.0; 3]);
        let (xyz, rpy) = fixed_pose(&tool.geometry).to_xyz_rpy();
        if xyz.iter().chain(&rpy).any(|v| *v != 0.0) {
            not_held.push(NotHeld {
                what: format!(
                    "the tool frame `{}` (xyz {} mm, rpy {} deg): give it to the controller as \
                     its TCP",
                    tool.name,
                    triple(xyz, 1.0),
                    triple(rpy, 180.0 / std::f64::consts::PI)
                ),
                tcp_shift_mm: spec_shift(&rigid, &arm)?,
            });
        }
    }
    let (xyz, rpy) = remainder.to_xyz_rpy();
    if remainder.trans.norm() > 1e-9 || Pose::identity().rotation_angle_to(&remainder) > 1e-12 {
        not_held.push(NotHeld {
            what: format!(
                "the flange's offset across / tilt of the last joint axis (xyz {} mm, rpy {} \
                 deg after wrist_3)",
                triple(xyz, 1.0),
                triple(rpy, 180.0 / std::f64::consts::PI)
            ),
            tcp_shift_mm: spec_shift(&arm, &read_back)?,
        });
    }
    let mut text = format!(
        "# Universal Robots kinematics file (ur_description `kinematics_parameters_file`) \
         written by armcal\n# from {source}. Lengths in m, angles in rad.\n# `hash` is NOT the \
         controller's calibration checksum, which cannot be reproduced for another\n# model: \
         the UR driver will warn that it does not match the robot's calibration.\n"
    );
    for n in &not_held {
        text.push_str(&format!("# {}\n", n.sentence()));
    }
    text.push_str(&yaml);
    Ok(UrKinematicsFile { text, not_held })
}

fn triple(v: [f64; 3], scale: f64) -> String {
    format!(
        "({:.4}, {:.4}, {:.4})",
        v[0] * scale + 0.0,
        v[1] * scale + 0.0,
        v[2] * scale + 0.0
    )
}

/// FNV-1a (64 bit) of the frames' numbers: a stable tag of the file's content.
fn fnv1a(k: &Kinematics) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for f in k.frames() {
        for v in [f.x, f.y, f.z, f.roll, f.pitch, f.yaw] {
            for b in v.to_le_bytes() {
                h ^= u64::from(b);
                h = h.wrapping_mul(0x0000_0100_0000_01b3);
            }
        }
    }
    h
}
