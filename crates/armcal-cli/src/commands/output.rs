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

/// Reads a data file for a cell (its joint-column mapping), noting ignored columns on
/// stderr.
pub fn load_data(
    cell: &armcal::cell::Cell,
    path: &Path,
) -> anyhow::Result<armcal::measure::Dataset> {
    let (data, report) = armcal::measure::csv::read(
        path,
        &cell.model,
        cell.data_columns.as_ref().map(|d| d.joints.as_slice()),
    )?;
    if !report.ignored.is_empty() {
        eprintln!("note: ignored columns: {}", report.ignored.join(", "));
    }
    Ok(data)
}
