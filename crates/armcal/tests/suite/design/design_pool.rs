//! Planning from the user's own pose pool (`plan --pool`): a 2000-row pool of the paper cell
//! with rows outside the joint limits and rows the tracker cannot see. The chosen rows are
//! all feasible and none of the infeasible ones; the infeasible rows are listed exactly;
//! the D value is at least as good as the greedy D-optimal selection + Fedorov exchange;
//! `refine_radius` keeps every joint within the radius of its pool pose (checked against
//! the pool file's degrees); every criterion runs; bad pools give clear errors.

use armcal::design::baselines::{greedy_then_exchange, random_feasible};
use armcal::design::plan_from_pool;
use armcal::design::{constraint_set, CellConstraints};
use armcal::design::{DesignModel, DesignObjective};
use armcal::measure::csv;
use armcal::model::random_configurations;
use armcal::{Cell, Criterion, DesignRecord, PoolSettings, Silent};
use nalgebra::DMatrix;
use std::collections::BTreeSet;
use std::path::Path;

fn paper_cell() -> Cell {
    Cell::from_file(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper-cell.toml"))
        .unwrap()
}

/// A pool text of `feasible` feasible rows with `blind` rows the tracker cannot see and
/// `outside` rows beyond a joint limit mixed in at known rows (1-based); the rows in
/// internal units.
pub fn pool(
    cell: &Cell,
    feasible: usize,
    blind: usize,
    outside: usize,
    seed: u64,
) -> (String, Vec<Vec<f64>>, BTreeSet<usize>) {
    let d = DesignModel::from_cell(cell).unwrap();
    let set = constraint_set(cell, true).unwrap();
    let cons = CellConstraints::new(&set, &d.params);
    let (good, _) =
        random_feasible(&d.model, feasible, seed, 2_000_000, |q| cons.feasible(q)).unwrap();
    let mut bad: Vec<Vec<f64>> = random_configurations(&d.model, 50 * blind + 10, seed + 1)
        .into_iter()
        .filter(|q| !cons.feasible(q))
        .take(blind)
        .collect();
    assert_eq!(bad.len(), blind);
    for (k, q0) in good.iter().take(outside).enumerate() {
        let mut q = q0.clone();
        let j = k % q.len();
        q[j] = d.model.joints[j].upper + 0.1;
        bad.push(q);
    }
    let total = feasible + bad.len();
    let mut rows = Vec::with_capacity(total);
    let mut infeasible = BTreeSet::new();
    let (mut g, mut b) = (good.into_iter(), bad.into_iter());
    for r in 0..total {
        // The infeasible rows spread evenly (Bresenham).
        let nb = blind + outside;
        if (r + 1) * nb / total > r * nb / total {
            rows.push(b.next().unwrap());
            infeasible.insert(r + 1);
        } else {
            rows.push(g.next().unwrap());
        }
    }
    assert_eq!(infeasible.len(), blind + outside);
    (csv::write_configurations(&d.model, &rows), rows, infeasible)
}

fn d_value(d: &DesignModel, qs: &[Vec<f64>], criterion: Criterion) -> f64 {
    let obj = DesignObjective::new(d, criterion, &[]);
    let mut ws = obj.workspace(qs.len());
    obj.value_and_gradient(&mut ws, &qs.concat(), None).unwrap()
}

#[test]
fn a_2000_row_pool_gives_a_feasible_d_design_as_good_as_greedy_plus_exchange() {
    let cell = paper_cell();
    let d = DesignModel::from_cell(&cell).unwrap();
    let (text, rows, infeasible) = pool(&cell, 1900, 80, 20, 21);
    assert_eq!(rows.len(), 2000);
    let read = csv::read_configurations_str(&text, "pool.csv", &cell.model, None).unwrap();
    let settings = PoolSettings {
        poses: 60,
        criterion: Criterion::D,
        ..PoolSettings::default()
    };
    let p = plan_from_pool(&cell, &read, "pool.csv", &settings, &[], &mut Silent).unwrap();
    // The infeasible rows, exactly, each with its reason.
    let listed: BTreeSet<usize> = p.pool.infeasible.iter().map(|r| r.pose.row).collect();
    assert_eq!(listed, infeasible);
    assert_eq!(p.pool.rows, 2000);
    assert_eq!(p.pool.feasible, 2000 - infeasible.len());
    let limits = p
        .pool
        .infeasible
        .iter()
        .filter(|r| r.constraint.starts_with("joint limits: "))
        .count();
    assert_eq!(limits, 20);
    assert!(p
        .pool
        .infeasible
        .iter()
        .all(|r| r.margin < 0.0 && !r.constraint.is_empty()));
    // The chosen rows: distinct, feasible, none listed, and the design is those rows.
    let chosen: BTreeSet<usize> = p.pool.chosen.iter().map(|r| r.row).collect();
    assert_eq!(chosen.len(), 60);
    assert!(chosen.is_disjoint(&infeasible));
    assert!(p.plan.feasible);
    for (q, r) in p.plan.design.iter().zip(&p.pool.chosen) {
        assert_eq!(r.id, r.row.to_string());
        for (a, b) in q.iter().zip(&read[r.row - 1].1) {
            assert_eq!(a, b);
        }
    }
    // At least as good as the reference on the same feasible rows.
    let feasible: Vec<Vec<f64>> = (1..=rows.len())
        .filter(|r| !infeasible.contains(r))
        .map(|r| read[r - 1].1.clone())
        .collect();
    let none = DMatrix::zeros(0, d.n());
    let reference =
        greedy_then_exchange(&d, Criterion::D, &feasible, &none, 60, &mut Silent).unwrap();
    let value = d_value(&d, &p.plan.design, Criterion::D);
    eprintln!(
        "pool: {} rows, {} infeasible; D {value:.6} ({}), reference greedy + exchange {:.6}; {:.2} s",
        p.pool.rows,
        p.pool.infeasible.len(),
        p.pool.selection,
        reference.value,
        p.plan.time.as_secs_f64()
    );
    assert!((value - p.plan.value).abs() < 1e-9);
    assert!(
        value <= reference.value + 1e-9,
        "{value} vs reference {}",
        reference.value
    );
}

#[test]
fn refine_radius_keeps_every_joint_within_the_radius_of_its_pool_pose() {
    let cell = paper_cell();
    let (text, _, _) = pool(&cell, 400, 10, 5, 5);
    let read = csv::read_configurations_str(&text, "pool.csv", &cell.model, None).unwrap();
    // The pool in the file's own degrees, row by row.
    let degrees: Vec<Vec<f64>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').skip(1).map(|v| v.parse().unwrap()).collect())
        .collect();
    let radius = 2.0;
    let settings = PoolSettings {
        poses: 30,
        criterion: Criterion::Kpi,
        refine_radius: Some(radius),
        ..PoolSettings::default()
    };
    let p = plan_from_pool(&cell, &read, "pool.csv", &settings, &[], &mut Silent).unwrap();
    let status = p.plan.refine_status.clone().unwrap();
    assert!(!status.contains("rejected"), "{status}");
    // The refined design is the result: its status is the refinement's, not the exchange's.
    assert_ne!(
        p.plan.status,
        armcal::Status::Converged {
            criterion: "exchange".into()
        }
    );
    // The same pool given as values plans the same design.
    let rows: Vec<Vec<f64>> = read.iter().map(|r| r.1.clone()).collect();
    let by_value = armcal::plan_pool(&cell, &rows, &settings, &mut Silent).unwrap();
    assert_eq!(by_value.plan.design, p.plan.design);
    assert_eq!(by_value.plan.status, p.plan.status);
    assert!(
        p.plan.value < p.pool.selection_value,
        "the refinement gains"
    );
    assert!(p.plan.feasible);
    let mut largest = 0.0f64;
    for (q, r) in p.plan.design.iter().zip(&p.pool.chosen) {
        for (x, p0) in q.iter().zip(&degrees[r.row - 1]) {
            // The file holds 6 decimals of a degree.
            let moved = (x.to_degrees() - p0).abs();
            assert!(moved <= radius + 1e-5, "row {} moved {moved}°", r.row);
            largest = largest.max(moved);
        }
    }
    eprintln!(
        "refined within {radius}°: largest move {largest:.4}° (record {:.4}°), KPI {:.5} → {:.5} ({status})",
        p.pool.largest_move, p.pool.selection_value, p.plan.value
    );
    assert!(largest > 0.1, "the refinement moved the poses");
    assert!((largest - p.pool.largest_move).abs() < 1e-5);
}

#[test]
fn every_criterion_chooses_feasible_rows_better_than_random_ones() {
    let cell = paper_cell();
    let d = DesignModel::from_cell(&cell).unwrap();
    let (text, rows, infeasible) = pool(&cell, 300, 10, 5, 9);
    let read = csv::read_configurations_str(&text, "pool.csv", &cell.model, None).unwrap();
    let random: Vec<Vec<f64>> = (1..=rows.len())
        .filter(|r| !infeasible.contains(r))
        .take(30)
        .map(|r| rows[r - 1].clone())
        .collect();
    for criterion in Criterion::ALL {
        let settings = PoolSettings {
            poses: 30,
            criterion,
            ..PoolSettings::default()
        };
        let p = plan_from_pool(&cell, &read, "pool.csv", &settings, &[], &mut Silent).unwrap();
        let chosen: BTreeSet<usize> = p.pool.chosen.iter().map(|r| r.row).collect();
        assert_eq!(chosen.len(), 30);
        assert!(chosen.is_disjoint(&infeasible), "{criterion:?}");
        assert!(p.plan.feasible);
        let r = d_value(&d, &random, criterion);
        assert!(
            p.plan.value < r,
            "{criterion:?}: {} vs random {r}",
            p.plan.value
        );
    }
}

#[test]
fn bad_pools_give_clear_errors() {
    let cell = paper_cell();
    let settings = PoolSettings {
        poses: 20,
        criterion: Criterion::D,
        ..PoolSettings::default()
    };
    // Wrong columns: five joints.
    let e = csv::read_configurations_str(
        "pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg\n1,0,0,0,0,0\n",
        "pool.csv",
        &cell.model,
        None,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("pool.csv") && e.contains("q6"), "{e}");
    // A row of five joints given as values.
    let e = armcal::plan_pool(&cell, &[vec![0.0; 5]], &settings, &mut Silent)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("row 1 (`1`): 5 joint values, the robot has 6 joints"),
        "{e}"
    );
    // Too few feasible rows: 8 feasible (27 parameters need 9 poses) among 40 rows.
    let (text, _, _) = pool(&cell, 8, 30, 2, 3);
    let read = csv::read_configurations_str(&text, "pool.csv", &cell.model, None).unwrap();
    let e = plan_from_pool(&cell, &read, "pool.csv", &settings, &[], &mut Silent)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("only 8 of its 40 rows are feasible") && e.contains("at least 9 poses"),
        "{e}"
    );
    // Enough feasible rows, too few poses asked for.
    let (text, _, _) = pool(&cell, 30, 2, 0, 4);
    let read = csv::read_configurations_str(&text, "pool.csv", &cell.model, None).unwrap();
    let few = PoolSettings {
        poses: 5,
        ..settings.clone()
    };
    let e = plan_from_pool(&cell, &read, "pool.csv", &few, &[], &mut Silent)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("5 poses are too few") && e.contains("at least 9"),
        "{e}"
    );
    // More poses than feasible rows.
    let many = PoolSettings {
        poses: 31,
        ..settings.clone()
    };
    let e = plan_from_pool(&cell, &read, "pool.csv", &many, &[], &mut Silent)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("30 of its 32 rows are feasible, fewer than the 31"),
        "{e}"
    );
    // Enough rows, but all one pose: nothing identified.
    let same = vec![read[0].clone(); 40];
    let e = plan_from_pool(&cell, &same, "pool.csv", &settings, &[], &mut Silent)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("identify only") && e.contains("of the 27 free parameters"),
        "{e}"
    );
    // A non-positive radius.
    let bad = PoolSettings {
        refine_radius: Some(0.0),
        ..settings.clone()
    };
    let e = plan_from_pool(&cell, &read, "pool.csv", &bad, &[], &mut Silent)
        .unwrap_err()
        .to_string();
    assert!(e.contains("refinement radius must be a positive"), "{e}");
}

#[test]
fn the_design_record_says_where_it_came_from() {
    let cell = paper_cell();
    let (text, _, infeasible) = pool(&cell, 60, 5, 1, 8);
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("design_pool_record");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("pool.csv");
    std::fs::write(&file, &text).unwrap();
    let settings = PoolSettings {
        poses: 20,
        criterion: Criterion::D,
        ..PoolSettings::default()
    };
    let record =
        DesignRecord::from_pool(&cell, None, "test", &file, &settings, &[], &mut Silent).unwrap();
    let back: DesignRecord =
        serde_json::from_str(&serde_json::to_string(&record).unwrap()).unwrap();
    let pool = back.pool.expect("the pool in the record");
    assert_eq!(pool.file, file.display().to_string());
    assert_eq!(pool.rows, 66);
    assert_eq!(pool.infeasible.len(), infeasible.len());
    assert_eq!(pool.chosen.len(), back.poses.len());
}
