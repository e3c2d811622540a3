//! Calibrated inverse kinematics of the paper robot with a perturbed (calibrated) model, full
//! tool poses, single thread:
//!
//! * random reachable targets, each seeded from the nominal closed form (the branch nearest a
//!   fixed home configuration; the closed-form solve is part of the timing);
//! * a program path of nearby targets (≈ 1° per joint between rows), each seeded from the
//!   previous row's solution, as in program filtering.

use armcal::compensate::CalibratedIk;
use armcal::model::random_configurations;
use armcal::model::{forward_kinematics, Data};
use armcal::{perturbed_truth, Cell, IkSettings, IkTarget, Perturbation};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};

use armcal::cell::builtin::PAPER_CELL as CELL;

fn ik(c: &mut Criterion) {
    let cell = Cell::from_toml(CELL, "paper-cell.toml", std::path::Path::new(".")).expect("cell");
    let model = &cell.model;
    let nominal = model.nominal();
    let calibrated = perturbed_truth(
        model,
        &Perturbation {
            all: true,
            ..Default::default()
        },
        3,
    );
    let mut data = Data::new(model);
    let mut pose_at = |q: &[f64]| {
        forward_kinematics(model, &mut data, &calibrated, q);
        IkTarget::Pose(*data.tool())
    };
    let random: Vec<IkTarget> = random_configurations(model, 1000, 4)
        .iter()
        .map(|q| pose_at(q))
        .collect();
    // A path: from a random start, every joint moves by up to ±1° per row, kept inside the
    // limits.
    let start = random_configurations(model, 1, 5).remove(0);
    let steps = random_configurations(model, 1000, 6);
    let mut q = start.clone();
    let path: Vec<IkTarget> = steps
        .iter()
        .map(|s| {
            for (k, j) in model.joints.iter().enumerate() {
                let u = (s[k] - j.lower) / (j.upper - j.lower) * 2.0 - 1.0;
                q[k] = (q[k] + u * 1f64.to_radians()).clamp(j.lower + 0.1, j.upper - 0.1);
            }
            pose_at(&q)
        })
        .collect();
    let home: Vec<f64> = model
        .joints
        .iter()
        .map(|j| 0.5 * (j.lower + j.upper))
        .collect();
    let mut ik = CalibratedIk::new(model, &nominal, &calibrated, IkSettings::default());
    let mut group = c.benchmark_group("calibrated IK");
    group.throughput(Throughput::Elements(1000));
    group.bench_function("1000 random poses, closed-form seed", |b| {
        b.iter(|| {
            for t in &random {
                std::hint::black_box(ik.solve(t, &home));
            }
        })
    });
    group.bench_function("1000-row path, previous-row seed", |b| {
        b.iter(|| {
            let mut seed = start.clone();
            for t in &path {
                let r = ik.solve_from(t, &seed);
                seed.copy_from_slice(&r.q);
                std::hint::black_box(r);
            }
        })
    });
    group.finish();
}

criterion_group!(benches, ik);
criterion_main!(benches);
