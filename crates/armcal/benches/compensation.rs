//! Calibrated inverse kinematics: full-pose solves of the paper robot from a seed within
//! 3° per joint (as from a nominal solution).

use armcal::cell::Cell;
use armcal::compensate::ik::IkWorkspace;
use armcal::compensate::{calibrated_ik, IkSettings, IkTarget};
use armcal::model::identifiability::random_configurations;
use armcal::model::{forward_kinematics, Data};
use armcal::sim::{perturbed_truth, Perturbation};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};

const CELL: &str = include_str!("../../../examples/paper-cell.toml");

fn ik(c: &mut Criterion) {
    let cell = Cell::from_toml(CELL, "paper-cell.toml", std::path::Path::new(".")).expect("cell");
    let model = &cell.model;
    let calibrated = perturbed_truth(
        model,
        &Perturbation {
            all: true,
            ..Default::default()
        },
        3,
    );
    let qs = random_configurations(model, 1000, 4);
    let mut data = Data::new(model);
    let cases: Vec<(IkTarget, Vec<f64>)> = qs
        .iter()
        .enumerate()
        .map(|(i, q)| {
            forward_kinematics(model, &mut data, &calibrated, q);
            let seed = q
                .iter()
                .enumerate()
                .map(|(j, x)| x + 0.05 * (((i * 7 + j * 13) % 11) as f64 / 5.0 - 1.0))
                .collect();
            (IkTarget::Pose(*data.tool()), seed)
        })
        .collect();
    let settings = IkSettings::default();
    let mut ws = IkWorkspace::new(model);
    let mut group = c.benchmark_group("calibrated IK");
    group.throughput(Throughput::Elements(cases.len() as u64));
    group.bench_function("1000 full-pose solves", |b| {
        b.iter(|| {
            for (t, s) in &cases {
                std::hint::black_box(calibrated_ik(model, &calibrated, t, s, &settings, &mut ws));
            }
        })
    });
    group.finish();
}

criterion_group!(benches, ik);
criterion_main!(benches);
