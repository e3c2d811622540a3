//! `armcal report`: one self-contained HTML file from armcal's JSON results (estimates,
//! designs, `study paper` results), with inline SVG figures and the 3D view of the cell.

use super::output::{AcceptUnconverged, Outputs};
use super::progress::Progress;
use armcal::{files_report, Observer};
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
    /// No progress display.
    #[arg(long)]
    pub quiet: bool,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let path = a.out.join("report.html");
    let inputs: Vec<&Path> = a.files.iter().map(PathBuf::as_path).collect();
    let outputs = Outputs::plan(a.force, &inputs, &[&path])?;
    let mut progress = Progress::new(a.quiet);
    progress.start("reading the results and drawing the report", None);
    let report = files_report(&a.files, &a.title, &a.accept.acceptance())?;
    let page = &report.page;
    let html = page.render();
    progress.finish();
    drop(progress);
    for n in &report.notes {
        eprintln!("note: {n}");
    }
    outputs.commit(&[(&path, &html)])?;
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
