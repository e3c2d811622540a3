//! Import, export and round trips of URDF chains.

use super::*;
use crate::model::chain::{LinkSpec, Model, ModelSpec};
use crate::model::kinematics::tool_pose;
use crate::model::link::{Convention, Joint, JointKind, LinkGeometry};
use crate::model::pose::{rot_axis, Pose};
use crate::robots;
use crate::Error;
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// ABB IRB 120 as a URDF (joint origins and limits as in the ROS-Industrial
/// abb_irb120_support model: axes at 0.29, +0.27, +0.07 m up, wrist 0.302 m and flange
/// 0.072 m forward), ending in ABB's `tool0` (`Ry(90°)`).
const IRB120: &str = r#"<?xml version="1.0"?>
<robot name="irb120">
  <link name="base_link"/> <link name="link_1"/> <link name="link_2"/> <link name="link_3"/>
  <link name="link_4"/> <link name="link_5"/> <link name="link_6"/> <link name="tool0"/>
  <joint name="joint_1" type="revolute">
<origin xyz="0 0 0" rpy="0 0 0"/> <parent link="base_link"/> <child link="link_1"/>
<axis xyz="0 0 1"/> <limit lower="-2.87979" upper="2.87979" effort="0" velocity="4.4"/>
  </joint>
  <joint name="joint_2" type="revolute">
<origin xyz="0 0 0.29" rpy="0 0 0"/> <parent link="link_1"/> <child link="link_2"/>
<axis xyz="0 1 0"/> <limit lower="-1.91986" upper="1.91986" effort="0" velocity="4.4"/>
  </joint>
  <joint name="joint_3" type="revolute">
<origin xyz="0 0 0.27" rpy="0 0 0"/> <parent link="link_2"/> <child link="link_3"/>
<axis xyz="0 1 0"/> <limit lower="-1.91986" upper="1.22173" effort="0" velocity="4.4"/>
  </joint>
  <joint name="joint_4" type="revolute">
<origin xyz="0 0 0.07" rpy="0 0 0"/> <parent link="link_3"/> <child link="link_4"/>
<axis xyz="1 0 0"/> <limit lower="-2.79253" upper="2.79253" effort="0" velocity="5.6"/>
  </joint>
  <joint name="joint_5" type="revolute">
<origin xyz="0.302 0 0" rpy="0 0 0"/> <parent link="link_4"/> <child link="link_5"/>
<axis xyz="0 1 0"/> <limit lower="-2.094395" upper="2.094395" effort="0" velocity="5.6"/>
  </joint>
  <joint name="joint_6" type="revolute">
<origin xyz="0.072 0 0" rpy="0 0 0"/> <parent link="link_5"/> <child link="link_6"/>
<axis xyz="1 0 0"/> <limit lower="-6.98132" upper="6.98132" effort="0" velocity="7.3"/>
  </joint>
  <joint name="link_6-tool0" type="fixed">
<origin xyz="0 0 0" rpy="0 1.5707963267948966 0"/>
<parent link="link_6"/> <child link="tool0"/>
  </joint>
</robot>"#;

fn random_q(spec: &ModelSpec, r: &mut ChaCha8Rng) -> Vec<f64> {
    spec.links
        .iter()
        .filter_map(|l| l.joint.as_ref())
        .map(|j| r.random_range(j.lower..j.upper))
        .collect()
}

/// |Δt| in mm and the rotation angle in rad (from the Frobenius norm, which unlike
/// `acos` stays accurate for tiny angles: ‖R₁ − R₂‖ = 2√2 sin(θ/2)).
fn pose_error(a: &Pose<f64>, b: &Pose<f64>) -> (f64, f64) {
    let f = (a.rot - b.rot).norm() / (2.0 * 2f64.sqrt());
    ((a.trans - b.trans).norm(), 2.0 * f.min(1.0).asin())
}

fn assert_same_fk(x: &ModelSpec, y: &ModelSpec, seed: u64, tol_mm: f64, tol_rad: f64) {
    let (mx, my) = (Model::from_spec(x).unwrap(), Model::from_spec(y).unwrap());
    assert_eq!(mx.dof(), my.dof());
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    for _ in 0..50 {
        let q = random_q(x, &mut r);
        let (px, py) = (
            tool_pose(&mx, &mx.nominal(), &q),
            tool_pose(&my, &my.nominal(), &q),
        );
        let (dt, dr) = pose_error(&px, &py);
        assert!(
            dt < tol_mm && dr < tol_rad,
            "q = {q:?}: Δt = {dt:e} mm, Δr = {dr:e} rad"
        );
    }
}

#[test]
fn urdf_irb120_equals_the_library_dh_model() {
    let imported = from_urdf_str(IRB120, None).unwrap();
    let names: Vec<&str> = imported.links.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "base",
            "joint_1",
            "joint_2",
            "joint_3",
            "joint_4",
            "joint_5",
            "joint_6",
            "link_6-tool0",
            "tool"
        ]
    );
    let library = robots::robot("irb120").unwrap().spec;
    // the URDF limits are the library's, rounded to 1e-5 rad
    let lim = |s: &ModelSpec| -> Vec<(f64, f64)> {
        s.links
            .iter()
            .filter_map(|l| l.joint.as_ref())
            .map(|j| (j.lower, j.upper))
            .collect()
    };
    for (a, b) in lim(&imported).iter().zip(lim(&library)) {
        assert!((a.0 - b.0).abs() < 1e-5 && (a.1 - b.1).abs() < 1e-5);
    }
    assert_same_fk(&imported, &library, 1, 1e-9, 1e-12);
}

/// A rail (prismatic), a fixed mount, a revolute joint about a tilted axis and a
/// continuous joint, against the product of the URDF transforms written out by hand.
#[test]
fn urdf_prismatic_fixed_and_continuous_joints() {
    let xml = r#"<robot name="rail.bot">
      <link name="floor"/> <link name="carriage"/> <link name="mount"/>
      <link name="arm"/> <link name="hand"/>
      <joint name="rail.x" type="prismatic">
        <origin xyz="0.1 0.2 0.3" rpy="0 0 0.5"/> <parent link="floor"/>
        <child link="carriage"/> <axis xyz="2 0 0"/>
        <limit lower="-0.5" upper="1.5" effort="1" velocity="1"/>
      </joint>
      <joint name="mount*" type="fixed">
        <origin xyz="0 0.05 0.4" rpy="0.1 -0.2 0.3"/>
        <parent link="carriage"/> <child link="mount"/>
      </joint>
      <joint name="shoulder" type="revolute">
        <origin xyz="0.02 0 0.1" rpy="0.4 0.3 -0.2"/> <parent link="mount"/>
        <child link="arm"/> <axis xyz="0 0.6 0.8"/>
        <limit lower="-2" upper="1" effort="1" velocity="1"/>
      </joint>
      <joint name="wrist" type="continuous">
        <origin xyz="0.5 0 0" rpy="0 0 0"/> <parent link="arm"/> <child link="hand"/>
        <axis xyz="0 0 -1"/>
      </joint>
    </robot>"#;
    let spec = from_urdf_str(xml, None).unwrap();
    let names: Vec<&str> = spec.links.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(
        names,
        ["base", "rail_x", "mount_", "shoulder", "wrist", "tool"]
    );
    let joints: Vec<&Joint> = spec.links.iter().filter_map(|l| l.joint.as_ref()).collect();
    assert_eq!(joints[0].kind, JointKind::Prismatic);
    assert_eq!((joints[0].lower, joints[0].upper), (-500.0, 1500.0));
    assert_eq!((joints[1].lower, joints[1].upper), (-2.0, 1.0));
    assert_eq!(
        (joints[2].lower, joints[2].upper),
        (-CONTINUOUS_RANGE, CONTINUOUS_RANGE)
    );
    let model = Model::from_spec(&spec).unwrap();
    let origin = |xyz: [f64; 3], rpy: [f64; 3]| Pose::from_xyz_rpy(xyz, rpy);
    let rot = |axis: [f64; 3], a: f64| Pose {
        rot: rot_axis(&Vector3::from(axis).normalize(), a),
        trans: Vector3::zeros(),
    };
    let mut r = ChaCha8Rng::seed_from_u64(2);
    for _ in 0..20 {
        let q = random_q(&spec, &mut r);
        let expected = origin([100.0, 200.0, 300.0], [0.0, 0.0, 0.5])
            .compose(&origin([q[0], 0.0, 0.0], [0.0; 3]))
            .compose(&origin([0.0, 50.0, 400.0], [0.1, -0.2, 0.3]))
            .compose(&origin([20.0, 0.0, 100.0], [0.4, 0.3, -0.2]))
            .compose(&rot([0.0, 0.6, 0.8], q[1]))
            .compose(&origin([500.0, 0.0, 0.0], [0.0; 3]))
            .compose(&rot([0.0, 0.0, -1.0], q[2]));
        let (dt, dr) = pose_error(&tool_pose(&model, &model.nominal(), &q), &expected);
        assert!(dt < 1e-9 && dr < 1e-12, "Δt = {dt:e} mm, Δr = {dr:e} rad");
    }
}

#[test]
fn export_reimport_paper_robot() {
    let paper = robots::robot("paper").unwrap().spec;
    let xml = to_urdf(&paper).unwrap();
    let back = from_urdf_str(&xml, None).unwrap();
    assert_same_fk(&paper, &back, 3, 1e-9, 1e-12);
    let lim = |s: &ModelSpec| -> Vec<(String, f64, f64)> {
        s.links
            .iter()
            .filter_map(|l| l.joint.as_ref())
            .map(|j| (j.name.clone(), j.lower, j.upper))
            .collect()
    };
    assert_eq!(lim(&back), lim(&paper));
}

/// A chain with every convention, revolute and prismatic, fixed links in between, a
/// fixed `Zrp` link and a chain that ends in a joint.
fn every_convention_spec(seed: u64) -> ModelSpec {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    let mut geometry = |c: Convention, kind: Option<JointKind>| {
        let values = c
            .fields(kind)
            .iter()
            .map(|(_, u)| match u {
                crate::model::Unit::Mm => r.random_range(-400.0..400.0),
                crate::model::Unit::Rad => r.random_range(-3.0..3.0),
                crate::model::Unit::Unitless => r.random_range(0.2..1.5),
                crate::model::Unit::RadPerMm
                | crate::model::Unit::RadPerNmm
                | crate::model::Unit::Arcsec => {
                    unreachable!("no link field is a joint correction")
                }
            })
            .collect();
        let mut g = LinkGeometry::new(c, values);
        if c == Convention::Urdf {
            g.axis = Some([0.3, -0.5, 0.8]);
        }
        g
    };
    let mut links = vec![LinkSpec {
        name: "base".into(),
        geometry: geometry(Convention::Frame6, None),
        joint: None,
    }];
    let mut n = 0;
    for c in [
        Convention::Dh,
        Convention::Hayati,
        Convention::Mdh,
        Convention::MdhBeta,
        Convention::SModel,
        Convention::BookType3,
        Convention::Urdf,
        Convention::Zrp,
    ] {
        for kind in [JointKind::Revolute, JointKind::Prismatic] {
            n += 1;
            let (lower, upper) = match kind {
                JointKind::Revolute => (-3.0, 3.0),
                JointKind::Prismatic => (-250.0, 250.0),
            };
            links.push(LinkSpec {
                name: format!("j{n}"),
                geometry: geometry(c, Some(kind)),
                joint: Some(Joint {
                    name: format!("q{n}"),
                    kind,
                    lower,
                    upper,
                }),
            });
        }
        links.push(LinkSpec {
            name: format!("fixed{n}"),
            geometry: geometry(
                if n == 14 {
                    Convention::Zrp
                } else {
                    Convention::Point
                },
                None,
            ),
            joint: None,
        });
    }
    links.push(LinkSpec {
        name: "last".into(),
        geometry: geometry(Convention::Dh, Some(JointKind::Revolute)),
        joint: Some(Joint {
            name: "q_last".into(),
            kind: JointKind::Revolute,
            lower: -1.0,
            upper: 1.0,
        }),
    });
    ModelSpec {
        compliance: None,
        periodic: None,
        payloads: Vec::new(),
        name: "every".into(),
        instrument: None,
        links,
        targets: vec![],
    }
}

#[test]
fn export_reimport_every_convention() {
    for seed in 0..3 {
        let spec = every_convention_spec(seed);
        let back = from_urdf_str(&to_urdf(&spec).unwrap(), None).unwrap();
        assert_same_fk(&spec, &back, 10 + seed, 1e-9, 1e-12);
    }
}

#[test]
fn export_reimport_dh_model_with_targets() {
    let mut spec = robots::robot("kr300").unwrap().spec;
    spec.links[0].geometry = LinkGeometry::frame6([100.0, -20.0, 645.0], [0.01, 0.02, 3.0]);
    for (name, xyz) in [
        ("smr1", [-89.58, -2.84, 327.03]),
        ("smr2", [60.0, 40.0, 300.0]),
    ] {
        spec.targets.push(LinkSpec {
            name: name.into(),
            geometry: LinkGeometry::point(xyz),
            joint: None,
        });
    }
    let xml = to_urdf(&spec).unwrap();
    // both targets hang off the tool, so the tree branches
    let err = from_urdf_str(&xml, None).unwrap_err().to_string();
    assert!(
        err.contains("choose the tip") && err.contains("smr1, smr2"),
        "{err}"
    );
    let chain = from_urdf_str(&xml, Some("tool")).unwrap();
    let mut no_targets = spec.clone();
    no_targets.targets.clear();
    assert_same_fk(&no_targets, &chain, 20, 1e-9, 1e-12);
    // to a target: the target's position of the original model
    let m = Model::from_spec(&spec).unwrap();
    let mut data = crate::model::Data::new(&m);
    let q = [0.1, -0.5, 0.3, 0.2, -0.4, 0.6];
    crate::model::forward_kinematics(&m, &mut data, &m.nominal(), &q);
    for (k, name) in ["smr1", "smr2"].iter().enumerate() {
        let t = Model::from_spec(&from_urdf_str(&xml, Some(name)).unwrap()).unwrap();
        let p = tool_pose(&t, &t.nominal(), &q);
        assert!((p.trans - data.targets[k].trans).norm() < 1e-9, "{name}");
    }
}

#[test]
fn names_are_sanitised_and_unique() {
    let xml = r#"<robot name="r">
      <link name="a"/> <link name="b"/> <link name="c"/> <link name="d"/>
      <joint name="base" type="revolute"><parent link="a"/><child link="b"/>
        <limit lower="-1" upper="1" effort="0" velocity="1"/></joint>
      <joint name="x.y" type="revolute"><parent link="b"/><child link="c"/>
        <limit lower="-1" upper="1" effort="0" velocity="1"/></joint>
      <joint name="x*y" type="revolute"><parent link="c"/><child link="d"/>
        <limit lower="-1" upper="1" effort="0" velocity="1"/></joint>
    </robot>"#;
    let spec = from_urdf_str(xml, None).unwrap();
    let names: Vec<&str> = spec.links.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(names, ["base", "base_2", "x_y", "x_y_2", "tool"]);
    // URDF's default axis is x
    assert_eq!(spec.links[1].geometry.axis, Some([1.0, 0.0, 0.0]));
    Model::from_spec(&spec).unwrap();
}

fn import_err(xml: &str, tip: Option<&str>) -> String {
    match from_urdf_str(xml, tip) {
        Ok(_) => panic!("accepted: {xml}"),
        Err(e) => e.to_string(),
    }
}

/// A two-link URDF with one joint described by `joint` (type attribute and body).
fn one_joint(joint: &str) -> String {
    format!(
        r#"<robot name="r"><link name="a"/><link name="b"/>
           <joint name="j" {joint}<parent link="a"/><child link="b"/></joint></robot>"#
    )
}

#[test]
fn bad_inputs_give_clear_errors() {
    let lim = r#"<limit lower="-1" upper="1" effort="0" velocity="1"/>"#;
    let cases: Vec<(String, Option<&str>, &str)> = vec![
        (
            "<robot name=\"r\"><link name=\"a\"".into(),
            None,
            "not a valid URDF",
        ),
        (
            r#"<robot name="r"><link name="a"/></robot>"#.into(),
            None,
            "no movable joint",
        ),
        (one_joint(r#"type="fixed">"#), None, "no movable joint"),
        (
            one_joint(&format!(r#"type="revolute"><axis xyz="0 0 0"/>{lim}"#)),
            None,
            "non-zero",
        ),
        (
            one_joint(&format!(r#"type="revolute"><mimic joint="k"/>{lim}"#)),
            None,
            "mimic",
        ),
        (one_joint(r#"type="floating">"#), None, "not supported"),
        (
            one_joint(r#"type="revolute"><limit lower="1" upper="-1" effort="0" velocity="1"/>"#),
            None,
            "empty joint range",
        ),
        (
            one_joint(r#"type="revolute">"#),
            None,
            "is <limit> missing?",
        ),
        (
            one_joint(r#"type="revolute"><origin xyz="nan 0 0"/>"#),
            None,
            "not finite",
        ),
        (
            one_joint(&format!(r#"type="revolute">{lim}"#)),
            Some("c"),
            "unknown tip link `c`",
        ),
        (
            format!(
                r#"<robot name="r"><link name="a"/><link name="b"/><link name="c"/>
                <joint name="j" type="revolute"><parent link="a"/><child link="b"/>{lim}</joint>
                <joint name="k" type="revolute"><parent link="a"/><child link="c"/>{lim}</joint>
                </robot>"#
            ),
            None,
            "several leaf links (b, c)",
        ),
        (
            format!(
                r#"<robot name="r"><link name="a"/><link name="b"/>
                <joint name="j" type="revolute"><parent link="a"/><child link="z"/>{lim}</joint>
                </robot>"#
            ),
            None,
            "unknown link `z`",
        ),
        (
            format!(
                r#"<robot name="r"><link name="a"/><link name="b"/><link name="c"/>
                <joint name="j" type="revolute"><parent link="a"/><child link="c"/>{lim}</joint>
                <joint name="k" type="revolute"><parent link="b"/><child link="c"/>{lim}</joint>
                </robot>"#
            ),
            None,
            "child of two joints",
        ),
        (
            format!(
                r#"<robot name="r"><link name="a"/><link name="b"/>
                <joint name="j" type="revolute"><parent link="a"/><child link="b"/>{lim}</joint>
                <joint name="k" type="revolute"><parent link="b"/><child link="a"/>{lim}</joint>
                </robot>"#
            ),
            None,
            "no root link",
        ),
        (
            format!(
                r#"<robot name="r"><link name="a"/><link name="b"/><link name="c"/><link name="d"/>
                <joint name="j" type="revolute"><parent link="a"/><child link="b"/>{lim}</joint>
                <joint name="k" type="revolute"><parent link="c"/><child link="d"/>{lim}</joint>
                <joint name="l" type="revolute"><parent link="d"/><child link="c"/>{lim}</joint>
                </robot>"#
            ),
            Some("d"),
            "form a cycle",
        ),
        (
            r#"<robot name="r"><link name="a"/><link name="b"/></robot>"#.into(),
            None,
            "several root links",
        ),
    ];
    for (xml, tip, expected) in cases {
        let e = import_err(&xml, tip);
        assert!(e.contains(expected), "expected `{expected}` in: {e}");
    }
}

#[test]
fn file_errors_name_the_file() {
    let e = read_urdf("/nonexistent/robot.urdf", None).unwrap_err();
    assert!(
        matches!(&e, Error::File { file, .. } if file == "/nonexistent/robot.urdf"),
        "{e}"
    );
    let dir = std::env::temp_dir().join(format!("armcal-urdf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.urdf");
    std::fs::write(&path, one_joint(r#"type="planar">"#)).unwrap();
    let e = read_urdf(&path, None).unwrap_err().to_string();
    assert!(
        e.starts_with(&path.display().to_string()) && e.contains("planar"),
        "{e}"
    );
    std::fs::write(&path, IRB120).unwrap();
    assert_eq!(read_urdf(&path, Some("tool0")).unwrap().links.len(), 9);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn export_rejects_duplicate_joint_names() {
    let mut spec = robots::robot("paper").unwrap().spec;
    spec.links[2].joint.as_mut().unwrap().name = "q1".into();
    let e = to_urdf(&spec).unwrap_err().to_string();
    assert!(e.contains("`q1` is used twice"), "{e}");
}
