//! `armcal report`: one self-contained HTML file from armcal's JSON results (estimates,
//! designs, `study paper` results), with inline SVG figures and the 3D view of the cell.

use super::output::{write_new, AcceptUnconverged};
use anyhow::bail;
use armcal::cell::Cell;
use armcal::report::{self, Document, Input, ReportContent};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// armcal JSON results: estimates (`armcal identify`), designs (the .json `armcal plan`
    /// writes beside the design CSV) and `armcal study paper` results, in any mix.
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Output folder; the report is written to DIR/report.html.
    #[arg(long)]
    pub out: PathBuf,
    /// Title of the report.
    #[arg(long, default_value = "armcal calibration report")]
    pub title: String,
    /// Overwrite an existing report.html.
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub accept: AcceptUnconverged,
}

/// The cell file a design names, looked up as given (relative to the working folder, or a
/// built-in robot) and beside the design file.
fn cell_of(source: &str, design_file: &Path) -> Result<Cell, armcal::Error> {
    let beside = design_file
        .parent()
        .map(|d| d.join(source))
        .filter(|p| !Path::new(source).exists() && p.exists());
    match beside {
        Some(p) => Cell::from_file(&p),
        None => Cell::load(source),
    }
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let path = a.out.join("report.html");
    if path.exists() && !a.force {
        bail!("{} exists; pass --force to overwrite it", path.display());
    }
    let mut inputs: Vec<Input> = Vec::new();
    let mut notes = Vec::new();
    for f in &a.files {
        let document = Document::from_file(f)?;
        if let Document::Estimate(e) = &document {
            let usable = e
                .check_usable(&a.accept.acceptance())
                .map_err(|e| anyhow::anyhow!("{}: {e}", f.display()))?;
            notes.extend(usable.overridden.map(|o| format!("{}: {o}", f.display())));
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
    let first_design = a
        .files
        .iter()
        .zip(&inputs)
        .find_map(|(f, i)| match &i.document {
            Document::Design(d) => Some((f, d)),
            _ => None,
        });
    let cell_view = match first_design {
        None => None,
        Some((f, d)) => {
            match &d.cell_source {
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
                        .filter(|i| matches!(&i.document, Document::Design(x) if x.cell != cell.name))
                        .map(|i| i.label.as_str())
                        .collect();
                        if !left_out.is_empty() {
                            notes.push(format!(
                                "The 3D view shows the designs for cell `{}` only; left out: {}.",
                                cell.name,
                                left_out.join(", ")
                            ));
                        }
                        report::cell_view_of(&cell, &inputs)?
                    }
                    Err(e) => {
                        notes.push(format!(
                            "No 3D view: the cell `{src}` of design {} could not be loaded ({e}).",
                            f.display()
                        ));
                        None
                    }
                },
            }
        }
    };
    for n in &notes {
        eprintln!("note: {n}");
    }
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
    let page = report::page(&ReportContent {
        title: &a.title,
        subtitle: &subtitle,
        inputs: &inputs,
        demo: None,
        cell_view,
        notes: &notes,
    })?;
    let html = page.render();
    write_new(&path, &html, a.force)?;
    println!(
        "report → {} ({} figure{}{}, {} kB)",
        path.display(),
        page.figure_count(),
        if page.figure_count() == 1 { "" } else { "s" },
        if html.contains("class=\"cell-view\"") {
            ", 3D view"
        } else {
            ""
        },
        html.len().div_ceil(1024)
    );
    Ok(())
}
