//! `armcal accuracy` on a large data file: 80 000 position measurements of the paper cell,
//! 20 000 commanded poses each approached 4 times (encoder jitter well below the grouping
//! tolerance), grouped into ISO 9283 poses and compared with the model.

use armcal::model::random_configurations;
use armcal::{
    accuracy_report, commanded_poses, perturbed_truth, simulate, AccuracyOrientation, Cell,
    Perturbation, SamePose,
};
use criterion::{criterion_group, criterion_main, Criterion};

use armcal::cell::builtin::PAPER_CELL as CELL;

/// Full width of the joint jitter of repeated approaches (rad): 0.05 mm at a metre.
const JITTER: f64 = 5e-5;

fn accuracy(c: &mut Criterion) {
    let cell =
        Cell::from_toml(CELL, "paper-cell.toml", std::path::Path::new(".")).expect("paper cell");
    let model = &cell.model;
    let truth = perturbed_truth(model, &Perturbation::default(), 1);
    let commanded = random_configurations(model, 20_000, 2);
    let jitter = random_configurations(model, 80_000, 3);
    let qs: Vec<Vec<f64>> = (0..80_000)
        .map(|k| {
            commanded[k % commanded.len()]
                .iter()
                .zip(&model.joints)
                .zip(&jitter[k])
                .map(|((q, j), u)| {
                    let d = JITTER * ((u - j.lower) / (j.upper - j.lower) - 0.5);
                    (q + d).clamp(j.lower, j.upper)
                })
                .collect()
        })
        .collect();
    let data = simulate(model, &truth, &qs, Some(&cell.noise()), 4).expect("simulate");
    let nominal = model.nominal();
    let mut group = c.benchmark_group("accuracy");
    group.sample_size(10);
    group.bench_function("80 000 rows, 20 000 poses × 4", |b| {
        b.iter(|| {
            let poses = commanded_poses(
                model,
                &data.configurations,
                &data.config_ids,
                &SamePose::default(),
            );
            let report = accuracy_report(
                model,
                &nominal,
                &data,
                &poses,
                AccuracyOrientation::IfMeasured,
            )
            .expect("position data");
            assert_eq!(report.poses.len(), 20_000);
            report
        })
    });
    group.finish();
}

criterion_group!(benches, accuracy);
criterion_main!(benches);
