//! The robot library: every robot builds and is consistent (joint count, ordered limits,
//! finite kinematics, capsules on existing frames), and the robots with published reference
//! poses reproduce them.

use armcal::model::{forward_kinematics, tool_pose, Data};
use armcal::model::{rot_x, rot_y};
use armcal::robots::{self, NAMES};
use armcal::Model;
use nalgebra::Vector3;

/// Joint count each library robot must have.
fn expected_dof(name: &str) -> Option<usize> {
    match name {
        "paper" | "kr15" | "kr300" | "kr500" | "irb120" | "ur10" => Some(6),
        // torso E + 6 arm joints
        "motoman-right" | "motoman-left" => Some(7),
        _ => None,
    }
}

#[test]
fn every_library_robot_is_consistent() {
    assert_eq!(armcal::Cell::robots().len(), NAMES.len());
    for name in NAMES {
        let robot = robots::robot(name).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(robot.name, *name);
        assert!(
            !robot.summary.is_empty() && !robot.source.is_empty(),
            "{name}"
        );
        let model = Model::from_spec(&robot.spec).unwrap_or_else(|e| panic!("{name}: {e}"));
        if let Some(n) = expected_dof(name) {
            assert_eq!(model.dof(), n, "{name}: joint count");
        }
        assert_eq!(model.links.first().unwrap().spec.name, "base", "{name}");
        assert_eq!(model.links.last().unwrap().spec.name, "tool", "{name}");
        for j in &model.joints {
            assert!(j.lower < j.upper, "{name}: joint `{}` limits", j.name);
        }
        // Finite kinematics at q = 0 and at the middle of the ranges.
        let (lo, hi) = model.joint_limits();
        let mid: Vec<f64> = lo.iter().zip(&hi).map(|(a, b)| 0.5 * (a + b)).collect();
        for q in [vec![0.0; model.dof()], mid] {
            let mut data = Data::new(&model);
            forward_kinematics(&model, &mut data, &model.nominal(), &q);
            for (f, l) in data.frames.iter().zip(&model.links) {
                assert!(
                    f.trans.iter().chain(f.rot.iter()).all(|x| x.is_finite()),
                    "{name}: frame `{}` not finite at {q:?}",
                    l.spec.name
                );
            }
        }
        assert!(!robot.capsules.is_empty(), "{name}: no capsules");
        for c in &robot.capsules {
            assert!(
                model.link_index(&c.frame).is_some(),
                "{name}: capsule on unknown frame `{}`",
                c.frame
            );
            assert!(c.radius > 0.0, "{name}: capsule radius");
            assert!(
                c.a.iter().chain(&c.b).all(|x| x.is_finite()),
                "{name}: capsule end points"
            );
        }
    }
}

/// The KUKA robots share the paper robot's link structure and parameter names, so that they
/// plug into the same study.
#[test]
fn kuka_robots_have_the_paper_structure() {
    let paper = Model::from_spec(&robots::robot("paper").unwrap().spec).unwrap();
    for name in ["kr15", "kr300", "kr500"] {
        let model = Model::from_spec(&robots::robot(name).unwrap().spec).unwrap();
        let conventions =
            |m: &Model| -> Vec<_> { m.links.iter().map(|l| l.spec.geometry.convention).collect() };
        assert_eq!(conventions(&model), conventions(&paper), "{name}");
        let names =
            |m: &Model| -> Vec<String> { m.registry.iter().map(|p| p.name.clone()).collect() };
        assert_eq!(names(&model), names(&paper), "{name}");
    }
}

/// Reach to the wrist centre, a1 + a2 + √(d4² + a3²), measured on the chain against the
/// datasheets' maximum reach (KR 15/2: 1570 mm; KR 300 R2700-2: 2701 mm; KR 500 R2830:
/// 2826 mm). The distances are taken between frames, so any q works.
#[test]
fn kuka_reach_matches_datasheets() {
    for (name, reach) in [("kr15", 1570.0f64), ("kr300", 2701.0), ("kr500", 2826.0)] {
        let model = Model::from_spec(&robots::robot(name).unwrap().spec).unwrap();
        let mut data: Data<f64> = Data::new(&model);
        let q = vec![0.3; model.dof()];
        forward_kinematics(&model, &mut data, &model.nominal(), &q);
        let at = |link: &str| data.frames[model.link_index(link).unwrap()].trans;
        // frame j1 is on axis 2, j2 on axis 3, j4 at the wrist centre; axis 1 is the z0 line
        let a1 = Vector3::new(at("j1").x, at("j1").y, 0.0).norm();
        let chain = a1 + (at("j2") - at("j1")).norm() + (at("j4") - at("j2")).norm();
        assert!(
            (chain - reach).abs() < 2.0,
            "{name}: reach {chain:.1} mm vs datasheet {reach} mm"
        );
    }
}

/// Distance between the segments `p1 q1` and `p2 q2` (Ericson, *Real-Time Collision
/// Detection*, §5.1.9: closest points with both parameters clamped to [0, 1]).
fn segment_distance(p1: Vector3<f64>, q1: Vector3<f64>, p2: Vector3<f64>, q2: Vector3<f64>) -> f64 {
    let (d1, d2, r) = (q1 - p1, q2 - p2, p1 - p2);
    let (a, e, f) = (d1.dot(&d1), d2.dot(&d2), d2.dot(&r));
    let (s, t) = if a < 1e-12 && e < 1e-12 {
        (0.0, 0.0)
    } else if a < 1e-12 {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e < 1e-12 {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut s = if denom > 1e-12 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    ((p1 + d1 * s) - (p2 + d2 * t)).norm()
}

/// At poses a real robot takes without touching itself (KUKA HOME and the study's working
/// pose, the IRB 120 calibration pose, the UR10 upright home), capsules on chain frames at
/// least three links apart do not intersect, nor does the pedestal (on `base`) touch the
/// upper arm. Closer frames share a joint and may overlap.
#[test]
fn capsules_are_clear_at_home_poses() {
    let d = f64::to_radians;
    let kuka_home = vec![0.0, d(-90.0), d(90.0), 0.0, 0.0, 0.0];
    let work = vec![0.0, d(-30.0), d(30.0), 0.0, d(-90.0), 0.0];
    let cases = [
        ("kr15", vec![kuka_home.clone(), work.clone()]),
        ("kr300", vec![kuka_home.clone(), work.clone()]),
        ("kr500", vec![kuka_home, work]),
        ("irb120", vec![vec![0.0; 6]]),
        ("ur10", vec![vec![0.0, d(-90.0), 0.0, d(-90.0), 0.0, 0.0]]),
    ];
    for (name, poses) in cases {
        let robot = robots::robot(name).unwrap();
        let model = Model::from_spec(&robot.spec).unwrap();
        for q in poses {
            model.check_joints(&q).unwrap();
            let mut data: Data<f64> = Data::new(&model);
            forward_kinematics(&model, &mut data, &model.nominal(), &q);
            let world: Vec<(usize, Vector3<f64>, Vector3<f64>, f64)> = robot
                .capsules
                .iter()
                .map(|c| {
                    let i = model.link_index(&c.frame).unwrap();
                    let f = &data.frames[i];
                    let (a, b) = (Vector3::from(c.a), Vector3::from(c.b));
                    (i, f.transform_point(&a), f.transform_point(&b), c.radius)
                })
                .collect();
            for (k, x) in world.iter().enumerate() {
                for y in &world[k + 1..] {
                    // the pedestal (on `base`) must clear the upper arm as well
                    let apart = if x.0.min(y.0) == 0 { 2 } else { 3 };
                    if x.0.abs_diff(y.0) < apart {
                        continue;
                    }
                    let gap = segment_distance(x.1, x.2, y.1, y.2) - x.3 - y.3;
                    assert!(
                        gap > 0.0,
                        "{name} at {q:?}: capsules on `{}` and `{}` overlap by {:.1} mm",
                        model.links[x.0].spec.name,
                        model.links[y.0].spec.name,
                        -gap
                    );
                }
            }
        }
    }
}

fn assert_pose(name: &str, q: &[f64], trans: [f64; 3], rot: nalgebra::Matrix3<f64>) {
    let model = Model::from_spec(&robots::robot(name).unwrap().spec).unwrap();
    let pose = tool_pose(&model, &model.nominal(), q);
    assert!(
        (pose.trans - Vector3::from(trans)).norm() < 1e-9,
        "{name}: flange at {:?}, expected {trans:?}",
        pose.trans
    );
    assert!(
        (pose.rot - rot).norm() < 1e-12,
        "{name}: flange orientation {}, expected {rot}",
        pose.rot
    );
}

/// UR10 at q = 0 (arm stretched): with UR's DH the flange centre is at
/// (a2 + a3, −(d4 + d6), d1 − d5) = (−612 − 572.3, −163.941 − 92.2, 127.3 − 115.7)
/// = (−1184.3, −256.141, 11.6) mm, flange z along −y, x along +x: `Rx(90°)`.
/// (Universal Robots, "DH parameters for calculations of kinematics and dynamics", UR10.)
#[test]
fn ur10_zero_pose_matches_manufacturer_dh() {
    assert_pose(
        "ur10",
        &[0.0; 6],
        [-1184.3, -256.141, 11.6],
        rot_x(90f64.to_radians()),
    );
}

/// IRB 120 at its calibration position (all axes 0: upper arm vertical, forearm
/// horizontal): ABB's product specification gives the wrist centre 302 mm in front of axis 1
/// at 290 + 270 + 70 = 630 mm height, and the flange 72 mm further: (374, 0, 630) mm, with
/// `tool0` z forward and x down, `Ry(90°)`.
#[test]
fn irb120_calibration_pose_matches_product_specification() {
    assert_pose(
        "irb120",
        &[0.0; 6],
        [374.0, 0.0, 630.0],
        rot_y(90f64.to_radians()),
    );
    // Axis 2 at +90° lays the arm forward: upper arm along +x from (0, 0, 290), the forearm
    // pointing down; the flange is at (270 + 70, 0, 290 − 302 − 72) with z down (tool0 x
    // then points backward): Ry(180°).
    let q2 = [0.0, 90f64.to_radians(), 0.0, 0.0, 0.0, 0.0];
    assert_pose(
        "irb120",
        &q2,
        [340.0, 0.0, -84.0],
        rot_y(180f64.to_radians()),
    );
}
