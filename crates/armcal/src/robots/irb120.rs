//! ABB IRB 120 (3 kg, reach 580 mm) in standard DH form, joint variables equal to ABB's axis
//! angles (same zero, same signs: axes 2, 3, 5 turn about the horizontal axis so that positive
//! angles tilt forward/down, axes 1, 4, 6 turn right-handed about the upward/forward axis).
//!
//! | joint | θ | d | a | α |
//! |---|---|---|---|---|
//! | 1 | 0 | 290 | 0 | −90° |
//! | 2 | −90° | 0 | 270 | 0 |
//! | 3 | 0 | 0 | 70 | −90° |
//! | 4 | 0 | 302 | 0 | 90° |
//! | 5 | 0 | 0 | 0 | −90° |
//! | 6 | 180° | 72 | 0 | 0 |
//!
//! Base frame: the robot's foot (ABB base frame, z up, x forward). At q = 0 (ABB calibration
//! position: upper arm vertical, forearm horizontal) the flange centre is at
//! (302 + 72, 0, 290 + 270 + 70) = (374, 0, 630) mm with its z axis forward and x axis down,
//! ABB's `tool0` orientation (a quaternion (0.7071, 0, 0.7071, 0), i.e. `Ry(90°)`).

use super::{capsule, dh_capsules, frame_link, joint_link, Robot};
use crate::model::{LinkGeometry, ModelSpec};

/// ABB IRB 120-3/0.6.
pub fn irb120() -> Robot {
    let d = f64::to_radians;
    let links = vec![
        frame_link("base", [0.0; 3], [0.0; 3]),
        joint_link(
            1,
            LinkGeometry::dh(0.0, 290.0, 0.0, d(-90.0)),
            (-165.0, 165.0),
        ),
        joint_link(
            2,
            LinkGeometry::dh(d(-90.0), 0.0, 270.0, 0.0),
            (-110.0, 110.0),
        ),
        joint_link(
            3,
            LinkGeometry::dh(0.0, 0.0, 70.0, d(-90.0)),
            (-110.0, 70.0),
        ),
        joint_link(
            4,
            LinkGeometry::dh(0.0, 302.0, 0.0, d(90.0)),
            (-160.0, 160.0),
        ),
        joint_link(
            5,
            LinkGeometry::dh(0.0, 0.0, 0.0, d(-90.0)),
            (-120.0, 120.0),
        ),
        joint_link(
            6,
            LinkGeometry::dh(d(180.0), 72.0, 0.0, 0.0),
            (-400.0, 400.0),
        ),
        frame_link("tool", [0.0; 3], [0.0; 3]),
    ];
    let mut capsules = vec![capsule("base", [0.0; 3], [0.0, 0.0, 100.0], 90.0)];
    capsules.extend(dh_capsules("j1", 290.0, 0.0, d(-90.0), 80.0));
    capsules.extend(dh_capsules("j2", 0.0, 270.0, 0.0, 60.0));
    capsules.extend(dh_capsules("j3", 0.0, 70.0, d(-90.0), 60.0));
    capsules.extend(dh_capsules("j4", 302.0, 0.0, d(90.0), 50.0));
    capsules.extend(dh_capsules("j6", 72.0, 0.0, 0.0, 40.0));
    Robot {
        name: "irb120".into(),
        summary: "ABB IRB 120-3/0.6, 3 kg, reach 580 mm".into(),
        source: "ABB IRB 120 product specification (dimension and working-range figures): \
                 base to axis 2 290 mm, upper arm 270 mm, elbow offset 70 mm, axis 3 to the \
                 wrist centre 302 mm, wrist centre to flange 72 mm; axis ranges ±165°, ±110°, \
                 −110°/+70°, ±160°, ±120°, ±400° (the same numbers as the ROS-Industrial \
                 abb_irb120_support model). Joint zero and signs are ABB's. Capsule radii are \
                 armcal's choice from the outline drawing."
            .into(),
        spec: ModelSpec {
            compliance: None,
            periodic: None,
            payloads: Vec::new(),
            name: "irb120".into(),
            instrument: None,
            links,
            targets: vec![],
        },
        capsules,
        collision: super::HAND_MADE.into(),
    }
}
