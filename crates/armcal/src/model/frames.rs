//! Every frame of a model at one configuration, as `armcal fk` shows it: the links' and
//! targets' poses in the world frame, and the targets as the instrument measures them
//! (instrument frame), at the nominal parameters.

use crate::model::{forward_kinematics, observed_pose, Data, Model, Observed, Pose};
use crate::Error;
use serde::{Deserialize, Serialize};

/// A pose in user units: position (mm), roll-pitch-yaw (deg) and the homogeneous matrix.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PoseRecord {
    /// Position (mm).
    pub xyz_mm: [f64; 3],
    /// Roll, pitch, yaw (deg).
    pub rpy_deg: [f64; 3],
    /// The homogeneous transform, rows (mm).
    pub matrix: [[f64; 4]; 4],
}

impl PoseRecord {
    /// The record of `p` (mm, rad).
    pub fn of(p: &Pose<f64>) -> PoseRecord {
        let (xyz, rpy) = p.to_xyz_rpy();
        PoseRecord {
            xyz_mm: xyz,
            rpy_deg: rpy.map(f64::to_degrees),
            matrix: p.to_matrix(),
        }
    }
}

/// A joint value in its display unit (deg or mm).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JointValue {
    /// The joint's name.
    pub name: String,
    /// Its value in `unit`.
    pub value: f64,
    /// `deg` or `mm`.
    pub unit: String,
}

/// A link's or target's pose in the world frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WorldFrame {
    /// The link's or target's name.
    pub frame: String,
    /// Its pose in the world frame.
    pub pose: PoseRecord,
}

/// A target's pose in the instrument frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MeasuredTarget {
    /// The target's name.
    pub target: String,
    /// Its pose in the instrument frame.
    pub pose: PoseRecord,
}

/// What `armcal fk` shows (and prints with `--json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FramesRecord {
    /// The cell's name.
    pub cell: String,
    /// The configuration, display units.
    pub joints: Vec<JointValue>,
    /// The links, then the targets.
    pub frames_world: Vec<WorldFrame>,
    /// The targets as the instrument measures them.
    pub in_instrument_frame: Vec<MeasuredTarget>,
}

impl FramesRecord {
    /// The record as JSON (keys in alphabetical order, see `crate::json`).
    pub fn to_json(&self) -> Result<String, Error> {
        crate::json::sorted_pretty(self)
    }
}

/// The frames of `model` (of the cell `cell`) at `q` (internal units: rad, mm), nominal
/// parameters; `q` must be within the joint limits.
pub fn frames(cell: &str, model: &Model, q: &[f64]) -> Result<FramesRecord, Error> {
    model.check_joints(q)?;
    let params = model.nominal();
    let mut data = Data::new(model);
    forward_kinematics(model, &mut data, &params, q);
    let world = |name: &str, p: &Pose<f64>| WorldFrame {
        frame: name.to_string(),
        pose: PoseRecord::of(p),
    };
    Ok(FramesRecord {
        cell: cell.to_string(),
        joints: model
            .joints
            .iter()
            .zip(q)
            .map(|(j, v)| JointValue {
                name: j.name.clone(),
                value: v * j.kind.unit().display_factor(),
                unit: j.kind.unit().display_name().to_string(),
            })
            .collect(),
        frames_world: model
            .links
            .iter()
            .zip(&data.frames)
            .map(|(l, p)| world(&l.spec.name, p))
            .chain(
                model
                    .targets
                    .iter()
                    .zip(&data.targets)
                    .map(|(l, p)| world(&l.spec.name, p)),
            )
            .collect(),
        in_instrument_frame: (0..model.targets.len())
            .map(|k| MeasuredTarget {
                target: model.targets[k].spec.name.clone(),
                pose: PoseRecord::of(&observed_pose(&data, Observed::Target(k))),
            })
            .collect(),
    })
}
