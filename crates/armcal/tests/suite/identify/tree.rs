//! Identification of a kinematic tree (issue 32): a two-arm robot on a shared torso axis
//! with a coupled wrist joint, fitted as one problem over both arms' rows.

use crate::common::*;
use armcal::model::tree::kinematics::{branch_kinematics, tree_observed_pose, TreeData};
use armcal::model::tree::Tree;
use armcal::{
    identify_tree, simulate_tree, Candidate, IdentifySettings, Measurement, NonGeometric,
    Perturbation, Silent, TreeCell, TreeEstimate, TruthRecord,
};
use nalgebra::{Matrix3, Vector3};
use rand::Rng;

/// The dual-arm example with the right arm's last joint coupled to its fourth
/// (`r_t = -r_r + 10°`, a wrist whose two rolls are driven together).
fn coupled_dual_arm() -> TreeCell {
    let text = include_str!("../../../../../examples/dual-arm-tree-cell.toml").replace(
        "joint_name = \"r_t\"\n",
        "joint_name = \"r_t\"\ncoupled = { r_r = -1, offset_deg = 10 }\n",
    );
    let cell = TreeCell::from_toml(&text, "coupled-dual-arm.toml").unwrap();
    assert_eq!(
        cell.tree.coupled.len(),
        1,
        "the replacement made r_t coupled"
    );
    cell
}

/// `n` configurations of the tree's joints, uniform within ±60 % of their limits (seeded).
fn poses(cell: &TreeCell, n: usize, seed: u64) -> Vec<(String, Vec<f64>)> {
    tree_poses(&cell.tree, n, seed)
}

/// A noise-free simulation of `cell`'s tree at the nominal (60 poses, seed 3; truth seed 7)
/// and its default fit, converged.
fn noise_free_fit(cell: &TreeCell) -> (armcal::Simulation, TreeEstimate) {
    let sim = simulate_tree(
        &cell.tree,
        cell.measurement,
        None,
        &poses(cell, 60, 3),
        &[],
        &Perturbation::default(),
        7,
    )
    .unwrap();
    let est = identify_tree(cell, &sim.data, &IdentifySettings::default(), &mut Silent).unwrap();
    assert!(est.solver.status.is_converged(), "{}", est.solver.status);
    (sim, est)
}

/// The position of tree target `t` in the instrument frame at `params`, `q`.
fn position(cell: &TreeCell, params: &[f64], q: &[f64], t: usize) -> Vector3<f64> {
    let tree = &cell.tree;
    let mut data = TreeData::new(tree);
    branch_kinematics(tree, &mut data, tree.targets[t].1, params, q);
    tree_observed_pose(tree, &data, t).trans
}

/// Every free parameter of `est` equals its truth to 1e-8 relative (display units, at
/// least 1e-8 absolute); the names of the free ones the truth moved from their nominal.
fn assert_recovered(est: &TreeEstimate, truth: &TruthRecord) -> Vec<String> {
    let mut moved = Vec::new();
    for (p, t) in est.parameters.iter().zip(&truth.parameters) {
        assert_eq!(p.name, t.name);
        if !p.free {
            continue;
        }
        if (t.truth - t.nominal).abs() > 1e-6 {
            moved.push(p.name.clone());
        }
        assert!(
            (p.estimate - t.truth).abs() <= 1e-8 * t.truth.abs().max(1.0),
            "{}: estimate {} truth {} (nominal {})",
            p.name,
            p.estimate,
            t.truth,
            t.nominal
        );
    }
    moved
}

#[test]
fn a_noise_free_two_arm_tree_with_a_coupled_joint_is_recovered_exactly() {
    let cell = coupled_dual_arm();
    assert_eq!(cell.measurement, Measurement::Position);
    let (sim, est) = noise_free_fit(&cell);
    // the shared torso and the tracker are one set of parameters fed by both arms
    assert!(
        est.free.iter().any(|n| n.starts_with("t1.")),
        "{:?}",
        est.free
    );
    assert!(est.free.iter().any(|n| n.starts_with("tracker.")));
    assert!(est.free.len() >= 40, "{} free", est.free.len());
    let moved = assert_recovered(&est, &sim.truth);
    assert!(
        moved.len() >= 30,
        "the truth moves the free parameters ({moved:?})"
    );
    // no redundant parameter is left free: the free set is the tree's numerical rank over
    // random configurations (the coupling accounted for), and every σ is finite
    let generic = cell.identifiability(60, 1).unwrap();
    assert_eq!(est.free.len(), generic.rank_svd, "{:?}", est.fixed_reasons);
    assert!(est
        .parameters
        .iter()
        .filter(|p| p.free)
        .all(|p| p.sigma.unwrap().is_finite()));
    for t in &est.targets {
        assert!(t.fitted.max < 1e-6, "{}: {}", t.target, t.fitted.max);
    }
}

/// The coupled dual arm with joint compliance over the tree: the robot hangs on a wall
/// (gravity along the root frame's −x, so the torso axis is horizontal and both arms load
/// it), compliant torso and shoulders; with `bending`, lateral compliance of the torso and
/// the right shoulder too; `without` drops the links and target of one arm (`"l"`: a
/// right-arm-only chain with its own torso compliance) or nothing (`""`).
fn compliant_dual_arm(without: &str, bending: bool) -> TreeCell {
    let mut text = include_str!("../../../../../examples/dual-arm-tree-cell.toml").replace(
        "joint_name = \"r_t\"\n",
        "joint_name = \"r_t\"\ncoupled = { r_r = -1, offset_deg = 10 }\n",
    );
    let mut joints = vec!["\"torso\"", "\"r_l\"", "\"l_l\""];
    if without == "l" {
        let start = text.find("[[robot.links]]\nname = \"lbase\"").unwrap();
        let end = text.find("[instrument]").unwrap();
        text.replace_range(start..end, "");
        let target = text.find("[[targets]]\nname = \"smr_l\"").unwrap();
        text.truncate(target);
        joints.pop();
    }
    let bent = if bending {
        "bending = [\"torso\", \"r_l\"]\n"
    } else {
        ""
    };
    let text = text
        .replace("[robot]\n", "[robot]\ngravity = [-1, 0, 0]\n")
        .replace(
            "[instrument]",
            &format!(
                "[parameters]\ncompliance = [{}]\n{bent}\n[instrument]",
                joints.join(", ")
            ),
        );
    TreeCell::from_toml(&text, "compliant-dual-arm.toml").unwrap()
}

/// The first evidence item, with joint compliance over the tree: a noise-free
/// two-arm tree with a shared torso, a coupled joint and a compliant torso loaded by both
/// arms is recovered to 1e-8 relative, every κ with it, each judged separable by the gate.
#[test]
fn a_noise_free_compliant_two_arm_tree_is_recovered_exactly() {
    recovered_exactly(&compliant_dual_arm("", false), &[".compliance."], 60);
}

/// The first evidence item in full: joint AND lateral compliance, the torso bent
/// by both arms' masses; every κ and κ⊥ recovered to 1e-8 relative, each separable (100
/// poses: 60 leave the worst κ at 1.03e-8).
#[test]
fn a_noise_free_two_arm_tree_with_joint_and_lateral_compliance_is_recovered_exactly() {
    let cell = compliant_dual_arm("", true);
    recovered_exactly(&cell, &[".compliance.", ".bending."], 100);
}

/// `cell` simulated noise-free at `n` poses and fitted: the non-geometric terms of each kind in `kinds`
/// (name fragments) load the torso from both arms, every one is kept by the gate and
/// recovered with the geometry to 1e-8 relative.
fn recovered_exactly(cell: &TreeCell, kinds: &[&str], n: usize) {
    let terms: Vec<&str> = cell
        .tree
        .registry
        .iter()
        .map(|p| p.name.as_str())
        .filter(|n| kinds.iter().any(|k| n.contains(k)))
        .collect();
    // the torso takes a mass of each arm, in each kind
    for kind in kinds {
        let torso = |arm: &str| {
            terms
                .iter()
                .any(|n| n.starts_with("torso.") && n.contains(kind) && n.contains(arm))
        };
        assert!(torso("_r_") && torso("_l_"), "{kind}: {terms:?}");
    }
    let sim = simulate_tree(
        &cell.tree,
        cell.measurement,
        None,
        &poses(cell, n, 3),
        &[],
        &Perturbation::default(),
        7,
    )
    .unwrap();
    let est = identify_tree(cell, &sim.data, &IdentifySettings::default(), &mut Silent).unwrap();
    assert!(est.solver.status.is_converged(), "{}", est.solver.status);
    assert_eq!(
        est.nongeometric.len(),
        terms.len(),
        "{:?}",
        est.fixed_reasons
    );
    assert!(
        est.nongeometric.iter().all(|v| v.separable),
        "{:?}",
        est.nongeometric
    );
    let moved = assert_recovered(&est, &sim.truth);
    let kappas = moved
        .iter()
        .filter(|n| kinds.iter().any(|k| n.contains(k)))
        .count();
    assert_eq!(kappas, terms.len(), "{moved:?}");
    for t in &est.targets {
        assert!(t.fitted.max < 1e-6, "{}: {}", t.target, t.fitted.max);
    }
}

/// A compliant tree's estimate exported: neither a URDF nor a tree cell holds a joint
/// compliance, so both are written rigid and warn with every κ's name and how far a target
/// moves without them; the cell read back is the tree at the estimate with κ = 0 (to 1e-9
/// mm), and the stated shift is the compliance's (the largest over 200 other random
/// configurations is of its size).
#[test]
fn a_compliant_tree_exports_rigid_and_says_what_that_costs() {
    let cell = compliant_dual_arm("", false);
    let (_, est) = noise_free_fit(&cell);
    let acceptance = armcal::Acceptance {
        accepted: false,
        accept: "--accept-unconverged",
        raise_iterations: "--max-iterations",
    };
    let export = |format| armcal::export_tree_estimate(&est, Some(&cell), format, &acceptance);
    let as_cell = export(armcal::ExportFormat::Cell(armcal::LinkForm::AsGiven)).unwrap();
    let as_urdf = export(armcal::ExportFormat::Urdf).unwrap();
    let fitted = Tree::from_spec(&est.tree).unwrap();
    let kappas: Vec<usize> = (0..fitted.registry.len())
        .filter(|&i| fitted.registry.get(i).name.contains(".compliance."))
        .collect();
    assert!(!kappas.is_empty());
    let warning = as_cell
        .warnings
        .iter()
        .find(|w| w.starts_with("not held: the joint compliance ("))
        .unwrap_or_else(|| panic!("{:?}", as_cell.warnings));
    assert!(as_urdf.warnings.contains(warning), "{:?}", as_urdf.warnings);
    for &k in &kappas {
        assert!(warning.contains(&fitted.registry.get(k).name), "{warning}");
    }
    let stated: f64 = warning
        .split("moves up to ")
        .nth(1)
        .and_then(|r| r.split(" mm").next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("{warning}"));
    let reread = TreeCell::from_toml(&as_cell.content, "exported.toml").unwrap();
    assert!(reread.tree.compliance.is_none());
    let compliant = fitted.nominal();
    let mut rigid = compliant.clone();
    for &k in &kappas {
        rigid[k] = 0.0;
    }
    let at = |tree: &Tree, params: &[f64], q: &[f64], t: usize| {
        let mut data = TreeData::new(tree);
        branch_kinematics(tree, &mut data, tree.targets[t].1, params, q);
        tree_observed_pose(tree, &data, t).trans
    };
    let mut r = rng(12);
    let mut largest = 0.0f64;
    for _ in 0..200 {
        let q: Vec<f64> = fitted
            .joints
            .iter()
            .map(|j| r.random_range(j.lower..j.upper))
            .collect();
        for t in 0..fitted.targets.len() {
            assert_eq!(reread.tree.targets[t].0, fitted.targets[t].0);
            let p = at(&reread.tree, &reread.tree.nominal(), &q, t);
            let d = (p - at(&fitted, &rigid, &q, t)).norm();
            assert!(d < 1e-9, "{}: {d} mm", fitted.targets[t].0);
            largest = largest.max((p - at(&fitted, &compliant, &q, t)).norm());
        }
    }
    assert!(
        largest > 1e-3 && largest <= 1.5 * stated && largest >= 0.3 * stated,
        "stated {stated} mm, largest over 200 configurations {largest} mm"
    );
}

/// `--nongeometric auto` on a tree: 5-fold cross-validation between the kinematic tree and
/// the compliant one keeps the compliance where the truth has it (κ drawn with σ = 1000
/// µrad/m) and the kinematic tree where it has none (the one-standard-error rule), and the
/// estimate records both candidates' scores with the fit of the one chosen.
#[test]
fn auto_on_a_tree_keeps_the_compliance_only_where_the_data_need_it() {
    let cell = compliant_dual_arm("", false);
    let opts = IdentifySettings {
        nongeometric: NonGeometric::Auto { folds: 5 },
        ..IdentifySettings::default()
    };
    for (compliance, expected) in [(1e-6, Candidate::Compliance), (0.0, Candidate::Kinematic)] {
        let truth = Perturbation {
            compliance,
            ..Perturbation::default()
        };
        let sim = simulate_tree(
            &cell.tree,
            cell.measurement,
            Some(&cell.noise),
            &poses(&cell, 60, 31),
            &[],
            &truth,
            13,
        )
        .unwrap();
        let est = identify_tree(&cell, &sim.data, &opts, &mut Silent).unwrap();
        assert!(est.solver.status.is_converged(), "{}", est.solver.status);
        let choice = est
            .nongeometric_choice
            .as_ref()
            .expect("the choice is recorded");
        let scores: Vec<String> = choice
            .candidates
            .iter()
            .map(|c| {
                format!(
                    "{}: {:.4} ± {:.4} mm",
                    c.candidate.words(),
                    c.held_out.rms,
                    c.standard_error
                )
            })
            .collect();
        assert_eq!(choice.candidates.len(), 2, "{scores:?}");
        assert_eq!(choice.chosen, expected, "κ σ {compliance}: {scores:?}");
        let kappas = est
            .free
            .iter()
            .filter(|n| n.contains(".compliance."))
            .count();
        assert_eq!(
            kappas > 0,
            expected == Candidate::Compliance,
            "{:?}",
            est.free
        );
        assert_eq!(
            est.nongeometric.is_empty(),
            expected == Candidate::Kinematic
        );
    }
}

/// The split-chain fit of the evidence: each arm fitted alone as its own chain with
/// its own torso compliance cannot see the other arm's weight on the torso, so on held-out
/// poses of the same compliant truth (both arms moving) it is measurably worse than the
/// tree fit. Prints the figures of `docs/src/trees.md`.
#[test]
fn a_split_chain_fit_of_a_compliant_tree_is_worse_on_held_out_poses() {
    split_chain_is_worse(false);
}

/// The same with lateral compliance in the truth and in both fits (the torso bent by both
/// arms; the split chain bends its torso under the right arm only), and the tree fitted
/// without its bending terms worse too. Prints the figures of `docs/src/trees.md`.
#[test]
fn a_split_chain_fit_of_a_bent_tree_is_worse_on_held_out_poses() {
    split_chain_is_worse(true);
}

fn split_chain_is_worse(bending: bool) {
    let cell = compliant_dual_arm("", bending);
    let right = compliant_dual_arm("l", bending);
    let truth = Perturbation {
        compliance: 1e-6,
        ..Perturbation::default()
    };
    let (train, test) = (poses(&cell, 60, 21), poses(&cell, 30, 22));
    let sim = |qs: &[(String, Vec<f64>)], t: &[usize]| {
        simulate_tree(
            &cell.tree,
            cell.measurement,
            Some(&cell.noise),
            qs,
            t,
            &truth,
            9,
        )
        .unwrap()
    };
    let (fit, held) = (sim(&train, &[]), sim(&test, &[]));
    // the held-out RMS of the first target (the right arm) of `c`'s fit to `fit`
    let held_out_rms = |c: &TreeCell, fit: &armcal::Dataset, held: &armcal::Dataset| {
        let opts = IdentifySettings {
            test: Some(held.clone()),
            ..IdentifySettings::default()
        };
        let est = identify_tree(c, fit, &opts, &mut Silent).unwrap();
        assert!(est.solver.status.is_converged());
        est.targets[0].held_out.rms
    };
    let tree_rms = held_out_rms(&cell, &fit.data, &held.data);
    // the right arm alone: its rows, its joints (torso and right arm) only
    let arm_joints: Vec<usize> = right
        .tree
        .joints
        .iter()
        .map(|j| {
            cell.tree
                .joints
                .iter()
                .position(|k| k.name == j.name)
                .unwrap()
        })
        .collect();
    let arm_rows = |qs: &[(String, Vec<f64>)]| {
        let mut d = sim(qs, &[0]).data;
        for q in &mut d.configurations {
            *q = arm_joints.iter().map(|&k| q[k]).collect();
        }
        d
    };
    let split_rms = held_out_rms(&right, &arm_rows(&train), &arm_rows(&test));
    println!(
        "{}: right arm, held-out RMS over {} poses: tree fit {tree_rms:.4} mm, split-chain \
         fit {split_rms:.4} mm (noise σ = 0.05 mm per axis)",
        if bending {
            "joint and lateral compliance"
        } else {
            "joint compliance"
        },
        test.len()
    );
    assert!(
        split_rms > 1.25 * tree_rms,
        "split {split_rms:.4} mm vs tree {tree_rms:.4} mm"
    );
    if bending {
        // the same tree without its lateral terms, on the same bent data
        let stiff_rms = held_out_rms(&compliant_dual_arm("", false), &fit.data, &held.data);
        println!("right arm, tree fit without the bending terms: {stiff_rms:.4} mm");
        assert!(
            stiff_rms > 1.25 * tree_rms,
            "without bending {stiff_rms:.4} mm vs with {tree_rms:.4} mm"
        );
    }
}

#[test]
fn the_predicted_tcp_covariance_of_each_arm_matches_monte_carlo() {
    tcp_covariance_matches_monte_carlo(&coupled_dual_arm());
}

/// With joint compliance over the tree (the κ free with the geometry).
#[test]
fn the_predicted_tcp_covariance_of_each_arm_of_a_compliant_tree_matches_monte_carlo() {
    tcp_covariance_matches_monte_carlo(&compliant_dual_arm("", false));
}

/// With joint and lateral compliance over the tree (the κ and κ⊥ free with the geometry).
#[test]
fn the_predicted_tcp_covariance_of_each_arm_of_a_bent_tree_matches_monte_carlo() {
    tcp_covariance_matches_monte_carlo(&compliant_dual_arm("", true));
}

fn tcp_covariance_matches_monte_carlo(cell: &TreeCell) {
    let tree = &cell.tree;
    let qs = poses(cell, 30, 5);
    let working = poses(cell, 1, 11).remove(0).1;
    let exact = Perturbation {
        length: 0.0,
        angle: 0.0,
        compliance: 0.0,
        instrument_length: Some(0.0),
        ..Perturbation::default()
    };
    let runs = 200;
    let mut predicted = vec![Matrix3::zeros(); tree.targets.len()];
    let mut samples: Vec<Vec<Vector3<f64>>> = vec![Vec::new(); tree.targets.len()];
    for run in 0..runs {
        // the nominal robot as the truth; only the noise changes with the seed
        let sim = simulate_tree(
            tree,
            cell.measurement,
            Some(&cell.noise),
            &qs,
            &[],
            &exact,
            100 + run,
        )
        .unwrap();
        let est =
            identify_tree(cell, &sim.data, &IdentifySettings::default(), &mut Silent).unwrap();
        assert!(est.solver.status.is_converged());
        let params = est.params_for(tree).unwrap();
        for (t, (name, _, _)) in tree.targets.iter().enumerate() {
            if run == 0 {
                predicted[t] = est.tcp_covariance(tree, name, &working).unwrap();
            }
            samples[t].push(position(cell, &params, &working, t));
        }
    }
    for (t, (name, _, _)) in tree.targets.iter().enumerate() {
        let n = samples[t].len() as f64;
        let mean = samples[t].iter().sum::<Vector3<f64>>() / n;
        let empirical = samples[t]
            .iter()
            .map(|p| (p - mean) * (p - mean).transpose())
            .sum::<Matrix3<f64>>()
            / (n - 1.0);
        let ratio = empirical.trace() / predicted[t].trace();
        assert!(
            (0.85..=1.15).contains(&ratio),
            "{name}: tr C_MC / tr C_predicted = {ratio:.3} ({:.3e} / {:.3e} mm²)",
            empirical.trace(),
            predicted[t].trace()
        );
    }
}

#[test]
fn tree_data_name_their_target_and_a_wrong_one_says_file_line_and_field() {
    let cell = coupled_dual_arm();
    let dir = std::env::temp_dir().join(format!("armcal-tree-data-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let sim = simulate_tree(
        &cell.tree,
        cell.measurement,
        Some(&cell.noise),
        &poses(&cell, 4, 1),
        &[1],
        &Perturbation::default(),
        2,
    )
    .unwrap();
    let text = cell.write_data(&sim.data).unwrap();
    assert!(text.lines().next().unwrap().contains("target"), "{text}");
    assert!(
        !text.lines().next().unwrap().contains("r_t"),
        "a coupled joint has no column"
    );
    let path = dir.join("left.csv");
    std::fs::write(&path, &text).unwrap();
    let back = cell.read_data(&path, None).unwrap();
    assert_eq!(back.measurements.len(), 4);
    assert!(back
        .measurements
        .iter()
        .all(|m| m.observed == armcal::model::Observed::Target(1)));
    // a file of one arm's rows read as that target's
    let named = cell.read_data(&path, Some("smr_l")).unwrap();
    assert_eq!(named.measurements, back.measurements);
    let bad = text.replacen("smr_l", "smr_x", 1);
    std::fs::write(&path, bad).unwrap();
    let e = cell.read_data(&path, None).unwrap_err().to_string();
    assert!(
        e.contains("left.csv") && e.contains("line 2") && e.contains("unknown target `smr_x`"),
        "{e}"
    );
    // without a `target` column a row of a two-target tree is ambiguous
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let k = header.iter().position(|h| *h == "target").unwrap();
    let dropped: Vec<String> = text
        .lines()
        .map(|l| {
            let mut f: Vec<&str> = l.split(',').collect();
            f.remove(k);
            f.join(",")
        })
        .collect();
    std::fs::write(&path, dropped.join("\n")).unwrap();
    let e = cell.read_data(&path, None).unwrap_err().to_string();
    assert!(
        e.contains("left.csv") && e.contains("line 2") && e.contains("add a `target` column"),
        "{e}"
    );
    let named = cell.read_data(&path, Some("smr_l")).unwrap();
    assert_eq!(named.measurements.len(), 4);
    assert!(named
        .measurements
        .iter()
        .all(|m| m.observed == armcal::model::Observed::Target(1)));
    let e = cell
        .read_data(&path, Some("smr_x"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("no target `smr_x`") && e.contains("smr_r, smr_l"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A tree cell's compliance errors name the file, line and field: an unknown or coupled
/// joint, a joint with no gravity torque (the torso axis along gravity), gravity without
/// compliance; `--nongeometric periodic` and `both` are refused by name and `none` fits
/// the rigid tree.
#[test]
fn a_tree_cell_with_compliance_says_file_line_and_field_of_what_it_cannot_model() {
    let text = include_str!("../../../../../examples/dual-arm-tree-cell.toml");
    let with = |robot: &str, joints: &str| {
        let t = text
            .replace("[robot]\n", &format!("[robot]\n{robot}"))
            .replace(
                "[instrument]",
                &format!("[parameters]\ncompliance = [{joints}]\n\n[instrument]"),
            );
        TreeCell::from_toml(&t, "c.toml")
            .map(|_| ())
            .unwrap_err()
            .to_string()
    };
    let e = with("", "\"r_x\"");
    assert!(
        e.contains("c.toml") && e.contains("line") && e.contains("parameters.compliance"),
        "{e}"
    );
    assert!(e.contains("unknown joint `r_x`"), "{e}");
    // the torso turns about the root frame's z, along the default gravity
    let e = with("", "\"torso\"");
    assert!(e.contains("`torso` carries no gravity torque"), "{e}");
    let e = TreeCell::from_toml(
        &text.replace("[robot]\n", "[robot]\ngravity = [0, 0, -1]\n"),
        "c.toml",
    )
    .map(|_| ())
    .unwrap_err()
    .to_string();
    assert!(e.contains("robot.gravity") && e.contains("line"), "{e}");
    let cell = compliant_dual_arm("", false);
    let sim = simulate_tree(
        &cell.tree,
        cell.measurement,
        None,
        &poses(&cell, 40, 3),
        &[],
        &Perturbation::default(),
        7,
    )
    .unwrap();
    for (asked, refused) in [
        (NonGeometric::Only(Candidate::Periodic), "periodic"),
        (NonGeometric::Only(Candidate::Both), "periodic"),
    ] {
        let opts = IdentifySettings {
            nongeometric: asked,
            ..IdentifySettings::default()
        };
        let e = identify_tree(&cell, &sim.data, &opts, &mut Silent)
            .unwrap_err()
            .to_string();
        assert!(e.contains(refused) && e.contains("is a tree"), "{e}");
    }
    let rigid = IdentifySettings {
        nongeometric: NonGeometric::Only(Candidate::Kinematic),
        ..IdentifySettings::default()
    };
    let est = identify_tree(&cell, &sim.data, &rigid, &mut Silent).unwrap();
    assert!(est.nongeometric.is_empty());
    assert!(!est.free.iter().any(|n| n.contains(".compliance.")));
}

/// A tree cell's bending errors name the file, line and field: an unknown joint, a coupled
/// joint, a joint with no mass beyond it (no bending moment), a term whose mass is not
/// beyond its joint; a serial cell refuses `bending` by name. `--nongeometric compliance`
/// fits the bending terms, `none` does not; a bent tree's estimate exported warns with
/// every κ⊥ too.
#[test]
fn a_cell_with_bending_says_file_line_and_field_of_what_it_cannot_model() {
    let text = include_str!("../../../../../examples/dual-arm-tree-cell.toml");
    let with = |text: &str, joints: &str| {
        let t = text.replace(
            "[instrument]",
            &format!("[parameters]\nbending = [{joints}]\n\n[instrument]"),
        );
        TreeCell::from_toml(&t, "b.toml")
            .map(|_| ())
            .unwrap_err()
            .to_string()
    };
    let e = with(text, "\"r_x\"");
    assert!(
        e.contains("b.toml") && e.contains("line") && e.contains("parameters.bending"),
        "{e}"
    );
    assert!(e.contains("unknown joint `r_x`"), "{e}");
    let coupled = text.replace(
        "joint_name = \"r_t\"\n",
        "joint_name = \"r_t\"\ncoupled = { r_r = -1, offset_deg = 10 }\n",
    );
    let e = with(&coupled, "\"r_t\"");
    assert!(
        e.contains("parameters.bending") && e.contains("a coupled joint deflects with the joints"),
        "{e}"
    );
    // the last joint: no elbow or wrist beyond it
    let e = with(text, "\"r_t\"");
    assert!(
        e.contains("parameters.bending") && e.contains("`r_t` carries no bending moment"),
        "{e}"
    );
    // a term whose mass is not beyond its joint, as a spec would give it
    let cell = compliant_dual_arm("", true);
    let mut spec = cell.tree.spec().clone();
    let c = spec.compliance.as_mut().unwrap();
    let mut t = c.bending[0].clone();
    t.joint = "r_l".into();
    t.mass = "elbow_r_s".into();
    t.at = Some("r_s".into());
    c.bending.push(t);
    let e = Tree::from_spec(&spec).unwrap_err().to_string();
    assert!(
        e.contains("r_l.bending.elbow_r_s") && e.contains("no bending moment"),
        "{e}"
    );
    let e = paper_cell_with("bending = [\"q2\"]", "bending")
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("parameters.bending") && e.contains("kinematic trees only"),
        "{e}"
    );
    // the export of a bent tree names every κ⊥ it does not hold
    let (sim, est) = noise_free_fit(&cell);
    // `--nongeometric compliance` fits the bending terms with the joint terms; `none` neither
    for (asked, kept) in [(Candidate::Compliance, true), (Candidate::Kinematic, false)] {
        let opts = IdentifySettings {
            nongeometric: NonGeometric::Only(asked),
            ..IdentifySettings::default()
        };
        let e = identify_tree(&cell, &sim.data, &opts, &mut Silent).unwrap();
        for kind in [".bending.", ".compliance."] {
            assert_eq!(
                e.free.iter().any(|n| n.contains(kind)),
                kept,
                "{asked:?}: {:?}",
                e.free
            );
        }
    }
    let acceptance = armcal::Acceptance {
        accepted: false,
        accept: "--accept-unconverged",
        raise_iterations: "--max-iterations",
    };
    let out =
        armcal::export_tree_estimate(&est, Some(&cell), armcal::ExportFormat::Urdf, &acceptance)
            .unwrap();
    let warning = out
        .warnings
        .iter()
        .find(|w| w.starts_with("not held: the joint and lateral (bending) compliance ("))
        .unwrap_or_else(|| panic!("{:?}", out.warnings));
    for p in cell
        .tree
        .registry
        .iter()
        .filter(|p| p.name.contains(".bending."))
    {
        assert!(warning.contains(&p.name), "{warning}");
    }
}
