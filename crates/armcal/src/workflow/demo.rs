//! `armcal demo` in one call: the demo's run ([`crate::study::demo`]) and its HTML report.

use crate::report::{self, Document, Input, ReportContent};
use crate::study::demo::{run_demo, DemoSummary};
use crate::Error;

/// The demo's summary and every file it writes (name, content), the report included.
pub struct DemoFiles {
    /// The demo's numbers.
    pub summary: DemoSummary,
    /// Every file (name, content), `report.html` last.
    pub files: Vec<(String, String)>,
}

/// Runs the demo and renders its report (`report.html`, the last file); `progress` receives
/// a short label before each stage.
pub fn demo(seed: u64, progress: &dyn Fn(&str)) -> Result<DemoFiles, Error> {
    let run = run_demo(seed, progress)?;
    let mut files = run.files;
    let summary = run.summary;
    progress("writing the report");
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
    files.push(("report.html".into(), html));
    Ok(DemoFiles { summary, files })
}
