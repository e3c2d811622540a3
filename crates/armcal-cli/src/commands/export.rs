//! `armcal export` (alias `armcal deploy`): the calibrated model as a cell file (DH,
//! modified-DH or zero-reference links), a parameter table, JSON, URDF (plain, with
//! `<calibration rising>` joint offsets, conservative), a Universal Robots kinematics YAML or
//! a ROS 2 parameter file of per-joint corrections. One command writes a model in every
//! format: the vendor files are formats of it, and `deploy` (the name) is an alias.

use super::output::{with_note, Calibration, NoteStyle, Outputs};
use armcal::{ExportFormat, DEFAULT_K_SIGMA};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub calibration: Calibration,
    /// Output format.
    #[arg(long, value_parser = ["dh", "mdh", "zrp", "json", "urdf", "cell", "urdf-calibration",
        "urdf-conservative", "ur-yaml", "ros-params"])]
    pub format: String,
    /// `urdf-conservative`: keep a correction only if it is more than this many σ from zero.
    #[arg(long, default_value_t = DEFAULT_K_SIGMA)]
    pub k_sigma: f64,
    /// Output file. `dh`, `mdh`, `zrp` and `cell` write a loadable cell file (TOML) and a
    /// parameter table next to it (same name, `.csv`).
    #[arg(long)]
    pub out: PathBuf,
    /// The cell the estimate was identified in: a cell export then carries its instrument
    /// (noise, incidence limit), capsules, working poses, obstacles, data columns, measurement
    /// type, fixed parameters and their stated σ (`fixed_prior`, `fixed_priors`), with
    /// `free = "auto"`, so every command accepts it unchanged.
    #[arg(long)]
    pub cell: Option<String>,
    /// Overwrite existing output files (never an input file).
    #[arg(long)]
    pub force: bool,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    if let Some(est) = armcal::TreeEstimate::read_if_tree(&a.calibration.estimate)? {
        return super::tree::export(a, &est);
    }
    let format = match ExportFormat::from_name(&a.format).expect("clap checked") {
        ExportFormat::UrdfCalibration(Some(_)) => ExportFormat::UrdfCalibration(Some(a.k_sigma)),
        f => f,
    };
    let table = a.out.with_extension("csv");
    let mut outs = vec![a.out.as_path()];
    if matches!(format, ExportFormat::Cell(_)) {
        outs.push(&table);
    }
    let mut inputs = vec![a.calibration.estimate.as_path()];
    inputs.extend(a.cell.as_deref().map(Path::new));
    let outputs = Outputs::plan(a.force, &inputs, &outs)?;
    let cell = a
        .cell
        .as_deref()
        .map(super::output::load_cell)
        .transpose()?;
    let (est, note) = a.calibration.load(cell.as_ref().map(|c| &c.model))?;
    let note = note.as_deref();
    let exported = armcal::export_estimate(&est, cell.as_ref(), format)?;
    for w in &exported.warnings {
        eprintln!("warning: {w}");
    }
    for n in &exported.notes {
        eprintln!("note: {n}");
    }
    match format {
        ExportFormat::Json => {
            outputs.commit(&[(&a.out, &with_note(exported.content, note, NoteStyle::Json))])?
        }
        ExportFormat::Urdf | ExportFormat::UrdfCalibration(_) => {
            outputs.commit(&[(&a.out, &with_note(exported.content, note, NoteStyle::Xml))])?
        }
        ExportFormat::UrKinematics | ExportFormat::JointCorrections => {
            outputs.commit(&[(&a.out, &with_note(exported.content, note, NoteStyle::Hash))])?
        }
        ExportFormat::Cell(_) => {
            if cell.is_none() {
                eprintln!(
                    "note: without --cell the exported cell holds the model alone (no instrument \
                     noise, working poses, obstacles, capsules); pass the estimate's cell with \
                     --cell to carry them"
                );
            }
            outputs.commit(&[
                (&a.out, &with_note(exported.content, note, NoteStyle::Hash)),
                (
                    &table,
                    &with_note(
                        exported.table_csv.unwrap_or_default(),
                        note,
                        NoteStyle::Hash,
                    ),
                ),
            ])?;
        }
    }
    println!("{} model of `{}` → {}", a.format, est.cell, a.out.display());
    Ok(())
}
