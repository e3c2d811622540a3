//! The planner end to end on the paper cell: feasible designs, the KPI design better than
//! the heuristic and the C_p design, the bound below the design.

use armcal::design::baselines::random_feasible;
use armcal::design::{constraint_set, CellConstraints};
use armcal::design::{DesignModel, DesignObjective};
use armcal::{plan, Cell, Criterion, PlanSettings, Silent};
use std::path::Path;

fn cell(name: &str) -> Cell {
    Cell::from_file(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples")
            .join(name),
    )
    .unwrap()
}

#[test]
fn planner_beats_the_heuristic_with_and_without_collisions() {
    for (file, collisions) in [
        ("paper-cell.toml", false),
        ("paper-cell-obstacles.toml", true),
    ] {
        let c = cell(file);
        let d = DesignModel::from_cell(&c).unwrap();
        let set = constraint_set(&c, collisions).unwrap();
        let cons = CellConstraints::new(&set, &d.params);
        let (heuristic, draws) =
            random_feasible(&d.model, 60, 3, 2_000_000, |q| cons.feasible(q)).unwrap();
        let kpi_obj = DesignObjective::new(&d, Criterion::Kpi, &[]);
        let mut ws = kpi_obj.workspace(60);
        let kpi_of = |qs: &[Vec<f64>], ws: &mut _| {
            kpi_obj.value_and_gradient(ws, &qs.concat(), None).unwrap()
        };
        let h = kpi_of(&heuristic, &mut ws);
        let settings = PlanSettings {
            collisions,
            ..PlanSettings::default()
        };
        let kpi = plan(&c, &settings, &[], &mut Silent).unwrap();
        let a = plan(
            &c,
            &PlanSettings {
                criterion: Criterion::A,
                ..settings.clone()
            },
            &[],
            &mut Silent,
        )
        .unwrap();
        let a_kpi = kpi_of(&a.design, &mut ws);
        eprintln!(
            "{file}: {} constraints/pose, {:.1} % of draws feasible; (1/3) tr C_s heuristic {h:.4}, C_p-optimal {a_kpi:.4}, KPI {:.4} (exchange {:.4}, refine {:?}, {:.2} s); bound {:.4}, efficiency {:.3}; min margin {:?}",
            kpi.constraints_per_pose,
            100.0 * 60.0 / draws as f64,
            kpi.value,
            kpi.exchange_value,
            kpi.refine_status,
            kpi.time.as_secs_f64(),
            kpi.bound.as_ref().unwrap().lower_bound,
            kpi.bound.as_ref().unwrap().efficiency.unwrap(),
            kpi.min_margin
        );
        assert!(kpi.feasible && a.feasible);
        assert!(kpi.min_margin.as_ref().is_none_or(|m| m.value >= 0.0));
        assert!(
            kpi.value < 0.7 * h,
            "KPI design at least 30 % better than the heuristic"
        );
        assert!(
            kpi.value < 0.95 * a_kpi,
            "KPI design better than the C_p design on the KPI"
        );
        assert!(kpi.bound.as_ref().unwrap().lower_bound <= kpi.value);
    }
}

#[test]
fn an_obstacle_over_the_tracker_gives_a_clear_report_and_the_best_design() {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper-cell-obstacles.toml")).unwrap()
        + "\n[[obstacles]]\nname = \"crate-over-tracker\"\nkind = \"capsule\"\na_mm = [2730.88, 4554.68, 1200]\nb_mm = [2730.88, 4554.68, 1600]\nradius_mm = 600\n";
    let c = Cell::from_toml(&text, "blocked.toml", Path::new(".")).unwrap();
    let rep = plan(
        &c,
        &PlanSettings {
            poses: 10,
            max_draws: 20_000,
            ..PlanSettings::default()
        },
        &[],
        &mut Silent,
    )
    .unwrap();
    assert!(!rep.feasible);
    assert!(
        matches!(rep.status, armcal::Status::Infeasible { .. }),
        "{}",
        rep.status
    );
    assert_eq!(rep.design.len(), 10);
    assert_eq!(rep.blocking[0].0, "beam / crate-over-tracker");
    assert!(rep.blocking[0].1 > 0.99);
    assert!(rep.min_margin.unwrap().value < 0.0);
}

/// A design of the fewest poses that identify the free set (a campaign's first batch, 9
/// poses for the paper cell's 27 parameters) does not depend on the seed's luck: with the
/// default 2 starts, seeds 1, 5 and 7 kept an exchange design of KPI 48–109 mm² (TCP σ
/// 7–10 mm) whose refinement was rejected, where the other seeds refined to 2.4–2.8 mm²;
/// when no start's refinement is accepted the planner now runs more starts, and every seed
/// of 1–8 lands within a factor 1.5 of the best.
#[test]
fn a_minimal_design_does_not_depend_on_the_seeds_luck() {
    let c = crate::common::paper_cell_with_default_margins();
    let values: Vec<f64> = (1..=8u64)
        .map(|seed| {
            let r = plan(
                &c,
                &PlanSettings {
                    poses: 9,
                    seed,
                    ..PlanSettings::default()
                },
                &[],
                &mut Silent,
            )
            .unwrap();
            assert!(r.feasible, "seed {seed}");
            r.value
        })
        .collect();
    let best = values.iter().copied().fold(f64::INFINITY, f64::min);
    assert!(
        values.iter().all(|&v| v <= 1.5 * best),
        "KPI per seed 1–8: {values:?}"
    );
}

/// The paper cell with its instrument's σ (position and angle) multiplied by `factor`.
fn with_noise_scaled(mut c: Cell, factor: f64) -> Cell {
    use armcal::measure::NoiseModel;
    let instrument = c.instrument.as_mut().unwrap();
    let NoiseModel::Constant { sigma, sigma_angle } = &mut instrument.noise else {
        panic!("the paper cell's noise is constant");
    };
    sigma.iter_mut().for_each(|s| *s *= factor);
    *sigma_angle *= factor;
    c
}

/// C_p scales with σ², so every criterion scales by σ² (the KPI) and the planned design does
/// not depend on σ: nothing in the exchange, the refinement or its acceptance may compare a
/// σ-dependent quantity with an absolute threshold. Scaling σ by a power of two scales every
/// intermediate exactly, so the design must be bit-identical and the value exactly σ²-scaled,
/// over 2⁻¹⁰…2⁴ — both for 60 poses (refinement accepted) and for 9 poses (the fewest, where
/// starts' refinements end near rank deficiency and are rejected). A scale that is not a
/// power of two (σ/20) rounds differently, and the non-convex descent may then end at another
/// local optimum of nearly the same value (measured: 0.02 % apart for 60 poses, 0.6 % for 9).
#[test]
fn a_planned_design_does_not_depend_on_the_noise_scale() {
    for poses in [60, 9] {
        let settings = PlanSettings {
            poses,
            collisions: false,
            starts: 2,
            ..PlanSettings::default()
        };
        let base = plan(&cell("paper-cell.toml"), &settings, &[], &mut Silent).unwrap();
        for factor in [2f64.powi(-10), 2f64.powi(-4), 16.0] {
            let scaled = plan(
                &with_noise_scaled(cell("paper-cell.toml"), factor),
                &settings,
                &[],
                &mut Silent,
            )
            .unwrap();
            assert!(
                scaled.design == base.design,
                "{poses} poses, σ × {factor}: another design"
            );
            assert_eq!(scaled.value, base.value * factor * factor);
            assert_eq!(scaled.exchange_value, base.exchange_value * factor * factor);
            assert_eq!(scaled.refine_status, base.refine_status);
        }
        let twentieth = plan(
            &with_noise_scaled(cell("paper-cell.toml"), 0.05),
            &settings,
            &[],
            &mut Silent,
        )
        .unwrap();
        let ratio = twentieth.value / (base.value * 0.05 * 0.05);
        assert!(
            (ratio - 1.0).abs() < 0.02,
            "{poses} poses: σ/20 value ratio {ratio}"
        );
    }
}
