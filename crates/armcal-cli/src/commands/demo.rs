//! `armcal demo`: the whole workflow on the built-in paper cell.

use super::progress::Progress;
use anyhow::{bail, Context};
use armcal::workflow::demo::demo;
use std::path::PathBuf;

/// Marks a folder as written by `armcal demo`, which may then overwrite it.
const MARKER: &str = ".armcal-demo";

#[derive(clap::Args)]
pub struct Args {
    /// Output folder.
    #[arg(long, default_value = "out/demo")]
    pub out: PathBuf,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// No progress display.
    #[arg(long)]
    pub quiet: bool,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    if a.out.exists() && std::fs::read_dir(&a.out)?.next().is_some() && !a.out.join(MARKER).exists()
    {
        bail!(
            "{} exists and was not written by `armcal demo`; choose another --out",
            a.out.display()
        );
    }
    let t0 = std::time::Instant::now();
    let demo = demo(a.seed, &mut Progress::new(a.quiet))?;
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    std::fs::write(a.out.join(MARKER), "written by armcal demo\n")?;
    for (name, content) in &demo.files {
        std::fs::write(a.out.join(name), content).with_context(|| format!("writing {name}"))?;
    }
    let s = &demo.summary;
    println!("armcal demo — paper cell (λ = 650 mm, μ = 600 mm), laser tracker σ = 1 mm, car body and wall, {} poses per design, seed {}", s.poses, s.seed);
    println!();
    println!("{:<40} {:>14} {:>14}", "", "heuristic", "KPI design");
    println!(
        "{:<40} {:>14.3} {:>14.3}",
        "TCP σ at the working pose, predicted",
        s.heuristic.tcp_sigma_predicted,
        s.kpi.tcp_sigma_predicted
    );
    println!(
        "{:<40} {:>14.3} {:>14.3}",
        "TCP error at the working pose, achieved",
        s.heuristic.tcp_error_achieved,
        s.kpi.tcp_error_achieved
    );
    println!(
        "{:<40} {:>14.3} {:>14.3}",
        "held-out error RMS (mm)", s.heuristic.held_out.rms, s.kpi.held_out.rms
    );
    println!(
        "{:<40} {:>14.3} {:>14.3}",
        "held-out error max (mm)", s.heuristic.held_out.max, s.kpi.held_out.max
    );
    println!();
    println!(
        "nominal model: held-out error RMS {:.3} mm, max {:.3} mm (100 feasible poses, true robot)",
        s.nominal_held_out.rms, s.nominal_held_out.max
    );
    println!(
        "working program on the true robot: largest miss {:.3} mm with nominal joints → {:.3} mm compensated",
        s.program_miss_nominal, s.program_miss_compensated
    );
    if let Some(e) = s.kpi_bound_efficiency {
        println!("KPI design efficiency (optimality bound): {e:.3}");
    }
    println!(
        "\n{} files → {} ({:.1} s)",
        demo.files.len(),
        a.out.display(),
        t0.elapsed().as_secs_f64()
    );
    println!(
        "report: {} — open it in a browser (one self-contained file)",
        a.out.join("report.html").display()
    );
    Ok(())
}
