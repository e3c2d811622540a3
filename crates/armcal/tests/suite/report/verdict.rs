//! The report's verdict panels and the figures added with them (issue 12 item 10): the data
//! each figure draws checked against the records (change / σ, the correlation matrix,
//! estimate − truth, held-out error per axis, joint corrections, C_s in the base frame),
//! and the page's structure (verdict first, one panel per estimate, one colour per design,
//! predicted ellipses on top, scrolling tables, a file given twice shown once).

use super::html::fixtures;
use armcal::compensate::filter_joint_program;
use armcal::identify::Chi2Outcome;
use armcal::model::tool_pose;
use armcal::report::compensation::joint_corrections;
use armcal::report::figures::{colour, design_colour, ellipse_figure, EllipseSeries};
use armcal::report::parameter_charts::{correlation_colour, heatmap_figure};
use armcal::report::parameter_view::{change_over_sigma, correlation, estimate_minus_truth};
use armcal::report::verdict::{estimate_grade, held_out_gain, Grade};
use armcal::report::{self, design_key, Document, Input, ReportContent};
use armcal::{
    files_report, perturbed_truth, Acceptance, IkSettings, Perturbation, ProgramRecord, TruthRecord,
};
use nalgebra::{DMatrix, Matrix3};
use plotters::style::RGBColor;

fn hex(c: RGBColor) -> String {
    format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)
}

#[test]
fn change_over_sigma_is_the_records_change_divided_by_its_sigma() {
    let (_, _, est) = fixtures();
    let change = change_over_sigma(est);
    let free: Vec<_> = est.parameters.iter().filter(|p| p.free).collect();
    assert_eq!(change.len(), free.len());
    assert_eq!(change.len(), est.free.len());
    for ((name, z), p) in change.iter().zip(&free) {
        assert_eq!(name, &p.name);
        let expected = (p.estimate - p.nominal) / p.sigma.unwrap();
        assert!(
            (z - expected).abs() <= 1e-12 * expected.abs().max(1.0),
            "{name}"
        );
    }
    // The fit moved some parameters far beyond their σ (the truth is perturbed).
    assert!(change.iter().any(|(_, z)| z.abs() > 3.0));
}

#[test]
fn heatmap_is_the_correlation_matrix_with_unit_diagonal() {
    let (_, _, est) = fixtures();
    let (names, rho) = correlation(est).unwrap();
    assert_eq!(names, est.free);
    let n = names.len();
    assert_eq!((rho.nrows(), rho.ncols()), (n, n));
    let c = &est.uncertainty.covariance;
    for i in 0..n {
        assert!((rho[(i, i)] - 1.0).abs() < 1e-12);
        for j in 0..n {
            // Symmetric, bounded, and C_ij / (σ_i σ_j) from the record's σ's.
            assert!((rho[(i, j)] - rho[(j, i)]).abs() < 1e-12);
            assert!(rho[(i, j)].abs() <= 1.0 + 1e-12);
            let s = est.uncertainty.sigma[i] * est.uncertainty.sigma[j];
            assert!((rho[(i, j)] - c[(i, j)] / s).abs() < 1e-9, "{i} {j}");
            // The same as the correlation matrix the estimate stores.
            assert!((rho[(i, j)] - est.uncertainty.correlation[(i, j)]).abs() < 1e-9);
        }
    }
    // One coloured cell per entry, white at ρ = 0, the palette's ends at ±1.
    let svg = heatmap_figure("ρ", &names, &rho).unwrap();
    let cells = svg.matches("<rect").count();
    assert!(cells >= n * n, "{cells} rects for {n}×{n}");
    assert_eq!(correlation_colour(0.0), RGBColor(255, 255, 255));
    assert_eq!(correlation_colour(1.0), colour(1));
    assert_eq!(correlation_colour(-1.0), colour(0));
    // A covariance that does not fit the names is an error, not a picture.
    let mut bad = est.clone();
    bad.free.pop();
    assert!(correlation(&bad).unwrap_err().to_string().contains("names"));
    assert!(heatmap_figure("ρ", &names[1..], &rho).is_err());
    let mut zero = est.clone();
    zero.uncertainty.covariance = DMatrix::zeros(n, n);
    assert!(correlation(&zero)
        .unwrap_err()
        .to_string()
        .contains("not positive"));
}

#[test]
fn estimate_minus_truth_is_matched_by_name() {
    let (cell, _, est) = fixtures();
    // The fixture's truth: the paper cell perturbed with seed 3.
    let truth = perturbed_truth(&cell.model, &Perturbation::default(), 3);
    let record = TruthRecord::new(&cell.name, &cell.model, &truth, 3);
    let errors = estimate_minus_truth(est, &record);
    assert_eq!(errors.len(), est.free.len());
    for x in &errors {
        let p = est.parameters.iter().find(|p| p.name == x.name).unwrap();
        let t = record.parameters.iter().find(|t| t.name == x.name).unwrap();
        assert_eq!(x.error, p.estimate - t.truth);
        assert_eq!(Some(x.sigma), p.sigma);
    }
    // A calibration from 1 mm noise: most parameters within 3 σ of the truth.
    let within = errors
        .iter()
        .filter(|x| (x.error / x.sigma).abs() < 3.0)
        .count();
    assert!(
        within * 10 >= errors.len() * 8,
        "{within} of {}",
        errors.len()
    );
}

#[test]
fn held_out_error_per_axis_adds_up_to_the_norm() {
    let (_, _, est) = fixtures();
    let v = est.validation.as_ref().unwrap();
    let a = v.per_axis.as_ref().expect("per-axis validation");
    // |e|² = x² + y² + z² per measurement, so the mean squares add up.
    for (axes, norm) in [
        (&a.nominal, &v.nominal),
        (&a.frames_only, &v.frames_only),
        (&a.calibrated, &v.calibrated),
    ] {
        assert_eq!(axes.x.count, norm.count);
        let sum = axes.x.rms.powi(2) + axes.y.rms.powi(2) + axes.z.rms.powi(2);
        assert!(
            (sum - norm.rms.powi(2)).abs() < 1e-9 * sum.max(1.0),
            "{sum}"
        );
    }
    // Calibration helps on every axis.
    for (before, after) in [
        (&a.nominal.x, &a.calibrated.x),
        (&a.nominal.y, &a.calibrated.y),
        (&a.nominal.z, &a.calibrated.z),
    ] {
        assert!(after.rms < before.rms);
    }
}

#[test]
fn base_frame_tcp_covariance_is_that_of_the_world_tcp_position() {
    let (cell, design, est) = fixtures();
    let model = &cell.model;
    let params = est.params_for(model).unwrap();
    let q = &cell.working[0].q;
    // G_w = ∂(tool position in the world)/∂p by central differences, independent of the
    // instrument frame.
    let n = est.free.len();
    let mut g = DMatrix::zeros(3, n);
    for (c, name) in est.free.iter().enumerate() {
        let i = model.registry.index_of(name).unwrap();
        let h = 1e-6;
        let (mut a, mut b) = (params.clone(), params.clone());
        a[i] += h;
        b[i] -= h;
        let d = (tool_pose(model, &a, q).trans - tool_pose(model, &b, q).trans) / (2.0 * h);
        g.set_column(c, &d);
    }
    let cw = &g * &est.uncertainty.covariance * g.transpose();
    let base = est.tcp[0].covariance_base.expect("base-frame C_s");
    let scale = cw.abs().max();
    for i in 0..3 {
        for j in 0..3 {
            assert!((base[(i, j)] - cw[(i, j)]).abs() < 1e-5 * scale, "{i}{j}");
        }
    }
    // The tracker is rotated and its pose is estimated too: the two frames differ, and the
    // instrument frame's C_s holds the tracker's uncertainty as well: not a rotation of the
    // base-frame one (a rotation would keep the trace).
    let inst = est.tcp[0].covariance;
    assert!((inst - base).abs().max() > 1e-3 * scale);
    assert!((base.trace() - inst.trace()).abs() > 1e-6 * inst.trace());
    // The design's prediction carries one too.
    assert!(design.assessment.tcp[0].covariance_base.is_some());
}

#[test]
fn joint_corrections_are_compensated_minus_nominal_in_degrees() {
    let (cell, _, est) = fixtures();
    let model = &cell.model;
    let calibrated = est.params_for(model).unwrap();
    let program: Vec<(String, Vec<f64>)> = [[0.0, -30.0, 60.0, 0.0, -60.0, 0.0f64]]
        .iter()
        .map(|q| ("p1".to_string(), q.iter().map(|x| x.to_radians()).collect()))
        .collect();
    let rows = filter_joint_program(
        model,
        &model.nominal(),
        &calibrated,
        &program,
        &IkSettings::default(),
    );
    let record = ProgramRecord::of(model, &rows);
    let d = joint_corrections(&record);
    assert_eq!(d.len(), 1);
    for (k, dk) in d[0].iter().enumerate() {
        let expected = (rows[0].result.q[k] - rows[0].q_nominal[k]).to_degrees();
        assert!((dk - expected).abs() < 1e-9, "joint {k}");
    }
    assert!(
        d[0].iter().any(|x| x.abs() > 1e-4),
        "the calibration changes the joints"
    );
    assert_eq!(record.units, vec!["deg"; 6]);
    assert!(record.rows[0].converged);
}

#[test]
fn predicted_ellipses_are_drawn_above_the_identified_ones() {
    let c = Matrix3::new(1.0, 0.1, 0.0, 0.1, 0.5, 0.0, 0.0, 0.0, 0.2);
    // The prediction first in the list: it must still be drawn last.
    let svg = ellipse_figure(
        armcal::report::ellipse::Plane::Xy,
        &[
            EllipseSeries {
                label: "design (predicted)".into(),
                covariance: c,
                dashed: true,
                colour: 1,
            },
            EllipseSeries {
                label: "design (identified)".into(),
                covariance: c,
                dashed: false,
                colour: 0,
            },
        ],
        2.8,
    )
    .unwrap();
    let first = |c: RGBColor| svg.find(&format!("stroke=\"{}\"", hex(c))).unwrap();
    assert!(first(colour(0)) < first(colour(1)));
}

#[test]
fn the_page_opens_with_one_verdict_panel_per_estimate() {
    let (_, design, est) = fixtures();
    let mut unconverged = est.clone();
    unconverged.verdicts = None;
    let mut too_small = est.clone();
    if let Some(v) = too_small.verdicts.as_mut() {
        v.chi2.outcome = Chi2Outcome::SigmaTooSmall;
    }
    assert_eq!(estimate_grade(&unconverged), Grade::Bad);
    assert_eq!(estimate_grade(&too_small), Grade::Check);
    let inputs = vec![
        Input {
            label: "design-kpi".into(),
            source: "design-kpi.json".into(),
            document: Document::Design(Box::new(design.clone())),
        },
        Input {
            label: "estimate-kpi".into(),
            source: "estimate-kpi.json".into(),
            document: Document::Estimate(Box::new(est.clone())),
        },
        Input {
            label: "old".into(),
            source: "old.json".into(),
            document: Document::Estimate(Box::new(unconverged)),
        },
    ];
    let html = report::render(&ReportContent {
        title: "t",
        inputs: &inputs,
        ..Default::default()
    })
    .unwrap();
    // The verdict is the first section and the first entry of the contents.
    let first_section = html.find("<section id=\"").unwrap();
    assert!(html[first_section..].starts_with("<section id=\"verdict\">"));
    assert!(html.contains("<li><a href=\"#verdict\">Verdict</a></li>\n<li>"));
    let panels = html.matches("class=\"verdict-panel").count();
    assert_eq!(panels, 3, "two estimates and one design");
    assert_eq!(html.matches("data-kind=\"Estimate\"").count(), 2);
    // The estimate without verdicts is red; the random design violates the incidence limit.
    assert_eq!(
        html.matches("data-verdict=\"bad\" data-kind=\"Estimate\"")
            .count(),
        1
    );
    assert!(design.margins.iter().any(|m| m.value < 0.0));
    assert_eq!(
        html.matches("data-verdict=\"bad\" data-kind=\"Design\"")
            .count(),
        1
    );
    let good = html.find("<h3>Estimate: estimate-kpi</h3>").unwrap();
    let section_end = html[good..]
        .find("</div>\n<div class=\"verdict-panel")
        .unwrap();
    let panel = &html[good..good + section_end];
    for key in [
        "status",
        "held-out error",
        "χ² test",
        "outliers",
        "identifiability",
    ] {
        assert!(panel.contains(&format!("<th>{key}</th>")), "{key}");
    }
    // The held-out line compares the calibration with the drawing's kinematics with the
    // frames fitted, not with the nominal model whose error is mostly the unplaced tracker.
    let v = est.validation.as_ref().unwrap();
    assert!(
        panel.contains(&format!(
            "RMS {:.3} mm with the drawing's kinematics, frames fitted → {:.3} mm calibrated",
            v.frames_only.rms, v.calibrated.rms
        )),
        "{panel}"
    );
    assert!(panel.contains(&format!("nothing fitted: RMS {:.3} mm", v.nominal.rms)));
    let gain = held_out_gain(est).unwrap();
    assert!((gain - (1.0 - v.calibrated.rms / v.frames_only.rms)).abs() < 1e-12);
    // The TCP σ of the estimate is stated with the model floor beside the measurement term.
    let floor = est.model_floor.as_ref().unwrap().tcp[0].kpi;
    assert!(floor > 0.0);
    let tcp = &est.tcp[0];
    assert!(
        panel.contains(&format!(
            "{} mm with the fixed parameters' model floor",
            armcal::report::html::number((tcp.kpi + floor).sqrt())
        )),
        "{panel}"
    );
    // The new figures are on the page, each once per estimate that can have it.
    for kind in [
        "change-sigma",
        "correlation",
        "held-out-axes",
        "ellipse-base",
        "ellipse-instrument",
    ] {
        assert!(html.contains(&format!("data-figure=\"{kind}\"")), "{kind}");
    }
    // One colour per design: "design-kpi" and "estimate-kpi" are one design.
    assert_eq!(design_key("design-kpi"), design_key("estimate-kpi"));
    assert_eq!(design_key("KPI design"), "kpi");
    let kpi = hex(colour(design_colour(0)));
    let change = html.find("data-figure=\"change-sigma\"").unwrap();
    let change_svg = &html[change..change + html[change..].find("</svg>").unwrap()];
    assert!(change_svg.contains(&format!("fill=\"{kpi}\"")), "{kpi}");
    // Every table scrolls sideways in its wrapper.
    assert_eq!(
        html.matches("<table").count(),
        html.matches("<div class=\"table-wrap\"><table").count()
    );
    assert!(html.contains(".table-wrap { max-width: 100%; overflow-x: auto; }"));
}

/// A cell whose only free parameters are frames: the frames-only fit is the calibration
/// itself, so its held-out error is compared with the nominal model's.
#[test]
fn a_frames_only_calibration_is_compared_with_the_nominal_model() {
    let mut est = fixtures().2.clone();
    let model = armcal::Model::from_spec(&est.model).unwrap();
    est.free.retain(|n| {
        armcal::identify::is_frame_parameter(&model, model.registry.index_of(n).unwrap())
    });
    assert!(!est.free.is_empty());
    let v = est.validation.clone().unwrap();
    let gain = held_out_gain(&est).unwrap();
    assert!((gain - (1.0 - v.calibrated.rms / v.nominal.rms)).abs() < 1e-12);
}

#[test]
fn a_file_given_twice_appears_once() {
    let (_, design, _) = fixtures();
    let dir = std::env::temp_dir().join(format!("armcal-twice-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("design.json");
    std::fs::write(&file, serde_json::to_string(design).unwrap()).unwrap();
    let other_path = dir.join(".").join("design.json");
    let acceptance = Acceptance {
        accepted: false,
        accept: "--accept",
        raise_iterations: "--max-iterations",
    };
    let r = files_report(&[file.clone(), other_path, file.clone()], "t", &acceptance).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert!(
        r.page.subtitle.starts_with("1 input file: "),
        "{}",
        r.page.subtitle
    );
    assert_eq!(
        r.notes
            .iter()
            .filter(|n| n.contains("more than once"))
            .count(),
        2
    );
    let html = r.page.render();
    assert_eq!(html.matches("<section id=\"design-").count(), 1);
}

#[test]
fn a_truth_record_is_a_document() {
    let (cell, _, _) = fixtures();
    let truth = perturbed_truth(&cell.model, &Perturbation::default(), 3);
    let record = TruthRecord::new(&cell.name, &cell.model, &truth, 3);
    match Document::from_json(&record.to_json().unwrap(), "truth.json").unwrap() {
        Document::Truth(t) => {
            assert_eq!(
                (t.cell.as_str(), t.seed),
                (record.cell.as_str(), record.seed)
            );
            assert_eq!(t.parameters.len(), record.parameters.len());
            for (a, b) in t.parameters.iter().zip(&record.parameters) {
                assert_eq!(a.name, b.name);
                assert!((a.truth - b.truth).abs() <= 1e-12 * b.truth.abs().max(1.0));
            }
        }
        other => panic!("{}", other.kind()),
    }
}
