//! Kinematic trees and coupled joints (issue 32): the tree's identification Jacobian (the
//! branches' columns scattered into one registry) against central finite differences of the
//! measurement over every tree parameter; the joint Jacobian w.r.t. the tree's joints
//! (through the coupling) against finite differences and dual numbers; the generic count
//! `4R + 2P + Σ e_b` against the numerical rank on random trees; coupled joints in
//! identifiability; and the errors of a malformed tree.

use crate::common::*;
use armcal::model::tree::bending::lumped_tree_bending;
use armcal::model::tree::compliance::lumped_tree_compliance;
use armcal::model::tree::identifiability::{analyze_tree, expected_tree_count};
use armcal::model::tree::kinematics::*;
use armcal::model::tree::*;
use armcal::model::*;
use armcal::{IdentifiabilitySettings, Joint, JointKind, Measurement};
use nalgebra::DMatrix;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

fn link(name: &str, c: Convention, kind: Option<JointKind>, r: &mut ChaCha8Rng) -> LinkSpec {
    LinkSpec {
        name: name.into(),
        geometry: random_geometry(c, kind, r),
        joint: kind.map(|k| joint(&format!("q_{name}"), k)),
    }
}

fn tree_link(l: LinkSpec, parent: Option<&str>) -> TreeLinkSpec {
    TreeLinkSpec {
        link: l,
        parent: parent.map(Into::into),
        coupling: None,
    }
}

/// A random tree: instrument, base, a torso of `torso` joints, then one branch per entry of
/// `arms` (its joint kinds, 'R' / 'P'), each starting with a frame at the fork and ending
/// in a tool frame and a target (a frame if `frames`, else a point). Jointed links have the
/// convention `conventions[seed % len]` (one per tree: an MDH link followed by a DH one
/// would turn both joints about one axis).
fn random_tree(torso: &str, arms: &[&str], frames: bool, seed: u64) -> TreeSpec {
    random_tree_in(
        torso,
        arms,
        frames,
        seed,
        &[Convention::Dh, Convention::Zrp],
    )
}

fn random_tree_in(
    torso: &str,
    arms: &[&str],
    frames: bool,
    seed: u64,
    conventions: &[Convention],
) -> TreeSpec {
    let mut r = rng(seed);
    let kind = |c: char| match c {
        'R' => JointKind::Revolute,
        _ => JointKind::Prismatic,
    };
    let one = conventions[seed as usize % conventions.len()];
    let mut links = vec![tree_link(
        link("base", Convention::Frame6, None, &mut r),
        None,
    )];
    let mut last = "base".to_string();
    for (i, c) in torso.chars().enumerate() {
        let name = format!("t{}", i + 1);
        links.push(tree_link(link(&name, one, Some(kind(c)), &mut r), None));
        last = name;
    }
    let mut targets = Vec::new();
    for (a, arm) in arms.iter().enumerate() {
        // every branch starts with a frame of its own at the fork (a complete tree)
        let base = format!("a{a}base");
        links.push(tree_link(
            link(&base, Convention::Frame6, None, &mut r),
            Some(&last),
        ));
        let mut parent = Some(base);
        for (i, c) in arm.chars().enumerate() {
            let name = format!("a{a}j{}", i + 1);
            links.push(tree_link(
                link(&name, one, Some(kind(c)), &mut r),
                parent.take().as_deref(),
            ));
        }
        let tool = format!("tool{a}");
        links.push(tree_link(
            link(&tool, Convention::Frame6, None, &mut r),
            parent.as_deref(),
        ));
        let convention = if frames {
            Convention::Frame6
        } else {
            Convention::Point
        };
        targets.push(TreeTargetSpec {
            target: link(&format!("smr{a}"), convention, None, &mut r),
            parent: tool,
        });
    }
    TreeSpec {
        name: "tree".into(),
        instrument: Some(link("tracker", Convention::Frame6, None, &mut r)),
        links,
        targets,
        compliance: None,
    }
}

/// A dual-arm tree on a torso axis with a coupled joint in the right arm:
/// `a0j3 = -0.7 a0j2 + 0.4 t1 + 0.1`.
fn coupled_dual_arm(seed: u64) -> TreeSpec {
    // every convention of a jointed link: the Jacobians hold whatever the tree's form
    let all = [
        Convention::Dh,
        Convention::Mdh,
        Convention::Zrp,
        Convention::Hayati,
    ];
    let mut spec = random_tree_in("R", &["RRRR", "RPRR"], true, seed, &all);
    let l = spec
        .links
        .iter_mut()
        .find(|l| l.link.name == "a0j3")
        .unwrap();
    l.coupling = Some(Coupling {
        terms: vec![("q_a0j2".into(), -0.7), ("q_t1".into(), 0.4)],
        offset: 0.1,
    });
    spec
}

fn random_tree_q(tree: &Tree, r: &mut ChaCha8Rng) -> Vec<f64> {
    tree.joints
        .iter()
        .map(|j| r.random_range(j.lower..j.upper))
        .collect()
}

fn pose_of(tree: &Tree, params: &[f64], q: &[f64], target: usize) -> Pose<f64> {
    let mut data = TreeData::new(tree);
    let (_, b, _) = tree.targets[target];
    branch_kinematics(tree, &mut data, b, params, q);
    tree_observed_pose(tree, &data, target)
}

/// `spec` with joint compliance on the torso joint, the second joint of the right arm (it
/// drives the coupled joint) and the third of the left, gravity oblique in the root frame, every κ at a
/// value that deflects the joints by milliradians.
fn compliant(spec: TreeSpec) -> TreeSpec {
    let tree = Tree::from_spec(&spec).unwrap();
    let joints = ["q_t1", "q_a0j2", "q_a1j3"].map(String::from);
    let mut c = lumped_tree_compliance(&tree, &joints, [0.3, -0.2, -1.0]).unwrap();
    for (i, t) in c.terms.iter_mut().enumerate() {
        t.value = 2e-6 * (1.0 + 0.3 * i as f64);
    }
    TreeSpec {
        compliance: Some(c),
        ..spec
    }
}

/// `spec` (with or without joint compliance) with lateral (bending) compliance on the torso
/// joint, the second joint of the right arm (it drives the coupled joint) and the third of
/// the left, every
/// κ⊥ at a value that bends by milliradians, or by centiradians for `seed` 0 (the
/// rotation's closed form rather than its series).
fn bent(spec: TreeSpec, seed: u64) -> TreeSpec {
    let tree = Tree::from_spec(&TreeSpec {
        compliance: None,
        ..spec.clone()
    })
    .unwrap();
    let joints = ["q_t1", "q_a0j2", "q_a1j3"].map(String::from);
    let gravity = [0.3, -0.2, -1.0];
    let mut bending = lumped_tree_bending(&tree, &joints, gravity).unwrap();
    assert!(
        bending
            .iter()
            .any(|t| t.joint == "q_t1" && t.at.as_deref().unwrap().starts_with("q_a0"))
            && bending
                .iter()
                .any(|t| t.joint == "q_t1" && t.at.as_deref().unwrap().starts_with("q_a1")),
        "the torso bends under both arms: {bending:?}"
    );
    let scale = if seed == 0 { 2e-5 } else { 2e-6 };
    for (i, t) in bending.iter_mut().enumerate() {
        t.value = scale * (1.0 + 0.3 * i as f64);
    }
    let mut c =
        spec.compliance
            .clone()
            .unwrap_or_else(|| armcal::model::compliance::ComplianceSpec {
                gravity,
                levers: tree.nominal(),
                terms: Vec::new(),
                bending: Vec::new(),
            });
    c.bending = bending;
    TreeSpec {
        compliance: Some(c),
        ..spec
    }
}

#[test]
fn tree_identification_jacobian_matches_finite_differences() {
    identification_jacobian_matches_finite_differences(coupled_dual_arm);
}

/// With joint compliance over the tree: the κ columns (the deflection of a torso joint by
/// both arms' masses moves both arms' targets) and the geometric columns at the deflected
/// joints.
#[test]
fn compliant_tree_identification_jacobian_matches_finite_differences() {
    identification_jacobian_matches_finite_differences(|s| compliant(coupled_dual_arm(s)));
}

/// With lateral compliance alone and with joint compliance: the κ⊥ columns (a torso bent by
/// both arms' masses moves both arms' targets), the chain's columns mapped by the bend and
/// the instrument's at the bent targets.
#[test]
fn bent_tree_identification_jacobian_matches_finite_differences() {
    identification_jacobian_matches_finite_differences(|s| bent(coupled_dual_arm(s), s));
    identification_jacobian_matches_finite_differences(|s| bent(compliant(coupled_dual_arm(s)), s));
}

fn identification_jacobian_matches_finite_differences(spec: fn(u64) -> TreeSpec) {
    for seed in 0..3 {
        let tree = Tree::from_spec(&spec(seed)).unwrap();
        assert_eq!(tree.branches.len(), 2);
        assert_eq!(tree.dof(), 8, "9 joints, one coupled");
        let params = tree.nominal();
        let n = tree.param_count();
        let columns: Vec<usize> = (0..n).collect();
        let mut r = rng(40 + seed);
        let mut data = TreeData::new(&tree);
        for _ in 0..3 {
            let q = random_tree_q(&tree, &mut r);
            for target in 0..tree.targets.len() {
                let (_, b, _) = tree.targets[target];
                branch_kinematics(&tree, &mut data, b, &params, &q);
                let mut jac = DMatrix::zeros(6, n);
                tree_identification_jacobian(
                    &tree,
                    &mut data,
                    target,
                    Rows::Pose,
                    &columns,
                    &mut jac,
                    0,
                );
                let mut zero_columns = 0;
                for j in 0..n {
                    let name = &tree.registry.get(j).name;
                    // a κ of 1e-6 rad/mm turns a joint by a milliradian: a step of its own
                    let h = if name.contains(".compliance.") || name.contains(".bending.") {
                        1e-7
                    } else {
                        1e-6
                    };
                    let fd = fd_pose(
                        |h| {
                            let mut p = params.clone();
                            p[j] += h;
                            pose_of(&tree, &p, &q, target)
                        },
                        h,
                    );
                    for row in 0..6 {
                        assert_close(
                            jac[(row, j)],
                            fd[row],
                            1e-6,
                            &format!("seed {seed} target {target} d(row {row})/d{name}"),
                        );
                    }
                    zero_columns += usize::from(fd.iter().all(|x| *x == 0.0));
                }
                // the other arm's links and target do not move this target
                assert!(zero_columns >= 20, "{zero_columns} zero columns");
            }
        }
    }
}

#[test]
fn tree_joint_jacobian_matches_finite_differences_and_dual_numbers() {
    joint_jacobian_matches_finite_differences_and_dual_numbers(coupled_dual_arm);
}

/// With joint compliance over the tree: the chain rule through the deflection
/// `q + Δq(q)`, whose levers turn with every joint before the masses.
#[test]
fn compliant_tree_joint_jacobian_matches_finite_differences_and_dual_numbers() {
    joint_jacobian_matches_finite_differences_and_dual_numbers(|s| compliant(coupled_dual_arm(s)));
}

/// With lateral compliance alone and with joint compliance: the chain rule through the
/// bend `δ_b(q)`, `t_b(q)`, whose levers, pivots and axes turn with the joints before them.
#[test]
fn bent_tree_joint_jacobian_matches_finite_differences_and_dual_numbers() {
    joint_jacobian_matches_finite_differences_and_dual_numbers(|s| bent(coupled_dual_arm(s), s));
    joint_jacobian_matches_finite_differences_and_dual_numbers(|s| {
        bent(compliant(coupled_dual_arm(s)), s)
    });
}

fn joint_jacobian_matches_finite_differences_and_dual_numbers(spec: fn(u64) -> TreeSpec) {
    use num_dual::Dual64;
    for seed in 0..3 {
        let tree = Tree::from_spec(&spec(seed)).unwrap();
        let params = tree.nominal();
        let mut r = rng(60 + seed);
        let q = random_tree_q(&tree, &mut r);
        let mut data = TreeData::new(&tree);
        let mut dual = TreeData::<Dual64>::new(&tree);
        for target in 0..tree.targets.len() {
            let (_, b, _) = tree.targets[target];
            branch_kinematics(&tree, &mut data, b, &params, &q);
            let jq = tree_joint_jacobian(&tree, &data, target);
            for k in 0..tree.dof() {
                let fd = fd_pose(
                    |h| {
                        let mut qq = q.clone();
                        qq[k] += h;
                        let mut d = TreeData::new(&tree);
                        branch_kinematics(&tree, &mut d, b, &params, &qq);
                        let (_, _, local) = tree.targets[target];
                        d.branches[b].targets[local]
                    },
                    1e-5,
                );
                let qd: Vec<Dual64> = q
                    .iter()
                    .enumerate()
                    .map(|(i, &x)| Dual64::new(x, if i == k { 1.0 } else { 0.0 }))
                    .collect();
                branch_kinematics(&tree, &mut dual, b, &params, &qd);
                let (_, _, local) = tree.targets[target];
                let pd = dual.branches[b].targets[local];
                let rd = pd.rot.map(|x| x.eps) * pd.rot.map(|x| x.re).transpose();
                let exact = [
                    pd.trans[0].eps,
                    pd.trans[1].eps,
                    pd.trans[2].eps,
                    rd[(2, 1)],
                    rd[(0, 2)],
                    rd[(1, 0)],
                ];
                for row in 0..6 {
                    let what = format!("seed {seed} target {target} dq{k} row {row}");
                    assert_close(jq[(row, k)], fd[row], 1e-6, &what);
                    assert_close(jq[(row, k)], exact[row], 1e-10, &what);
                }
            }
        }
    }
}

#[test]
fn tree_count_matches_the_numerical_rank_on_random_trees() {
    // N = 4R + 2P + Σ_b e_b (e_b = 6 per frame target, 3 per point): the serial counts of
    // the branches less what their shared links count twice.
    let cases: [(&str, &[&str]); 5] = [
        ("R", &["RRRRRR", "RRRRRR"]),
        ("RR", &["RRR", "RPR", "RR"]),
        ("P", &["RRRR", "RRR"]),
        ("", &["RRR", "RRRR"]),
        ("RR", &["RR", ""]),
    ];
    for (seed, (torso, arms)) in cases.iter().enumerate() {
        for (frames, m) in [(true, Measurement::Pose), (false, Measurement::Position)] {
            let tree = Tree::from_spec(&random_tree(torso, arms, frames, seed as u64)).unwrap();
            let expected = expected_tree_count(&tree, m).unwrap();
            let joints: usize = torso.len() + arms.iter().map(|a| a.len()).sum::<usize>();
            let prismatic = (torso.to_string() + &arms.concat()).matches('P').count();
            let e = if frames { 6 } else { 3 };
            assert_eq!(expected, 4 * joints - 2 * prismatic + e * arms.len());
            // the branch-sum form of the same count
            let shared = 4 * torso.len() - 2 * torso.matches('P').count();
            let serial: usize = tree
                .branches
                .iter()
                .map(|b| {
                    let r = b
                        .model
                        .joints
                        .iter()
                        .filter(|j| j.kind == JointKind::Revolute);
                    4 * r.count()
                        + 2 * (b.model.dof()
                            - b.model
                                .joints
                                .iter()
                                .filter(|j| j.kind == JointKind::Revolute)
                                .count())
                        + e
                })
                .sum();
            assert_eq!(expected, serial - shared * (arms.len() - 1));
            let opts = IdentifiabilitySettings {
                measurement: m,
                poses: 40,
                ..Default::default()
            };
            let report = analyze_tree(&tree, &tree.nominal(), None, &opts).unwrap();
            let what = format!("torso {torso} arms {arms:?} {m:?}");
            assert_eq!(report.rank_svd, expected, "{what} SVD rank");
            assert_eq!(report.rank_qr, expected, "{what} QR rank");
            assert_eq!(report.identifiable.len(), expected, "{what} selection");
            assert_eq!(
                report.identifiable.len() + report.excluded.len(),
                tree.param_count()
            );
            assert_eq!(report.completeness.expected_for_measurement, Some(expected));
        }
    }
}

/// A dual-arm cell on a torso axis: `t1`, then arms `r1…r3` and `l1…l3` hanging from it,
/// a point target on each arm; `extra` is appended to the right arm's third link.
fn dual_arm_cell(extra: &str, left_parent: &str, target_link: &str) -> String {
    let link = |name: &str, parent: &str, theta: f64, d: f64, a: f64, alpha: f64, extra: &str| {
        let joint_name = if extra.contains("joint_name") {
            String::new()
        } else {
            format!("joint_name = \"q_{name}\"\n")
        };
        format!(
            "[[robot.links]]\nname = \"{name}\"\n{parent}convention = \"dh\"\njoint = \"revolute\"\n\
             {joint_name}limits = [-170, 170]\ntheta_deg = {theta}\nd_mm = {d}\n\
             a_mm = {a}\nalpha_deg = {alpha}\n{extra}\n"
        )
    };
    let mut text = String::from(
        "name = \"dual\"\n[robot]\nname = \"dual-arm\"\n\n\
         [instrument]\nname = \"tracker\"\nxyz_mm = [2500, 300, 400]\nrpy_deg = [0, 0, 170]\n\n",
    );
    text += &link("t1", "", 10.0, 900.0, 100.0, 20.0, "");
    let frame = |name: &str, parent: &str, xyz: [f64; 3], rz: f64| {
        format!(
            "[[robot.links]]\nname = \"{name}\"\nparent = \"{parent}\"\nconvention = \"frame6\"\n\
             x_mm = {}\ny_mm = {}\nz_mm = {}\nrx_deg = 0\nry_deg = 0\nrz_deg = {rz}\n\n",
            xyz[0], xyz[1], xyz[2]
        )
    };
    text += &frame("rbase", "t1", [100.0, -250.0, 300.0], -30.0);
    text += &link("r1", "", 5.0, 150.0, 250.0, -80.0, "");
    text += &link("r2", "", -30.0, 40.0, 400.0, 5.0, "");
    text += &link("r3", "", 20.0, 10.0, 300.0, 85.0, extra);
    text += &frame("lbase", left_parent, [100.0, 250.0, 300.0], 30.0);
    text += &link("l1", "", -5.0, -150.0, 250.0, 80.0, "");
    text += &link("l2", "", 25.0, -40.0, 380.0, -5.0, "");
    text += &link("l3", "", -15.0, 20.0, 310.0, -95.0, "");
    text += &format!(
        "[[targets]]\nname = \"right\"\nlink = \"r3\"\nxyz_mm = [30, 50, 120]\n\n\
         [[targets]]\nname = \"left\"\nlink = \"{target_link}\"\nxyz_mm = [-20, 40, 110]\n"
    );
    text
}

#[test]
fn a_tree_cell_loads_as_one_registry_and_identifies_the_tree_count() {
    use armcal::TreeCell;
    let cell = TreeCell::from_toml(&dual_arm_cell("", "t1", "l3"), "dual.toml").unwrap();
    let tree = &cell.tree;
    assert_eq!(tree.branches.len(), 2);
    assert_eq!(tree.forks, ["t1"]);
    assert_eq!(tree.dof(), 7);
    // tracker 6, two arm frames 6 each, seven DH links 4 each, two points 3 each: the
    // torso once
    assert_eq!(tree.param_count(), 6 + 2 * 6 + 7 * 4 + 2 * 3);
    assert_eq!(cell.measurement, Measurement::Position);
    let report = cell.identifiability(40, 1).unwrap();
    // 4R + 3 per point: 4·7 + 6
    assert_eq!(report.completeness.expected_for_measurement, Some(34));
    assert_eq!(report.rank_svd, 34);
    assert_eq!(report.identifiable.len(), 34);
    // the serial loader refuses the tree with its line and field
    let e = armcal::Cell::from_toml(
        &dual_arm_cell("", "t1", "l3"),
        "dual.toml",
        std::path::Path::new("."),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("robot.links[1].parent") && e.contains("kinematic tree"),
        "{e}"
    );
    // both arms' first joints straight on the fork as DH links: both axes are the fork
    // frame's z, one line where a complete tree has two; the count is not claimed and the
    // rank is 4 lower than a complete tree's with these joints (4·9 + 6)
    let mut text = dual_arm_cell("", "t1", "l3");
    for (side, xyz) in [
        (
            "rbase",
            "x_mm = 100\ny_mm = -250\nz_mm = 300\nrx_deg = 0\nry_deg = 0\nrz_deg = -30",
        ),
        (
            "lbase",
            "x_mm = 100\ny_mm = 250\nz_mm = 300\nrx_deg = 0\nry_deg = 0\nrz_deg = 30",
        ),
    ] {
        text = text.replace(
            &format!("name = \"{side}\"\nparent = \"t1\"\nconvention = \"frame6\"\n{xyz}"),
            &format!("name = \"{side}\"\nparent = \"t1\"\nconvention = \"dh\"\njoint = \"revolute\"\njoint_name = \"q_{side}\"\nlimits = [-90, 90]\ntheta_deg = 10\nd_mm = 50\na_mm = 120\nalpha_deg = 70"),
        );
    }
    let cell = TreeCell::from_toml(&text, "dual.toml").unwrap();
    assert_eq!(cell.tree.dof(), 9);
    assert_eq!(cell.tree.incomplete_forks().len(), 1);
    assert!(cell.tree.incomplete_forks()[0].starts_with("link `lbase` hangs from `t1`"));
    let report = cell.identifiability(40, 1).unwrap();
    assert_eq!(report.completeness.expected_for_measurement, None);
    assert_eq!(report.rank_svd, 4 * 9 + 6 - 4);
}

#[test]
fn a_malformed_tree_cell_says_file_line_and_field() {
    use armcal::TreeCell;
    let err = |text: String| {
        TreeCell::from_toml(&text, "dual.toml")
            .unwrap_err()
            .to_string()
    };
    let cases = [
        (
            dual_arm_cell("", "t9", "l3"),
            "`robot.links[5].parent`: names `t9`, which is no link of the robot",
        ),
        (
            dual_arm_cell("", "l2", "l3"),
            "`robot.links[5]`: links `lbase` → `l2` → `l1` form a cycle",
        ),
        (
            dual_arm_cell("", "t1", "x3"),
            "`targets[1].link`: names `x3`, which is no link of the robot",
        ),
        (
            dual_arm_cell("joint_name = \"q_r2\"\n", "t1", "l3"),
            "`robot.links[3]`: joint `q_r2` is named twice (links `r2` and `r3`)",
        ),
        (
            dual_arm_cell("coupled = { q_r9 = 1 }\n", "t1", "l3"),
            "`robot.links[4]`: link `r3`: coupled joint `q_r3` follows `q_r9`, which is no joint of the robot",
        ),
        (
            dual_arm_cell("coupled = { q_r2 = \"x\" }\n", "t1", "l3"),
            "`robot.links[4].coupled`: the coefficient of `q_r2` must be a finite number",
        ),
        (
            dual_arm_cell("coupled = { q_r2 = 1, offset_mm = 3 }\n", "t1", "l3"),
            "`robot.links[4].coupled`: `offset_mm`: the offset of this joint is `offset_deg` or `offset_rad`",
        ),
        (
            dual_arm_cell("", "t1", "t1") ,
            "`robot.links[5]`: link `lbase` leads to no target",
        ),
    ];
    for (text, expected) in cases {
        let e = err(text.clone());
        // the line is the one of the entry the field is in
        let index: usize = expected
            .split("robot.links[")
            .nth(1)
            .or_else(|| expected.split("targets[").nth(1))
            .and_then(|r| r.split(']').next())
            .and_then(|n| n.parse().ok())
            .expect("the expectation names an entry");
        let header = if expected.contains("robot.links[") {
            "[[robot.links]]"
        } else {
            "[[targets]]"
        };
        let line = text
            .lines()
            .enumerate()
            .filter(|(_, l)| *l == header)
            .nth(index)
            .map(|(n, _)| n + 1)
            .unwrap();
        assert!(
            e.starts_with(&format!("dual.toml: line {line}: ")),
            "line {line}: {e}"
        );
        assert!(e.contains(expected), "expected `{expected}` in: {e}");
    }
}

/// A palletizer: a vertical axis `j1`, horizontal parallel axes `j2`, `j3` and a passive
/// `j4` kept by a parallelogram at `q4 = -(q2 + q3)` (the flange stays level), a flange
/// axis `j5` and a reflector: one branch, one coupled joint.
fn palletizer(coupled: bool) -> TreeSpec {
    let dh = |name: &str, v: [f64; 4]| {
        let d = std::f64::consts::PI / 180.0;
        tree_link(
            LinkSpec {
                name: name.into(),
                geometry: LinkGeometry::new(Convention::Dh, vec![v[0] * d, v[1], v[2], v[3] * d]),
                joint: Some(Joint {
                    name: format!("q{}", &name[1..]),
                    kind: JointKind::Revolute,
                    // q4 = -(q2 + q3) spans twice the others' range
                    lower: if name == "j4" { -3.0 } else { -1.5 },
                    upper: if name == "j4" { 3.0 } else { 1.5 },
                }),
            },
            None,
        )
    };
    let mut links = vec![
        dh("j1", [3.0, 700.0, 250.0, -90.0]),
        dh("j2", [-90.0, 0.0, 1100.0, 0.0]),
        dh("j3", [2.0, 0.0, 1200.0, 0.0]),
        dh("j4", [-1.0, 0.0, 250.0, 90.0]),
        dh("j5", [0.0, -200.0, 0.0, 0.0]),
    ];
    if coupled {
        links[3].coupling = Some(Coupling {
            terms: vec![("q2".into(), -1.0), ("q3".into(), -1.0)],
            offset: 0.0,
        });
    }
    let mut r = rng(5);
    TreeSpec {
        name: "palletizer".into(),
        instrument: Some(link("tracker", Convention::Frame6, None, &mut r)),
        links,
        targets: vec![TreeTargetSpec {
            target: LinkSpec {
                name: "smr".into(),
                geometry: LinkGeometry::point([80.0, 60.0, 150.0]),
                joint: None,
            },
            parent: "j5".into(),
        }],
        compliance: None,
    }
}

#[test]
fn a_coupled_joint_leaves_no_redundant_parameter_free_and_says_why() {
    // Oracle: the same robot as an ordinary serial model whose five joints are measured
    // only where q4 = -(q2 + q3): the tree's coupling map must give the same rank and the
    // same identifiable set as the serial analysis at those configurations.
    let tree = Tree::from_spec(&palletizer(true)).unwrap();
    assert_eq!(tree.dof(), 4, "q4 is not a data column");
    let opts = IdentifiabilitySettings {
        measurement: Measurement::Position,
        poses: 60,
        ..Default::default()
    };
    let tree_qs = random_tree_configurations(&tree, 60);
    let coupled = analyze_tree(&tree, &tree.nominal(), Some(&tree_qs), &opts).unwrap();
    let free = Tree::from_spec(&palletizer(false)).unwrap();
    let serial = &free.branches[0].model;
    let qs: Vec<Vec<f64>> = tree_qs
        .iter()
        .map(|q| vec![q[0], q[1], q[2], -(q[1] + q[2]), q[3]])
        .collect();
    let oracle = armcal::model::analyze_at(serial, &serial.nominal(), &qs, &opts).unwrap();
    assert_eq!(coupled.rank_svd, oracle.rank_svd);
    assert_eq!(coupled.identifiable, oracle.identifiable);
    // the coupling costs identifiable parameters against free joints
    let uncoupled = analyze_tree(&free, &free.nominal(), None, &opts).unwrap();
    assert!(
        coupled.rank_svd < uncoupled.rank_svd,
        "coupled {} vs free {}",
        coupled.rank_svd,
        uncoupled.rank_svd
    );
    // every parameter the coupling makes redundant says so; none is left free
    let lost: Vec<_> = coupled
        .excluded
        .iter()
        .filter(|e| !uncoupled.excluded.iter().any(|u| u.name == e.name))
        .collect();
    assert_eq!(lost.len(), uncoupled.rank_svd - coupled.rank_svd);
    for e in &lost {
        assert!(
            e.reason
                .contains("the coupling (joint `q4` = -1 × `q2` - 1 × `q3`) makes it redundant"),
            "{}",
            e.reason
        );
    }
    assert!(coupled
        .variance_inflation
        .iter()
        .all(|v| v.is_finite() && *v < 1e6));
    assert_eq!(coupled.identifiable.len(), coupled.rank_svd);
}

fn random_tree_configurations(tree: &Tree, n: usize) -> Vec<Vec<f64>> {
    let mut r = rng(77);
    (0..n).map(|_| random_tree_q(tree, &mut r)).collect()
}

#[test]
fn a_one_branch_tree_is_its_serial_chain() {
    // The same configurations, the same rows: the tree's analysis of a chain is the serial
    // analysis (rank, identifiable set, reasons), its measurement the serial measurement.
    let tree = Tree::from_spec(&random_tree("", &["RRPRRR"], false, 3)).unwrap();
    let serial = &tree.branches[0].model;
    assert_eq!(tree.param_count(), serial.param_count());
    let opts = IdentifiabilitySettings {
        measurement: Measurement::Position,
        poses: 30,
        ..Default::default()
    };
    let qs = random_tree_configurations(&tree, 30);
    let t = analyze_tree(&tree, &tree.nominal(), Some(&qs), &opts).unwrap();
    let s = armcal::model::analyze_at(serial, &serial.nominal(), &qs, &opts).unwrap();
    assert_eq!(t.rank_svd, s.rank_svd);
    assert_eq!(t.identifiable, s.identifiable);
    assert_eq!(
        t.completeness.expected_for_measurement,
        s.completeness.expected_for_measurement
    );
    let q = &qs[0];
    let p = pose_of(&tree, &tree.nominal(), q, 0);
    let m = measure(serial, &serial.nominal(), q, Observed::Target(0));
    assert_eq!(p.trans, m.trans);
}

/// The lumped masses of a tree: the torso joint takes terms of both arms' masses (both
/// arms load it), an arm's joint only its own arm's; every term deflects its joint (κ
/// moves it) and a coupled joint is refused by name.
#[test]
fn a_torso_joint_is_loaded_by_both_arms_and_an_arm_joint_by_its_own() {
    let spec = compliant(coupled_dual_arm(1));
    let c = spec.compliance.as_ref().unwrap();
    let on = |joint: &str, arm: &str| {
        c.terms
            .iter()
            .filter(|t| t.joint == joint && t.at.as_deref().unwrap().starts_with(arm))
            .count()
    };
    assert!(
        on("q_t1", "q_a0") >= 1 && on("q_t1", "q_a1") >= 1,
        "{:?}",
        c.terms
    );
    assert_eq!(on("q_a0j2", "q_a1"), 0, "{:?}", c.terms);
    assert_eq!(on("q_a1j3", "q_a0"), 0, "{:?}", c.terms);
    assert!(on("q_a1j3", "q_a1") >= 1);
    let tree = Tree::from_spec(&spec).unwrap();
    assert_eq!(tree.compliance.as_ref().unwrap().terms.len(), c.terms.len());
    // the estimate's spec carries the κ back
    let mut params = tree.nominal();
    let last = tree.param_count() - 1;
    params[last] = 7e-6;
    assert_eq!(
        tree.spec_at(&params)
            .compliance
            .unwrap()
            .terms
            .last()
            .unwrap()
            .value,
        7e-6
    );
    // a coupled joint deflects with the joints it follows: the error says so
    let rigid = Tree::from_spec(&coupled_dual_arm(1)).unwrap();
    let err = lumped_tree_compliance(&rigid, &["q_a0j3".into()], [0.0, 0.0, -1.0]).unwrap_err();
    assert!(err.contains("q_a0j3") && err.contains("coupled"), "{err}");
}
