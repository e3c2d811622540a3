//! `armcal plan`: optimal measurement poses for a cell; `armcal evaluate`: what any design
//! (including a hand-made one) gives.

use super::digits::decimals_or_digits;
use super::output::{load_cell_to_measure, Outputs};
use super::progress::Progress;
use anyhow::bail;
use armcal::{
    evaluate_design, next_pose_ids, Criterion, DesignAssessment, DesignRecord, KindMargin,
    PathPrecision, PlanSettings, PoolReport, PoolSettings, TcpCovariance, TrackerShift,
};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct PlanArgs {
    /// Cell file or built-in robot.
    #[arg(long)]
    pub cell: String,
    /// Number of measurement poses.
    #[arg(long, default_value_t = 60)]
    pub poses: usize,
    /// Criterion: kpi (mean TCP variance at the working poses and paths, paper eq. 24), kpi-max
    /// (the largest one), a, d, e, o1…o5.
    #[arg(long, default_value = "kpi", value_parser = ["kpi", "kpi-max", "a", "d", "e", "o1", "o2", "o3", "o4", "o5"])]
    pub criterion: String,
    /// Collision and line-of-sight constraints.
    #[arg(long, default_value = "on", value_parser = ["on", "off"])]
    pub collisions: String,
    /// Independent exchange + refinement starts (run in parallel; not with --pool, whose
    /// selection is deterministic).
    #[arg(long, default_value_t = 2, conflicts_with = "pool")]
    pub starts: usize,
    /// Seed of the random candidate pool and the exchange starts (not with --pool).
    #[arg(long, default_value_t = 1, conflicts_with = "pool")]
    pub seed: u64,
    /// Choose the poses from this pool of joint configurations (CSV as a design file:
    /// pose_id, q1_deg, …) instead of random candidates; rows that violate a joint limit or
    /// a constraint are listed in the report and never chosen.
    #[arg(long, value_name = "POOL.csv")]
    pub pool: Option<PathBuf>,
    /// With --pool: refine the chosen poses continuously, each joint moving at most this far
    /// from its pool pose (deg; mm for a prismatic joint). Without it the design is pool rows.
    #[arg(long, requires = "pool", value_name = "DEG")]
    pub refine_radius: Option<f64>,
    /// Poses already measured (CSV); the design augments them.
    #[arg(long)]
    pub measured: Option<PathBuf>,
    /// Output design (CSV: pose_id, q1_deg, …).
    #[arg(long)]
    pub out: PathBuf,
    /// Also write the JSON report (default: the design path with .json).
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Overwrite existing output files (never an input file).
    #[arg(long)]
    pub force: bool,
    /// No progress display.
    #[arg(long)]
    pub quiet: bool,
}

#[derive(clap::Args)]
pub struct EvaluateArgs {
    /// Cell file or built-in robot.
    #[arg(long)]
    pub cell: String,
    /// Design (CSV with joint columns).
    #[arg(long)]
    pub design: PathBuf,
    /// Collision and line-of-sight constraints for the margin report.
    #[arg(long, default_value = "on", value_parser = ["on", "off"])]
    pub collisions: String,
    /// Print the evaluation (criteria, covariances, constraint margins) as JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// Also count the poses that stay measurable with the tracker up to this many mm from
    /// where the cell puts it, in the worst direction for each pose and constraint.
    #[arg(long, value_name = "MM")]
    pub tracker_shift_mm: Option<f64>,
}

pub fn run_plan(a: &PlanArgs) -> anyhow::Result<()> {
    let report_path = a
        .report
        .clone()
        .unwrap_or_else(|| a.out.with_extension("json"));
    let mut inputs = vec![Path::new(&a.cell)];
    inputs.extend(a.measured.as_deref());
    inputs.extend(a.pool.as_deref());
    let outputs = Outputs::plan(a.force, &inputs, &[&a.out, &report_path])?;
    let cell = load_cell_to_measure(&a.cell)?;
    let (measured_ids, measured): (Vec<String>, Vec<Vec<f64>>) = match &a.measured {
        Some(p) => cell.read_poses(p)?.into_iter().unzip(),
        None => Default::default(),
    };
    let criterion = Criterion::from_name(&a.criterion).expect("clap checked");
    let record = match &a.pool {
        Some(pool) => DesignRecord::from_pool(
            &cell,
            Some(&a.cell),
            &format!(
                "armcal plan, criterion {}, from the pose pool {}",
                a.criterion,
                pool.display()
            ),
            pool,
            &PoolSettings {
                poses: a.poses,
                criterion,
                collisions: a.collisions == "on",
                refine_radius: a.refine_radius,
                ..PoolSettings::default()
            },
            &measured,
            &mut Progress::new(a.quiet),
        )?,
        None => DesignRecord::planned(
            &cell,
            Some(&a.cell),
            &format!(
                "armcal plan, criterion {}, {} start(s), seed {}",
                a.criterion, a.starts, a.seed
            ),
            &PlanSettings {
                poses: a.poses,
                criterion,
                collisions: a.collisions == "on",
                starts: a.starts,
                seed: a.seed,
                ..PlanSettings::default()
            },
            &measured,
            &mut Progress::new(a.quiet),
        )?,
    };
    if let Some(pool) = &record.pool {
        print_pool(pool);
    }
    let rep = record.plan.as_ref().expect("a planned design");
    // The new poses are numbered on from the measured ones, so both files can be measured
    // into one data set.
    let ids = next_pose_ids(&measured_ids, rep.design.len());
    let poses: Vec<(String, &[f64])> = ids
        .iter()
        .cloned()
        .zip(rep.design.iter().map(Vec::as_slice))
        .collect();
    outputs.commit(&[
        (&a.out, &cell.write_poses(&poses)?),
        (&report_path, &serde_json::to_string_pretty(&record)?),
    ])?;
    let with_measured = match record.measured {
        0 => String::new(),
        m => format!(" with the {m} measured"),
    };
    if record.measured > 0 {
        println!(
            "the {} measured poses ({}) are augmented; the new poses are numbered {} to {}",
            record.measured,
            a.measured
                .as_deref()
                .map_or(String::new(), |p| p.display().to_string()),
            ids.first().map_or("", String::as_str),
            ids.last().map_or("", String::as_str),
        );
    }
    println!(
        "{} poses for `{}`, criterion {}{with_measured}: value {} ({} {}; refinement {}) in {:.2} s",
        rep.design.len(),
        cell.name,
        rep.criterion.words(),
        decimals_or_digits(rep.value, 6),
        if record.pool.is_some() {
            "pool selection"
        } else {
            "exchange"
        },
        decimals_or_digits(rep.exchange_value, 6),
        rep.refine_status.as_deref().unwrap_or("skipped"),
        rep.time.as_secs_f64()
    );
    let unchecked_arm = a.collisions == "on" && rep.arm_capsules == 0;
    if a.collisions == "on" {
        println!(
            "arm collision model: {}; {} capsules move with the joints",
            rep.collision_model, rep.arm_capsules
        );
    }
    if unchecked_arm {
        eprintln!(
            "WARNING: the arm of `{}` has NO collision model (no capsule moves with a joint): \
             self collision, the obstacles and the floor are NOT checked, and a feasible pose \
             is only within the joint limits and the checks listed. Draw the arm with \
             [[robot.capsules]] (or leave them out for the skeleton, [robot] link_radius_mm).",
            cell.name
        );
    }
    match (rep.feasible, &rep.min_margin) {
        (true, _) if unchecked_arm => println!(
            "constraints: {} per pose; every pose within them, but the arm's collisions are NOT checked",
            rep.constraints_per_pose
        ),
        (false, Some(m)) => println!(
            "constraints: {} per pose; NOT FEASIBLE (worst: {:.4} on `{}` at pose {})",
            rep.constraints_per_pose,
            m.value,
            m.constraint,
            m.pose + 1
        ),
        (false, None) => println!(
            "constraints: {} per pose; NOT FEASIBLE",
            rep.constraints_per_pose
        ),
        (true, _) => println!(
            "constraints: {} per pose; every pose feasible",
            rep.constraints_per_pose
        ),
    }
    if !rep.pairs_in_contact.is_empty() {
        println!(
            "not checked, in contact at every sampled configuration (shorten a capsule to check them): {}",
            rep.pairs_in_contact.join(", ")
        );
    }
    print_margins(&record.margins);
    match rep.bound.as_ref().map(|b| (b, b.efficiency)) {
        Some((b, Some(e))) => println!(
            "optimality bound: no {}-pose design{with_measured} can go below {}; this design's efficiency {e:.3}",
            rep.design.len(),
            decimals_or_digits(b.lower_bound, 6)
        ),
        Some(_) => println!(
            "optimality bound: none (the bound found is not positive, so it says nothing about \
             this design)"
        ),
        None => {}
    }
    if let Some(d) = &record.rank_deficit {
        println!("below the generic count: {d}");
    }
    for t in &record.assessment.tcp {
        println!(
            "(1/3) tr C_s at `{}`{with_measured}: {} mm²{}{}",
            t.name,
            decimals_or_digits(t.kpi, 5),
            orientation_note(t),
            floor_note(&record.assessment, &t.name)
        );
    }
    print_paths(&record.assessment.paths, "");
    println!(
        "design → {}, report → {}",
        a.out.display(),
        report_path.display()
    );
    if !rep.feasible {
        if !rep.blocking.is_empty() {
            println!("no feasible configurations could be drawn; the constraints that block random configurations:");
            for (name, share) in rep.blocking.iter().take(8) {
                println!("  {name:<28} rejects {:.1} % of draws", 100.0 * share);
            }
            println!("the design written is the best found (largest smallest margin), and it is NOT feasible");
        }
        bail!("the design violates constraints; see the report");
    }
    Ok(())
}

/// `; orientation (1/3) tr C_ω = … deg²` for a design whose instrument measures
/// orientations, or nothing.
fn orientation_note(t: &TcpCovariance) -> String {
    t.orientation_kpi_deg2
        .map(|v| {
            format!(
                "; orientation (1/3) tr C_ω = {} deg² (not in the KPI)",
                decimals_or_digits(v, 5)
            )
        })
        .unwrap_or_default()
}

/// `; model floor … mm² (…; not in the KPI)` for
/// the working pose `name`, or nothing without a floor.
fn floor_note(a: &DesignAssessment, name: &str) -> String {
    match a.model_floor.as_ref().and_then(|f| f.at(name)) {
        Some(f) => format!(
            "; model floor (1/3) tr C_floor = {} mm² (fixed parameters at their stated prior; not in the KPI)",
            decimals_or_digits(f.kpi, 5)
        ),
        None => String::new(),
    }
}

/// Each working path's mean and largest (1/3) tr C_s, indented by `indent`.
fn print_paths(paths: &[PathPrecision], indent: &str) {
    for p in paths {
        println!(
            "{indent}(1/3) tr C_s along `{}` ({} configurations): mean {} mm², largest {} mm² at configuration {}",
            p.name,
            p.kpi.len(),
            decimals_or_digits(p.mean_kpi, 5),
            decimals_or_digits(p.max_kpi, 5),
            p.worst
        );
    }
}

/// The pool's rows on stderr: how many are infeasible (the first ten of them), which were
/// chosen is in the report.
fn print_pool(pool: &PoolReport) {
    eprintln!(
        "pool {}: {} rows, {} feasible, {} infeasible (never chosen; all listed in the report)",
        pool.file,
        pool.rows,
        pool.feasible,
        pool.infeasible.len()
    );
    let mut by_constraint: Vec<(&str, usize)> = Vec::new();
    for r in &pool.infeasible {
        match by_constraint.iter_mut().find(|(c, _)| *c == r.constraint) {
            Some(entry) => entry.1 += 1,
            None => by_constraint.push((&r.constraint, 1)),
        }
    }
    by_constraint.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(b.0)));
    if !by_constraint.is_empty() {
        let counts: Vec<String> = by_constraint
            .iter()
            .map(|(c, n)| format!("{c} {n}"))
            .collect();
        eprintln!("  violated: {}", counts.join(", "));
    }
    for r in pool.infeasible.iter().take(10) {
        eprintln!(
            "  row {} (`{}`): {} margin {:.3} {}",
            r.pose.row, r.pose.id, r.constraint, r.margin, r.unit
        );
    }
    if pool.infeasible.len() > 10 {
        eprintln!("  … and {} more", pool.infeasible.len() - 10);
    }
    eprintln!("selection: {}", pool.selection);
    if let Some(r) = pool.refine_radius {
        eprintln!(
            "refined within ±{r} deg per joint (mm for a prismatic joint) of the pool poses: largest joint move {:.4}",
            pool.largest_move
        );
    }
}

pub fn run_evaluate(a: &EvaluateArgs) -> anyhow::Result<()> {
    let cell = load_cell_to_measure(&a.cell)?;
    let design: Vec<Vec<f64>> = cell
        .read_armcal_poses(Path::new(&a.design))?
        .into_iter()
        .map(|(_, q)| q)
        .collect();
    let ev = evaluate_design(&cell, &design, a.collisions == "on", a.tracker_shift_mm)?;
    if a.json {
        println!("{}", ev.to_json()?);
        return Ok(());
    }
    println!("{} poses on `{}`", ev.poses, ev.cell);
    for (c, v) in &ev.assessment.criteria {
        println!("  {:<4} {}", c.name(), decimals_or_digits(*v, 6));
    }
    println!("  φ_A(C_p) = tr(C_p)/n_p = {:.6}", ev.assessment.phi_a_cp);
    for t in &ev.assessment.tcp {
        println!(
            "  (1/3) tr C_s at `{}` = {} mm²{}{}",
            t.name,
            decimals_or_digits(t.kpi, 5),
            orientation_note(t),
            floor_note(&ev.assessment, &t.name)
        );
    }
    print_paths(&ev.assessment.paths, "  ");
    let infeasible = &ev.infeasible_poses;
    match (&ev.min_margin, infeasible.is_empty()) {
        (_, true) => println!("every pose feasible"),
        (Some(m), false) => println!(
            "{} poses violate constraints ({}); worst: {:.4} on `{}` at pose {}",
            infeasible.len(),
            infeasible
                .iter()
                .map(|i| i.to_string())
                .collect::<Vec<_>>()
                .join(", "),
            m.value,
            m.constraint,
            m.pose + 1
        ),
        (None, false) => println!("{} poses outside the joint limits", infeasible.len()),
    }
    print_margins(&ev.margins);
    if let Some(t) = &ev.tracker_shift {
        print_tracker_shift(t);
    }
    Ok(())
}

/// How many poses stay measurable with the tracker displaced, and the ones that do not.
fn print_tracker_shift(t: &TrackerShift) {
    println!(
        "tracker up to {} mm off (worst direction per pose): {} of {} poses stay measurable",
        t.shift_mm, t.measurable, t.poses
    );
    if let Some((v, pose)) = t.incidence_margin_deg {
        println!("  least incidence margin {v:.3} deg (pose {pose})");
    }
    if let Some((v, pose)) = t.line_of_sight_mm {
        println!("  least line-of-sight clearance {v:.3} mm (pose {pose})");
    }
    for u in &t.unmeasurable {
        println!("  {u}");
    }
}

/// The least margin of each kind of constraint against what the cell's `[design]` asks.
fn print_margins(margins: &[KindMargin]) {
    if margins.is_empty() {
        return;
    }
    println!("least margin per constraint kind (required: the cell's [design]):");
    for m in margins {
        println!(
            "  {:<15} {:>10.3} {:<3}  required {:>7.3}  {}  (`{}` at pose {})",
            m.kind,
            m.value,
            m.unit,
            m.required,
            if m.meets { "met" } else { "NOT MET" },
            m.constraint,
            m.pose
        );
    }
}
