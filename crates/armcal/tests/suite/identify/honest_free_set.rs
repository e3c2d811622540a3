//! The free set is decided where the fit is, never at the nominal, and every rank below the
//! generic count names its cause (issue 10, items 1 and 2).

use armcal::model::random_configurations;
use armcal::model::Convention;
use armcal::{
    identify, perturbed_truth, robots, simulate, Cell, IdentifySettings, Perturbation, Silent,
};
use std::path::Path;

/// A 6R arm of our own as URDF (metres, radians): shoulder and elbow axes parallel (y),
/// wrist x–y–x, offsets everywhere, nothing like the built-in robots.
const ARM_URDF: &str = r#"<?xml version="1.0"?>
<robot name="own_arm">
  <link name="base_link"/><link name="l1"/><link name="l2"/><link name="l3"/>
  <link name="l4"/><link name="l5"/><link name="flange"/>
  <joint name="q1" type="revolute"><parent link="base_link"/><child link="l1"/>
    <origin xyz="0 0 0.35" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-2.9" upper="2.9" effort="1" velocity="1"/></joint>
  <joint name="q2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0.12 0.04 0.18" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-1.9" upper="1.6" effort="1" velocity="1"/></joint>
  <joint name="q3" type="revolute"><parent link="l2"/><child link="l3"/>
    <origin xyz="0.02 -0.03 0.52" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2.2" upper="1.2" effort="1" velocity="1"/></joint>
  <joint name="q4" type="revolute"><parent link="l3"/><child link="l4"/>
    <origin xyz="0.25 0 0.09" rpy="0 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-3.0" upper="3.0" effort="1" velocity="1"/></joint>
  <joint name="q5" type="revolute"><parent link="l4"/><child link="l5"/>
    <origin xyz="0.21 0 0" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2.0" upper="2.0" effort="1" velocity="1"/></joint>
  <joint name="q6" type="revolute"><parent link="l5"/><child link="flange"/>
    <origin xyz="0.08 0 0" rpy="0 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-3.0" upper="3.0" effort="1" velocity="1"/></joint>
</robot>
"#;

fn cell(robot: &str, marker: [f64; 3]) -> Cell {
    let text = format!(
        r#"name = "unknown-marker"
[robot]
{robot}
[instrument]
name = "tracker"
xyz_mm = [2600, 1800, 400]
rpy_deg = [5, -3, 40]
noise = {{ model = "constant", sigma_mm = 0.05 }}
[[targets]]
name = "smr1"
xyz_mm = [{}, {}, {}]
[parameters]
fixed = ["base", "tool"]
free = "auto"
measurement = "position"
"#,
        marker[0], marker[1], marker[2]
    );
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("honest-free-set");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("own_arm.urdf"), ARM_URDF).unwrap();
    Cell::from_toml(&text, "unknown-marker.toml", &dir).unwrap()
}

/// A marker of unknown offset written `[0, 0, 0]` (on the flange axis): identification
/// still frees all 27 parameters, and the held-out error is within 10 % of the fit that
/// knew the marker's true nominal offset.
#[test]
fn an_unknown_marker_at_zero_loses_no_parameter() {
    let true_marker = [-89.58, -2.84, 327.03];
    for robot in ["builtin = \"paper\"", "urdf = \"own_arm.urdf\""] {
        let known = cell(robot, true_marker);
        let unknown = cell(robot, [0.0; 3]);
        let model = &known.model;
        let truth = perturbed_truth(model, &Perturbation::default(), 7);
        let qs = random_configurations(model, 1000, 3);
        let noise = known.instrument.as_ref().unwrap().noise.clone();
        let data = simulate(model, &truth, &qs, Some(&noise), 5).unwrap();
        let opts = IdentifySettings {
            holdout: 0.3,
            ..Default::default()
        };
        let reference = identify(&known, &data, &opts, &mut Silent).unwrap();
        let est = identify(&unknown, &data, &opts, &mut Silent).unwrap();
        assert_eq!(reference.free.len(), 27, "{robot}: {:?}", reference.free);
        assert_eq!(est.free.len(), 27, "{robot}: {:?}", est.fixed_reasons);
        assert!(
            est.rank_deficit.is_none(),
            "{robot}: {:?}",
            est.rank_deficit
        );
        assert!(est.solver.status.is_converged(), "{robot}");
        let (a, b) = (
            est.validation.as_ref().unwrap().calibrated.rms,
            reference.validation.as_ref().unwrap().calibrated.rms,
        );
        assert!(
            a <= 1.1 * b,
            "{robot}: held-out RMS {a:.4} mm vs {b:.4} mm with the true marker"
        );
    }
}

fn with_target(robot: &str, measurement: &str) -> String {
    let rpy = if measurement == "pose" {
        "rpy_deg = [5, 10, 15]"
    } else {
        ""
    };
    format!(
        "[robot]\n{robot}\n[instrument]\nxyz_mm = [3000, 1000, 500]\n[[targets]]\nname = \"t\"\n\
         xyz_mm = [10, 20, 100]\n{rpy}\n[parameters]\nfree = \"auto\"\nmeasurement = \"{measurement}\"\n"
    )
}

fn load(text: &str) -> Cell {
    Cell::from_toml(text, "c.toml", Path::new(".")).unwrap()
}

/// Every built-in 6R robot with a tracker and one target identifies the generic count
/// under `auto` (27 for positions, 30 for poses); plain DH across parallel axes gives
/// fewer, and the report names the cause and the fix.
#[test]
fn every_builtin_6r_robot_is_complete_under_auto() {
    for name in robots::NAMES {
        let robot = robots::robot(name).unwrap();
        if robot
            .spec
            .links
            .iter()
            .filter(|l| l.joint.is_some())
            .count()
            != 6
        {
            continue;
        }
        for (m, expected) in [("position", 27), ("pose", 30)] {
            let cell = load(&with_target(&format!("builtin = \"{name}\""), m));
            let report = cell
                .identifiability(&cell.identifiability_settings())
                .unwrap();
            assert_eq!(
                report.identifiable.len(),
                expected,
                "{name} {m}: {:?}",
                report.excluded
            );
            let deficit = cell
                .rank_deficit(&report, &cell.model.nominal(), None)
                .unwrap();
            assert!(deficit.is_none(), "{name} {m}: {deficit:?}");
        }
    }
    // Plain DH across the UR10's parallel axes 2–3–4: two fewer, with the cause.
    let text = with_target("builtin = \"ur10\"\nconvention = \"dh\"", "position");
    let cell = load(&text);
    let report = cell
        .identifiability(&cell.identifiability_settings())
        .unwrap();
    assert!(
        report.identifiable.len() < 27,
        "{}",
        report.identifiable.len()
    );
    let d = cell
        .rank_deficit(&report, &cell.model.nominal(), None)
        .unwrap()
        .expect("a deficit");
    let text = d.to_string();
    assert!(
        text.contains("q2 and q3") && text.contains("plain dh") && text.contains("\"auto\""),
        "{text}"
    );
}

/// A target written on the flange axis is named as the cause by the cell-level analysis.
#[test]
fn a_target_on_the_last_axis_is_named() {
    let text =
        with_target("builtin = \"paper\"", "position").replace("[10, 20, 100]", "[0, 0, 50]");
    let cell = load(&text);
    let report = cell
        .identifiability(&cell.identifiability_settings())
        .unwrap();
    assert_eq!(report.identifiable.len(), 25);
    let d = cell
        .rank_deficit(&report, &cell.model.nominal(), None)
        .unwrap()
        .expect("a deficit")
        .to_string();
    assert!(d.contains("target `t` lies on the axis of q6"), "{d}");
}

const MDH_PARALLEL: &str = r#"
[[robot.links]]
name = "j1"
convention = "mdh"
joint = "revolute"
limits = [-170, 170]
alpha_deg = 0
a_mm = 0
theta_deg = 0
d_mm = 400
[[robot.links]]
name = "j2"
convention = "mdh"
joint = "revolute"
limits = [-120, 120]
alpha_deg = -90
a_mm = 150
theta_deg = -90
d_mm = 0
[[robot.links]]
name = "j3"
convention = "mdh"
joint = "revolute"
limits = [-150, 150]
alpha_deg = 0
a_mm = 600
theta_deg = 0
d_mm = 30
[[robot.links]]
name = "j4"
convention = "mdh"
joint = "revolute"
limits = [-180, 180]
alpha_deg = -90
a_mm = 120
theta_deg = 0
d_mm = 620
[[robot.links]]
name = "j5"
convention = "mdh"
joint = "revolute"
limits = [-120, 120]
alpha_deg = 90
a_mm = 0
theta_deg = 0
d_mm = 0
[[robot.links]]
name = "j6"
convention = "mdh"
joint = "revolute"
limits = [-180, 180]
alpha_deg = -90
a_mm = 0
theta_deg = 0
d_mm = 100
"#;

/// An inline modified-DH table with parallel axes 2–3 gives 27 under `auto` (link j3 gets
/// β), 26 as written, and accepts `beta_deg`.
#[test]
fn an_inline_mdh_table_with_parallel_axes_is_completed() {
    let cell_text = |robot: &str| with_target(robot, "position").replace("[robot]\n", "");
    let auto = load(&format!("[robot]\n{}", cell_text(MDH_PARALLEL)));
    let j3 = &auto.model.links[auto.model.link_index("j3").unwrap()];
    assert_eq!(j3.spec.geometry.convention, Convention::MdhBeta);
    let report = auto
        .identifiability(&auto.identifiability_settings())
        .unwrap();
    assert_eq!(report.identifiable.len(), 27, "{:?}", report.excluded);

    let given = load(&format!(
        "[robot]\nconvention = \"as-given\"\n{}",
        cell_text(MDH_PARALLEL)
    ));
    let report = given
        .identifiability(&given.identifiability_settings())
        .unwrap();
    assert_eq!(report.identifiable.len(), 26);
    let d = given
        .rank_deficit(&report, &given.model.nominal(), None)
        .unwrap()
        .expect("a deficit")
        .to_string();
    assert!(d.contains("q2 and q3") && d.contains("plain mdh"), "{d}");

    // β written by the user: the link is MDH with β, the forward kinematics move by it.
    let with_beta = MDH_PARALLEL.replacen("d_mm = 30", "d_mm = 30\nbeta_deg = 0.5", 1);
    let cell = load(&format!("[robot]\n{}", cell_text(&with_beta)));
    let j3 = cell.model.link_index("j3").unwrap();
    let beta = cell.model.registry.require("j3.beta").unwrap();
    assert_eq!(
        cell.model.links[j3].spec.geometry.convention,
        Convention::MdhBeta
    );
    assert!((cell.model.registry.get(beta).nominal - 0.5f64.to_radians()).abs() < 1e-15);

    // An unknown field lists the valid ones.
    let bad = MDH_PARALLEL.replacen("d_mm = 30", "d_mm = 30\ngamma_deg = 1", 1);
    let e = Cell::from_toml(
        &format!("[robot]\n{}", cell_text(&bad)),
        "c.toml",
        Path::new("."),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("unknown field `gamma_deg`") && e.contains("beta_deg|beta_rad"),
        "{e}"
    );
}

/// The complete form has the same forward kinematics as the robot as published, and its
/// capsules stay where they were in the world.
#[test]
fn the_complete_form_changes_no_pose_and_no_capsule() {
    use armcal::model::in_form;
    use armcal::model::{forward_kinematics, Data};
    use armcal::{LinkForm, Model};
    // A DH table of our own whose axes 2 and 3 are 3° apart with d2 = 35 mm (the case a
    // published, already calibrated DH table often is), followed by a frame6 tool.
    let mut own = robots::robot("irb120").unwrap();
    own.name = "own".into();
    let j2 = own.spec.links.iter().position(|l| l.name == "j2").unwrap();
    own.spec.links[j2].geometry.values[1] = 35.0;
    own.spec.links[j2].geometry.values[3] = 3f64.to_radians();
    let j6 = own.spec.links.iter().position(|l| l.name == "j6").unwrap();
    own.spec.links[j6].geometry.values[3] = 0.7f64.to_radians();
    own.spec.links[j6 + 1].geometry.values[2] = 40.0;
    let owned = [("own", own)];
    let builtin = ["ur10", "irb120", "motoman-right"].map(|n| (n, robots::robot(n).unwrap()));
    for (name, robot) in builtin.into_iter().chain(owned) {
        let given = Model::from_spec(&robot.spec).unwrap();
        let formed = in_form(&robot.spec, LinkForm::Auto).unwrap();
        assert!(!formed.changes.is_empty(), "{name}");
        let model = Model::from_spec(&formed.spec).unwrap();
        let moved = robots::transfer_capsules(&given, &model, &robot.capsules).unwrap();
        let (mut d0, mut d1) = (Data::new(&given), Data::new(&model));
        for q in random_configurations(&given, 20, 9) {
            forward_kinematics(&given, &mut d0, &given.nominal(), &q);
            forward_kinematics(&model, &mut d1, &model.nominal(), &q);
            let (a, b) = (d0.tool(), d1.tool());
            assert!((a.trans - b.trans).amax() < 1e-9 && (a.rot - b.rot).amax() < 1e-12);
            for (c0, c1) in robot.capsules.iter().zip(&moved) {
                let f0 = &d0.frames[given.link_index(&c0.frame).unwrap()];
                let f1 = &d1.frames[model.link_index(&c1.frame).unwrap()];
                for (p0, p1) in [(c0.a, c1.a), (c0.b, c1.b)] {
                    let w0 = f0.transform_point(&p0.into());
                    let w1 = f1.transform_point(&p1.into());
                    assert!((w0 - w1).amax() < 1e-9, "{name} capsule on {}", c0.frame);
                }
            }
        }
    }
}
