//! The optimality bound lies below every design found, and the efficiency is reported.

use armcal::design::baselines::{strategy, Strategy};
use armcal::design::bound::optimality_bound;
use armcal::design::exchange::{exchange, ExchangeSettings};
use armcal::design::refine::{refine, RefineSettings};
use armcal::design::{DesignModel, DesignObjective};
use armcal::model::random_configurations;
use armcal::{Cell, Criterion, Silent};
use nalgebra::DMatrix;
use std::path::Path;

#[test]
fn bound_is_below_every_design_and_efficiency_is_high_for_optimised_designs() {
    let cell = Cell::from_file(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper-cell.toml"),
    )
    .unwrap();
    let d = DesignModel::from_cell(&cell).unwrap();
    let pool = random_configurations(&d.model, 800, 11);
    let (lo, hi) = d.model.joint_limits();
    for criterion in [Criterion::Kpi, Criterion::A, Criterion::D] {
        let obj = DesignObjective::new(&d, criterion, &[]);
        let ex = exchange(
            &d,
            criterion,
            &pool,
            &DMatrix::zeros(0, d.n()),
            30,
            &ExchangeSettings::default(),
            &mut Silent,
        )
        .unwrap();
        let start: Vec<Vec<f64>> = ex.chosen.iter().map(|&i| pool[i].clone()).collect();
        let refined = refine(
            &obj,
            &start,
            &lo,
            &hi,
            None,
            &RefineSettings {
                max_iterations: 800,
                ..Default::default()
            },
            &mut Silent,
        )
        .unwrap();
        let b = optimality_bound(&obj, &refined.q, &pool, 20, || |_: &[f64]| true).unwrap();
        let random = strategy(&d.model, Strategy::S4, 30, 4);
        let mut ws = obj.workspace(30);
        let v_random = obj
            .value_and_gradient(&mut ws, &random.concat(), None)
            .unwrap();
        eprintln!(
            "{criterion:?}: random {v_random:.5}, exchange {:.5}, refined {:.5}, lower bound {:.5}, efficiency {:.3}",
            ex.value, refined.value, b.lower_bound, b.efficiency.unwrap_or(f64::NAN)
        );
        assert!(
            b.lower_bound <= refined.value
                && b.lower_bound <= ex.value
                && b.lower_bound <= v_random
        );
        assert!(
            b.efficiency.is_some_and(|e| e > 0.5 && e <= 1.0),
            "efficiency {:?}",
            b.efficiency
        );
    }
}

#[test]
fn book_strategy_one_is_much_worse_than_random() {
    // Book Table 4.6: strategy 1 (all joints together along one curve) is the bad one.
    let cell = Cell::from_file(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper-cell.toml"),
    )
    .unwrap();
    let d = DesignModel::from_cell(&cell).unwrap();
    let obs = |qs: &[Vec<f64>]| {
        let mut ws = armcal::design::InformationWorkspace::new(&d);
        let mut j = DMatrix::zeros(d.rows() * qs.len(), d.n());
        for (i, q) in qs.iter().enumerate() {
            d.jacobian(&mut ws, q);
            j.rows_mut(i * d.rows(), d.rows()).copy_from(&ws.jac);
        }
        armcal::identify::observability(j.as_view()).condition_number
    };
    let k1 = obs(&strategy(&d.model, Strategy::S1, 60, 0));
    let k2 = obs(&strategy(&d.model, Strategy::S2, 60, 0));
    let k3 = obs(&strategy(&d.model, Strategy::S3, 60, 0));
    let k4 = obs(&strategy(&d.model, Strategy::S4, 60, 0));
    eprintln!("condition numbers: S1 {k1:.3e}, S2 {k2:.3e}, S3 {k3:.3e}, S4 {k4:.3e}");
    assert!(k1 > 10.0 * k4 && k1 > k2 && k1 > k3);
}
