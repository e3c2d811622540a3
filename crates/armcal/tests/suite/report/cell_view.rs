//! The report's 3D cell view (`armcal::report::cell_view`): the HTML fragment, its embedded
//! scene JSON checked against forward kinematics written out independently here (the paper
//! robot's DH table, `src/robots/paper.rs`), the constraint status of each pose against the
//! library's constraint set and parry's capsule distances, and bad input.

use armcal::design::constraint_set;
use armcal::model::random_configurations;
use armcal::report::cell_view::cell_view_section;
use armcal::Cell;
use nalgebra::{Matrix4, Vector3, Vector4};
use serde_json::Value;
use std::path::Path;

use armcal::cell::builtin::PAPER_CELL_OBSTACLES as CELL;

fn cell() -> Cell {
    Cell::from_toml(CELL, "paper-cell-obstacles.toml", Path::new(".")).expect("paper cell")
}

fn deg(q: [f64; 6]) -> Vec<f64> {
    q.map(f64::to_radians).to_vec()
}

/// The scene JSON of a fragment.
fn scene_json(html: &str) -> Value {
    let open = "<script type=\"application/json\" class=\"cell-view-data\">";
    let start = html.find(open).expect("scene JSON element") + open.len();
    let end = start
        + html[start..]
            .find("</script>")
            .expect("end of JSON element");
    serde_json::from_str(&html[start..end]).expect("scene JSON parses")
}

fn section_id(html: &str) -> String {
    let start = html
        .find("<section class=\"cell-view\" id=\"")
        .expect("section")
        + 31;
    let end = start + html[start..].find('"').unwrap();
    html[start..end].to_string()
}

fn point(v: &Value) -> Vector3<f64> {
    Vector3::new(
        v[0].as_f64().unwrap(),
        v[1].as_f64().unwrap(),
        v[2].as_f64().unwrap(),
    )
}

fn rz(t: f64) -> Matrix4<f64> {
    let (s, c) = t.sin_cos();
    Matrix4::new(
        c, -s, 0.0, 0.0, s, c, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
    )
}

fn rx(t: f64) -> Matrix4<f64> {
    let (s, c) = t.sin_cos();
    Matrix4::new(
        1.0, 0.0, 0.0, 0.0, 0.0, c, -s, 0.0, 0.0, s, c, 0.0, 0.0, 0.0, 0.0, 1.0,
    )
}

fn tr(x: f64, y: f64, z: f64) -> Matrix4<f64> {
    Matrix4::new_translation(&Vector3::new(x, y, z))
}

/// World transforms of frames j1…j6 of the paper robot (λ = 650, μ = 600; base and tool
/// frames are identities): DH `Rz(θ+q) Tz(d) Tx(a) Rx(α)`, joint 2 Hayati `Rz(q) Tx(λ)`.
fn paper_frames(q: &[f64]) -> Vec<Matrix4<f64>> {
    let r = f64::to_radians;
    let dh = |theta: f64, d: f64, a: f64, alpha: f64, qi: f64| {
        rz(theta + qi) * tr(0.0, 0.0, d) * tr(a, 0.0, 0.0) * rx(alpha)
    };
    let links = [
        dh(0.0, 0.0, 350.0, r(90.0), q[0]),
        rz(q[1]) * tr(650.0, 0.0, 0.0),
        dh(r(-90.0), 0.0, 145.0, r(90.0), q[2]),
        dh(0.0, -600.0, 0.0, r(-90.0), q[3]),
        dh(0.0, 0.0, 0.0, r(90.0), q[4]),
        dh(r(180.0), -170.0, 0.0, r(180.0), q[5]),
    ];
    let mut t = Matrix4::identity();
    links
        .iter()
        .map(|l| {
            t *= l;
            t
        })
        .collect()
}

fn apply(t: &Matrix4<f64>, p: [f64; 3]) -> Vector3<f64> {
    (t * Vector4::new(p[0], p[1], p[2], 1.0)).xyz()
}

#[test]
fn fragment_embeds_world_geometry_that_matches_forward_kinematics() {
    let cell = cell();
    let design = random_configurations(&cell.model, 12, 3);
    let html = cell_view_section(&cell, &[("random", &design)]).unwrap();
    assert!(html.starts_with("<section class=\"cell-view\""));
    for part in [
        "<h2>",
        "<canvas",
        "cell-view-slider",
        "cell-view-prev",
        "cell-view-next",
    ] {
        assert!(html.contains(part), "missing {part}");
    }
    // One design: no selector. One JSON element, one drawing script.
    assert!(!html.contains("<select"));
    assert_eq!(html.matches("<script").count(), 2);
    assert!(!html.contains("http://") && !html.contains("https://"));

    let s = scene_json(&html);
    let robot = s["robot"].as_array().unwrap();
    // Six robot capsules (paper.rs) and the reflector holder on the tool.
    assert_eq!(robot.len(), 7);
    assert_eq!(robot.len(), cell.capsules.len());
    assert_eq!(robot[6]["frame"], "tool");
    let poses = s["designs"][0]["poses"].as_array().unwrap();
    assert_eq!(poses.len(), design.len());
    // Tracker at the instrument origin of the cell (paper Table 3), rounded to 0.1 mm.
    let tracker = point(&s["tracker"]);
    assert!((tracker - Vector3::new(2730.88, 4554.68, 1397.67)).norm() < 0.1);

    let tol = 0.05 * 3f64.sqrt() + 1e-9;
    for (q, pose) in design.iter().zip(poses) {
        let frames = paper_frames(q);
        let caps = pose["caps"].as_array().unwrap();
        assert_eq!(caps.len(), 7);
        let end = |k: usize, b: bool| {
            let c = &caps[k];
            let o = if b { 3 } else { 0 };
            Vector3::new(
                c[o].as_f64().unwrap(),
                c[o + 1].as_f64().unwrap(),
                c[o + 2].as_f64().unwrap(),
            )
        };
        // Upper arm on j2 from (−λ, 0, 0): the axis-2 point, the end of link 1.
        let shoulder = apply(&frames[0], [0.0; 3]);
        assert!((end(2, false) - shoulder).norm() < tol);
        assert!((end(2, true) - apply(&frames[1], [0.0; 3])).norm() < tol);
        // Wrist on j5 to the flange (the end of link 6).
        assert!((end(5, true) - apply(&frames[5], [0.0; 3])).norm() < tol);
        // Reflector holder on the tool frame (= flange) to (−89.58, −2.84, 300).
        assert!((end(6, true) - apply(&frames[5], [-89.58, -2.84, 300.0])).norm() < tol);
        // The beam's end: the reflector smr1 in the flange frame (paper Table 3).
        let target = point(&pose["targets"][0]);
        assert!((target - apply(&frames[5], [-89.58, -2.84, 327.03])).norm() < tol);
        // Joints shown in degrees.
        for (j, v) in pose["q"].as_array().unwrap().iter().enumerate() {
            assert!((v.as_f64().unwrap() - q[j].to_degrees()).abs() <= 0.005 + 1e-9);
        }
    }

    // Wall and floor: quads on their boundary planes, inside the scene box.
    let (lo, hi) = (point(&s["bounds"][0]), point(&s["bounds"][1]));
    let planes = s["planes"].as_array().unwrap();
    assert_eq!(planes.len(), 2);
    for (plane, axis, offset) in [(&planes[0], 0, -450.0), (&planes[1], 2, -1700.0)] {
        let corners = plane["corners"].as_array().unwrap();
        assert_eq!(corners.len(), 4, "{}", plane["name"]);
        for c in corners {
            let c = point(c);
            assert!((c[axis] - offset).abs() < 1e-9);
            assert!((0..3).all(|k| c[k] >= lo[k] - 1e-9 && c[k] <= hi[k] + 1e-9));
        }
    }
    assert_eq!(s["ground"].as_f64(), Some(-1700.0));
    // The box holds every capsule at every pose.
    for pose in poses {
        for (c, r) in pose["caps"].as_array().unwrap().iter().zip(robot) {
            let r = r["r"].as_f64().unwrap();
            for k in 0..6 {
                let v = c[k].as_f64().unwrap();
                assert!(v - r >= lo[k % 3] && v + r <= hi[k % 3]);
            }
        }
    }
}

/// `ok` agrees with the library's feasibility test (joint limits and paper eq. 24b); capsules
/// marked as hitting an obstacle capsule do overlap it by parry's capsule distance.
#[test]
fn pose_status_follows_the_constraints() {
    use parry3d_f64::math::{Pose, Vector};
    use parry3d_f64::query;
    use parry3d_f64::shape::Capsule;
    let cell = cell();
    let mut design = random_configurations(&cell.model, 150, 11);
    // q_work is 3° outside the q5 range.
    design.push(deg([0.0, -30.0, 30.0, 0.0, -90.0, 0.0]));
    let html = cell_view_section(&cell, &[("random", &design)]).unwrap();
    let s = scene_json(&html);
    let poses = s["designs"][0]["poses"].as_array().unwrap();
    let set = constraint_set(&cell, true).unwrap();
    let mut ws = set.workspace();
    let params = cell.model.nominal();
    let v = |p: Vector3<f64>| Vector::new(p.x, p.y, p.z);
    let (mut feasible, mut obstacle_hits) = (0, 0);
    for (q, pose) in design.iter().zip(poses) {
        let ok = set.feasible(&mut ws, &params, q);
        assert_eq!(pose["ok"].as_bool(), Some(ok));
        assert_eq!(pose["violations"].as_array().unwrap().is_empty(), ok);
        feasible += usize::from(ok);
        for h in pose["hit"].as_array().unwrap() {
            let k = h.as_u64().unwrap() as usize;
            let c = &pose["caps"][k];
            let a = Vector3::new(
                c[0].as_f64().unwrap(),
                c[1].as_f64().unwrap(),
                c[2].as_f64().unwrap(),
            );
            let b = Vector3::new(
                c[3].as_f64().unwrap(),
                c[4].as_f64().unwrap(),
                c[5].as_f64().unwrap(),
            );
            let mine = Capsule::new(v(a), v(b), cell.capsules[k].radius);
            for o in pose["hit_obstacles"].as_array().unwrap() {
                let Some(ob) = s["obstacles"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .find(|x| x["name"] == *o)
                else {
                    continue;
                };
                let label = format!(
                    "{} / {}",
                    s["robot"][k]["label"].as_str().unwrap(),
                    o.as_str().unwrap()
                );
                let violated = pose["violations"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .any(|x| *x == label);
                if !violated {
                    continue;
                }
                let theirs = Capsule::new(
                    v(point(&ob["a"])),
                    v(point(&ob["b"])),
                    ob["r"].as_f64().unwrap(),
                );
                let id = Pose::identity();
                let d = query::distance(&id, &mine, &id, &theirs).unwrap().distance;
                assert!(d < 0.1, "{label}: parry distance {d}");
                obstacle_hits += 1;
            }
        }
    }
    let last = poses.last().unwrap();
    assert_eq!(last["ok"], false);
    assert!(last["violations"][0]
        .as_str()
        .unwrap()
        .starts_with("q5 = -90.00 outside"));
    assert!((last["incidence"].as_f64().unwrap()) >= 0.0);
    assert!(
        feasible > 0 && feasible < design.len(),
        "{feasible} feasible"
    );
    assert!(obstacle_hits > 0);
}

/// With a `[design]` clearance and joint margin, a pose the robot can take but that keeps
/// less than them is flagged `below_required` (issue 12 item 5): exactly the feasible poses
/// that the planner's own feasibility test at the clearance refuses.
#[test]
fn poses_closer_than_the_cell_asks_are_flagged() {
    let text = CELL
        .replace("clearance_mm = 0", "clearance_mm = 50")
        .replace("joint_margin_deg = 0", "joint_margin_deg = 5");
    let cell = Cell::from_toml(&text, "clearance.toml", Path::new(".")).expect("cell");
    let physical = Cell::from_toml(CELL, "no-clearance.toml", Path::new(".")).expect("cell");
    let design = random_configurations(&cell.model, 150, 5);
    let html = cell_view_section(&cell, &[("random", &design)]).unwrap();
    let s = scene_json(&html);
    let poses = s["designs"][0]["poses"].as_array().unwrap();
    let (with_clearance, without) = (
        constraint_set(&cell, true).unwrap(),
        constraint_set(&physical, true).unwrap(),
    );
    let (mut ws, params) = (with_clearance.workspace(), cell.model.nominal());
    let (mut short_distance, mut short_joint) = (0, 0);
    for (q, pose) in design.iter().zip(poses) {
        let below = pose["below_required"].as_array().unwrap();
        assert_eq!(
            pose["ok"].as_bool(),
            Some(without.feasible(&mut ws, &params, q))
        );
        let meets_cell = with_clearance.feasible(&mut ws, &params, q);
        assert_eq!(
            pose["ok"].as_bool().unwrap() && below.is_empty(),
            meets_cell,
            "pose {q:?}: {below:?}"
        );
        for b in below.iter().map(|b| b.as_str().unwrap()) {
            short_distance += usize::from(b.contains("(clearance_mm 50.0)"));
            short_joint += usize::from(b.contains("(joint_margin_deg 5.00)"));
        }
    }
    assert!(
        short_distance > 0 && short_joint > 0,
        "{short_distance} {short_joint}"
    );
    assert!(include_str!("../../../src/report/cell_view.js").contains("below_required"));
}

#[test]
fn sections_on_one_page_do_not_clash_and_repeat_exactly() {
    let cell = cell();
    let a = random_configurations(&cell.model, 5, 1);
    let b = random_configurations(&cell.model, 5, 2);
    let first = cell_view_section(&cell, &[("KPI", &a), ("heuristic", &b)]).unwrap();
    let second = cell_view_section(&cell, &[("heuristic", &b)]).unwrap();
    assert_ne!(section_id(&first), section_id(&second));
    // Every element id in the page is unique.
    let page = format!("{first}{second}");
    let ids: Vec<&str> = page
        .match_indices(" id=\"")
        .map(|(i, _)| {
            let rest = &page[i + 5..];
            &rest[..rest.find('"').unwrap()]
        })
        .collect();
    let mut unique = ids.clone();
    unique.sort_unstable();
    unique.dedup();
    assert_eq!(unique.len(), ids.len(), "{ids:?}");
    assert!(ids.len() >= 6);
    // Several designs: a selector with one option each.
    assert!(first.contains("<select") && first.matches("<option").count() == 2);
    // The same input gives the same bytes.
    assert_eq!(
        first,
        cell_view_section(&cell, &[("KPI", &a), ("heuristic", &b)]).unwrap()
    );
}

#[test]
fn names_cannot_break_out_of_the_page() {
    let cell = cell();
    let a = random_configurations(&cell.model, 2, 1);
    let html = cell_view_section(&cell, &[("a</script><b>", &a), ("\"x\"", &a)]).unwrap();
    // Only the two script elements close.
    assert_eq!(html.matches("</script>").count(), 2);
    assert!(html.contains("<option value=\"0\">a&lt;/script&gt;&lt;b&gt;</option>"));
    assert_eq!(scene_json(&html)["designs"][0]["name"], "a</script><b>");
}

#[test]
fn bad_input_is_an_error() {
    let cell = cell();
    let good = random_configurations(&cell.model, 3, 1);
    let mut short = good.clone();
    short[1].pop();
    let e = cell_view_section(&cell, &[("d", &short)])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("design `d`, pose 2") && e.contains("6 joints, got 5"),
        "{e}"
    );
    let mut nan = good.clone();
    nan[2][3] = f64::NAN;
    let e = cell_view_section(&cell, &[("d", &nan)])
        .unwrap_err()
        .to_string();
    assert!(e.contains("pose 3: joint 4 is not finite"), "{e}");
    assert!(cell_view_section(&cell, &[]).is_err());
    assert!(cell_view_section(&cell, &[("empty", &[])]).is_err());
}
