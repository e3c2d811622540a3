//! `armcal model <robot-or-cell>`: parameters, completeness and identifiability.
//!
//! With `--convention dh|mdh|zrp` the model is first converted (forward kinematics
//! unchanged; `armcal::cell::model_analysis` says how and with which statuses); the table
//! and the identifiability analysis are then those of the converted model.

use super::digits::fixed;
use armcal::cell::model_analysis::{analyze_model, ModelRecord};
use armcal::model::complete::LinkForm;
use armcal::model::identifiability::{IdentifiabilitySettings, Measurement};
use armcal::model::Status;

#[derive(clap::Args)]
pub struct Args {
    /// Built-in robot name or cell file.
    pub target: String,
    /// Measurement type for the identifiability analysis (default: the cell's).
    #[arg(long, value_parser = ["pose", "position", "distance"])]
    pub measurement: Option<String>,
    /// Random configurations used by the analysis (at least 1).
    #[arg(long, default_value_t = 60, value_parser = clap::value_parser!(u32).range(1..))]
    pub poses: u32,
    /// Seed of the random configurations.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Print JSON instead of tables.
    #[arg(long)]
    pub json: bool,
    /// Convert the model to this convention first (forward kinematics unchanged): the
    /// table and the analysis are those of the converted model, all chain parameters free.
    #[arg(long, value_parser = ["dh", "mdh", "zrp"])]
    pub convention: Option<String>,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let cell = super::output::load_cell(&a.target)?;
    let measurement = a
        .measurement
        .as_deref()
        .and_then(Measurement::from_name)
        .unwrap_or(cell.measurement);
    let opts = IdentifiabilitySettings {
        measurement,
        poses: a.poses as usize,
        seed: a.seed,
        ..cell.identifiability_settings()
    };
    let convention = a
        .convention
        .as_deref()
        .map(|c| LinkForm::from_name(c).expect("clap checked"));
    let analysis = analyze_model(&cell, &opts, convention)?;
    if a.json {
        println!("{}", ModelRecord::new(&cell, &analysis).to_json()?);
        return Ok(());
    }
    let (model, report, deficit) = (
        &analysis.model,
        &analysis.identifiability,
        &analysis.rank_deficit,
    );
    println!("{} ({})", cell.name, cell.origin);
    println!("source: {}", cell.robot.source);
    println!(
        "collision model: {} ({} capsules with the tool's)",
        cell.robot.collision,
        cell.capsules.len()
    );
    for c in &cell.form_changes {
        println!(
            "complete, minimal form (convention = \"{}\"): {c}",
            cell.form.name()
        );
    }
    for c in &cell.form_incomplete {
        println!("incomplete: {c}");
    }
    if let Some(c) = &a.convention {
        println!(
            "converted to {c} (forward kinematics unchanged); chain parameters all free, \
             instrument and targets as the cell declares them"
        );
    }
    println!();
    println!(
        "{:<4} {:<14} {:>14} {:<4} status",
        "#", "parameter", "nominal", "unit"
    );
    for (i, p) in model.registry.iter().enumerate() {
        let status = match p.status {
            Status::Free => "free".to_string(),
            Status::Fixed if report.excluded.iter().any(|e| e.name == p.name) => {
                "fixed (not identifiable, see below)".to_string()
            }
            Status::Fixed => "fixed".to_string(),
            Status::Prior { sigma } => format!(
                "prior σ = {:.4} {}",
                sigma * p.unit.display_factor(),
                p.unit.display_name()
            ),
        };
        println!(
            "{:<4} {:<14} {:>14} {:<4} {status}",
            i + 1,
            p.name,
            fixed(p.nominal * p.unit.display_factor(), 6),
            p.unit.display_name()
        );
    }
    println!("\njoints:");
    for j in &model.joints {
        let f = j.kind.unit().display_factor();
        println!(
            "  {:<6} {} [{:.2}, {:.2}] {}",
            j.name,
            match j.kind {
                armcal::model::JointKind::Revolute => "revolute",
                armcal::model::JointKind::Prismatic => "prismatic",
            },
            j.lower * f,
            j.upper * f,
            j.kind.unit().display_name()
        );
    }
    let c = &report.completeness;
    println!(
        "\ncompleteness (book §2.3): {} revolute, {} prismatic joints → complete pose model 4R + 2P + 6 = {}",
        c.revolute, c.prismatic, c.complete_pose_model
    );
    match c.expected_for_measurement {
        Some(n) => println!(
            "expected identifiable from {} measurements in generic geometry: {n}",
            measurement.words()
        ),
        None => {
            println!(
                "no closed-form count for {} measurements of several targets",
                measurement.words()
            )
        }
    }
    println!(
        "numerical analysis over {} random configurations (seed {}): {} candidate parameters, rank {} (SVD), {} (pivoted QR)",
        report.poses, a.seed, report.candidates.len(), report.rank_svd, report.rank_qr
    );
    println!(
        "identifiable: {} at these random configurations and the nominal, condition number of the column-scaled Jacobian {:.1}",
        report.count(model),
        report.condition_number
    );
    println!("  {}", report.identifiable.join(", "));
    println!("  (`identify` counts again, by the same rule, at the data's configurations and at the fit: data that move some joints little, or terms they cannot separate, give fewer, and it says why)");
    if let Some(d) = &deficit {
        println!("below the generic count: {d}");
    }
    if !report.excluded.is_empty() {
        println!("not identifiable ({}):", report.excluded.len());
        for e in &report.excluded {
            println!("  - {}", e.reason);
        }
    }
    if !report.fixed.is_empty() {
        println!(
            "fixed by the cell ({}): {}",
            report.fixed.len(),
            report.fixed.join(", ")
        );
    }
    Ok(())
}
