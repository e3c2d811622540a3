//! `armcal check`: a drift check — check poses measured after the calibration against the
//! calibrated model's prediction (χ² with its p-value) and, per parameter group, which
//! parameters most likely moved (a score test).

use super::campaign::{print_last_step, step_files, Files};
use super::output::{
    load_cell, load_data, warn_outside_fitted_ranges, with_note, Calibration, NoteStyle, Outputs,
};
use armcal::Silent;
use armcal::{
    campaign_start_after_check, check, CampaignPrior, CampaignSettings, CheckSettings, DriftVerdict,
};
use std::path::{Path, PathBuf};

/// Groups printed, smallest p-value first (the record holds them all).
const SHOWN: usize = 3;

#[derive(clap::Args)]
pub struct Args {
    /// Cell file or built-in robot.
    #[arg(long)]
    pub cell: String,
    #[command(flatten)]
    pub calibration: Calibration,
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
    /// When the check says "drifted", start a re-identification campaign in DIR: the old
    /// estimate is the prior, the groups that moved are released from it, and the check
    /// poses are its first step (writes DIR/campaign.json, DIR/next.csv,
    /// DIR/estimate.json); then `armcal campaign step DIR --data …`.
    #[arg(long, value_name = "DIR", requires = "target_sigma_mm")]
    pub campaign: Option<PathBuf>,
    /// The campaign's target: every working pose's TCP σ at or below this (mm).
    #[arg(long, requires = "campaign")]
    pub target_sigma_mm: Option<f64>,
    /// Groups to release from the prior, comma-separated (`j2,tracker`); default: the
    /// groups Holm's step-down procedure over the score tests rejects at α (at least the first).
    #[arg(long, value_delimiter = ',', requires = "campaign")]
    pub release: Vec<String>,
    /// The campaign's poses per batch.
    #[arg(long, default_value_t = 5, requires = "campaign")]
    pub batch: usize,
    /// The campaign's most poses in all, the check poses included.
    #[arg(long, requires = "campaign")]
    pub budget: Option<usize>,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let files = a.campaign.as_deref().map(Files::of);
    let mut planned: Vec<&Path> = vec![&a.out];
    if let Some(f) = &files {
        planned.extend([f.state.as_path(), f.next.as_path(), f.estimate.as_path()]);
    }
    let outputs = Outputs::plan(
        a.force,
        &[Path::new(&a.cell), &a.calibration.estimate, &a.data],
        &planned,
    )?;
    let cell = load_cell(&a.cell)?;
    let (est, note) = a.calibration.load(Some(&cell.model))?;
    let data = load_data(&cell, &a.data)?;
    let poses: Vec<(String, Vec<f64>)> = data
        .config_ids
        .iter()
        .cloned()
        .zip(data.configurations.iter().cloned())
        .collect();
    warn_outside_fitted_ranges(&est, &cell.model, &poses);
    let c = check(&cell, &est, &data, &CheckSettings { alpha: a.alpha })?;
    let mut written = vec![(
        a.out.clone(),
        with_note(c.to_json()?, note.as_deref(), NoteStyle::Json),
    )];
    let started = match (&files, a.target_sigma_mm) {
        (Some(f), Some(target)) if c.verdict == DriftVerdict::Drifted => {
            let release = if a.release.is_empty() {
                c.moved_groups()
            } else {
                a.release.clone()
            };
            let source = a.calibration.estimate.display().to_string();
            let settings = CampaignSettings {
                target_sigma_mm: target,
                batch: a.batch,
                budget: a.budget,
                prior: Some(CampaignPrior::from_estimate(
                    &cell, &est, &source, &release,
                )?),
                ..CampaignSettings::default()
            };
            let cell_source = std::fs::canonicalize(&a.cell)
                .map(|p| p.display().to_string())
                .unwrap_or_else(|_| a.cell.clone());
            let r = campaign_start_after_check(&cell, &cell_source, &settings, &data, &mut Silent)?;
            written.extend(step_files(&cell, &r, f)?);
            Some((r.state, release))
        }
        _ => None,
    };
    let refs: Vec<(&Path, &str)> = written
        .iter()
        .map(|(p, t)| (p.as_path(), t.as_str()))
        .collect();
    outputs.commit(&refs)?;
    println!(
        "check of {} poses ({} residual components) against {}",
        c.poses,
        c.dof,
        a.calibration.estimate.display()
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
    match (&started, &files) {
        (Some((state, release)), Some(f)) => {
            println!(
                "campaign from {} (prior: its estimate and covariance; released: {}), the check poses its first step:",
                a.calibration.estimate.display(),
                release.join(", ")
            );
            print_last_step(state, f);
        }
        (None, Some(_)) => println!("consistent: no campaign started"),
        _ => {}
    }
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
