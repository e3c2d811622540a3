//! `armcal export`: the calibrated model as a cell file (DH, modified-DH or zero-reference
//! links), a parameter table, JSON or URDF.

use super::output::{load_estimate, with_note, write_new, AcceptUnconverged, NoteStyle};
use anyhow::Context;
use armcal::model::complete::LinkForm;
use armcal::model::{export, urdf, Model};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Identified parameters (estimate.json).
    #[arg(long)]
    pub estimate: PathBuf,
    /// Output format.
    #[arg(long, value_parser = ["dh", "mdh", "zrp", "json", "urdf", "cell"])]
    pub format: String,
    /// Output file. `dh`, `mdh`, `zrp` and `cell` write a loadable cell file (TOML) and a
    /// parameter table next to it (same name, `.csv`).
    #[arg(long)]
    pub out: PathBuf,
    /// The cell the estimate was identified in: a cell export then carries its instrument
    /// (noise, incidence limit), capsules, working poses, obstacles, data columns, measurement
    /// type and fixed parameters, with `free = "auto"`, so every command accepts it unchanged.
    #[arg(long)]
    pub cell: Option<String>,
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub accept: AcceptUnconverged,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let cell = a
        .cell
        .as_deref()
        .map(super::output::load_cell)
        .transpose()?;
    let (est, note) = load_estimate(&a.estimate, &a.accept, cell.as_ref().map(|c| &c.model))?;
    let note = note.as_deref();
    let model = Model::from_spec(&est.model).context("rebuilding the identified model")?;
    let form = match a.format.as_str() {
        "zrp" => LinkForm::Zrp,
        "dh" => LinkForm::Dh,
        "mdh" => LinkForm::Mdh,
        _ => LinkForm::AsGiven,
    };
    let spec = export::export_form(&est.model, form)?;
    let reference = match &cell {
        Some(c) => export::export_form(&c.model.spec(), form)?,
        None => spec.clone(),
    };
    for w in export::suspicious_values(&Model::from_spec(&reference)?, &spec)? {
        eprintln!("warning: {w}");
    }
    match a.format.as_str() {
        "json" => write_new(
            &a.out,
            &with_note(serde_json::to_string_pretty(&spec)?, note, NoteStyle::Json),
            a.force,
        )?,
        "urdf" => write_new(
            &a.out,
            &with_note(urdf::to_urdf(&spec)?, note, NoteStyle::Xml),
            a.force,
        )?,
        _ => {
            if cell.is_none() {
                eprintln!(
                    "note: without --cell the exported cell holds the model alone (no instrument \
                     noise, working poses, obstacles, capsules); pass the estimate's cell with \
                     --cell to carry them"
                );
            }
            write_new(
                &a.out,
                &with_note(
                    match &cell {
                        Some(c) => armcal::cell::export::to_cell_toml(c, &model, &spec)?,
                        None => export::to_cell_toml(&spec)?,
                    },
                    note,
                    NoteStyle::Hash,
                ),
                a.force,
            )?;
            write_new(
                &a.out.with_extension("csv"),
                &with_note(export::to_table_csv(&spec), note, NoteStyle::Hash),
                a.force,
            )?;
        }
    }
    println!("{} model of `{}` → {}", a.format, est.cell, a.out.display());
    Ok(())
}
