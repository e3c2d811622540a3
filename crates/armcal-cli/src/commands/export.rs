//! `armcal export`: the calibrated model as a cell file (DH, modified-DH or zero-reference
//! links), a parameter table, JSON or URDF.

use super::output::{load_estimate, with_note, write_new, AcceptUnconverged, NoteStyle};
use anyhow::Context;
use armcal::model::{convert, export, urdf, Model};
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
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub accept: AcceptUnconverged,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let (est, note) = load_estimate(&a.estimate, &a.accept, None)?;
    let note = note.as_deref();
    let model = Model::from_spec(&est.model).context("rebuilding the identified model")?;
    let params = model.nominal();
    let spec = match a.format.as_str() {
        "zrp" => convert::to_zrp(&model, &params),
        "dh" => convert::zrp_to_dh(&convert::to_zrp(&model, &params), Some(&est.model))?,
        // Pure DH first: a Hayati link of the nominal cannot be regrouped into modified DH.
        "mdh" => convert::dh_to_mdh(&convert::zrp_to_dh(
            &convert::to_zrp(&model, &params),
            None,
        )?)?,
        _ => est.model.clone(),
    };
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
            write_new(
                &a.out,
                &with_note(export::to_cell_toml(&spec)?, note, NoteStyle::Hash),
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
