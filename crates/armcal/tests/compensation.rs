//! Calibrated inverse kinematics on 10 000 random reachable poses, and the closed loop:
//! identify a truth robot, filter a program, and execute it on the truth.

use armcal::cell::Cell;
use armcal::compensate::ik::IkWorkspace;
use armcal::compensate::program::filter_joint_program;
use armcal::compensate::{calibrated_ik, IkSettings, IkStatus, IkTarget};
use armcal::identify::{identify, IdentifyOptions, Silent};
use armcal::model::identifiability::random_configurations;
use armcal::model::{forward_kinematics, Data};
use armcal::sim::{perturbed_truth, simulate, Perturbation};
use rand::{Rng, SeedableRng};
use std::path::Path;

fn paper_cell() -> Cell {
    Cell::from_file(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper-cell.toml"))
        .unwrap()
}

#[test]
fn calibrated_ik_reaches_10000_random_poses() {
    let cell = paper_cell();
    let model = &cell.model;
    let calibrated = perturbed_truth(
        model,
        &Perturbation {
            all: true,
            ..Default::default()
        },
        3,
    );
    let qs = random_configurations(model, 10_000, 4);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let mut data = Data::new(model);
    let mut ws = IkWorkspace::new(model);
    let settings = IkSettings::default();
    let (mut converged, mut singular, mut other) = (0, 0, 0);
    for q in &qs {
        forward_kinematics(model, &mut data, &calibrated, q);
        let target = IkTarget::Pose(*data.tool());
        // Seed: the configuration disturbed by up to 3° per joint (a nominal solution).
        let seed: Vec<f64> = q
            .iter()
            .map(|x| x + rng.random_range(-0.05..0.05))
            .collect();
        let r = calibrated_ik(model, &calibrated, &target, &seed, &settings, &mut ws);
        match r.status {
            IkStatus::Converged => {
                converged += 1;
                assert!(
                    r.position_error < 1e-3 && r.orientation_error < 1e-6,
                    "{r:?}"
                );
            }
            IkStatus::Singular => singular += 1,
            _ => other += 1,
        }
    }
    eprintln!("IK: {converged} converged, {singular} near a singularity, {other} other of 10 000");
    assert!(converged >= 9_900, "{converged}");
    assert!(
        other <= 20,
        "{other} solves ended neither converged nor at a reported singularity"
    );
}

#[test]
fn closed_loop_filtered_program_hits_targets_within_predicted_uncertainty() {
    // A laser tracker of realistic precision (20 µm per axis; the paper's 1 mm would hide
    // the effect under the identification uncertainty).
    let mut cell = paper_cell();
    let noise = armcal::measure::NoiseModel::Constant {
        sigma: [0.02; 3],
        sigma_angle: 1e-5,
    };
    cell.instrument.as_mut().unwrap().noise = noise.clone();
    let model = &cell.model;
    let truth = perturbed_truth(model, &Perturbation::default(), 12);
    let qs = random_configurations(model, 120, 13);
    let data = simulate(model, &truth, &qs, Some(&noise), 14).unwrap();
    let est = identify(&cell, &data, &IdentifyOptions::default(), &mut Silent).unwrap();
    let calibrated = est.params_for(model).unwrap();
    // A small working program: 20 configurations within ±15° of a reach-forward-and-down
    // pose (away from the stretched-elbow singularity, where no solution exists).
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(15);
    let center = [0.0f64, -30.0, 60.0, 0.0, -60.0, 0.0].map(f64::to_radians);
    let program: Vec<(String, Vec<f64>)> = (0..20)
        .map(|i| {
            let q = center
                .iter()
                .map(|c| c + rng.random_range(-0.26..0.26))
                .collect();
            (format!("{}", i + 1), q)
        })
        .collect();
    let rows = filter_joint_program(
        model,
        &model.nominal(),
        &calibrated,
        &program,
        &IkSettings::default(),
    );
    let mut d = Data::new(model);
    let (mut miss_nominal, mut miss_filtered) = (0.0f64, 0.0f64);
    for row in &rows {
        assert_eq!(row.result.status, IkStatus::Converged, "{row:?}");
        forward_kinematics(model, &mut d, &model.nominal(), &row.q_nominal);
        let wanted = d.tool().trans;
        forward_kinematics(model, &mut d, &truth, &row.q_nominal);
        miss_nominal = miss_nominal.max((d.tool().trans - wanted).norm());
        forward_kinematics(model, &mut d, &truth, &row.result.q);
        miss_filtered = miss_filtered.max((d.tool().trans - wanted).norm());
    }
    // What the identification uncertainty predicts for the TCP: 3σ of its position.
    let predicted = 3.0 * est.tcp[0].covariance.trace().sqrt();
    eprintln!("closed loop: max miss nominal {miss_nominal:.3} mm, filtered {miss_filtered:.3} mm, predicted 3σ at q_work {predicted:.3} mm");
    assert!(miss_filtered <= miss_nominal / 10.0);
    assert!(miss_filtered <= 2.0 * predicted);
}

#[test]
fn damping_keeps_wrist_corrections_bounded_near_the_wrist_singularity() {
    // Book Table 5.7 (check 9): at θ5 = −1°, a small pose correction with γ → 0 asks for
    // large, opposite motions of joints 4 and 6; damping keeps them small.
    use armcal::compensate::ik::{damped_step, task_jacobian};
    use nalgebra::{DVector, Vector3};
    let cell = paper_cell();
    let model = &cell.model;
    let p = model.nominal();
    let q = [0.0, -30.0, 60.0, 20.0, -1.0, 10.0].map(f64::to_radians);
    let mut data = Data::new(model);
    forward_kinematics(model, &mut data, &p, &q);
    let length = 1000.0;
    let j = task_jacobian(&data, 6, length);
    // A correction of 0.5 mm and 0.2° about the world x axis (perpendicular to the wrist).
    let w = Vector3::new(0.2f64.to_radians(), 0.0, 0.0);
    let e = DVector::from_vec(vec![
        0.5,
        0.0,
        0.0,
        w[0] * length,
        w[1] * length,
        w[2] * length,
    ]);
    let (jtj, jte) = (j.tr_mul(&j), j.tr_mul(&e));
    let undamped = damped_step(&jtj, &jte, 1e-12).unwrap();
    let damped = damped_step(&jtj, &jte, 1e4).unwrap();
    let deg = |v: f64| v.to_degrees().abs();
    eprintln!(
        "θ5 = −1°: Δθ4 = {:.2}°, Δθ6 = {:.2}° undamped; {:.3}°, {:.3}° damped",
        undamped[3].to_degrees(),
        undamped[5].to_degrees(),
        damped[3].to_degrees(),
        damped[5].to_degrees()
    );
    assert!(
        deg(undamped[3]) > 5.0 && deg(undamped[5]) > 5.0,
        "γ → 0 blows up the wrist"
    );
    assert!(undamped[3] * undamped[5] < 0.0, "Δθ4 ≈ −Δθ6");
    assert!(deg(damped[3]) < 0.5 * deg(undamped[3]));
}
