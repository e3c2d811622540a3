//! Vendor model files (issue 33, item 2): every writer's file, read back by armcal, gives
//! the same forward kinematics to 1e-9 mm over random configurations; what a format cannot
//! hold is listed with the TCP shift its omission causes, and that shift is what reading the
//! file back loses. The UR kinematics file of the built-in UR10 is Universal Robots' own
//! `default_kinematics.yaml`, and one written with known deltas, read as a cell's nominal
//! robot, reproduces the deltas' forward kinematics.

use armcal::cell::{export_against_nominal, NominalReference};
use armcal::model::tcp_shift::{NotHeld, SHIFT_CONFIGURATIONS, SHIFT_SEED};
use armcal::model::ur_kinematics::{from_ur_kinematics_str, to_ur_kinematics};
use armcal::model::urdf::conservative;
use armcal::model::urdf::from_urdf_str;
use armcal::model::urdf::joint_corrections::apply_joint_corrections;
use armcal::model::{random_configurations, tool_pose, LinkGeometry, ModelSpec};
use armcal::{perturbed_truth, Cell, ExportFormat, Model, Perturbation};
use std::f64::consts::PI;

/// `max_q` of the tool position (mm) and orientation differences (`‖R_a − R_b‖_F`, about the
/// angle in rad; the angle from `acos` is blind below ~1e-8) of two specs over 300 random
/// configurations of `a`.
fn fk_gap(a: &ModelSpec, b: &ModelSpec) -> (f64, f64) {
    let (ma, mb) = (Model::from_spec(a).unwrap(), Model::from_spec(b).unwrap());
    assert_eq!(ma.dof(), mb.dof());
    let (pa, pb) = (ma.nominal(), mb.nominal());
    random_configurations(&ma, 300, 5)
        .iter()
        .map(|q| {
            let (ta, tb) = (tool_pose(&ma, &pa, q), tool_pose(&mb, &pb, q));
            ((ta.trans - tb.trans).norm(), (ta.rot - tb.rot).norm())
        })
        .fold((0.0, 0.0), |(p, r), (x, y)| (p.max(x), r.max(y)))
}

/// A built-in robot's nominal spec and a calibrated one (every parameter perturbed, seeded).
fn nominal_and_calibrated(name: &str, seed: u64) -> (ModelSpec, ModelSpec) {
    let spec = armcal::robots::robot(name).unwrap().spec;
    let model = Model::from_spec(&spec).unwrap();
    let truth = perturbed_truth(&model, &Perturbation::default(), seed);
    (spec, model.spec_at(&truth))
}

/// `spec` with its tool frame at the identity.
fn without_tool(spec: &ModelSpec) -> ModelSpec {
    let mut s = spec.clone();
    let last = s.links.last_mut().unwrap();
    assert!(last.joint.is_none());
    last.geometry = LinkGeometry::frame6([0.0; 3], [0.0; 3]);
    s
}

fn sigma_of(_: &str) -> Option<f64> {
    Some(0.05)
}

fn export(calibrated: &ModelSpec, nominal: &ModelSpec, format: ExportFormat) -> String {
    let reference = NominalReference {
        nominal,
        sigma: &sigma_of,
        source: "a test",
    };
    export_against_nominal(calibrated, Some(&reference), None, format)
        .unwrap()
        .content
}

const ROBOTS: [&str; 6] = [
    "ur10",
    "puma560",
    "irb120",
    "kr15",
    "motoman-right",
    "paper",
];

#[test]
fn urdf_with_calibration_offsets_reloads_to_the_same_kinematics() {
    for name in ROBOTS {
        let (nominal, calibrated) = nominal_and_calibrated(name, 3);
        let text = export(&calibrated, &nominal, ExportFormat::UrdfCalibration(None));
        assert!(
            text.contains("<calibration rising="),
            "{name}: no joint offset written"
        );
        let back = from_urdf_str(&text, None).unwrap();
        let (p, r) = fk_gap(&calibrated, &back);
        assert!(p < 1e-9 && r < 1e-12, "{name}: {p} mm, {r} rad");
        // Read without the offsets (as robot_state_publisher does) it is another robot.
        let stripped = text
            .lines()
            .filter(|l| !l.contains("<calibration"))
            .collect::<Vec<_>>()
            .join("\n");
        let (p, _) = fk_gap(&calibrated, &from_urdf_str(&stripped, None).unwrap());
        assert!(p > 1e-3, "{name}: the offsets do nothing ({p} mm)");
    }
}

#[test]
fn conservative_urdf_keeps_what_is_beyond_k_sigma_and_lists_the_rest() {
    for name in ["ur10", "kr15"] {
        let (nominal, calibrated) = nominal_and_calibrated(name, 4);
        let k = 3.0;
        let (kept, dropped, total) = conservative(&calibrated, &nominal, &sigma_of, k).unwrap();
        assert!(
            !dropped.is_empty(),
            "{name}: σ = 0.05 drops some corrections"
        );
        assert!(dropped
            .iter()
            .all(|d| d.correction.abs() <= k * 0.05 && d.sigma == 0.05));
        // Every kept parameter is the calibrated value or beyond k σ; every dropped one nominal.
        let (mk, mc, mn) = (
            Model::from_spec(&kept).unwrap(),
            Model::from_spec(&calibrated).unwrap(),
            Model::from_spec(&nominal).unwrap(),
        );
        for (i, p) in mk.registry.iter().enumerate() {
            let (v, c, n) = (mk.nominal()[i], mc.nominal()[i], mn.nominal()[i]);
            if dropped.iter().any(|d| d.name == p.name) {
                assert_eq!(v, n, "{name}: {}", p.name);
            } else {
                assert_eq!(v, c, "{name}: {}", p.name);
            }
        }
        // The shift reported is the largest tool-position change over the stated sample.
        let shift = |a: &ModelSpec, b: &ModelSpec| {
            let (ma, mb) = (Model::from_spec(a).unwrap(), Model::from_spec(b).unwrap());
            random_configurations(&ma, SHIFT_CONFIGURATIONS, SHIFT_SEED)
                .iter()
                .map(|q| {
                    (tool_pose(&ma, &ma.nominal(), q).trans
                        - tool_pose(&mb, &mb.nominal(), q).trans)
                        .norm()
                })
                .fold(0.0, f64::max)
        };
        let gap = shift(&calibrated, &kept);
        assert!(
            total > 0.0 && (gap - total).abs() < 1e-12,
            "{name}: {gap} ≠ {total}"
        );
        let first = &dropped[0];
        let i = mc.registry.index_of(&first.name).unwrap();
        let mut one = mc.nominal();
        one[i] = mn.nominal()[i];
        let gap = shift(&calibrated, &mc.spec_at(&one));
        assert!(
            (gap - first.tcp_shift_mm).abs() < 1e-12,
            "{name}: {gap} vs {first:?}"
        );
        // The file holds the conservative model and lists what it dropped.
        let text = export(
            &calibrated,
            &nominal,
            ExportFormat::UrdfCalibration(Some(k)),
        );
        for d in &dropped {
            assert!(
                text.contains(&format!("dropped {}:", d.name)),
                "{name}: {}",
                d.name
            );
        }
        let (p, r) = fk_gap(&kept, &from_urdf_str(&text, None).unwrap());
        assert!(p < 1e-9 && r < 1e-12, "{name}: {p} mm, {r} rad");
        // k = 0 keeps every correction.
        let (all, none, shift) = conservative(&calibrated, &nominal, &sigma_of, 0.0).unwrap();
        assert!(none.is_empty() && shift == 0.0 && fk_gap(&calibrated, &all).0 == 0.0);
    }
}

#[test]
fn ros_joint_corrections_reload_to_the_same_kinematics() {
    for name in ROBOTS {
        let (nominal, calibrated) = nominal_and_calibrated(name, 5);
        let text = export(&calibrated, &nominal, ExportFormat::JointCorrections);
        assert!(
            text.contains("ros__parameters:") && text.contains("droll:"),
            "{text}"
        );
        let back = apply_joint_corrections(&text, &nominal).unwrap();
        let (p, r) = fk_gap(&calibrated, &back);
        assert!(p < 1e-9 && r < 1e-12, "{name}: {p} mm, {r} rad");
        // Applied to the nominal, no correction is the nominal robot.
        let zero = export(&nominal, &nominal, ExportFormat::JointCorrections);
        let (p, _) = fk_gap(&nominal, &apply_joint_corrections(&zero, &nominal).unwrap());
        assert!(p < 1e-9, "{name}: {p} mm");
    }
}

#[test]
fn ros_joint_corrections_errors_name_line_and_field() {
    let nominal = armcal::robots::robot("ur10").unwrap().spec;
    let text =
        "armcal_joint_corrections:\n  ros__parameters:\n    corrections:\n      q9:\n        \
                dx: 0\n        dy: 0\n        dz: 0\n        droll: 0\n        dpitch: 0\n        \
                dyaw: 0\n";
    let e = apply_joint_corrections(text, &nominal)
        .unwrap_err()
        .to_string();
    assert!(e.contains("line 4") && e.contains("corrections.q9"), "{e}");
    let e = apply_joint_corrections(&text.replace("droll: 0", "droll: .nan"), &nominal)
        .unwrap_err()
        .to_string();
    assert!(e.contains("line 8") && e.contains("droll"), "{e}");
    let e = apply_joint_corrections(&text.replace("        dyaw: 0\n", ""), &nominal)
        .unwrap_err()
        .to_string();
    assert!(e.contains("dyaw") && e.contains("line"), "{e}");
}

#[test]
fn the_builtin_ur10_is_universal_robots_default_kinematics_file() {
    let spec = armcal::robots::robot("ur10").unwrap().spec;
    let file = to_ur_kinematics(&spec, "the built-in UR10").unwrap();
    assert!(file.not_held.is_empty(), "{:?}", file.not_held);
    assert!(file
        .text
        .contains("NOT the controller's calibration checksum"));
    let value: serde_norway::Value = serde_norway::from_str(&file.text).unwrap();
    let k = &value["kinematics"];
    let v = |frame: &str, field: &str| k[frame][field].as_f64().unwrap();
    // Universal_Robots_ROS2_Description config/ur10/default_kinematics.yaml
    let expected = [
        ("shoulder", [0.0, 0.0, 0.1273, 0.0, 0.0, 0.0]),
        ("upper_arm", [0.0, 0.0, 0.0, PI / 2.0, 0.0, 0.0]),
        ("forearm", [-0.612, 0.0, 0.0, 0.0, 0.0, 0.0]),
        ("wrist_1", [-0.5723, 0.0, 0.163941, 0.0, 0.0, 0.0]),
        ("wrist_2", [0.0, -0.1157, 0.0, PI / 2.0, 0.0, 0.0]),
    ];
    for (frame, values) in expected {
        for (field, x) in ["x", "y", "z", "roll", "pitch", "yaw"].iter().zip(values) {
            assert!((v(frame, field) - x).abs() < 1e-12, "{frame}.{field}");
        }
    }
    // wrist_3: y = d6, and UR's (roll, pitch, yaw) = (π/2, π, π) is Rx(−π/2).
    let w3 = [v("wrist_3", "x"), v("wrist_3", "y"), v("wrist_3", "z")];
    assert!((w3[0]).abs() < 1e-12 && (w3[1] - 0.0922).abs() < 1e-12 && w3[2].abs() < 1e-12);
    let ur = armcal::model::Pose::from_xyz_rpy([0.0; 3], [PI / 2.0, PI, PI]);
    let ours = armcal::model::Pose::from_xyz_rpy(
        [0.0; 3],
        [
            v("wrist_3", "roll"),
            v("wrist_3", "pitch"),
            v("wrist_3", "yaw"),
        ],
    );
    assert!((ur.rot - ours.rot).norm() < 1e-9);
    let (p, r) = fk_gap(&spec, &from_ur_kinematics_str(&file.text).unwrap());
    assert!(p < 1e-9 && r < 1e-12, "{p} mm, {r} rad");
}

#[test]
fn ur_kinematics_reload_and_say_what_they_do_not_hold() {
    for name in ["ur10", "puma560", "irb120", "kr15"] {
        let (_, calibrated) = nominal_and_calibrated(name, 6);
        let file = to_ur_kinematics(&calibrated, "a test").unwrap();
        let back = from_ur_kinematics_str(&file.text).unwrap();
        let arm = without_tool(&calibrated);
        let flange = |n: &&NotHeld| n.what.contains("last joint axis");
        let tool = |n: &&NotHeld| n.what.contains("tool frame");
        let (p, r) = fk_gap(&arm, &back);
        match file.not_held.iter().find(flange) {
            // The rest of the flange beyond the last joint is lost: the shift reported is
            // the one reading back shows.
            Some(n) => assert!((p - n.tcp_shift_mm).abs() < 1e-9, "{name}: {p} vs {n:?}"),
            None => assert!(p < 1e-9 && r < 1e-12, "{name}: {p} mm, {r} rad"),
        }
        let t = file
            .not_held
            .iter()
            .find(tool)
            .expect("a perturbed tool frame is listed");
        let (pt, _) = fk_gap(&calibrated, &arm);
        assert!((pt - t.tcp_shift_mm).abs() < 1e-9 && pt > 0.0, "{name}");
        assert!(file.text.contains(&format!("# {}", t.sentence())));
    }
}

#[test]
fn ur10_kinematics_with_known_deltas_read_as_a_cell_robot_reproduce_them() {
    // Known deltas on the UR10's DH geometry (every link but the last's a and α, which a
    // UR file holds only through wrist_3's frame): mm and degrees.
    let spec = armcal::robots::robot("ur10").unwrap().spec;
    let mut delta = spec.clone();
    let deltas: [(usize, [f64; 4]); 6] = [
        (1, [0.02, 0.3, -0.2, 0.01]),
        (2, [-0.03, 0.1, 0.4, -0.02]),
        (3, [0.015, -0.25, 0.3, 0.03]),
        (4, [0.01, 0.2, -0.1, 0.015]),
        (5, [-0.02, -0.15, 0.12, -0.01]),
        (6, [0.05, 0.35, 0.0, 0.0]),
    ];
    for (i, [theta_deg, d, a, alpha_deg]) in deltas {
        let v = &mut delta.links[i].geometry.values;
        v[0] += theta_deg.to_radians();
        v[1] += d;
        v[2] += a;
        v[3] += alpha_deg.to_radians();
    }
    let file = to_ur_kinematics(&delta, "UR10 with known deltas").unwrap();
    assert!(file.not_held.is_empty(), "{:?}", file.not_held);
    let dir = std::env::temp_dir().join(format!("armcal-ur-deltas-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("calibration.yaml"), &file.text).unwrap();
    std::fs::write(
        dir.join("cell.toml"),
        "name = \"ur10-factory\"\n[robot]\nur_kinematics = \"calibration.yaml\"\n",
    )
    .unwrap();
    let cell = Cell::from_file(&dir.join("cell.toml")).unwrap();
    let (p, r) = fk_gap(&delta, &cell.model.spec());
    assert!(p < 1e-9 && r < 1e-12, "{p} mm, {r} rad");
    // The nominal UR10 is not that robot: the deltas move the flange by millimetres.
    assert!(fk_gap(&spec, &cell.model.spec()).0 > 0.5);
    // A bad value names the file, the line and the field.
    let bad = file.text.replacen("roll: ", "roll: .inf #", 2);
    std::fs::write(dir.join("calibration.yaml"), &bad).unwrap();
    let e = Cell::from_file(&dir.join("cell.toml"))
        .unwrap_err()
        .to_string();
    let line = bad
        .lines()
        .position(|l| l.contains(".inf"))
        .map(|i| i + 1)
        .unwrap();
    assert!(
        e.contains("calibration.yaml") && e.contains(&format!("line {line}")) && e.contains("roll"),
        "{e}"
    );
    std::fs::write(
        dir.join("calibration.yaml"),
        file.text.replace("  pitch:", "  pich:"),
    )
    .unwrap();
    let e = Cell::from_file(&dir.join("cell.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("pich") && e.contains("line"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}
