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
    // Capsules (not published; chosen for a KUKA-like arm of this size and kept the same
    // for the whole study). Coordinates in the frame at the end of the named link.
    let capsules = vec![
        // pedestal and rotating column below the shoulder (frame 0 is at shoulder height)
        capsule("base", [0.0, 0.0, -1000.0], [0.0, 0.0, -350.0], 300.0),
        // shoulder: from the axis-1 line to the axis-2 origin (x1 points along a1)
        capsule("j1", [-350.0, 0.0, 0.0], [0.0, 0.0, 0.0], 220.0),
        // upper arm along x2, length λ
        capsule("j2", [-lambda, 0.0, 0.0], [0.0, 0.0, 0.0], 140.0),
        // elbow offset a3 = 145 along x3, then the forearm along −z3 to the wrist centre
        capsule("j3", [-145.0, 0.0, 0.0], [0.0, 0.0, -250.0], 130.0),
        capsule("j3", [0.0, 0.0, -250.0], [0.0, 0.0, -mu + 120.0], 100.0),
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
            name: format!("paper-{lambda}-{mu}"),
            instrument: None,
            links,
            targets: vec![],
        },
        capsules,
    }
}
