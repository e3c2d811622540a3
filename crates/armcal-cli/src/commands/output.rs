//! Loading a command's inputs and writing its outputs all or nothing.
//!
//! Every command that writes files makes an [`Outputs`] plan first, before it computes
//! anything: each output path is refused if it exists (without `--force`), if it is one of
//! the command's own input files (even with `--force`; paths compared canonically), if two
//! outputs are one file, or if its directory cannot be written. After the computation,
//! [`Outputs::commit`] writes every file to a temporary name in its own directory, then
//! renames them into place; if anything fails, the temporary files, the files it created and
//! the directories it made are removed again, so a failed command leaves no new file behind.

use anyhow::{bail, Context};
use armcal::Estimate;
use std::path::{Path, PathBuf};

/// The files a command will write, checked before it computes anything.
pub struct Outputs {
    paths: Vec<PathBuf>,
    force: bool,
}

impl Outputs {
    /// Checks `outputs` against the rules above; `inputs` are the files the command reads
    /// (paths that do not exist, e.g. a built-in cell's name, are no file and are skipped).
    pub fn plan(force: bool, inputs: &[&Path], outputs: &[&Path]) -> anyhow::Result<Outputs> {
        let canonical: Vec<PathBuf> = inputs
            .iter()
            .filter_map(|p| std::fs::canonicalize(p).ok())
            .collect();
        let mut seen: Vec<PathBuf> = Vec::new();
        for &path in outputs {
            if path.is_dir() {
                bail!("{} is a directory; name a file", path.display());
            }
            if let Ok(c) = std::fs::canonicalize(path) {
                if canonical.contains(&c) {
                    bail!(
                        "{} is an input of this command; write the output to another file",
                        path.display()
                    );
                }
            }
            if path.exists() && !force {
                bail!("{} exists; pass --force to overwrite it", path.display());
            }
            let full = absolute(path)?;
            if seen.contains(&full) {
                bail!("{} is given as two outputs", path.display());
            }
            check_writable(&full)?;
            seen.push(full);
        }
        Ok(Outputs {
            paths: outputs.iter().map(|p| p.to_path_buf()).collect(),
            force,
        })
    }

    /// Writes `files` (each a planned path with its content), all or nothing.
    pub fn commit(&self, files: &[(&Path, &str)]) -> anyhow::Result<()> {
        let mut done = Commit::default();
        let result = self.write_all(files, &mut done);
        if result.is_err() {
            done.undo();
        }
        result
    }

    fn write_all(&self, files: &[(&Path, &str)], done: &mut Commit) -> anyhow::Result<()> {
        for (path, content) in files {
            if !self.paths.iter().any(|p| p == path) {
                bail!("{} was not planned as an output", path.display());
            }
            if path.exists() && !self.force {
                bail!("{} exists; pass --force to overwrite it", path.display());
            }
            let dir = parent(path);
            let mut missing: Vec<PathBuf> = dir
                .ancestors()
                // A relative path's last ancestor is "", which is the working directory.
                .take_while(|d| !d.as_os_str().is_empty() && !d.exists())
                .map(Path::to_path_buf)
                .collect();
            missing.reverse();
            for d in missing {
                std::fs::create_dir(&d).with_context(|| format!("creating {}", d.display()))?;
                done.dirs.push(d);
            }
            let name = path.file_name().unwrap_or_default().to_string_lossy();
            let temp = dir.join(format!(".{name}.armcal-{}.tmp", std::process::id()));
            done.temps.push(temp.clone());
            std::fs::write(&temp, content)
                .with_context(|| format!("writing {}", path.display()))?;
        }
        for ((path, _), temp) in files.iter().zip(done.temps.clone()) {
            let created = !path.exists();
            std::fs::rename(&temp, path).with_context(|| format!("writing {}", path.display()))?;
            done.temps.retain(|t| t != &temp);
            if created {
                done.created.push(path.to_path_buf());
            }
        }
        Ok(())
    }
}

/// What a commit has made so far, to be removed if it fails.
#[derive(Default)]
struct Commit {
    temps: Vec<PathBuf>,
    created: Vec<PathBuf>,
    dirs: Vec<PathBuf>,
}

impl Commit {
    fn undo(&self) {
        for f in self.temps.iter().chain(&self.created) {
            let _ = std::fs::remove_file(f);
        }
        for d in self.dirs.iter().rev() {
            let _ = std::fs::remove_dir(d);
        }
    }
}

/// The directory a file path is in (`.` for a bare name).
fn parent(path: &Path) -> &Path {
    path.parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

fn absolute(path: &Path) -> anyhow::Result<PathBuf> {
    std::path::absolute(path).with_context(|| format!("resolving {}", path.display()))
}

/// Whether a file can be made at `path`: its nearest existing ancestor directory accepts a
/// probe file (which is removed at once).
fn check_writable(path: &Path) -> anyhow::Result<()> {
    let Some(dir) = parent(path).ancestors().find(|d| d.exists()) else {
        bail!("{} has no existing directory above it", path.display());
    };
    if !dir.is_dir() {
        bail!(
            "cannot write {}: {} is not a directory",
            path.display(),
            dir.display()
        );
    }
    let probe = dir.join(format!(".armcal-probe-{}.tmp", std::process::id()));
    std::fs::write(&probe, "").with_context(|| {
        format!(
            "cannot write {}: {} is not writable",
            path.display(),
            dir.display()
        )
    })?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// Loads a cell and prints its warnings to stderr.
pub fn load_cell(name_or_path: &str) -> anyhow::Result<armcal::Cell> {
    let cell = armcal::Cell::load(name_or_path)?;
    for w in &cell.warnings {
        eprintln!("warning: {w}");
    }
    Ok(cell)
}

/// Loads a cell whose poses a command checks for measurability (plan, evaluate, simulate,
/// campaign) and notes on stderr when its line of sight and incidence go unchecked because
/// the cell does not place its instrument
/// ([`armcal::unplaced_instrument`]).
pub fn load_cell_to_measure(name_or_path: &str) -> anyhow::Result<armcal::Cell> {
    let cell = load_cell(name_or_path)?;
    if let Some(note) = armcal::unplaced_instrument(&cell) {
        eprintln!("note: {note}");
    }
    Ok(cell)
}

/// Reads a data file for a cell (its `[data]` column mapping), with the reader's remarks
/// ([`print_read_report`]) and a note when the cell's noise model does not use the σ columns.
pub fn load_data(cell: &armcal::Cell, path: &Path) -> anyhow::Result<armcal::Dataset> {
    let (data, report) = cell.read_data(path)?;
    print_read_report(&report);
    if let Some(note) = cell.noise().unused_sigmas(&data) {
        eprintln!("note: {note}");
    }
    Ok(data)
}

/// The files of `--data` arguments, each `FILE` or `STATION=FILE` (a `=` in an existing
/// file's name is part of the name), with the station each names.
pub fn station_files(args: &[String]) -> Vec<(Option<String>, PathBuf)> {
    args.iter()
        .map(|a| match a.split_once('=') {
            Some((station, file)) if !Path::new(a).exists() => {
                (Some(station.to_string()), PathBuf::from(file))
            }
            _ => (None, PathBuf::from(a)),
        })
        .collect()
}

/// The data of several files ([`station_files`]) read for a cell ([`load_data`]), merged by
/// the library's rule ([`armcal::Dataset::merge_stations`]).
pub fn load_station_data(
    cell: &armcal::Cell,
    files: &[(Option<String>, PathBuf)],
) -> anyhow::Result<armcal::Dataset> {
    let parts = files
        .iter()
        .map(|(station, file)| Ok((station.clone(), load_data(cell, file)?)))
        .collect::<anyhow::Result<Vec<_>>>()?;
    Ok(armcal::Dataset::merge_stations(parts)?)
}

/// The reader's remarks on stderr: ignored columns, then rows read with a warning (the first
/// few, and how many more).
pub fn print_read_report(report: &armcal::ReadReport) {
    const SHOWN: usize = 5;
    if !report.ignored.is_empty() {
        eprintln!("note: ignored columns: {}", report.ignored.join(", "));
    }
    for w in report.warnings.iter().take(SHOWN) {
        eprintln!("warning: {w}");
    }
    if report.warnings.len() > SHOWN {
        eprintln!(
            "warning: … and {} more rows like these",
            report.warnings.len() - SHOWN
        );
    }
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
    pub fn acceptance(&self) -> armcal::Acceptance<'static> {
        armcal::Acceptance {
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
    model: Option<&armcal::Model>,
) -> anyhow::Result<(armcal::Estimate, Option<String>)> {
    let file = |e: armcal::Error| anyhow::anyhow!("{}: {e}", path.display());
    let est = armcal::Estimate::from_file(path)?;
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

/// The payload a prediction is made at (an index into the model's payloads) and, unless the
/// model has no payloads and none was asked for, the sentence saying how.
pub type PayloadChoice = (Option<usize>, Option<String>);

/// What [`CalibrationOrNominal::load_at_payload`] returns: the parameters, the note every
/// output made with them carries, the payload choice and the estimate they came from
/// (`None`: nominal).
pub type ParamsAtPayload = (Vec<f64>, Option<String>, PayloadChoice, Option<Estimate>);

/// `--estimate` (required) and `--accept-unconverged`: the calibration a command applies.
#[derive(clap::Args)]
pub struct Calibration {
    /// Identified parameters (estimate.json).
    #[arg(long)]
    pub estimate: PathBuf,
    #[command(flatten)]
    pub accept: AcceptUnconverged,
}

impl Calibration {
    /// The estimate, checked against `model` ([`load_estimate`]), with the line every output
    /// made with it must carry.
    pub fn load(
        &self,
        model: Option<&armcal::Model>,
    ) -> anyhow::Result<(Estimate, Option<String>)> {
        load_estimate(&self.estimate, &self.accept, model)
    }
}

/// `--estimate` (optional: the nominal model without it) and `--accept-unconverged`.
#[derive(clap::Args)]
pub struct CalibrationOrNominal {
    /// Identified parameters (estimate.json); nominal if absent.
    #[arg(long)]
    pub estimate: Option<PathBuf>,
    #[command(flatten)]
    pub accept: AcceptUnconverged,
}

impl CalibrationOrNominal {
    /// The parameters of the estimate for `model` ([`load_estimate`]), or the nominal ones
    /// without an estimate, with the line every output made with them must carry, and the
    /// payload the robot carries: `name` checked against the estimate
    /// ([`armcal::Estimate::payload_for`]) — the payload index and the sentence
    /// saying how it is predicted (`None` for a model without payloads and no `--payload`).
    /// Without an estimate, the nominal model at payload `name`.
    pub fn load_at_payload(
        &self,
        model: &armcal::Model,
        name: Option<&str>,
    ) -> anyhow::Result<ParamsAtPayload> {
        let quiet = name.is_none() && model.payloads.is_empty();
        match &self.estimate {
            Some(p) => {
                let (est, note) = load_estimate(p, &self.accept, Some(model))?;
                let (payload, how) = est.payload_for(model, name)?;
                Ok((
                    est.params_for(model)?,
                    note,
                    (payload, (!quiet).then_some(how)),
                    Some(est),
                ))
            }
            None => {
                let payload = model
                    .payload_index(name.unwrap_or("none"))
                    .map_err(|e| anyhow::anyhow!("--payload: {e}"))?;
                Ok((model.nominal(), None, (payload, None), None))
            }
        }
    }
}

/// Prints a warning when `configurations` (id, q) leave the joint ranges `est` was fitted on
/// ([`Estimate::outside_fitted_ranges`]).
pub fn warn_outside_fitted_ranges(
    est: &Estimate,
    model: &armcal::Model,
    configurations: &[(String, Vec<f64>)],
) {
    if let Some(w) = est.outside_fitted_ranges(model, configurations) {
        eprintln!("warning: {w}");
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

#[cfg(test)]
mod tests {
    use super::Outputs;

    #[test]
    fn a_failed_commit_removes_what_it_wrote() {
        let dir = std::env::temp_dir().join(format!("armcal-outputs-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let (a, b) = (dir.join("new/a.txt"), dir.join("sub/b.txt"));
        let outputs = Outputs::plan(false, &[], &[&a, &b]).unwrap();
        // After the plan, a file takes the place of b's folder: its write fails.
        std::fs::write(dir.join("sub"), "in the way").unwrap();
        assert!(outputs.commit(&[(&a, "a"), (&b, "b")]).is_err());
        let left: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        assert_eq!(left, ["sub"], "the new folder and its file are gone");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
