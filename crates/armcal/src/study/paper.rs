//! The paper's study (Jost et al. 2017, §3.3–3.4, Tables 6–8): for the three KUKA robots and
//! the 90 notional manipulators (λ ∈ {650, …, 1100} mm, μ ∈ {600, …, 1000} mm), the KPI
//! (1/3) tr(C_s) at the working configuration for three designs of 60 poses — the heuristic
//! (uniform random measurable poses), the φ_A(C_p)-optimal design and the φ_A(C_s)-optimal
//! (KPI) design — without and with collision avoidance.
//!
//! The cells are the example cells `examples/paper-cell.toml` (no obstacles) and
//! `examples/paper-cell-obstacles.toml`, with the robot replaced.

use crate::cell::Cell;
use crate::design::baselines::random_feasible;
use crate::design::plan::{constraint_set, design_from_pool, CellConstraints, PlanSettings};
use crate::design::refine::RefineSettings;
use crate::design::{Criterion, DesignModel, DesignObjective};
use crate::progress::{Observer, Shared, Silent};
use crate::Error;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::time::Instant;

const CELL: &str = include_str!("../../../../examples/paper-cell.toml");
const CELL_OBSTACLES: &str = include_str!("../../../../examples/paper-cell-obstacles.toml");

/// The paper cell with another robot of the library.
pub fn cell_for(robot: &str, collisions: bool) -> Result<Cell, Error> {
    let template = if collisions { CELL_OBSTACLES } else { CELL };
    let text = template.replace(
        "builtin = \"paper-650-600\"",
        &format!("builtin = \"{robot}\""),
    );
    let mut cell = Cell::from_toml(&text, &format!("paper cell with {robot}"), Path::new("."))?;
    // The working configuration may lie outside a robot's limits; the study keeps it.
    cell.warnings.clear();
    Ok(cell)
}

/// One robot, one collision setting: the KPI of each design (mm²).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StudyRow {
    pub robot: String,
    pub collisions: bool,
    pub heuristic: f64,
    pub cp_optimal: f64,
    pub cs_optimal: f64,
    /// Improvement of the KPI design over the heuristic and over the C_p design (fractions).
    pub gain_vs_heuristic: f64,
    pub gain_vs_cp: f64,
    pub feasible: bool,
    pub seconds: f64,
    /// Why this robot has no result (e.g. no feasible configuration in the cell).
    pub error: Option<String>,
}

/// Settings of the study.
#[derive(Clone, Debug)]
pub struct StudySettings {
    pub collisions: bool,
    pub poses: usize,
    pub seed: u64,
    /// The planner's settings (poses, criterion and collisions are set per run).
    pub plan: PlanSettings,
}

impl Default for StudySettings {
    fn default() -> Self {
        StudySettings {
            collisions: true,
            poses: 60,
            seed: 1,
            // One start per design and 250 refinement iterations: 186 designs share two
            // cores, and a second start or a longer refinement changes the study's means by
            // less than 1 %.
            plan: PlanSettings {
                starts: 1,
                pool: 600,
                refine: RefineSettings {
                    max_iterations: 250,
                    ..RefineSettings::default()
                },
                ..PlanSettings::default()
            },
        }
    }
}

/// The robots of Table 6 and of Tables 7–8.
pub fn table6_robots() -> Vec<String> {
    ["kr15", "kr300", "kr500"].map(String::from).to_vec()
}

pub fn notional_robots() -> Vec<String> {
    let mut v = Vec::new();
    for l in (650..=1100).step_by(50) {
        for m in (600..=1000).step_by(50) {
            v.push(format!("paper-{l}-{m}"));
        }
    }
    v
}

/// Runs the three designs for one robot. One candidate pool serves both optimal designs,
/// and its first `poses` draws are the heuristic design (the same seeded uniform feasible
/// draws); the study reports criterion values only, so the planner's bound and travel
/// ordering are left out. `observer` follows the two plans.
pub fn run_robot(
    robot: &str,
    s: &StudySettings,
    observer: &mut dyn Observer,
) -> Result<StudyRow, Error> {
    let t0 = Instant::now();
    let cell = cell_for(robot, s.collisions)?;
    let d = DesignModel::from_cell(&cell)?;
    let set = constraint_set(&cell, s.collisions)?;
    let cons = CellConstraints::new(&set, &d.params);
    let (pool, _) = random_feasible(
        &d.model,
        s.plan.pool.max(s.poses),
        s.seed,
        s.plan.max_draws,
        |q| cons.feasible(q),
    )?;
    let heuristic = &pool[..s.poses];
    let kpi = DesignObjective::new(&d, Criterion::Kpi, &[]);
    let mut ws = kpi.workspace(s.poses);
    let h = kpi.value_and_gradient(&mut ws, &heuristic.concat(), None)?;
    let settings = PlanSettings {
        poses: s.poses,
        collisions: s.collisions,
        seed: s.seed,
        ..s.plan.clone()
    };
    let a = design_from_pool(
        &d,
        &set,
        &pool,
        &PlanSettings {
            criterion: Criterion::A,
            ..settings.clone()
        },
        &[],
        observer,
    )?;
    let c = design_from_pool(
        &d,
        &set,
        &pool,
        &PlanSettings {
            criterion: Criterion::Kpi,
            ..settings
        },
        &[],
        observer,
    )?;
    let a_kpi = kpi.value_and_gradient(&mut ws, &a.design.concat(), None)?;
    let feasible = a.design.iter().chain(&c.design).all(|q| cons.feasible(q));
    Ok(StudyRow {
        robot: robot.to_string(),
        collisions: s.collisions,
        heuristic: h,
        cp_optimal: a_kpi,
        cs_optimal: c.value,
        gain_vs_heuristic: 1.0 - c.value / h,
        gain_vs_cp: 1.0 - c.value / a_kpi,
        feasible,
        seconds: t0.elapsed().as_secs_f64(),
        error: None,
    })
}

/// Runs a list of robots in parallel; `observer` receives the task `study robots` and a
/// step after each robot (the robots' own plans run silently: they interleave). A robot
/// that fails (e.g. no feasible configuration) gets a row with its error instead of
/// stopping the study.
pub fn run(robots: &[String], s: &StudySettings, observer: &mut dyn Observer) -> Vec<StudyRow> {
    observer.start("study robots", Some(robots.len()));
    let shared = Shared::new(observer);
    let rows = robots
        .par_iter()
        .map(|r| {
            let row = run_robot(r, s, &mut Silent).unwrap_or_else(|e| StudyRow {
                robot: r.clone(),
                collisions: s.collisions,
                heuristic: f64::NAN,
                cp_optimal: f64::NAN,
                cs_optimal: f64::NAN,
                gain_vs_heuristic: f64::NAN,
                gain_vs_cp: f64::NAN,
                feasible: false,
                seconds: 0.0,
                error: Some(e.to_string()),
            });
            (&shared).step();
            row
        })
        .collect();
    observer.finish();
    rows
}

/// The paper's published values: (design, no collision avoidance, with collision avoidance),
/// (1/3) tr C_s in mm² (Tables 6–8 as read in docs/paper-setup.md).
pub const PAPER_SUMMARY: [(&str, f64, f64); 3] = [
    ("heuristic", 0.61, 0.61),
    ("C_p-optimal", 0.39, 0.43),
    ("C_s-optimal (KPI)", 0.33, 0.35),
];

/// Table 6 (with collision avoidance): robot, heuristic, C_p-optimal, C_s-optimal.
pub const PAPER_TABLE6: [(&str, f64, f64, f64); 3] = [
    ("kr15", 0.59, 0.40, 0.33),
    ("kr300", 0.58, 0.39, 0.35),
    ("kr500", 0.61, 0.40, 0.35),
];
