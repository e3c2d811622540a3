//! Pose-design benchmarks, the README rows: one KPI design of 60 poses for the paper cell
//! (27 parameters) without collision avoidance (`examples/paper-cell.toml`: joint limits
//! and the incidence limit) and with it (`examples/paper-cell-obstacles.toml`, 67
//! constraints per pose), with the planner's default settings (2 starts in parallel); and one
//! campaign re-plan step: 10 new poses given 40 measured (the paper cell, no collisions); and
//! one evaluation of the design objective and its gradient (60 poses); and one start's
//! exchange (60 of the 500 feasible pool poses, the planner's defaults). The
//! criterion value, feasibility and bound of each design are printed once before timing.
//! The 90-manipulator study is timed by the CLI:
//! `time ./target/release/armcal study paper --collisions on --out DIR`.

use armcal::design::baselines::random_feasible;
use armcal::design::exchange::{exchange, ExchangeSettings};
use armcal::design::DesignModel;
use armcal::design::DesignObjective;
use armcal::design::{constraint_set, CellConstraints, EXCHANGE_TOLERANCE_BEFORE_REFINEMENT};
use armcal::{plan, Cell, Criterion as KpiCriterion, PlanSettings, Silent};
use criterion::{criterion_group, criterion_main, Criterion};

use armcal::cell::builtin::PAPER_CELL as CELL;
use armcal::cell::builtin::PAPER_CELL_OBSTACLES as CELL_OBSTACLES;

fn design(c: &mut Criterion) {
    let mut group = c.benchmark_group("plan");
    group.sample_size(10);
    for (name, text, collisions, poses, measured) in [
        ("KPI, 60 poses, no collisions", CELL, false, 60, 0),
        ("KPI, 60 poses, collisions", CELL_OBSTACLES, true, 60, 0),
        (
            "KPI, 10 poses given 40 measured, no collisions",
            CELL,
            false,
            10,
            40,
        ),
    ] {
        let cell = Cell::from_toml(text, "cell.toml", std::path::Path::new(".")).expect("cell");
        assert_eq!(cell.model.registry.free().len(), 27);
        let settings = PlanSettings {
            poses,
            collisions,
            ..PlanSettings::default()
        };
        // The measured poses: a 40-pose KPI design of another seed.
        let measured = if measured > 0 {
            let first = PlanSettings {
                poses: measured,
                seed: 2,
                ..settings.clone()
            };
            plan(&cell, &first, &[], &mut Silent).expect("plan").design
        } else {
            Vec::new()
        };
        let r = plan(&cell, &settings, &measured, &mut Silent).expect("plan");
        eprintln!(
            "{name}: (1/3) tr C_s = {:.5} mm², feasible {}, efficiency {:.3}, refinement: {} ({} iterations)",
            r.value,
            r.feasible,
            r.bound.as_ref().and_then(|b| b.efficiency).unwrap_or(f64::NAN),
            r.refine_status.as_deref().unwrap_or("skipped"),
            r.refine_iterations
        );
        group.bench_function(name, |b| {
            b.iter(|| plan(&cell, &settings, &measured, &mut Silent).expect("plan"))
        });
    }
    // One evaluation of φ and ∇φ of the 60-pose KPI design (no collisions), at nearby
    // points so that the objective's cache never answers: the refinement's unit of work.
    let cell = Cell::from_toml(CELL, "cell.toml", std::path::Path::new(".")).expect("cell");
    let settings = PlanSettings {
        collisions: false,
        ..PlanSettings::default()
    };
    let design = plan(&cell, &settings, &[], &mut Silent)
        .expect("plan")
        .design;
    let d = DesignModel::from_cell(&cell).expect("design model");
    let objective = DesignObjective::new(&d, KpiCriterion::Kpi, &[]);
    let mut ws = objective.workspace(design.len());
    let mut u = design.concat();
    let mut g = vec![0.0; u.len()];
    group.bench_function("KPI value and gradient, 60 poses", |b| {
        b.iter(|| {
            u[0] += 1e-12;
            objective
                .value_and_gradient(&mut ws, &u, Some(&mut g))
                .expect("value")
        })
    });
    // One start's exchange as the planner runs it before the refinement: 60 of the 500
    // feasible pool poses (the default pool and seed), sweeps until one gains less than 0.1 %.
    let set = constraint_set(&cell, false).expect("constraints");
    let cons = CellConstraints::new(&set, &d.params);
    let defaults = PlanSettings::default();
    let (pool, _) = random_feasible(
        &d.model,
        defaults.pool,
        defaults.seed,
        defaults.max_draws,
        |q| cons.feasible(q),
    )
    .expect("pool");
    let exchange_settings = ExchangeSettings {
        seed: defaults.seed,
        tolerance: EXCHANGE_TOLERANCE_BEFORE_REFINEMENT,
        ..ExchangeSettings::default()
    };
    group.bench_function("KPI exchange, 60 of 500 pool poses, one start", |b| {
        b.iter(|| {
            exchange(
                &d,
                KpiCriterion::Kpi,
                &pool,
                &objective.prior_rows,
                60,
                &exchange_settings,
                &mut Silent,
            )
            .expect("exchange")
        })
    });
    group.finish();
}

criterion_group!(benches, design);
criterion_main!(benches);
