//! Identification of a kinematic tree (issue 32): a two-arm robot on a shared torso axis
//! with a coupled wrist joint, fitted as one problem over both arms' rows.

use crate::common::*;
use armcal::model::identifiability::Measurement;
use armcal::model::tree::kinematics::{branch_kinematics, tree_observed_pose, TreeData};
use armcal::progress::Silent;
use armcal::sim::Perturbation;
use armcal::{identify_tree, simulate_tree, IdentifySettings, TreeCell};
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
    let mut r = rng(seed);
    (0..n)
        .map(|i| {
            let q = cell
                .tree
                .joints
                .iter()
                .map(|j| 0.6 * r.random_range(j.lower..j.upper))
                .collect();
            (format!("{}", i + 1), q)
        })
        .collect()
}

/// The position of tree target `t` in the instrument frame at `params`, `q`.
fn position(cell: &TreeCell, params: &[f64], q: &[f64], t: usize) -> Vector3<f64> {
    let tree = &cell.tree;
    let mut data = TreeData::new(tree);
    branch_kinematics(tree, &mut data, tree.targets[t].1, params, q);
    tree_observed_pose(tree, &data, t).trans
}

#[test]
fn a_noise_free_two_arm_tree_with_a_coupled_joint_is_recovered_exactly() {
    let cell = coupled_dual_arm();
    assert_eq!(cell.measurement, Measurement::Position);
    let sim = simulate_tree(
        &cell.tree,
        cell.measurement,
        None,
        &poses(&cell, 60, 3),
        &[],
        &Perturbation::default(),
        7,
    )
    .unwrap();
    let est = identify_tree(&cell, &sim.data, &IdentifySettings::default(), &mut Silent).unwrap();
    assert!(est.solver.status.is_converged(), "{}", est.solver.status);
    // the shared torso and the tracker are one set of parameters fed by both arms
    assert!(
        est.free.iter().any(|n| n.starts_with("t1.")),
        "{:?}",
        est.free
    );
    assert!(est.free.iter().any(|n| n.starts_with("tracker.")));
    assert!(est.free.len() >= 40, "{} free", est.free.len());
    let mut moved = 0;
    for (p, t) in est.parameters.iter().zip(&sim.truth.parameters) {
        assert_eq!(p.name, t.name);
        if !p.free {
            continue;
        }
        moved += usize::from((t.truth - t.nominal).abs() > 1e-6);
        assert!(
            (p.estimate - t.truth).abs() <= 1e-8 * t.truth.abs().max(1.0),
            "{}: estimate {} truth {} (nominal {})",
            p.name,
            p.estimate,
            t.truth,
            t.nominal
        );
    }
    assert!(moved >= 30, "the truth moves the free parameters ({moved})");
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

#[test]
fn the_predicted_tcp_covariance_of_each_arm_matches_monte_carlo() {
    let cell = coupled_dual_arm();
    let tree = &cell.tree;
    let qs = poses(&cell, 30, 5);
    let working = poses(&cell, 1, 11).remove(0).1;
    let exact = Perturbation {
        length: 0.0,
        angle: 0.0,
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
            identify_tree(&cell, &sim.data, &IdentifySettings::default(), &mut Silent).unwrap();
        assert!(est.solver.status.is_converged());
        let params = est.params_for(tree).unwrap();
        for (t, (name, _, _)) in tree.targets.iter().enumerate() {
            if run == 0 {
                predicted[t] = est.tcp_covariance(tree, name, &working).unwrap();
            }
            samples[t].push(position(&cell, &params, &working, t));
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
