//! The cell's `[design]` clearance and joint margin hold in a planned design, checked
//! independently of the planner's constraint code: the capsules are placed from the forward
//! kinematics and their distances measured by parry3d (capsule–capsule, GJK) and by a plain
//! projection for the half-spaces (issue 12, item 5).

use crate::common::example_cell;
use armcal::cell::Obstacle;
use armcal::design::kind_margins;
use armcal::model::{forward_kinematics, Data};
use armcal::{plan, Cell, PlanSettings, Silent};
use nalgebra::Vector3;
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::query;
use parry3d_f64::shape::Capsule;
use std::path::Path;

/// The radius of the laser beam as a capsule (mm; `ConstraintSettings::default`).
const BEAM_RADIUS: f64 = 5.0;

fn obstacle_cell_with(clearance: &str, margin: &str) -> Cell {
    let text = armcal::cell::builtin::PAPER_CELL_OBSTACLES
        .replace(
            "clearance_mm = 0\n",
            &format!("clearance_mm = {clearance}\n"),
        )
        .replace(
            "joint_margin_deg = 0\n",
            &format!("joint_margin_deg = {margin}\n"),
        )
        // The beam keeps the same distance (`line_of_sight_margin_mm`, its own field).
        .replace(
            "line_of_sight_margin_mm = 0\n",
            &format!("line_of_sight_margin_mm = {clearance}\n"),
        );
    assert_ne!(text, armcal::cell::builtin::PAPER_CELL_OBSTACLES);
    Cell::from_toml(&text, "obstacles-10mm.toml", Path::new(".")).unwrap()
}

fn capsule(a: &Vector3<f64>, b: &Vector3<f64>, r: f64) -> Capsule {
    Capsule::new(Vector::new(a.x, a.y, a.z), Vector::new(b.x, b.y, b.z), r)
}

fn distance(c1: &Capsule, c2: &Capsule) -> f64 {
    let id = Pose::identity();
    query::distance(&id, c1, &id, c2).unwrap().distance
}

/// The smallest distance of each kind at one pose: robot–robot (non-neighbouring capsule
/// bodies), robot–obstacle, robot–half-space, beam–everything; and the smallest distance of
/// a joint from its limits (deg).
fn margins_at(cell: &Cell, data: &mut Data<f64>, q: &[f64]) -> [f64; 5] {
    let model = &cell.model;
    forward_kinematics(model, data, &model.nominal(), q);
    let first_joint = model.links.iter().position(|l| l.joint.is_some()).unwrap();
    // Capsule-carrying frames in chain order, and each capsule placed in the world.
    let mut frames: Vec<usize> = cell
        .capsules
        .iter()
        .map(|c| model.link_index(&c.frame).unwrap())
        .collect();
    frames.sort_unstable();
    frames.dedup();
    let placed: Vec<(usize, bool, Capsule)> = cell
        .capsules
        .iter()
        .map(|c| {
            let link = model.link_index(&c.frame).unwrap();
            let f = &data.frames[link];
            let a = f.transform_point(&Vector3::from(c.a));
            let b = f.transform_point(&Vector3::from(c.b));
            let rank = frames.binary_search(&link).unwrap();
            (rank, link >= first_joint, capsule(&a, &b, c.radius))
        })
        .collect();
    let mut m = [f64::INFINITY; 5];
    for (i, (ri, _, ci)) in placed.iter().enumerate() {
        for (rj, _, cj) in &placed[i + 1..] {
            if ri.abs_diff(*rj) >= 2 {
                m[0] = m[0].min(distance(ci, cj));
            }
        }
    }
    let reflector = data.targets[0].trans;
    let beam = capsule(&reflector, &data.instrument.trans, BEAM_RADIUS);
    for (k, (_, moves, c)) in placed.iter().enumerate() {
        // The reflector holder (the last capsule, on `tool`) carries the reflector.
        if cell.capsules[k].frame != "tool" {
            m[3] = m[3].min(distance(&beam, c));
        }
        if !moves {
            continue;
        }
        for o in &cell.obstacles {
            match o {
                Obstacle::Capsule { a, b, radius, .. } => {
                    let oc = capsule(&Vector3::from(*a), &Vector3::from(*b), *radius);
                    m[1] = m[1].min(distance(c, &oc));
                }
                Obstacle::Box { .. } => panic!("the paper cells of this test have no boxes"),
                Obstacle::HalfSpace { normal, offset, .. } => {
                    let n = Vector3::from(*normal).normalize();
                    for end in [c.segment.a, c.segment.b] {
                        let x = Vector3::new(end.x, end.y, end.z);
                        m[2] = m[2].min(n.dot(&x) - c.radius - offset);
                    }
                }
            }
        }
    }
    for o in &cell.obstacles {
        if let Obstacle::Capsule { a, b, radius, .. } = o {
            let oc = capsule(&Vector3::from(*a), &Vector3::from(*b), *radius);
            m[3] = m[3].min(distance(&beam, &oc));
        }
    }
    for (j, joint) in model.joints.iter().enumerate() {
        m[4] = m[4].min((q[j] - joint.lower).min(joint.upper - q[j]).to_degrees());
    }
    m
}

#[test]
fn a_planned_design_keeps_the_cells_clearance_and_joint_margin() {
    let cell = obstacle_cell_with("10", "1");
    assert_eq!(cell.design.clearance, 10.0);
    // 60 poses: with 30 the design happens to stay 17 mm off the upper arm / forearm pair,
    // whose distance is flat over most of the joint space (the clearance exemption of a
    // constant distance must not take it for one).
    let settings = PlanSettings {
        starts: 1,
        ..PlanSettings::default()
    };
    let r = plan(&cell, &settings, &[], &mut Silent).unwrap();
    assert!(r.feasible, "{:?}", r.refine_status);
    let mut data = Data::new(&cell.model);
    let mut least = [f64::INFINITY; 5];
    for q in &r.design {
        for (l, v) in least.iter_mut().zip(margins_at(&cell, &mut data, q)) {
            *l = l.min(v);
        }
    }
    eprintln!(
        "least over the design: self {:.3} mm, obstacle {:.3} mm, half-space {:.3} mm, beam {:.3} mm, joints {:.4}°",
        least[0], least[1], least[2], least[3], least[4]
    );
    // parry's GJK distance is accurate to ≈ 1e-7 relative.
    for (what, v) in ["self", "obstacle", "half-space", "beam"]
        .iter()
        .zip(&least)
    {
        assert!(*v >= 10.0 - 1e-6 * (1.0 + v), "{what}: {v} mm < 10 mm");
    }
    assert!(least[4] >= 1.0 - 1e-9, "joints: {}° < 1°", least[4]);

    // The record reports the same margins against the requirement, and says they are met.
    let margins = kind_margins(&cell, &r.design, true).unwrap();
    for m in &margins {
        assert!(m.meets, "{m:?}");
        let expected = match m.kind.as_str() {
            "self-collision" => least[0],
            "obstacle" => least[1],
            "half-space" => least[2],
            "line of sight" => least[3],
            "joint limits" => least[4],
            _ => continue,
        };
        assert!((m.value - expected).abs() < 1e-5, "{m:?} vs {expected}");
        let required = if m.kind == "joint limits" { 1.0 } else { 10.0 };
        assert!((m.required - required).abs() < 1e-12, "{m:?}");
    }
}

#[test]
fn the_paper_cells_design_touches_what_a_clearance_keeps_off() {
    // The same plan without clearance (the paper's constraints) rests on a constraint: the
    // clearance above is what moved the poses, not a lucky design.
    let cell = example_cell("paper-cell-obstacles.toml");
    let settings = PlanSettings {
        poses: 30,
        starts: 1,
        ..PlanSettings::default()
    };
    let r = plan(&cell, &settings, &[], &mut Silent).unwrap();
    let mut data = Data::new(&cell.model);
    let least = r
        .design
        .iter()
        .flat_map(|q| margins_at(&cell, &mut data, q)[..4].to_vec())
        .fold(f64::INFINITY, f64::min);
    assert!(least < 10.0, "least distance {least} mm");
    let margins = kind_margins(&cell, &r.design, true).unwrap();
    assert!(margins.iter().all(|m| m.required == 0.0 && m.meets));
}

#[test]
fn design_section_errors_name_file_and_field() {
    let base = example_cell("paper-cell-obstacles.toml");
    assert_eq!(base.design.clearance, 0.0);
    for (from, to, says) in [
        (
            "clearance_mm = 0\n",
            "clearance_mm = -1\n",
            "design.clearance_mm",
        ),
        (
            "clearance_mm = 0\n",
            "clearance_mm = 5000\n",
            "design.clearance_mm",
        ),
        ("clearance_mm = 0\n", "clearance_mm = nan\n", "finite"),
        (
            "clearance_mm = 0\n",
            "clearence_mm = 5\n",
            "unknown field `clearence_mm`",
        ),
        (
            "joint_margin_deg = 0\n",
            "joint_margin_deg = 100\n",
            "design.joint_margin_deg",
        ),
        (
            "joint_margin_deg = 0\n",
            "joint_margin_deg = 0\njoint_margin_rad = 0\n",
            "twice",
        ),
        // An incidence margin must leave an angle below the instrument's 30° limit.
        (
            "incidence_margin_deg = 0\n",
            "incidence_margin_deg = 30\n",
            "design.incidence_margin_deg",
        ),
        (
            "incidence_margin_deg = 0\n",
            "incidence_margin_deg = -1\n",
            "design.incidence_margin_deg",
        ),
        (
            "line_of_sight_margin_mm = 0\n",
            "line_of_sight_margin_mm = 501\n",
            "design.line_of_sight_margin_mm",
        ),
    ] {
        let text = armcal::cell::builtin::PAPER_CELL_OBSTACLES.replace(from, to);
        let e = Cell::from_toml(&text, "c.toml", Path::new("."))
            .unwrap_err()
            .to_string();
        assert!(e.contains("c.toml") && e.contains(says), "{to}: {e}");
    }
    // Without a `[design]` section: the defaults.
    let mut text = armcal::cell::builtin::PAPER_CELL_OBSTACLES.to_string();
    let start = text.find("[design]").unwrap();
    let end = start + text[start..].find("[[working]]").unwrap();
    text.replace_range(start..end, "");
    let c = Cell::from_toml(&text, "c.toml", Path::new(".")).unwrap();
    assert_eq!(c.design, armcal::cell::DesignClearance::default());
}

#[test]
fn only_a_distance_no_pose_changes_is_exempt_from_the_clearance() {
    // The wall moved to 5 mm behind the shoulder capsule's end on the axis of joint 1
    // (x − r = 0 − 220 mm ≥ −225 mm): that distance is 5 mm at every pose, below any
    // clearance over 5 mm a design could keep.
    let text = armcal::cell::builtin::PAPER_CELL_OBSTACLES
        .replace("offset_mm = -450", "offset_mm = -225")
        .replace("clearance_mm = 0\n", "clearance_mm = 10\n")
        .replace(
            "line_of_sight_margin_mm = 0\n",
            "line_of_sight_margin_mm = 10\n",
        );
    let cell = Cell::from_toml(&text, "wall-5mm.toml", Path::new(".")).unwrap();
    let set = armcal::design::constraint_set(&cell, true).unwrap();
    let params = cell.model.nominal();
    let mut ws = set.workspace();
    let qs = armcal::model::random_configurations(&cell.model, 200, 5);
    let mut values = vec![vec![0.0; set.len()]; qs.len()];
    for (q, v) in qs.iter().zip(values.iter_mut()) {
        set.evaluate(&mut ws, &params, q, v, None);
    }
    let mut exempt = 0;
    for i in 0..set.len() {
        if set.kind(i) == armcal::design::ConstraintKind::Incidence {
            assert_eq!(set.required(i), 0.0);
            continue;
        }
        let (lo, hi) = values
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v[i]), b.max(v[i]))
            });
        if set.required(i) == 0.0 {
            exempt += 1;
            assert!(hi - lo < 1e-9 && hi < 10.0, "{}: {lo} … {hi}", set.name(i));
        } else {
            assert_eq!(set.required(i), 10.0, "{}", set.name(i));
        }
    }
    assert!(
        exempt > 0,
        "the shoulder capsule's end stays 5 mm off the wall"
    );
}
