//! Plan, measure, identify: the paper's cell from its drawing to a calibrated robot.
//!
//! Plans 30 measurement poses that minimise the predicted TCP variance at the cell's working
//! poses (the paper's KPI criterion, (1/3) tr C_s), measures them on a virtual robot that
//! differs from its drawing, identifies its parameters with their uncertainty, and compares
//! what the design predicted with what the fit reports and with the truth.
//!
//! Run: `cargo run --release -p armcal --example plan_and_calibrate`
//! (the same steps as `armcal plan`, `armcal simulate`, `armcal identify`; guide: "Plan the
//! measurement poses" and "Identify").

use armcal::{
    assess, identify, perturbed_truth, plan, simulate, IdentifySettings, Perturbation,
    PlanSettings, Silent,
};

fn main() -> armcal::Result<()> {
    let cell = armcal::cell::builtin::paper_cell()?;
    let model = &cell.model;

    // Plan: 30 KPI-optimal poses under the joint limits, the tracker's incidence limit and
    // the capsule collision model (paper §3–4).
    let settings = PlanSettings {
        poses: 30,
        ..PlanSettings::default()
    };
    let planned = plan(&cell, &settings, &[], &mut Silent)?;
    assert!(planned.feasible, "the planner found no feasible design");
    let predicted = assess(&cell, &planned.design)?;
    let predicted_kpi = mean_kpi(predicted.tcp.iter().map(|t| t.kpi));
    println!(
        "planned {} poses: predicted (1/3) tr C_s {predicted_kpi:.5} mm² (mean over the working poses: {})",
        planned.design.len(),
        predicted.tcp.iter().map(|t| t.name.as_str()).collect::<Vec<_>>().join(", ")
    );

    // Measure: a virtual robot whose free parameters differ from the drawing (0.5 mm,
    // 0.1° by default), seen by the cell's tracker with its noise model.
    let truth = perturbed_truth(model, &Perturbation::default(), 7);
    let data = simulate(model, &truth, &planned.design, Some(&cell.noise()), 2)?;

    // Identify: Levenberg–Marquardt from the drawing, with the covariance of the estimate.
    let estimate = identify(&cell, &data, &IdentifySettings::default(), &mut Silent)?;
    if !estimate.solver.status.is_converged() {
        return Err(armcal::Error::Input(format!(
            "the fit did not converge ({:?}): not a calibration",
            estimate.solver.status
        )));
    }
    let reported_kpi = mean_kpi(estimate.tcp.iter().map(|t| t.kpi));
    println!(
        "identified {} free parameters in {} iterations: (1/3) tr C_s {reported_kpi:.5} mm²",
        estimate.free.len(),
        estimate.solver.iterations
    );

    // Each free parameter's error against the truth, in units of its stated σ.
    let fitted = estimate.params_for(model)?;
    let mut largest = (String::new(), 0.0_f64);
    for (k, par) in model.registry.iter().enumerate() {
        let Some(p) = estimate.parameters.iter().find(|p| p.name == par.name) else {
            continue;
        };
        if let (true, Some(sigma)) = (p.free, p.sigma) {
            let z = (fitted[k] - truth[k]) / sigma;
            if z.abs() > largest.1.abs() {
                largest = (par.name.clone(), z);
            }
        }
    }
    println!(
        "largest error of a free parameter: {} at {:+.2} σ",
        largest.0, largest.1
    );
    Ok(())
}

/// The mean of the working poses' (1/3) tr C_s.
fn mean_kpi(kpis: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = kpis.fold((0.0, 0usize), |(s, n), k| (s + k, n + 1));
    sum / n.max(1) as f64
}
