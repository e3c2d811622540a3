//! `armcal predict`: what the (nominal or identified) model says the instrument measures.

use super::output::{
    load_cell, warn_outside_fitted_ranges, with_note, CalibrationOrNominal, NoteStyle, Outputs,
};
use armcal::measure::csv;
use armcal::sim::predict;
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
    let poses = csv::read_configurations_with(&a.joints, model, &cell.data_format())?;
    if let Some(est) = &est {
        warn_outside_fitted_ranges(est, model, &poses);
    }
    let data = predict(model, &params, &poses, payload.0, cell.measurement)?;
    outputs.commit(&[(
        &a.out,
        &with_note(
            csv::write_string(&data, model)?,
            note.as_deref(),
            NoteStyle::Hash,
        ),
    )])?;
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
    Ok(())
}
