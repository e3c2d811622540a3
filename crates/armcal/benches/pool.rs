//! Choosing 60 of a 2000-pose pool for the D criterion (README rows): the paper cell's full
//! position-only model (27 parameters, tracker frame and reflector unknown), the pool 2000
//! random configurations the tracker can see (incidence ≤ 30°). Timed: the low-rank
//! selection (`select_d`: greedy start and exchange by rank-3 updates, the pool's Jacobians
//! included) and the reference, the greedy D-optimal selection followed by the Fedorov
//! exchange (`baselines::greedy_then_exchange`). Both designs' `log det M` and the D-efficiency
//! of the low-rank selection relative to the reference, `exp((log det M − log det M_ref)/n)`,
//! are printed once before timing.

use armcal::design::baselines::{greedy_then_exchange, random_feasible};
use armcal::design::exchange::pool_jacobians;
use armcal::design::selection::{select_d, SelectionSettings};
use armcal::design::DesignModel;
use armcal::design::{constraint_set, CellConstraints};
use armcal::{Cell, Criterion as DesignCriterion, Silent};
use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::DMatrix;

use armcal::cell::builtin::PAPER_CELL as CELL;

fn pool(c: &mut Criterion) {
    let cell = Cell::from_toml(CELL, "cell.toml", std::path::Path::new(".")).expect("cell");
    let d = DesignModel::from_cell(&cell).expect("design model");
    let n = d.n();
    assert_eq!(n, 27);
    let set = constraint_set(&cell, false).expect("constraints");
    let cons = CellConstraints::new(&set, &d.params);
    let (pool, _) =
        random_feasible(&d.model, 2000, 11, 2_000_000, |q| cons.feasible(q)).expect("pool");
    let prior = DMatrix::zeros(0, n);
    let ours = || {
        let jp = pool_jacobians(&d, &pool);
        select_d(
            &jp,
            d.rows(),
            &prior,
            60,
            &SelectionSettings::default(),
            &mut Silent,
        )
        .expect("selection")
    };
    let reference = || {
        greedy_then_exchange(&d, DesignCriterion::D, &pool, &prior, 60, &mut Silent)
            .expect("reference")
    };
    let a = ours();
    let b = reference();
    // The D criterion is log det C / n = −log det M / n.
    let ref_log_det = -b.value * n as f64;
    eprintln!(
        "low-rank selection: log det M = {:.4} (greedy {:.4}; {} sweeps, {} exchanges) in {:.3} s",
        a.log_det,
        a.greedy_log_det,
        a.sweeps,
        a.exchanges,
        a.time.as_secs_f64()
    );
    eprintln!(
        "greedy + Fedorov exchange: log det M = {ref_log_det:.4} ({} sweeps, {} exchanges) in {:.3} s",
        b.sweeps,
        b.exchanges,
        b.time.as_secs_f64()
    );
    eprintln!(
        "D-efficiency of the low-rank selection relative to the reference: {:.5}",
        ((a.log_det - ref_log_det) / n as f64).exp()
    );
    let mut group = c.benchmark_group("pool");
    group.sample_size(10);
    group.bench_function("D, 60 of 2000, low-rank selection", |b| b.iter(ours));
    group.bench_function("D, 60 of 2000, greedy + Fedorov exchange", |b| {
        b.iter(reference)
    });
    group.finish();
}

criterion_group!(benches, pool);
criterion_main!(benches);
