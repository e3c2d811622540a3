//! Universal Robots UR10 (CB3) with the manufacturer's standard DH parameters
//! `Rz(q) Tz(d) Tx(a) Rx(α)`:
//!
//! | joint | d (mm) | a (mm) | α |
//! |---|---|---|---|
//! | 1 | 127.3 | 0 | 90° |
//! | 2 | 0 | −612 | 0 |
//! | 3 | 0 | −572.3 | 0 |
//! | 4 | 163.941 | 0 | 90° |
//! | 5 | 115.7 | 0 | −90° |
//! | 6 | 92.2 | 0 | 0 |
//!
//! (Universal Robots, "DH parameters for calculations of kinematics and dynamics"). Joint zero
//! and signs are the controller's. At q = 0 the arm lies stretched along −x and the flange
//! centre is at (a2 + a3, −(d4 + d6), d1 − d5) = (−1184.3, −256.141, 11.6) mm in the base
//! frame, with the flange z axis along −y (`Rx(90°)`).

use super::{capsule, dh_capsules, frame_link, joint_link, Robot};
use crate::model::{LinkGeometry, ModelSpec};

/// Lateral offsets of the upper arm and the forearm tubes from the DH plane along the
/// parallel axes 2–4 (mm), from Universal Robots' ROS description (`shoulder_offset`,
/// `shoulder_offset + elbow_offset`); the DH chain folds them into d4.
const UPPER_ARM_OFFSET: f64 = 220.941;
const FOREARM_OFFSET: f64 = 220.941 - 171.9;

/// Universal Robots UR10 (CB3).
pub fn ur10() -> Robot {
    let d = f64::to_radians;
    let lim = (-360.0, 360.0);
    let links = vec![
        frame_link("base", [0.0; 3], [0.0; 3]),
        joint_link(1, LinkGeometry::dh(0.0, 127.3, 0.0, d(90.0)), lim),
        joint_link(2, LinkGeometry::dh(0.0, 0.0, -612.0, 0.0), lim),
        joint_link(3, LinkGeometry::dh(0.0, 0.0, -572.3, 0.0), lim),
        joint_link(4, LinkGeometry::dh(0.0, 163.941, 0.0, d(90.0)), lim),
        joint_link(5, LinkGeometry::dh(0.0, 115.7, 0.0, d(-90.0)), lim),
        joint_link(6, LinkGeometry::dh(0.0, 92.2, 0.0, 0.0), lim),
        frame_link("tool", [0.0; 3], [0.0; 3]),
    ];
    let (s, f) = (UPPER_ARM_OFFSET, FOREARM_OFFSET);
    let mut capsules = dh_capsules("j1", 127.3, 0.0, d(90.0), 95.0);
    capsules.extend([
        // shoulder housing along axis 2 out to the upper-arm tube
        capsule("j1", [0.0; 3], [0.0, 0.0, s], 90.0),
        // upper arm from the shoulder (a2 = −612 back along x2) to the elbow
        capsule("j2", [612.0, 0.0, s], [0.0, 0.0, s], 75.0),
        // elbow housing along axis 3, then the forearm to wrist 1
        capsule("j2", [0.0, 0.0, s], [0.0, 0.0, f], 75.0),
        capsule("j3", [572.3, 0.0, f], [0.0, 0.0, f], 60.0),
        // wrist 1 housing along axis 4 to the wrist plane (d4)
        capsule("j3", [0.0, 0.0, f], [0.0, 0.0, 163.941], 60.0),
    ]);
    capsules.extend(dh_capsules("j5", 115.7, 0.0, d(-90.0), 60.0));
    capsules.extend(dh_capsules("j6", 92.2, 0.0, 0.0, 50.0));
    Robot {
        name: "ur10".into(),
        summary: "Universal Robots UR10 (CB3), 10 kg, reach 1300 mm".into(),
        source: "Universal Robots' published DH parameters for the UR10: d1 = 127.3, \
                 a2 = −612, a3 = −572.3, d4 = 163.941, d5 = 115.7, d6 = 92.2 mm, \
                 α = (90°, 0, 0, 90°, −90°, 0); joint ranges ±360° (UR10 datasheet). Capsule \
                 radii are armcal's choice from the outline drawing; the lateral tube offsets \
                 (220.941 and 49.041 mm) are from UR's ROS description."
            .into(),
        spec: ModelSpec {
            compliance: None,
            periodic: None,
            payloads: Vec::new(),
            name: "ur10".into(),
            instrument: None,
            links,
            targets: vec![],
        },
        capsules,
        collision: super::HAND_MADE.into(),
    }
}
