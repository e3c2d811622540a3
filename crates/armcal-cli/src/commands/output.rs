//! Writing output files without losing anything a user has.

use anyhow::{bail, Context};
use std::path::Path;

/// Writes `content` to `path`, refusing to replace an existing file unless `force`.
pub fn write_new(path: &Path, content: &str, force: bool) -> anyhow::Result<()> {
    if path.exists() && !force {
        bail!("{} exists; pass --force to overwrite it", path.display());
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    std::fs::write(path, content).with_context(|| format!("writing {}", path.display()))
}

/// Loads a cell and prints its warnings to stderr.
pub fn load_cell(name_or_path: &str) -> anyhow::Result<armcal::cell::Cell> {
    let cell = armcal::cell::Cell::load(name_or_path)?;
    for w in &cell.warnings {
        eprintln!("warning: {w}");
    }
    Ok(cell)
}

/// Reads a data file for a cell (its `[data]` column mapping), noting ignored columns on
/// stderr.
pub fn load_data(
    cell: &armcal::cell::Cell,
    path: &Path,
) -> anyhow::Result<armcal::measure::Dataset> {
    let (data, report) = armcal::measure::csv::read_with(path, &cell.model, &cell.data_format())?;
    if !report.ignored.is_empty() {
        eprintln!("note: ignored columns: {}", report.ignored.join(", "));
    }
    Ok(data)
}

/// `--accept-unconverged`, shared by the commands that use an estimate.
#[derive(clap::Args)]
pub struct AcceptUnconverged {
    /// Use an estimate whose fit did not converge (or that records no verdicts); every output
    /// then says so.
    #[arg(long)]
    pub accept_unconverged: bool,
}

impl AcceptUnconverged {
    /// The library's acceptance, in this CLI's flags.
    pub fn acceptance(&self) -> armcal::identify::Acceptance<'static> {
        armcal::identify::Acceptance {
            accepted: self.accept_unconverged,
            accept: "--accept-unconverged",
            raise_iterations: "--max-iterations",
        }
    }
}

/// Reads an estimate, refuses it if its fit did not converge (unless accepted) and, given a
/// model, if it was identified on another model; prints its notes to stderr. Returns the
/// estimate and the line every output made with it must carry (`None` if converged).
pub fn load_estimate(
    path: &Path,
    accept: &AcceptUnconverged,
    model: Option<&armcal::model::Model>,
) -> anyhow::Result<(armcal::identify::Estimate, Option<String>)> {
    let file = |e: armcal::Error| anyhow::anyhow!("{}: {e}", path.display());
    let est = armcal::identify::Estimate::from_file(path)?;
    let usable = est.check_usable(&accept.acceptance()).map_err(file)?;
    if let Some(m) = model {
        est.check_model(m).map_err(file)?;
    }
    if let Some(o) = &usable.overridden {
        eprintln!("warning: {o}");
    }
    for n in &usable.notes {
        eprintln!("note: {}: {n}", path.display());
    }
    Ok((est, usable.overridden))
}

/// The parameters of the estimate at `path` for `model` ([`load_estimate`]), or the nominal
/// ones without an estimate; with the line every output made with them must carry.
pub fn load_params(
    path: Option<&Path>,
    accept: &AcceptUnconverged,
    model: &armcal::model::Model,
) -> anyhow::Result<(Vec<f64>, Option<String>)> {
    match path {
        Some(p) => {
            let (est, note) = load_estimate(p, accept, Some(model))?;
            Ok((est.params_for(model)?, note))
        }
        None => Ok((model.nominal(), None)),
    }
}

/// How an output format carries a note.
#[derive(Clone, Copy)]
pub enum NoteStyle {
    /// A `# …` first line (CSV — armcal's readers skip it — and TOML).
    Hash,
    /// An XML comment before the root element (armcal's URDF has no XML declaration).
    Xml,
    /// A first `"armcal_note"` field of the top-level JSON object.
    Json,
}

/// `content` carrying `note`, if any, in the format's own comment syntax.
pub fn with_note(content: String, note: Option<&str>, style: NoteStyle) -> String {
    let Some(note) = note else {
        return content;
    };
    match style {
        NoteStyle::Hash => format!("# {note}\n{content}"),
        NoteStyle::Xml => format!("<!-- {} -->\n{content}", note.replace("--", "- -")),
        // The output is a pretty-printed JSON object: the field goes right after its `{`.
        NoteStyle::Json => content.replacen(
            '{',
            &format!("{{\n  \"armcal_note\": {},", serde_json::Value::from(note)),
            1,
        ),
    }
}
