//! Monte Carlo check of the design's promise: 200 simulated calibrations at the KPI design
//! and at the heuristic design; the empirical ratio of TCP error variances at the working
//! pose matches the predicted ratio within ±15 %.

use crate::common::monte_carlo_tcp_covariances;
use armcal::design::baselines::random_feasible;
use armcal::design::{constraint_set, CellConstraints};
use armcal::design::{DesignModel, DesignObjective};
use armcal::{perturbed_truth, plan, Cell, Criterion, Perturbation, PlanSettings, Silent};
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
    let truth = perturbed_truth(model, &Perturbation::default(), 8);
    let work = [cell.working[0].q.clone()];
    let empirical = |design: &[Vec<f64>], seed: u64| -> f64 {
        monte_carlo_tcp_covariances(&cell, &truth, design, &work, 200, seed)[0].trace() / 3.0
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
