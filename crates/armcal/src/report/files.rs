//! A report of armcal's JSON files, as `armcal report` makes it: each file recognised
//! ([`Document::from_file`]) once however often it is given, labelled by its file name,
//! estimates checked for use, and
//! the 3D view of the cell the first design names (looked up as given, then beside the
//! design file), with a note for the reader where something is left out.

use super::html::Page;
use super::{cell_view_of, page, Document, Input, ReportContent};
use crate::cell::Cell;
use crate::identify::Acceptance;
use crate::Error;
use std::path::{Path, PathBuf};

/// The report's page and the notes it carries (also for the user's terminal).
pub struct FilesReport {
    /// The report page ([`Page::render`] gives the HTML).
    pub page: Page,
    /// Notes for the reader, e.g. why the 3D view is missing.
    pub notes: Vec<String>,
}

/// The cell file a design names, looked up as given (relative to the working folder, or a
/// built-in robot) and beside the design file.
fn cell_of(source: &str, design_file: &Path) -> Result<Cell, Error> {
    let beside = design_file
        .parent()
        .map(|d| d.join(source))
        .filter(|p| !Path::new(source).exists() && p.exists());
    match beside {
        Some(p) => Cell::from_file(&p),
        None => Cell::load(source),
    }
}

/// The report of `files` titled `title`; an estimate whose fit did not converge is refused
/// unless `accept_unconverged` (the report then says so).
///
/// ```
/// use armcal::model::random_configurations;
/// use armcal::{files_report, identify, perturbed_truth, simulate, Acceptance};
/// use armcal::{IdentifySettings, Perturbation, Silent};
///
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let cell = armcal::cell::builtin::paper_cell()?;
/// let model = &cell.model;
/// let truth = perturbed_truth(model, &Perturbation::default(), 5);
/// let poses = random_configurations(model, 30, 2);
/// let data = simulate(model, &truth, &poses, Some(&cell.noise()), 3)?;
/// let estimate = identify(&cell, &data, &IdentifySettings::default(), &mut Silent)?;
/// // The estimate file, as `armcal identify --out` writes it, and its report page.
/// let dir = std::env::temp_dir().join(format!("armcal-doc-report-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// let file = dir.join("estimate.json");
/// std::fs::write(&file, serde_json::to_string_pretty(&estimate)?)?;
/// let accept = Acceptance { accepted: false, accept: "", raise_iterations: "" };
/// let report = files_report(&[file], "Calibration", &accept)?;
/// assert!(report.page.render().contains("<html"));
/// std::fs::remove_dir_all(&dir)?;
/// # Ok(())
/// # }
/// ```
pub fn files_report(
    files: &[PathBuf],
    title: &str,
    acceptance: &Acceptance,
) -> Result<FilesReport, Error> {
    let mut inputs: Vec<Input> = Vec::new();
    let mut notes = Vec::new();
    // A file given twice (by the same or another path) is shown once.
    let mut seen: Vec<PathBuf> = Vec::new();
    let mut unique: Vec<&PathBuf> = Vec::new();
    for f in files {
        let key = f.canonicalize().unwrap_or_else(|_| f.clone());
        if seen.contains(&key) {
            notes.push(format!(
                "{} was given more than once; it is shown once.",
                f.display()
            ));
        } else {
            seen.push(key);
            unique.push(f);
        }
    }
    let files = unique;
    for f in files.iter().copied() {
        let document = Document::from_file(f)?;
        if let Document::Estimate(e) = &document {
            let usable = e.check_usable(acceptance).map_err(|e| Error::File {
                file: f.display().to_string(),
                message: e.to_string(),
            })?;
            notes.extend(usable.overridden.map(|o| format!("{}: {o}", f.display())));
        }
        if let Document::TreeEstimate(e) = &document {
            notes.extend(e.check_usable(acceptance).map_err(|e| Error::File {
                file: f.display().to_string(),
                message: e.to_string(),
            })?);
        }
        let stem = f
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| f.display().to_string());
        let label = if inputs.iter().any(|i| i.label == stem) {
            f.display().to_string()
        } else {
            stem
        };
        inputs.push(Input {
            label,
            source: f.display().to_string(),
            document,
        });
    }
    let first_design = files
        .iter()
        .zip(&inputs)
        .find_map(|(f, i)| match &i.document {
            Document::Design(d) => Some((f, d)),
            _ => None,
        });
    let cell_view = match first_design {
        None => None,
        Some((f, d)) => match &d.cell_source {
            None => {
                notes.push(format!(
                    "No 3D view: the design {} does not say which cell file it was made for.",
                    f.display()
                ));
                None
            }
            Some(src) => match cell_of(src, f) {
                Ok(cell) => {
                    let left_out: Vec<&str> = inputs
                        .iter()
                        .filter(
                            |i| matches!(&i.document, Document::Design(x) if x.cell != cell.name),
                        )
                        .map(|i| i.label.as_str())
                        .collect();
                    if !left_out.is_empty() {
                        notes.push(format!(
                            "The 3D view shows the designs for cell `{}` only; left out: {}.",
                            cell.name,
                            left_out.join(", ")
                        ));
                    }
                    cell_view_of(&cell, &inputs)?
                }
                Err(e) => {
                    notes.push(format!(
                        "No 3D view: the cell `{src}` of design {} could not be loaded ({e}).",
                        f.display()
                    ));
                    None
                }
            },
        },
    };
    let subtitle = format!(
        "{} input file{}: {}",
        inputs.len(),
        if inputs.len() == 1 { "" } else { "s" },
        inputs
            .iter()
            .map(|i| format!("{} ({})", i.label, i.document.kind()))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let page = page(&ReportContent {
        title,
        subtitle: &subtitle,
        inputs: &inputs,
        demo: None,
        cell_view,
        notes: &notes,
    })?;
    Ok(FilesReport { page, notes })
}
