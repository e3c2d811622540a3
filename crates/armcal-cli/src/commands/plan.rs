//! `armcal plan`: optimal measurement poses for a cell; `armcal evaluate`: what any design
//! (including a hand-made one) gives.

use super::output::{load_cell, Outputs};
use super::progress::Progress;
use anyhow::bail;
use armcal::design::assess::evaluate_design;
use armcal::design::plan::PlanSettings;
use armcal::design::Criterion;
use armcal::design::DesignRecord;
use armcal::measure::csv;
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct PlanArgs {
    /// Cell file or built-in robot.
    #[arg(long)]
    pub cell: String,
    /// Number of measurement poses.
    #[arg(long, default_value_t = 60)]
    pub poses: usize,
    /// Criterion: kpi (TCP variance at the working poses, paper eq. 24), a, d, e, o1…o5.
    #[arg(long, default_value = "kpi", value_parser = ["kpi", "a", "d", "e", "o1", "o2", "o3", "o4", "o5"])]
    pub criterion: String,
    /// Collision and line-of-sight constraints.
    #[arg(long, default_value = "on", value_parser = ["on", "off"])]
    pub collisions: String,
    /// Independent exchange + refinement starts (run in parallel).
    #[arg(long, default_value_t = 2)]
    pub starts: usize,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Poses already measured (CSV); the design augments them.
    #[arg(long)]
    pub measured: Option<PathBuf>,
    /// Output design (CSV: pose_id, q1_deg, …).
    #[arg(long)]
    pub out: PathBuf,
    /// Also write the JSON report (default: the design path with .json).
    #[arg(long)]
    pub report: Option<PathBuf>,
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
    #[arg(long)]
    pub json: bool,
}

pub fn run_plan(a: &PlanArgs) -> anyhow::Result<()> {
    let report_path = a
        .report
        .clone()
        .unwrap_or_else(|| a.out.with_extension("json"));
    let mut inputs = vec![Path::new(&a.cell)];
    inputs.extend(a.measured.as_deref());
    let outputs = Outputs::plan(a.force, &inputs, &[&a.out, &report_path])?;
    let cell = load_cell(&a.cell)?;
    let measured: Vec<Vec<f64>> = match &a.measured {
        Some(p) => csv::read_configurations(p, &cell.model, None)?
            .into_iter()
            .map(|(_, q)| q)
            .collect(),
        None => Vec::new(),
    };
    let settings = PlanSettings {
        poses: a.poses,
        criterion: Criterion::from_name(&a.criterion).expect("clap checked"),
        collisions: a.collisions == "on",
        starts: a.starts,
        seed: a.seed,
        ..PlanSettings::default()
    };
    let record = DesignRecord::planned(
        &cell,
        Some(&a.cell),
        &format!(
            "armcal plan, criterion {}, {} start(s), seed {}",
            a.criterion, a.starts, a.seed
        ),
        &settings,
        &measured,
        &mut Progress::new(a.quiet),
    )?;
    let rep = record.plan.as_ref().expect("a planned design");
    outputs.commit(&[
        (&a.out, &csv::write_configurations(&cell.model, &rep.design)),
        (&report_path, &serde_json::to_string_pretty(&record)?),
    ])?;
    println!(
        "{} poses for `{}`, criterion {:?}: value {:.6} (exchange {:.6}; refinement {}) in {:.2} s",
        rep.design.len(),
        cell.name,
        rep.criterion,
        rep.value,
        rep.exchange_value,
        rep.refine_status.as_deref().unwrap_or("skipped"),
        rep.time.as_secs_f64()
    );
    println!(
        "constraints: {} per pose; {} (smallest margin {})",
        rep.constraints_per_pose,
        if rep.feasible {
            "every pose feasible"
        } else {
            "NOT FEASIBLE"
        },
        rep.min_margin
            .as_ref()
            .map(|m| format!(
                "{:.4} on `{}` at pose {}",
                m.value,
                m.constraint,
                m.pose + 1
            ))
            .unwrap_or_else(|| "none".into())
    );
    match rep.bound.as_ref().map(|b| (b, b.efficiency)) {
        Some((b, Some(e))) => println!(
            "optimality bound: no {}-pose design can go below {:.6}; this design's efficiency {e:.3}",
            rep.design.len(),
            b.lower_bound
        ),
        Some(_) => println!(
            "optimality bound: none (the bound found is not positive, so it says nothing about \
             this design)"
        ),
        None => {}
    }
    if let Some(t) = record.assessment.tcp.first() {
        println!("(1/3) tr C_s at `{}`: {:.5} mm²", t.name, t.kpi);
    }
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

pub fn run_evaluate(a: &EvaluateArgs) -> anyhow::Result<()> {
    let cell = load_cell(&a.cell)?;
    let design: Vec<Vec<f64>> = csv::read_configurations(Path::new(&a.design), &cell.model, None)?
        .into_iter()
        .map(|(_, q)| q)
        .collect();
    let ev = evaluate_design(&cell, &design, a.collisions == "on")?;
    if a.json {
        println!("{}", ev.to_json()?);
        return Ok(());
    }
    println!("{} poses on `{}`", ev.poses, ev.cell);
    for (c, v) in &ev.assessment.criteria {
        println!("  {:<4} {v:.6}", c.name());
    }
    println!("  φ_A(C_p) = tr(C_p)/n_p = {:.6}", ev.assessment.phi_a_cp);
    for t in &ev.assessment.tcp {
        println!("  (1/3) tr C_s at `{}` = {:.5} mm²", t.name, t.kpi);
    }
    let infeasible = &ev.infeasible_poses;
    match (&ev.min_margin, infeasible.is_empty()) {
        (margin, true) => println!(
            "every pose feasible; smallest margin {}",
            margin
                .as_ref()
                .map(|m| format!(
                    "{:.4} on `{}` at pose {}",
                    m.value,
                    m.constraint,
                    m.pose + 1
                ))
                .unwrap_or_else(|| "none".into())
        ),
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
    if !ev.margins.is_empty() {
        println!("least margin per constraint kind (required: the cell's [design]):");
        for m in &ev.margins {
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
    Ok(())
}
