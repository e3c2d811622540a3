//! `armcal model <robot-or-cell>`: parameters, completeness and identifiability.

use armcal::model::identifiability::{IdentifiabilityOptions, Measurement};
use armcal::model::Status;

#[derive(clap::Args)]
pub struct Args {
    /// Built-in robot name or cell file.
    pub target: String,
    /// Measurement type for the identifiability analysis (default: the cell's).
    #[arg(long, value_parser = ["pose", "position", "distance"])]
    pub measurement: Option<String>,
    /// Random configurations used by the analysis.
    #[arg(long, default_value_t = 60)]
    pub poses: usize,
    /// Seed of the random configurations.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Print JSON instead of tables.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let cell = super::output::load_cell(&a.target)?;
    let model = &cell.model;
    let measurement = a
        .measurement
        .as_deref()
        .and_then(Measurement::from_name)
        .unwrap_or(cell.measurement);
    // The analysis runs on the parameters the cell declared free, before the automatic
    // reduction, so that every excluded parameter gets its reason.
    let report = cell.identifiability(&IdentifiabilityOptions {
        measurement,
        poses: a.poses,
        seed: a.seed,
        ..cell.identifiability_options()
    })?;
    if a.json {
        let params: Vec<_> = model
            .registry
            .iter()
            .map(|p| {
                serde_json::json!({
                    "name": p.name,
                    "unit": p.unit.display_name(),
                    "nominal": p.nominal * p.unit.display_factor(),
                    "status": p.status,
                })
            })
            .collect();
        let out = serde_json::json!({
            "cell": cell.name,
            "source": cell.robot.source,
            "joints": model.joints,
            "parameters": params,
            "identifiability": report,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!("{} ({})", cell.name, cell.origin);
    println!("source: {}\n", cell.robot.source);
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
            "{:<4} {:<14} {:>14.6} {:<4} {status}",
            i + 1,
            p.name,
            p.nominal * p.unit.display_factor(),
            p.unit.display_name()
        );
    }
    println!("\njoints:");
    for j in &model.joints {
        let f = j.kind.unit().display_factor();
        println!(
            "  {:<6} {:?} [{:.2}, {:.2}] {}",
            j.name,
            j.kind,
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
            "expected identifiable from {measurement:?} measurements in generic geometry: {n}"
        ),
        None => {
            println!("no closed-form count for {measurement:?} measurements of several targets")
        }
    }
    println!(
        "numerical analysis over {} random configurations (seed {}): {} candidate parameters, rank {} (SVD), {} (pivoted QR)",
        report.poses, a.seed, report.candidates.len(), report.rank_svd, report.rank_qr
    );
    println!(
        "identifiable: {} parameters, condition number of the column-scaled Jacobian {:.1}",
        report.identifiable.len(),
        report.condition_number
    );
    println!("  {}", report.identifiable.join(", "));
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
