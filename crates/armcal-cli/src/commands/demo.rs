//! `armcal demo`: the whole workflow on the built-in paper cell.

use super::output::Outputs;
use super::progress::Progress;
use anyhow::Context;
use armcal::{demo, DEMO_FILES as FILES};
use std::path::{Path, PathBuf};

/// Marks a folder as written by `armcal demo`, which may then overwrite it.
const MARKER: &str = ".armcal-demo";

#[derive(clap::Args)]
pub struct Args {
    /// Output folder.
    #[arg(long, default_value = "out/demo")]
    pub out: PathBuf,
    /// Seed of every random draw (the simulated robot's errors, the measurement noise, the
    /// planner's starts): the same seed gives the same numbers.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// No progress display.
    #[arg(long)]
    pub quiet: bool,
    /// Overwrite existing files in a folder that is not the demo's own (one it wrote, which
    /// it rewrites without `--force`).
    #[arg(long)]
    pub force: bool,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    // The demo's own folder (it holds the marker) is rewritten without `--force`: the
    // marker stands for it. Any other existing file is refused as every command refuses it.
    let force = a.force || a.out.join(MARKER).is_file();
    let paths: Vec<PathBuf> = std::iter::once(MARKER)
        .chain(FILES)
        .map(|name| a.out.join(name))
        .collect();
    let planned: Vec<&Path> = paths.iter().map(PathBuf::as_path).collect();
    let outputs = Outputs::plan(force, &[], &planned)?;
    let t0 = std::time::Instant::now();
    let demo = demo(a.seed, &mut Progress::new(a.quiet))?;
    let mut files = vec![(paths[0].as_path(), "written by armcal demo\n")];
    for (name, content) in &demo.files {
        let path = paths
            .iter()
            .find(|p| p.file_name().is_some_and(|f| f == name.as_str()));
        let path = path.with_context(|| format!("the demo wrote an unplanned file {name}"))?;
        files.push((path.as_path(), content.as_str()));
    }
    outputs.commit(&files)?;
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
