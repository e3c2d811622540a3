//! `armcal accuracy`: ISO 9283 accuracy and repeatability, and the model's errors, from a
//! data file.

use super::output::{load_cell, load_data, load_params, AcceptUnconverged};
use armcal::accuracy::report::accuracy_report;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Cell file or built-in robot.
    #[arg(long)]
    pub cell: String,
    /// Data file (repeated measurements of the same pose_id give RP).
    #[arg(long)]
    pub data: PathBuf,
    /// Identified parameters; nominal if absent.
    #[arg(long)]
    pub estimate: Option<PathBuf>,
    /// Print the report as JSON instead of tables.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub accept: AcceptUnconverged,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let cell = load_cell(&a.cell)?;
    let model = &cell.model;
    let data = load_data(&cell, &a.data)?;
    let (params, note) = load_params(a.estimate.as_deref(), &a.accept, model)?;
    let rep = accuracy_report(model, &params, &data);
    if a.json {
        println!("{}", serde_json::to_string_pretty(&rep)?);
        return Ok(());
    }
    if let Some(n) = &note {
        println!("{n}");
    }
    let e = &rep.errors;
    println!(
        "{} position measurements vs the {} model: mean {:.4}, RMS {:.4}, max {:.4}, p95 {:.4} mm",
        e.count,
        if a.estimate.is_some() {
            "identified"
        } else {
            "nominal"
        },
        e.mean,
        e.rms,
        e.max,
        e.p95
    );
    let repeated: Vec<_> = rep
        .poses
        .iter()
        .filter(|p| p.repeatability.is_some())
        .collect();
    if repeated.is_empty() {
        println!("no pose was measured twice: no repeatability (ISO 9283 RP needs repeated approaches of one pose)");
    }
    for p in repeated {
        let r = p.repeatability.as_ref().expect("filtered");
        println!(
            "pose {}: n = {}, RP = l̄ + 3 S_l = {:.4} + 3 · {:.4} = {:.4} mm; AP = {:.4} mm ({:.4}, {:.4}, {:.4})",
            p.pose_id, r.n, r.mean_distance, r.std_distance, r.rp, p.accuracy.ap, p.accuracy.apx, p.accuracy.apy, p.accuracy.apz
        );
    }
    Ok(())
}
