//! Kinematics benchmarks: FK + position identification Jacobian of the paper cell (6R,
//! 27 free parameters), the mixed derivative ∂J/∂q, and its weighted sum ∂/∂q ⟨Ω, J⟩ (what
//! a design gradient needs per pose).

use armcal::model::*;
use armcal::Cell;
use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::DMatrix;
use std::hint::black_box;

use armcal::cell::builtin::PAPER_CELL as CELL;

fn paper_cell() -> Cell {
    Cell::from_toml(CELL, "paper-cell.toml", std::path::Path::new(".")).expect("paper cell")
}

fn kinematics(c: &mut Criterion) {
    let cell = paper_cell();
    let model = &cell.model;
    let params = model.nominal();
    let columns = model.registry.free();
    assert_eq!(columns.len(), 27);
    let q = [0.3, -0.4, 0.9, 0.5, -0.7, 1.1];
    let mut data = Data::new(model);
    let mut jac = DMatrix::zeros(3, columns.len());
    c.bench_function(
        "fk + position identification jacobian (6R, 27 params)",
        |b| {
            b.iter(|| {
                forward_kinematics(model, &mut data, black_box(&params), black_box(&q));
                identification_jacobian(
                    model,
                    &data,
                    Observed::Target(0),
                    Rows::Position,
                    &columns,
                    &mut jac,
                    0,
                );
                black_box(&jac);
            })
        },
    );
    c.bench_function("fk only (6R with tracker and reflector)", |b| {
        b.iter(|| {
            forward_kinematics(model, &mut data, black_box(&params), black_box(&q));
            black_box(&data.targets[0]);
        })
    });
    let mut ws = MixedWorkspace::new(model);
    let mut value = DMatrix::zeros(3, columns.len());
    let mut dq = vec![DMatrix::zeros(3, columns.len()); 6];
    c.bench_function(
        "mixed derivative dJ/dq (6 joints × 3 × 27, analytic)",
        |b| {
            b.iter(|| {
                identification_jacobian_dq(
                    model,
                    &mut ws,
                    &params,
                    black_box(&q),
                    Observed::Target(0),
                    Rows::Position,
                    &columns,
                    &mut value,
                    &mut dq,
                );
                black_box(&dq);
            })
        },
    );
    let mut along_ws = AlongWorkspace::new(model);
    let weight = DMatrix::from_fn(3, columns.len(), |r, c| {
        ((r * 31 + c * 7) % 11) as f64 - 5.0
    });
    forward_kinematics(model, &mut data, &params, &q);
    let mut along = [0.0; 6];
    c.bench_function(
        "weighted mixed derivative d<W, J>/dq (6 joints, 3 × 27 weights, from the FK)",
        |b| {
            b.iter(|| {
                along.fill(0.0);
                identification_jacobian_dq_along(
                    model,
                    &mut along_ws,
                    &data,
                    Observed::Target(0),
                    Rows::Position,
                    &columns,
                    black_box(&weight),
                    0,
                    &mut along,
                );
                black_box(&along);
            })
        },
    );
}

criterion_group!(benches, kinematics);
criterion_main!(benches);
