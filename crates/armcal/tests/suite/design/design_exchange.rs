//! The exchange algorithm improves on random designs, and the KPI design beats the
//! parameter-variance design on the KPI (paper Table 7's picture, without constraints).

use armcal::design::exchange::{exchange, ExchangeSettings};
use armcal::design::{DesignModel, DesignObjective};
use armcal::model::random_configurations;
use armcal::{Cell, Criterion, Silent};
use nalgebra::DMatrix;
use std::path::Path;

#[test]
fn kpi_exchange_beats_random_and_parameter_variance_designs() {
    let cell = Cell::from_file(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper-cell.toml"),
    )
    .unwrap();
    let d = DesignModel::from_cell(&cell).unwrap();
    let pool = random_configurations(&d.model, 2000, 3);
    let none = DMatrix::zeros(0, d.n());
    let kpi_of = |qs: &[Vec<f64>]| {
        let obj = DesignObjective::new(&d, Criterion::Kpi, &[]);
        let mut ws = obj.workspace(qs.len());
        obj.value_and_gradient(&mut ws, &qs.concat(), None).unwrap()
    };
    let random: Vec<Vec<f64>> = pool[..60].to_vec();
    let kpi_random = kpi_of(&random);
    let s = ExchangeSettings::default();
    let a = exchange(&d, Criterion::A, &pool, &none, 60, &s, &mut Silent).unwrap();
    let kpi = exchange(&d, Criterion::Kpi, &pool, &none, 60, &s, &mut Silent).unwrap();
    let pick = |r: &[usize]| r.iter().map(|&i| pool[i].clone()).collect::<Vec<_>>();
    let kpi_a = kpi_of(&pick(&a.chosen));
    let kpi_k = kpi_of(&pick(&kpi.chosen));
    eprintln!(
        "(1/3) tr C_s: random {kpi_random:.4}, A-optimal {kpi_a:.4}, KPI-optimal {kpi_k:.4} mm² ({} sweeps, {} exchanges, {:.2} s)",
        kpi.sweeps, kpi.exchanges, kpi.time.as_secs_f64()
    );
    assert!((kpi.value - kpi_k).abs() < 1e-9 * kpi_k);
    // Without the incidence limit random poses are far more varied than the paper's
    // heuristic (which keeps only the ≈6 % of draws the tracker can see), so the gain over
    // random is smaller here than the paper's 40 %; the study with constraints checks that.
    assert!(
        kpi_k < 0.8 * kpi_random,
        "KPI design ≥ 20 % better than unconstrained random"
    );
    assert!(
        kpi_k < 0.9 * kpi_a,
        "KPI design ≥ 10 % better than the A design"
    );
    for c in [Criterion::D, Criterion::E, Criterion::O1, Criterion::O3] {
        let r = exchange(
            &d,
            c,
            &pool,
            &none,
            60,
            &ExchangeSettings {
                max_sweeps: 3,
                ..s.clone()
            },
            &mut Silent,
        )
        .unwrap();
        assert!(
            r.history.last().unwrap() <= &r.history[0],
            "{c:?} must not get worse"
        );
    }
}
