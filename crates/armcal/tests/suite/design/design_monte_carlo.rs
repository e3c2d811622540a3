//! Monte Carlo check of the design's promise: 200 simulated calibrations at the KPI design
//! and at the heuristic design; the empirical ratio of TCP error variances at the working
//! pose matches the predicted ratio within ±15 %.

use armcal::cell::Cell;
use armcal::design::baselines::random_feasible;
use armcal::design::plan::{constraint_set, plan, CellConstraints, PlanSettings};
use armcal::design::{Criterion, DesignModel, DesignObjective};
use armcal::identify::{solve, IdentifySettings, Problem};
use armcal::model::{forward_kinematics, observed_position, Data, Observed};
use armcal::progress::Silent;
use armcal::sim::{perturbed_truth, simulate, Perturbation};
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;
use std::path::Path;

#[test]
fn kpi_design_variance_gain_holds_in_monte_carlo() {
    let cell = Cell::from_file(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper-cell.toml"),
    )
    .unwrap();
    let model = &cell.model;
    let d = DesignModel::from_cell(&cell).unwrap();
    let set = constraint_set(&cell, false).unwrap();
    let cons = CellConstraints::new(&set, &d.params);
    let (heuristic, _) = random_feasible(model, 60, 5, 2_000_000, |q| cons.feasible(q)).unwrap();
    let kpi = plan(
        &cell,
        &PlanSettings {
            collisions: false,
            exchange_only: true,
            pool: 600,
            starts: 1,
            ..Default::default()
        },
        &[],
        &mut Silent,
    )
    .unwrap();
    let obj = DesignObjective::new(&d, Criterion::Kpi, &[]);
    let mut ws = obj.workspace(60);
    let pred_h = obj
        .value_and_gradient(&mut ws, &heuristic.concat(), None)
        .unwrap();
    let pred_k = obj
        .value_and_gradient(&mut ws, &kpi.design.concat(), None)
        .unwrap();
    let noise = cell.instrument.as_ref().unwrap().noise.clone();
    let truth = perturbed_truth(model, &Perturbation::default(), 8);
    let work = cell.working[0].q.clone();
    let tcp = |p: &[f64]| {
        let mut data = Data::new(model);
        forward_kinematics(model, &mut data, p, &work);
        observed_position(&data, Observed::Tool)
    };
    let empirical = |design: &[Vec<f64>], offset: u64| -> f64 {
        let est: Vec<Vector3<f64>> = (0..200u64)
            .into_par_iter()
            .map(|s| {
                let data = simulate(model, &truth, design, Some(&noise), offset + s).unwrap();
                let mut p = Problem::new(model, &data, &noise).unwrap();
                let (sol, _, _) = solve(
                    &mut p,
                    &model.nominal(),
                    &IdentifySettings::default(),
                    &mut Silent,
                )
                .unwrap();
                tcp(&sol.params)
            })
            .collect();
        let n = est.len() as f64;
        let mean = est.iter().fold(Vector3::zeros(), |a, b| a + b) / n;
        let c = est.iter().fold(Matrix3::zeros(), |a, e| {
            a + (e - mean) * (e - mean).transpose()
        }) / (n - 1.0);
        c.trace() / 3.0
    };
    let emp_h = empirical(&heuristic, 10_000);
    let emp_k = empirical(&kpi.design, 20_000);
    let (pred_ratio, emp_ratio) = (pred_k / pred_h, emp_k / emp_h);
    eprintln!("(1/3) tr C_s predicted heuristic {pred_h:.4}, KPI {pred_k:.4} (ratio {pred_ratio:.3}); empirical {emp_h:.4}, {emp_k:.4} (ratio {emp_ratio:.3})");
    assert!(
        (emp_ratio / pred_ratio - 1.0).abs() <= 0.15,
        "empirical ratio {emp_ratio:.3} vs predicted {pred_ratio:.3}"
    );
    assert!(pred_ratio < 0.7);
}
