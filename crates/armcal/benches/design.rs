//! Pose-design benchmarks: one KPI design of 60 poses for the paper cell (27 parameters),
//! without and with collision avoidance (the planner's default settings: 2 starts).

use armcal::cell::Cell;
use armcal::design::plan::{plan, PlanSettings};
use criterion::{criterion_group, criterion_main, Criterion};

const CELL: &str = include_str!("../../../examples/paper-cell.toml");
const CELL_OBSTACLES: &str = include_str!("../../../examples/paper-cell-obstacles.toml");

fn design(c: &mut Criterion) {
    let mut group = c.benchmark_group("plan");
    group.sample_size(10);
    for (name, text, collisions) in [
        ("KPI, 60 poses, no collisions", CELL, false),
        ("KPI, 60 poses, collisions", CELL_OBSTACLES, true),
    ] {
        let cell = Cell::from_toml(text, "cell.toml", std::path::Path::new(".")).expect("cell");
        let settings = PlanSettings {
            collisions,
            ..PlanSettings::default()
        };
        group.bench_function(name, |b| {
            b.iter(|| plan(&cell, &settings, &[]).expect("plan"))
        });
    }
    group.finish();
}

criterion_group!(benches, design);
criterion_main!(benches);
