//! Identification benchmark: 1000 simulated poses of the paper cell, 27 free parameters:
//! Levenberg–Marquardt alone from the nominal model on a prepared problem, and the whole
//! root call `armcal::identify` (frames-first start, free set, LM, uncertainty, residuals),
//! the call the CLI and the Python package make (the Python figure is compared with this
//! one, docs/src/reference/benchmarks.md).

use armcal::identify::{levenberg_marquardt, Problem};
use armcal::model::random_configurations;
use armcal::{perturbed_truth, simulate, Cell, LmSettings, Perturbation, Silent};
use criterion::{criterion_group, criterion_main, Criterion};

use armcal::cell::builtin::PAPER_CELL as CELL;

fn identification(c: &mut Criterion) {
    let cell =
        Cell::from_toml(CELL, "paper-cell.toml", std::path::Path::new(".")).expect("paper cell");
    let model = &cell.model;
    let noise = cell.instrument.as_ref().expect("tracker").noise.clone();
    let truth = perturbed_truth(model, &Perturbation::default(), 1);
    let qs = random_configurations(model, 1000, 2);
    let data = simulate(model, &truth, &qs, Some(&noise), 3).expect("simulate");
    let problem = Problem::new(model, &data, &noise).expect("problem");
    assert_eq!(problem.columns(), 27);
    let start = model.nominal();
    let mut group = c.benchmark_group("identification");
    group.sample_size(20);
    group.bench_function("LM, 1000 poses, 27 parameters", |b| {
        b.iter(|| {
            let sol = levenberg_marquardt(&problem, &start, &LmSettings::default(), &mut Silent)
                .expect("solve");
            assert!(sol.status.is_converged());
            sol
        })
    });
    group.bench_function("identify (the root call), 1000 poses, 27 parameters", |b| {
        b.iter(|| {
            let estimate = armcal::identify(
                &cell,
                &data,
                &armcal::IdentifySettings::default(),
                &mut Silent,
            )
            .expect("identify");
            assert!(estimate.solver.status.is_converged());
            estimate
        })
    });
    group.finish();
}

criterion_group!(benches, identification);
criterion_main!(benches);
