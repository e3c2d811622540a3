//! A report of an estimate with many measurements: the per-pose residual figure draws at
//! most `decimate::MAX_POINTS` points per component, keeps the extremes, and says so.

use crate::common::example_cell;
use armcal::identify::MeasurementResidual;
use armcal::model::random_configurations;
use armcal::report::{self, Document, Input, ReportContent};
use armcal::{identify, perturbed_truth, simulate, IdentifySettings, Perturbation, Silent};

/// The numbers written as tick labels (`<text …>value</text>`) in the SVG `svg`.
fn tick_values(svg: &str) -> Vec<f64> {
    svg.split("</text>")
        .filter_map(|t| t.rsplit('>').next())
        .filter_map(|t| t.trim().replace('\u{2212}', "-").parse::<f64>().ok())
        .collect()
}

#[test]
fn a_large_estimate_is_drawn_decimated_with_its_extremes_and_says_so() {
    let cell = example_cell("paper-cell.toml");
    let model = &cell.model;
    let truth = perturbed_truth(model, &Perturbation::default(), 3);
    let qs = random_configurations(model, 40, 7);
    let noise = cell.instrument.as_ref().unwrap().noise.clone();
    let data = simulate(model, &truth, &qs, Some(&noise), 9).unwrap();
    let mut est = identify(&cell, &data, &IdentifySettings::default(), &mut Silent).unwrap();
    // 50 000 measurements' residuals (small, deterministic), one spike far above the rest.
    let n = 50_000;
    let spike = 31_337;
    est.residuals.per_measurement = (0..n)
        .map(|i| {
            let v = ((i * 7919) % 1000) as f64 / 1000.0 - 0.5;
            let z = if i == spike { 250.0 } else { -v };
            MeasurementResidual {
                pose: i + 1,
                pose_id: format!("p{i}"),
                xyz: Some([v, 0.5 * v, z]),
                norm: (v * v * 1.25 + z * z).sqrt(),
            }
        })
        .collect();
    let inputs = [Input {
        label: "large".into(),
        source: "large.json".into(),
        document: Document::Estimate(Box::new(est)),
    }];
    let page = report::page(&ReportContent {
        title: "large",
        inputs: &inputs,
        ..Default::default()
    })
    .unwrap();
    let html = page.render();
    assert!(
        html.contains("at most 2\u{202f}000 of the 50\u{202f}000 measurements per component"),
        "the page says the plot is decimated"
    );
    // The whole page stays small (undecimated, the per-pose figure alone is ~15 MB).
    assert!(html.len() < 3 << 20, "{} bytes", html.len());
    // The spike is drawn: the per-pose figure's value axis reaches it.
    let start = html.find("Residuals per pose").expect("per-pose figure");
    let svg = &html[start..];
    let svg = &svg[..svg.find("</svg>").unwrap()];
    let top = tick_values(svg).into_iter().fold(f64::MIN, f64::max);
    assert!(top >= 200.0, "largest tick {top}: the spike was dropped");
}
