//! `armcal study paper`: the paper's Tables 6–8 reproduced beside the published values.

use super::output::write_new;
use armcal::study::paper::{
    notional_robots, run, table6_robots, StudyRow, StudySettings, PAPER_SUMMARY, PAPER_TABLE6,
};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Which study: `paper` (Jost et al. 2017, Tables 6–8).
    #[arg(value_parser = ["paper"])]
    pub which: String,
    /// Collision avoidance.
    #[arg(long, default_value = "on", value_parser = ["on", "off"])]
    pub collisions: String,
    /// Robots: table6 (the three KUKA robots), notional (the 90 manipulators) or all.
    #[arg(long, default_value = "all", value_parser = ["table6", "notional", "all"])]
    pub robots: String,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Directory for study.csv and study.json.
    #[arg(long, default_value = "out/study-paper")]
    pub out: PathBuf,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    #[arg(long)]
    pub force: bool,
}

fn mean(rows: &[&StudyRow], f: impl Fn(&StudyRow) -> f64) -> (f64, f64, f64) {
    let v: Vec<f64> = rows.iter().map(|r| f(r)).collect();
    let m = v.iter().sum::<f64>() / v.len().max(1) as f64;
    let lo = v.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    (m, lo, hi)
}

pub fn run_study(a: &Args) -> anyhow::Result<()> {
    let collisions = a.collisions == "on";
    let mut robots = Vec::new();
    if a.robots != "notional" {
        robots.extend(table6_robots());
    }
    if a.robots != "table6" {
        robots.extend(notional_robots());
    }
    let settings = StudySettings {
        collisions,
        seed: a.seed,
        ..StudySettings::default()
    };
    let bar = ProgressBar::new(robots.len() as u64);
    if a.quiet || !std::io::stderr().is_terminal() {
        bar.set_draw_target(ProgressDrawTarget::hidden());
    }
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} robots, {elapsed} (eta {eta})")
            .expect("valid template"),
    );
    let t0 = std::time::Instant::now();
    let all = run(&robots, &settings, &|| bar.inc(1));
    for r in all.iter().filter(|r| r.error.is_some()) {
        println!(
            "{}: no result: {}",
            r.robot,
            r.error.as_deref().unwrap_or("")
        );
    }
    let rows: Vec<StudyRow> = all.iter().filter(|r| r.error.is_none()).cloned().collect();
    bar.finish_and_clear();
    let secs = t0.elapsed().as_secs_f64();
    let col = if collisions { "with" } else { "without" };
    println!("paper study, {col} collision avoidance, 60 poses, (1/3) tr C_s in mm² — {} robots in {secs:.1} s", rows.len());
    let t6: Vec<&StudyRow> = rows.iter().filter(|r| r.robot.starts_with("kr")).collect();
    if !t6.is_empty() {
        println!(
            "\nTable 6 {:>22} {:>22} {:>22}",
            "heuristic", "C_p-optimal", "C_s-optimal (KPI)"
        );
        println!(
            "{:<8} {:>10} {:>11} {:>10} {:>11} {:>10} {:>11}",
            "robot", "armcal", "paper", "armcal", "paper", "armcal", "paper"
        );
        for r in &t6 {
            let p = PAPER_TABLE6.iter().find(|p| p.0 == r.robot);
            let (ph, pa, pc) = p
                .map(|p| (p.1, p.2, p.3))
                .unwrap_or((f64::NAN, f64::NAN, f64::NAN));
            let note = if collisions { "" } else { " (paper: with CA)" };
            println!(
                "{:<8} {:>10.3} {:>11.2} {:>10.3} {:>11.2} {:>10.3} {:>11.2}{note}",
                r.robot, r.heuristic, ph, r.cp_optimal, pa, r.cs_optimal, pc
            );
        }
    }
    let nt: Vec<&StudyRow> = rows
        .iter()
        .filter(|r| r.robot.starts_with("paper-"))
        .collect();
    if !nt.is_empty() {
        println!(
            "\nTables 7–8, {} notional manipulators: mean (min–max)",
            nt.len()
        );
        let paper_col = |i: usize| {
            if collisions {
                PAPER_SUMMARY[i].2
            } else {
                PAPER_SUMMARY[i].1
            }
        };
        for (i, (name, f)) in [
            (
                "heuristic",
                Box::new(|r: &StudyRow| r.heuristic) as Box<dyn Fn(&StudyRow) -> f64>,
            ),
            ("C_p-optimal", Box::new(|r: &StudyRow| r.cp_optimal)),
            ("C_s-optimal (KPI)", Box::new(|r: &StudyRow| r.cs_optimal)),
        ]
        .into_iter()
        .enumerate()
        {
            let (m, lo, hi) = mean(&nt, f);
            println!(
                "  {name:<18} armcal {m:.3} ({lo:.3}–{hi:.3})   paper {:.2}",
                paper_col(i)
            );
        }
        let (gh, ghl, ghh) = mean(&nt, |r| r.gain_vs_heuristic);
        let (gc, gcl, gch) = mean(&nt, |r| r.gain_vs_cp);
        println!(
            "  KPI design vs heuristic: −{:.0} % ({:.0}–{:.0} %), vs C_p design: −{:.0} % ({:.0}–{:.0} %)   paper: 40–44 %, 10–19 %",
            100.0 * gh, 100.0 * ghl, 100.0 * ghh, 100.0 * gc, 100.0 * gcl, 100.0 * gch
        );
    }
    let infeasible: Vec<&str> = rows
        .iter()
        .filter(|r| !r.feasible)
        .map(|r| r.robot.as_str())
        .collect();
    if !infeasible.is_empty() {
        println!("designs violating constraints: {}", infeasible.join(", "));
    }
    let mut csv = String::from("robot,collisions,heuristic_mm2,cp_optimal_mm2,cs_optimal_mm2,gain_vs_heuristic,gain_vs_cp,feasible,seconds\n");
    for r in &rows {
        csv.push_str(&format!(
            "{},{},{:.6},{:.6},{:.6},{:.4},{:.4},{},{:.2}\n",
            r.robot,
            r.collisions,
            r.heuristic,
            r.cp_optimal,
            r.cs_optimal,
            r.gain_vs_heuristic,
            r.gain_vs_cp,
            r.feasible,
            r.seconds
        ));
    }
    let suffix = if collisions {
        "collisions"
    } else {
        "no-collisions"
    };
    let csv_path = a.out.join(format!("study-{suffix}.csv"));
    let json_path = a.out.join(format!("study-{suffix}.json"));
    write_new(&csv_path, &csv, a.force)?;
    write_new(
        &json_path,
        &serde_json::to_string_pretty(
            &serde_json::json!({"study": "paper", "collisions": collisions, "seconds": secs, "rows": rows}),
        )?,
        a.force,
    )?;
    println!("\n→ {}, {}", csv_path.display(), json_path.display());
    Ok(())
}
