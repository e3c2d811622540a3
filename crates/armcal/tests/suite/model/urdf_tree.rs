//! URDF trees (issue 32): a branching URDF with a `<mimic>` joint loads as one tree, is
//! identified, and exports back to an equal tree; the import's refusals name the joints.

use crate::common::*;
use armcal::model::tree::kinematics::{branch_kinematics, tree_observed_pose, TreeData};
use armcal::model::tree::{Tree, TreeSpec};
use armcal::model::urdf::{tree_from_urdf_str, tree_to_urdf};
use armcal::{identify_tree, simulate_tree, IdentifySettings, Perturbation, Silent, TreeCell};
use nalgebra::Vector3;
use rand::Rng;
use std::collections::HashMap;
use std::path::Path;

const CELL: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../examples/dual-arm-urdf-tree-cell.toml"
);

/// The position of every target of `tree` (by name) in its root frame at the joints `q`
/// (by joint name, internal units).
fn target_positions(tree: &Tree, q: &HashMap<String, f64>) -> HashMap<String, Vector3<f64>> {
    let params = tree.nominal();
    let qv: Vec<f64> = tree.joints.iter().map(|j| q[&j.name]).collect();
    let mut data = TreeData::new(tree);
    let mut out = HashMap::new();
    for (t, (name, b, _)) in tree.targets.iter().enumerate() {
        branch_kinematics(tree, &mut data, *b, &params, &qv);
        out.insert(name.clone(), tree_observed_pose(tree, &data, t).trans);
    }
    out
}

/// Each joint's nearest jointed ancestor (by joint name; `None`: the root), and each coupled
/// joint's coupling (offset to 1e-12): the structure a round trip keeps.
#[allow(clippy::type_complexity)]
fn structure(
    spec: &TreeSpec,
) -> (
    HashMap<String, Option<String>>,
    Vec<(String, Vec<(String, f64)>, f64)>,
) {
    let by_name: HashMap<&str, usize> = spec
        .links
        .iter()
        .enumerate()
        .map(|(i, l)| (l.link.name.as_str(), i))
        .collect();
    let parent = |i: usize| match &spec.links[i].parent {
        Some(p) => Some(by_name[p.as_str()]),
        None => i.checked_sub(1),
    };
    let mut parents = HashMap::new();
    for (i, l) in spec.links.iter().enumerate() {
        let Some(j) = &l.link.joint else { continue };
        let mut at = parent(i);
        while let Some(k) = at {
            if spec.links[k].link.joint.is_some() {
                break;
            }
            at = parent(k);
        }
        let above = at.map(|k| spec.links[k].link.joint.as_ref().unwrap().name.clone());
        parents.insert(j.name.clone(), above);
    }
    let couplings = spec
        .links
        .iter()
        .filter_map(|l| {
            let c = l.coupling.as_ref()?;
            Some((
                l.link.joint.as_ref().unwrap().name.clone(),
                c.terms.clone(),
                // to 1e-12 (a cell writes the offset in degrees)
                (c.offset * 1e12).round(),
            ))
        })
        .collect();
    (parents, couplings)
}

#[test]
fn a_branching_urdf_with_a_mimic_joint_loads_as_a_tree() {
    let cell = TreeCell::from_file(Path::new(CELL)).unwrap();
    let tree = &cell.tree;
    assert_eq!(tree.branches.len(), 2, "one branch per arm");
    // the head holds no target and is left out; the mimic joint has no data column
    let names: Vec<&str> = tree.joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(names.len(), 14, "{names:?}");
    assert!(!names.contains(&"torso_level") && !names.contains(&"head_pan"));
    assert_eq!(tree.coupled.len(), 1);
    let c = &tree.coupled[0];
    assert_eq!(c.joint, "torso_level");
    assert_eq!(c.coupling.terms, vec![("torso_pitch".to_string(), -1.0)]);
    assert_eq!(
        c.coupling.offset, 0.05,
        "URDF radians are the internal unit"
    );
    assert_eq!(tree.forks, vec!["torso_level".to_string()]);
    // the coupled joint moves with its leader: FK at q equals FK of the uncoupled tree with
    // torso_level = 0.05 − torso_pitch
    let free = tree.uncoupled().unwrap();
    let mut r = rng(4);
    for _ in 0..5 {
        let mut q: HashMap<String, f64> = tree
            .joints
            .iter()
            .map(|j| (j.name.clone(), r.random_range(j.lower..j.upper)))
            .collect();
        let coupled = target_positions(tree, &q);
        q.insert("torso_level".into(), 0.05 - q["torso_pitch"]);
        let uncoupled = target_positions(&free, &q);
        for (name, p) in &coupled {
            assert!((p - uncoupled[name]).norm() < 1e-9, "{name}");
        }
    }
}

#[test]
fn a_dual_arm_urdf_identifies_and_exports_back_to_an_equal_tree() {
    let cell = TreeCell::from_file(Path::new(CELL)).unwrap();
    let poses = tree_poses(&cell.tree, 50, 21);
    let sim = simulate_tree(
        &cell.tree,
        cell.measurement,
        None,
        &poses,
        &[],
        &Perturbation::default(),
        5,
    )
    .unwrap();
    let est = identify_tree(&cell, &sim.data, &IdentifySettings::default(), &mut Silent).unwrap();
    assert!(est.solver.status.is_converged(), "{}", est.solver.status);
    let mut moved = 0;
    for (p, t) in est.parameters.iter().zip(&sim.truth.parameters) {
        if p.free {
            moved += usize::from((t.truth - t.nominal).abs() > 1e-6);
            assert!(
                (p.estimate - t.truth).abs() <= 1e-8 * t.truth.abs().max(1.0),
                "{}: estimate {} truth {}",
                p.name,
                p.estimate,
                t.truth
            );
        }
    }
    assert!(moved >= 30, "the truth moves the free parameters ({moved})");
    // the estimate as one URDF file, loaded again with a frame at every leaf (the targets)
    let mut at_estimate = est.tree.clone();
    at_estimate.instrument = None;
    let xml = tree_to_urdf(&at_estimate).unwrap();
    assert!(xml.contains("<mimic"), "{xml}");
    let back = tree_from_urdf_str(&xml, None).unwrap();
    let (a, b) = (
        Tree::from_spec(&at_estimate).unwrap(),
        Tree::from_spec(&back).unwrap(),
    );
    assert_eq!(structure(&at_estimate), structure(&back));
    // and as a tree cell, read back with its instrument
    let text = armcal::export_tree_estimate(
        &est,
        Some(&cell),
        armcal::ExportFormat::Cell(armcal::LinkForm::AsGiven),
        &armcal::Acceptance {
            accepted: false,
            accept: "--accept-unconverged",
            raise_iterations: "--max-iterations",
        },
    )
    .unwrap()
    .content;
    let reread = TreeCell::from_toml(&text, "exported.toml").unwrap();
    let fitted = Tree::from_spec(&est.tree).unwrap();
    assert_eq!(structure(&reread.spec), structure(&est.tree));
    let mut r = rng(8);
    // a configuration of the tree's joints by name, uniform within their limits
    let mut random_q = || -> HashMap<String, f64> {
        a.joints
            .iter()
            .map(|j| (j.name.clone(), r.random_range(j.lower..j.upper)))
            .collect()
    };
    for _ in 0..20 {
        let q = random_q();
        let (pa, pb) = (
            target_positions(&fitted, &q),
            target_positions(&reread.tree, &q),
        );
        for (name, p) in &pa {
            assert!((p - pb[name]).norm() < 1e-9, "{name}");
        }
    }
    for _ in 0..20 {
        let q = random_q();
        let (pa, pb) = (target_positions(&a, &q), target_positions(&b, &q));
        assert_eq!(pa.len(), 2);
        for (name, p) in &pa {
            let d = (p - pb[name]).norm();
            assert!(d < 1e-9, "{name}: {d} mm");
        }
    }
}

/// A URDF of two arms on a base, with `extra` joints inserted.
fn two_arms(extra: &str) -> String {
    let joint = |name: &str, parent: &str, child: &str, more: &str| {
        format!(
            r#"<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/><origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>{more}</joint>"#
        )
    };
    format!(
        r#"<robot name="two"><link name="b"/><link name="a1"/><link name="a2"/><link name="c1"/><link name="c2"/>{}{}{}{}{extra}</robot>"#,
        joint("ja1", "b", "a1", ""),
        joint("ja2", "a1", "a2", ""),
        joint("jc1", "b", "c1", ""),
        joint("jc2", "c1", "c2", ""),
    )
}

#[test]
fn mimic_units_follow_the_joint_kinds() {
    // a prismatic joint following a revolute one: m/rad → mm/rad, offset m → mm
    let xml = two_arms(
        r#"<link name="p"/><joint name="jp" type="prismatic"><parent link="a2"/><child link="p"/><origin xyz="0 0 0" rpy="0 0 0"/><axis xyz="1 0 0"/><limit lower="0" upper="0.1" effort="1" velocity="1"/><mimic joint="ja1" multiplier="0.01" offset="0.002"/></joint>"#,
    );
    let spec = tree_from_urdf_str(&xml, None).unwrap();
    // the coupling of link `jp` in a spec
    let coupling = |spec: &TreeSpec| {
        spec.links
            .iter()
            .find(|l| l.link.name == "jp")
            .unwrap()
            .coupling
            .clone()
            .unwrap()
    };
    let c = coupling(&spec);
    assert_eq!(c.terms, vec![("ja1".to_string(), 10.0)]);
    assert!((c.offset - 2.0).abs() < 1e-12);
    // and back
    let xml = tree_to_urdf(&spec).unwrap();
    let c2 = coupling(&tree_from_urdf_str(&xml, None).unwrap());
    assert!((c2.terms[0].1 - 10.0).abs() < 1e-12 && (c2.offset - 2.0).abs() < 1e-12);
}

#[test]
fn bad_urdf_trees_are_refused_naming_the_joints() {
    let mimic = |of: &str| {
        two_arms(&format!(
            r#"<link name="m"/><joint name="jm" type="revolute"><parent link="c2"/><child link="m"/><origin xyz="0 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="{of}"/></joint>"#
        ))
    };
    let err = |xml: &str| tree_from_urdf_str(xml, None).unwrap_err().to_string();
    for (xml, expected) in [
        (
            mimic("nope"),
            "joint `jm`, <mimic joint=\"nope\">: the URDF has no joint `nope`",
        ),
        (mimic("jm"), "cannot mimic itself"),
        (
            mimic("ja2").replacen(
                r#"velocity="1"/></joint><joint name="jc1""#,
                r#"velocity="1"/><mimic joint="ja1"/></joint><joint name="jc1""#,
                1,
            ),
            "`ja2` mimics `ja1` itself",
        ),
        (
            two_arms(
                r#"<link name="x"/><link name="y"/><joint name="jx" type="fixed"><parent link="y"/><child link="x"/></joint><joint name="jy" type="fixed"><parent link="x"/><child link="y"/></joint>"#,
            ),
            "joints `jx`, `jy` form a cycle",
        ),
    ] {
        let e = err(&xml);
        assert!(e.contains(expected), "{e}\nexpected: {expected}");
    }
    // a mimic of a joint that is not on any kept branch
    let xml = mimic("ja1");
    let targets = [armcal::model::tree::TreeTargetSpec {
        target: armcal::model::LinkSpec {
            name: "t".into(),
            geometry: armcal::model::LinkGeometry::point([0.0; 3]),
            joint: None,
        },
        parent: "m".into(),
    }];
    let e = tree_from_urdf_str(&xml, Some(&targets))
        .unwrap_err()
        .to_string();
    assert!(e.contains("on no path from the root to a target"), "{e}");
    // a coupling of two joints has no URDF form
    let mut spec = tree_from_urdf_str(&two_arms(""), None).unwrap();
    let jc2 = spec
        .links
        .iter_mut()
        .find(|l| l.link.name == "jc2")
        .unwrap();
    jc2.coupling = Some(armcal::model::tree::Coupling {
        terms: vec![("ja1".into(), 1.0), ("ja2".into(), 1.0)],
        offset: 0.0,
    });
    let e = tree_to_urdf(&spec).unwrap_err().to_string();
    assert!(
        e.contains("follows 2 joints; a URDF <mimic> follows one"),
        "{e}"
    );
}
