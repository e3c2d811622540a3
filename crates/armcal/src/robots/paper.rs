//! The paper's notional 6R manipulator family (paper Table 2, Table 4; reading in
//! `docs/paper-setup.md`): DH links with joint 2 in Hayati form, segment lengths λ (upper
//! arm) and μ (forearm).

use super::{capsule, frame_link, joint_link, Robot};
use crate::model::{LinkGeometry, ModelSpec};

/// The notional robot with upper arm λ and forearm μ (mm). The paper's study uses
/// λ ∈ {650, …, 1100}, μ ∈ {600, …, 1000}.
///
/// Table 2 prints d4 = μ; armcal uses d4 = −μ (KUKA sign): with +μ the forearm folds back
/// over the upper arm at q = 0 and the flange ends up inside it.
pub fn notional(lambda: f64, mu: f64) -> Robot {
    let d = f64::to_radians;
    let links = vec![
        frame_link("base", [0.0; 3], [0.0; 3]),
        joint_link(1, LinkGeometry::dh(0.0, 0.0, 350.0, d(90.0)), (-82.0, 82.0)),
        joint_link(
            2,
            LinkGeometry::hayati(0.0, lambda, 0.0, 0.0),
            (-77.0, 31.0),
        ),
        joint_link(
            3,
            LinkGeometry::dh(d(-90.0), 0.0, 145.0, d(90.0)),
            (-13.0, 154.0),
        ),
        joint_link(
            4,
            LinkGeometry::dh(0.0, -mu, 0.0, d(-90.0)),
            (-347.0, 347.0),
        ),
        joint_link(5, LinkGeometry::dh(0.0, 0.0, 0.0, d(90.0)), (-87.0, 87.0)),
        joint_link(
            6,
            LinkGeometry::dh(d(180.0), -170.0, 0.0, d(180.0)),
            (-347.0, 347.0),
        ),
        frame_link("tool", [0.0; 3], [0.0; 3]),
    ];
    // Capsules (not published; armcal's choice for a KUKA-like arm of this size, kept the same
    // for the whole study). Coordinates in the frame at the end of the named link, mm.
    //
    // Orientation: frame 0 is at shoulder height, x forward, and its z axis points from the
    // shoulder towards the robot's mounting flange, as in the KUKA models (`kuka.rs`). The
    // joint variables are KUKA axis angles: the Table 4 ranges are subsets of KUKA's datasheet
    // ranges with KUKA's signs (q2 ≤ 31° against A2 ≤ 35°, q3 ≤ 154° = A3 max), and with this
    // DH a positive q2 turns the upper arm towards +z0. KUKA's A2 = −90° (HOME
    // (0, −90°, 90°, 0, 0, 0): upper arm straight out of the base, forearm at right angles)
    // then points the upper arm along −z0, away from the mount, and the mount is on the +z0
    // side: the base column below runs from the shoulder towards +z0. At the lower limit
    // q2 = −77° the upper arm leans 13° forward of −z0 and at q2 = 31° it points 31° from the
    // x axis towards the mount: a KUKA's usual working range. Which way is up in the world is
    // the cell's business: the paper cell (`examples/paper-cell-obstacles.toml`) hangs the
    // robot, z0 up, from the object it is mounted on.
    let capsules = vec![
        // Base and rotating column: from z0 = +300, where the cap clears the upper-arm capsule
        // at the axis-2 point (350, 0, 0) by √(350² + 300²) − 300 − 140 = 21 mm for every q1
        // (KUKA models: 20 mm), to the mounting flange at z0 = +700 (base height of a KR 15
        // class arm, 675 mm for the KR 15/2; the paper does not publish one).
        capsule("base", [0.0, 0.0, 700.0], [0.0, 0.0, 300.0], 300.0),
        // shoulder: from the axis-1 line to the axis-2 origin (x1 points along a1)
        capsule("j1", [-350.0, 0.0, 0.0], [0.0, 0.0, 0.0], 220.0),
        // upper arm along x2, length λ
        capsule("j2", [-lambda, 0.0, 0.0], [0.0, 0.0, 0.0], 140.0),
        // elbow: from the axis-3 point (a3 = 145 back along x3) to 250 mm down the forearm
        // axis (−z3)
        capsule("j3", [-145.0, 0.0, 0.0], [0.0, 0.0, -250.0], 130.0),
        // forearm, 250 mm down the axis to the wrist centre. It is symmetric about the axis-4
        // line, so it sits on frame j4 (the A4 housing): frame-3 point (0, 0, z) is
        // (0, −(z + μ), 0) in frame 4 (link 4 is Rz(q4) Tz(−μ) Rx(−90°)). On j4 it is the wrist's
        // neighbouring body and is not compared with the wrist capsule (on j3 it would touch
        // the wrist capsule at every q5).
        capsule("j4", [0.0, -(mu - 250.0), 0.0], [0.0, 0.0, 0.0], 100.0),
        // wrist: from the wrist centre along −z5 to the flange (d6 = −170)
        capsule("j5", [0.0, 0.0, 0.0], [0.0, 0.0, -170.0], 75.0),
    ];
    Robot {
        name: if lambda == 650.0 && mu == 600.0 {
            "paper".into()
        } else {
            format!("paper-{lambda}-{mu}")
        },
        summary: format!("notional 6R of Jost et al. 2017, λ = {lambda} mm, μ = {mu} mm"),
        source: "Jost, Kudruss, Körkel, Walter (2017) Table 2 (DH, joint 2 Hayati), joint \
                 ranges Table 4; d4 = −μ (KUKA sign, the paper prints μ). Capsules are \
                 armcal's choice: the paper does not publish its collision geometry."
            .into(),
        spec: ModelSpec {
            compliance: None,
            periodic: None,
            payloads: Vec::new(),
            name: format!("paper-{lambda}-{mu}"),
            instrument: None,
            links,
            targets: vec![],
        },
        capsules,
        collision: super::HAND_MADE.into(),
    }
}
