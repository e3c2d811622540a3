//! `armcal check`: a drift check — check poses measured after the calibration against the
//! calibrated model's prediction (χ² with its p-value) and, per parameter group, which
//! parameters most likely moved (a score test).

use super::output::{
    load_cell, load_data, load_estimate, with_note, AcceptUnconverged, NoteStyle, Outputs,
};
use armcal::campaign::drift::{check, CheckSettings, DriftVerdict};
use std::path::{Path, PathBuf};

/// Groups printed, smallest p-value first (the record holds them all).
const SHOWN: usize = 3;

#[derive(clap::Args)]
pub struct Args {
    /// Cell file or built-in robot.
    #[arg(long)]
    pub cell: String,
    /// The calibration (estimate.json).
    #[arg(long)]
    pub estimate: PathBuf,
    /// The check measurements: a data file of the cell, measured after the calibration.
    #[arg(long)]
    pub data: PathBuf,
    /// Significance level of the χ² test: "drifted" when p < α.
    #[arg(long, default_value_t = 0.05)]
    pub alpha: f64,
    /// Output record (JSON).
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite an existing output file (never an input file).
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub accept: AcceptUnconverged,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let outputs = Outputs::plan(
        a.force,
        &[Path::new(&a.cell), &a.estimate, &a.data],
        &[&a.out],
    )?;
    let cell = load_cell(&a.cell)?;
    let (est, note) = load_estimate(&a.estimate, &a.accept, Some(&cell.model))?;
    let data = load_data(&cell, &a.data)?;
    let c = check(&cell, &est, &data, &CheckSettings { alpha: a.alpha })?;
    outputs.commit(&[(
        &a.out,
        &with_note(c.to_json()?, note.as_deref(), NoteStyle::Json),
    )])?;
    println!(
        "check of {} poses ({} residual components) against {}",
        c.poses,
        c.dof,
        a.estimate.display()
    );
    println!(
        "  χ² = {:.2} with {} dof, p = {} (α = {}): {}",
        c.chi2,
        c.dof,
        p_value(c.p_value),
        c.alpha,
        c.verdict.words()
    );
    println!(
        "  RMS position residual {:.3} mm; χ² without the calibration's own uncertainty {:.2}",
        c.rms_position_mm, c.chi2_without_prediction
    );
    println!(
        "{} (score test per parameter group, smallest p first):",
        match c.verdict {
            DriftVerdict::Drifted => "most likely moved",
            DriftVerdict::Consistent => "closest to moving",
        }
    );
    for g in c.groups.iter().take(SHOWN) {
        println!(
            "  {:<10} T = {:>8.2}, rank {}, p = {}",
            g.group,
            g.statistic,
            g.rank,
            p_value(g.p_value)
        );
    }
    println!("→ {}", a.out.display());
    Ok(())
}

/// A p-value to three decimals, or in scientific notation below 0.001.
fn p_value(p: f64) -> String {
    if p < 1e-3 {
        format!("{p:.1e}")
    } else {
        format!("{p:.3}")
    }
}
