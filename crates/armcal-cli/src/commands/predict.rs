//! `armcal predict`: what the (nominal or identified) model says the instrument measures.

use super::output::{
    load_cell, warn_outside_fitted_ranges, with_note, CalibrationOrNominal, NoteStyle, Outputs,
};
use armcal::predict;
use armcal::{csv_with_sigmas, prediction_sigmas, RowSigma};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// Cell file or built-in robot.
    #[arg(long)]
    pub cell: String,
    #[command(flatten)]
    pub calibration: CalibrationOrNominal,
    /// Joint configurations (CSV).
    #[arg(long)]
    pub joints: PathBuf,
    /// Output (CSV, the columns of a data file).
    #[arg(long)]
    pub out: PathBuf,
    /// The payload the robot carries (a cell's `[[payload]]` name, or `none`); default: the
    /// payload the calibration data carried if they carried one only, else none. A payload
    /// the calibration did not measure needs its joint compliances identified.
    #[arg(long)]
    pub payload: Option<String>,
    /// Overwrite existing output files (never an input file).
    #[arg(long)]
    pub force: bool,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let mut inputs = vec![Path::new(&a.cell), &a.joints];
    inputs.extend(a.calibration.estimate.as_deref());
    let outputs = Outputs::plan(a.force, &inputs, &[&a.out])?;
    let cell = load_cell(&a.cell)?;
    let model = &cell.model;
    let (params, note, payload, est) =
        a.calibration.load_at_payload(model, a.payload.as_deref())?;
    let poses = cell.read_poses(&a.joints)?;
    if let Some(est) = &est {
        warn_outside_fitted_ranges(est, model, &poses);
    }
    let data = predict(model, &params, &poses, payload.0, cell.measurement)?;
    let sigmas = match &est {
        Some(est) => prediction_sigmas(model, &params, est, &data)?,
        None => None,
    };
    let text = match &sigmas {
        Some(s) => cell.with_controller_columns(csv_with_sigmas(&data, model, s)?)?,
        None => cell.write_data(&data)?,
    };
    outputs.commit(&[(&a.out, &with_note(text, note.as_deref(), NoteStyle::Hash))])?;
    println!(
        "predicted {} measurements at {} configurations with the {} model → {}",
        data.measurements.len(),
        poses.len(),
        if a.calibration.estimate.is_some() {
            "identified"
        } else {
            "nominal"
        },
        a.out.display()
    );
    if let Some(how) = payload.1 {
        println!("payload: {how}");
    }
    match (&est, &sigmas) {
        (Some(_), Some(s)) => println!("{}", sigma_summary(s)),
        (Some(_), None) => println!(
            "no σ columns: the estimate's free parameters are not all the cell's (a fit over instrument stations), or a row is neither a position nor a pose"
        ),
        _ => {}
    }
    Ok(())
}

/// The largest σ's of the columns `predict` wrote.
fn sigma_summary(s: &[RowSigma]) -> String {
    let largest = |f: &dyn Fn(&RowSigma) -> Option<f64>| s.iter().filter_map(f).reduce(f64::max);
    let mm = |x: Option<f64>| x.map(|x| format!("{x:.4} mm")).unwrap_or_default();
    let mut line = format!(
        "σ of each row from the estimate's C_p (sigma_mm): largest {}",
        mm(largest(&|r| Some(r.point.position_mm)))
    );
    if let Some(t) = largest(&|r| r.point.total_mm()) {
        line += &format!(
            "; with the model floor of the fixed parameters (total_sigma_mm) {}",
            mm(Some(t))
        );
    } else {
        line += "; the estimate states no model floor";
    }
    if let Some(t) = largest(&|r| r.tcp.map(|t| t.total_mm().unwrap_or(t.position_mm))) {
        line += &format!("; at the TCP (tcp_total_sigma_mm) {}", mm(Some(t)));
    }
    line
}
