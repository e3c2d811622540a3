//! `armcal study paper`: the paper's Tables 6–8 reproduced beside the published values.
//! `armcal study puma`: the book's Chapter 6 PUMA case (Tables 6.9/6.10 and 6.13).

use super::output::Outputs;
use super::progress::Progress;
use armcal::{
    paper_study, puma_study, PaperStudyRecord, PaperStudySettings, PumaSettings, RobotSelection,
    PAPER_SUMMARY, PAPER_TABLE6,
};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Which study: `paper` (Jost et al. 2017, Tables 6–8) or `puma` (Mooring, Roth, Driels
    /// 1991, Chapter 6: modified-DH and zero-reference calibration of the PUMA 560).
    #[arg(value_parser = ["paper", "puma"])]
    pub which: String,
    /// Collision avoidance.
    #[arg(long, default_value = "on", value_parser = ["on", "off"])]
    pub collisions: String,
    /// Robots: table6 (the three KUKA robots), notional (the 90 manipulators) or all.
    #[arg(long, default_value = "all", value_parser = ["table6", "notional", "all"])]
    pub robots: String,
    /// Seed of every random draw (simulated robots, measurement noise, starts): the same seed
    /// gives the same tables.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Directory for the CSV and JSON files [default: out/study-paper or out/study-puma].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Overwrite existing output files (never an input file).
    #[arg(long)]
    pub force: bool,
}

pub fn run_study(a: &Args) -> anyhow::Result<()> {
    if a.which == "puma" {
        return run_puma(a);
    }
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out/study-paper"));
    let collisions = a.collisions == "on";
    let stem = PaperStudyRecord::stem(collisions);
    let csv_path = out.join(format!("{stem}.csv"));
    let json_path = out.join(format!("{stem}.json"));
    let outputs = Outputs::plan(a.force, &[], &[&csv_path, &json_path])?;
    let robots = RobotSelection::from_name(&a.robots)
        .expect("clap checked")
        .robots();
    let settings = PaperStudySettings {
        collisions,
        seed: a.seed,
        ..PaperStudySettings::default()
    };
    let study = paper_study(&robots, &settings, &mut Progress::new(a.quiet));
    let record = &study.record;
    outputs.commit(&[
        (&csv_path, &record.to_csv()),
        (&json_path, &record.to_json()?),
    ])?;
    for r in &study.failed {
        println!(
            "{}: no result: {}",
            r.robot,
            r.error.as_deref().unwrap_or("")
        );
    }
    let rows = &record.rows;
    let secs = record.seconds;
    let col = if collisions { "with" } else { "without" };
    println!("paper study, {col} collision avoidance, 60 poses, (1/3) tr C_s in mm² — {} robots in {secs:.1} s", rows.len());
    let t6 = record.table6();
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
    if let Some(nt) = record.notional_summary() {
        println!(
            "\nTables 7–8, {} notional manipulators: mean (min–max)",
            nt.robots
        );
        for (i, (name, s)) in [
            ("heuristic", nt.heuristic),
            ("C_p-optimal", nt.cp_optimal),
            ("C_s-optimal (KPI)", nt.cs_optimal),
        ]
        .into_iter()
        .enumerate()
        {
            let paper = if collisions {
                PAPER_SUMMARY[i].2
            } else {
                PAPER_SUMMARY[i].1
            };
            println!(
                "  {name:<18} armcal {:.3} ({:.3}–{:.3})   paper {paper:.2}",
                s.mean, s.min, s.max
            );
        }
        let (gh, gc) = (nt.gain_vs_heuristic, nt.gain_vs_cp);
        println!(
            "  KPI design vs heuristic: −{:.0} % ({:.0}–{:.0} %), vs C_p design: −{:.0} % ({:.0}–{:.0} %)   paper: 40–44 %, 10–19 %",
            100.0 * gh.mean, 100.0 * gh.min, 100.0 * gh.max, 100.0 * gc.mean, 100.0 * gc.min, 100.0 * gc.max
        );
    }
    let infeasible = record.infeasible();
    if !infeasible.is_empty() {
        println!("designs violating constraints: {}", infeasible.join(", "));
    }
    println!("\n→ {}, {}", csv_path.display(), json_path.display());
    Ok(())
}

/// `armcal study puma`: prints Tables 6.9/6.10 and 6.13 (armcal beside the book) and writes
/// `puma.json`, `puma-conversion.csv` and `puma-accuracy.csv`.
fn run_puma(a: &Args) -> anyhow::Result<()> {
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out/study-puma"));
    let json_path = out.join("puma.json");
    let conv_path = out.join("puma-conversion.csv");
    let acc_path = out.join("puma-accuracy.csv");
    let outputs = Outputs::plan(a.force, &[], &[&json_path, &conv_path, &acc_path])?;
    let record = puma_study(
        &PumaSettings {
            seed: a.seed,
            ..Default::default()
        },
        &mut Progress::new(a.quiet),
    )?;
    let s = &record.result;
    outputs.commit(&[
        (&conv_path, &s.conversion_csv()),
        (&acc_path, &s.accuracy_csv()),
        (&json_path, &record.to_json()?),
    ])?;
    let secs = record.seconds;
    println!(
        "PUMA 560 study (book ch. 6): truth Table 6.5, {} full poses with Table 6.4 noise \
         (σ {:.4}/{:.4}/{:.4} mm, {:.4} mrad; seed {}), {} held-out poses — {secs:.1} s",
        s.identification_poses,
        s.sigma_mm[0],
        s.sigma_mm[1],
        s.sigma_mm[2],
        1e3 * s.sigma_rad,
        s.seed,
        s.held_out_poses
    );
    for f in [&s.mdh, &s.zrp] {
        println!(
            "\n{}: {} free parameters, {} rows, {} iterations{}, whitened SSQ {:.1} (variance factor {:.2}); \
             fit RMS δr {:.4} in, δθ {:.3}°",
            f.model,
            f.free,
            f.rows,
            f.iterations,
            if f.converged { "" } else { " (NOT converged)" },
            f.ssq,
            f.variance_factor,
            f.fit_rms_dr_in,
            f.fit_rms_dtheta_deg
        );
        for (name, why) in &f.unidentifiable {
            println!("  fixed {name}: {why}");
        }
    }
    println!(
        "\nTables 6.9/6.10: zero reference converted to DH vs modified DH identified \
         (p1–p3; in, deg)"
    );
    println!(
        "{:<5} {:<16} {:>28} {:>28} {:>28} {:>28} {:>28} {:>28}",
        "",
        "fields",
        "converted",
        "identified",
        "σ identified",
        "truth (Table 6.5)",
        "book converted",
        "book identified"
    );
    let three = |v: &[f64; 3]| format!("{:>9.3}{:>9.3}{:>10.3}", v[0], v[1], v[2]);
    for r in &s.conversion {
        println!(
            "{:<5} {:<16} {:>28} {:>28} {:>28} {:>28} {:>28} {:>28}",
            r.transform,
            r.fields.join(","),
            three(&r.converted),
            three(&r.identified),
            format!(
                "{:>9.4}{:>9.4}{:>10.4}",
                r.identified_sigma[0], r.identified_sigma[1], r.identified_sigma[2]
            ),
            three(&r.truth),
            three(&r.book_converted),
            three(&r.book_identified)
        );
    }
    println!(
        "max |converted − identified|: {:.1e} in, {:.1e}°",
        s.conversion_max_dlength_in, s.conversion_max_dangle_deg
    );
    println!("\nTable 6.13: held-out accuracy, δr (in) and δθ (deg) against the measured pose");
    println!(
        "{:<5} {:>20} {:>20} {:>20}   {:>20} {:>20} {:>20}",
        "pose",
        "nominal",
        "modified DH",
        "zero reference",
        "book nominal",
        "book mod. DH",
        "book ZRP"
    );
    let pair = |r: f64, t: f64| format!("{r:>9.4} {t:>9.3}");
    for r in &s.held_out {
        let b = r
            .book
            .map(|b| {
                format!(
                    "{:>20} {:>20} {:>20}",
                    pair(b.nominal_dr_in, b.nominal_dtheta_deg),
                    pair(b.mdh_dr_in, b.mdh_dtheta_deg),
                    pair(b.zrp_dr_in, b.zrp_dtheta_deg)
                )
            })
            .unwrap_or_default();
        println!(
            "{:<5} {:>20} {:>20} {:>20}   {b}",
            r.pose,
            pair(r.nominal_dr_in, r.nominal_dtheta_deg),
            pair(r.mdh_dr_in, r.mdh_dtheta_deg),
            pair(r.zrp_dr_in, r.zrp_dtheta_deg)
        );
    }
    let (m, b) = (&s.held_out_mean, &s.book_mean);
    println!(
        "{:<5} {:>20} {:>20} {:>20}   {:>20} {:>20} {:>20}",
        "mean",
        pair(m.nominal_dr_in, m.nominal_dtheta_deg),
        pair(m.mdh_dr_in, m.mdh_dtheta_deg),
        pair(m.zrp_dr_in, m.zrp_dtheta_deg),
        pair(b.nominal_dr_in, b.nominal_dtheta_deg),
        pair(b.mdh_dr_in, b.mdh_dtheta_deg),
        pair(b.zrp_dr_in, b.zrp_dtheta_deg)
    );
    println!(
        "against the true poses (no CMM noise): modified DH δr {:.4} in, δθ {:.3}°; \
         zero reference δr {:.4} in, δθ {:.3}°",
        s.exact_mean_mdh.0, s.exact_mean_mdh.1, s.exact_mean_zrp.0, s.exact_mean_zrp.1
    );
    println!(
        "(the simulated robot is exactly geometric and the CMM noise-only; the book's calibrated \
         errors include non-geometric errors and the CMM's accuracy)"
    );

    println!(
        "\n→ {}, {}, {}",
        json_path.display(),
        conv_path.display(),
        acc_path.display()
    );
    Ok(())
}
