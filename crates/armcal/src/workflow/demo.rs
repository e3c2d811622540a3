//! `armcal demo` in one call: the demo's run ([`crate::study::demo`]) and its HTML report.

use crate::progress::Observer;
use crate::report::{self, Document, Input, ReportContent};
use crate::study::demo::{run_demo, DemoSummary};
use crate::Error;

/// The names of the files [`demo`] gives, known before it runs (a command checks where it
/// will write them first).
pub const FILES: [&str; 13] = [
    "cell.toml",
    "data-heuristic.csv",
    "data-kpi.csv",
    "design-heuristic.csv",
    "design-heuristic.json",
    "design-kpi.csv",
    "design-kpi.json",
    "estimate-heuristic.json",
    "estimate-kpi.json",
    "program-corrected.csv",
    "program.csv",
    "report.html",
    "summary.json",
];

/// The demo's summary and every file it writes (name, content), the report included.
pub struct DemoFiles {
    /// The demo's numbers.
    pub summary: DemoSummary,
    /// Every file (name, content; the names are [`FILES`]), `report.html` last.
    pub files: Vec<(String, String)>,
}

/// Runs the demo and renders its report (`report.html`, the last file); `observer` sees
/// each stage as a task.
pub fn demo(seed: u64, observer: &mut dyn Observer) -> Result<DemoFiles, Error> {
    let run = run_demo(seed, observer)?;
    let mut files = run.files;
    let summary = run.summary;
    observer.start("writing the report", None);
    let inputs = [
        (
            "KPI design",
            "design-kpi.json",
            Document::Design(Box::new(run.kpi_design)),
        ),
        (
            "heuristic design",
            "design-heuristic.json",
            Document::Design(Box::new(run.heuristic_design)),
        ),
        (
            "KPI design",
            "estimate-kpi.json",
            Document::Estimate(Box::new(run.kpi_estimate)),
        ),
        (
            "heuristic design",
            "estimate-heuristic.json",
            Document::Estimate(Box::new(run.heuristic_estimate)),
        ),
    ]
    .map(|(label, source, document)| Input {
        label: label.into(),
        source: source.into(),
        document,
    });
    let html = report::render(&ReportContent {
        title: "armcal demo: calibrating the paper cell",
        subtitle: &format!(
            "KPI-optimal vs heuristic measurement poses, {} poses each, seed {}; simulated laser-tracker campaign on a perturbed robot",
            summary.poses, summary.seed
        ),
        inputs: &inputs,
        demo: Some(&summary),
        cell_view: report::cell_view_of(&run.cell, &inputs)?,
        notes: &[],
    })?;
    observer.finish();
    files.push(("report.html".into(), html));
    Ok(DemoFiles { summary, files })
}
