//! Compensate a joint program with a calibration, and check it on the robot it came from.
//!
//! Identifies a virtual robot from 40 random measurement poses, filters a 200-row joint
//! program through the calibrated inverse kinematics (book §8.2: each row's joints are
//! replaced by those with which the *calibrated* robot reaches the pose the nominal model
//! predicts), then runs both programs on the virtual robot and compares how far its tool lands
//! from where the program meant it to be.
//!
//! Run: `cargo run --release -p armcal --example compensate_program`
//! (the same as `armcal compensate --program …`; guide: "Compensation and exports").

use std::collections::BTreeMap;

use armcal::compensate::filter_joint_program;
use armcal::model::{random_configurations, tool_pose};
use armcal::{
    identify, perturbed_truth, simulate, IdentifySettings, IkSettings, IkStatus, Perturbation,
    Silent,
};

fn main() -> armcal::Result<()> {
    let cell = armcal::cell::builtin::paper_cell()?;
    let model = &cell.model;
    let truth = perturbed_truth(model, &Perturbation::default(), 11);
    let measured = random_configurations(model, 40, 3);
    let data = simulate(model, &truth, &measured, Some(&cell.noise()), 4)?;
    let estimate = identify(&cell, &data, &IdentifySettings::default(), &mut Silent)?;
    if !estimate.solver.status.is_converged() {
        return Err(armcal::Error::Input(
            "the fit did not converge: not a calibration".into(),
        ));
    }
    let nominal = model.nominal();
    let calibrated = estimate.params_for(model)?;

    // A program taught on the nominal model: joint values per row.
    let program: Vec<(String, Vec<f64>)> = random_configurations(model, 200, 5)
        .into_iter()
        .enumerate()
        .map(|(i, q)| (format!("row{}", i + 1), q))
        .collect();
    let rows = filter_joint_program(
        model,
        &nominal,
        &calibrated,
        &program,
        &IkSettings::default(),
    );

    // Each row's miss on the virtual robot: where its tool goes minus where the program
    // meant it to go (the nominal model's pose of the program's joints).
    let miss = |q: &[f64], q_program: &[f64]| {
        (tool_pose(model, &truth, q).trans - tool_pose(model, &nominal, q_program).trans).norm()
    };
    // Rows that could not be compensated (a singularity, a joint limit, a joint change over
    // the limit) keep a status of their own and are counted, never called converged.
    let mut statuses: BTreeMap<&str, usize> = BTreeMap::new();
    let (mut before, mut after) = (Vec::new(), Vec::new());
    for row in &rows {
        *statuses.entry(row.result.status.name()).or_default() += 1;
        if row.result.status == IkStatus::Converged {
            before.push(miss(&row.q_nominal, &row.q_nominal));
            after.push(miss(&row.result.q, &row.q_nominal));
        }
    }
    println!("rows by status: {statuses:?}");
    let rms = |m: &[f64]| (m.iter().map(|x| x * x).sum::<f64>() / m.len().max(1) as f64).sqrt();
    let largest = |m: &[f64]| m.iter().fold(0.0_f64, |a, &b| a.max(b));
    println!(
        "miss on the robot over the compensated rows: RMS {:.3} mm, largest {:.3} mm as taught; \
         RMS {:.3} mm, largest {:.3} mm compensated",
        rms(&before),
        largest(&before),
        rms(&after),
        largest(&after)
    );
    // What the calibration's own uncertainty predicts for the compensated miss: the TCP σ at
    // the cell's working poses.
    for t in &estimate.tcp {
        println!(
            "stated TCP σ at working pose {}: {:.3} mm",
            t.name,
            t.kpi.sqrt()
        );
    }
    Ok(())
}
