//! Geometry benchmarks: segment–segment distance with its endpoint gradient (the kernel of
//! every capsule constraint, paper eq. 20–23), and the full constraint set of the paper cell
//! with obstacles (FK + 67 values + 67 × 6 Jacobian).

use armcal::design::{ConstraintSet, ConstraintSettings};
use armcal::geometry::segment_distance;
use armcal::Cell;
use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::Vector3;
use std::hint::black_box;

use armcal::cell::builtin::PAPER_CELL_OBSTACLES as CELL;

fn geometry(c: &mut Criterion) {
    // A general pair, a parallel pair and a point–segment pair, as capsule checks meet them.
    let pairs = [
        [
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(650.0, 120.0, -40.0),
            Vector3::new(300.0, -200.0, 400.0),
            Vector3::new(420.0, 500.0, -300.0),
        ],
        [
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(600.0, 0.0, 0.0),
            Vector3::new(100.0, 250.0, 0.0),
            Vector3::new(900.0, 250.0, 0.0),
        ],
        [
            Vector3::new(10.0, 20.0, 30.0),
            Vector3::new(10.0, 20.0, 30.0),
            Vector3::new(-500.0, 0.0, 0.0),
            Vector3::new(500.0, 100.0, 0.0),
        ],
    ];
    for (name, p) in ["general", "parallel", "point"].iter().zip(&pairs) {
        c.bench_function(&format!("segment distance + gradient ({name})"), |b| {
            b.iter(|| {
                let sd = segment_distance(
                    black_box(&p[0]),
                    black_box(&p[1]),
                    black_box(&p[2]),
                    black_box(&p[3]),
                );
                black_box((sd.distance, sd.gradient()))
            })
        });
    }

    let cell = Cell::from_toml(CELL, "paper-cell-obstacles.toml", std::path::Path::new("."))
        .expect("paper cell");
    let set = ConstraintSet::new(&cell, &ConstraintSettings::default()).expect("constraints");
    let params = cell.model.nominal();
    let q = [0.3, -0.4, 0.9, 0.5, -0.7, 1.1];
    let mut ws = set.workspace();
    let mut values = vec![0.0; set.len()];
    let mut jac = vec![0.0; set.len() * set.dof()];
    c.bench_function(
        &format!(
            "paper cell constraints: FK + {} values + jacobian",
            set.len()
        ),
        |b| {
            b.iter(|| {
                set.evaluate(
                    &mut ws,
                    black_box(&params),
                    black_box(&q),
                    &mut values,
                    Some(&mut jac),
                );
                black_box(&jac);
            })
        },
    );
}

criterion_group!(benches, geometry);
criterion_main!(benches);
