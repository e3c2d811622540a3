//! The HTML report: ellipse geometry, figure builders, escaping, self-containedness, the
//! figure count, document recognition and the constraint margins of the design file.

use crate::common;
use armcal::design::kind_margins;
use armcal::model::random_configurations;
use armcal::model::{forward_kinematics, Data};
use armcal::report::ellipse::{confidence_scale, ellipse_axes, ellipse_points, Plane};
use armcal::report::figures::{
    bar_figure, cdf_figure, colour, ellipse_figure, histogram_figure, joint_figure, series_figure,
    EllipseSeries, JointTrace, Reference,
};
use armcal::report::html::{escape, number};
use armcal::report::{self, Document, Input, ReportContent};
use armcal::{
    identify, notional_robots, perturbed_truth, simulate, Cell, DesignRecord, Estimate,
    IdentifySettings, PaperStudyRecord, PaperStudyRow, Perturbation, Silent,
};
use common::example_cell;
use nalgebra::{Matrix2, Matrix3, Vector2};
use std::sync::OnceLock;

/// A design record and an estimate of the paper cell (simulated, 40 random poses, 30 %
/// held out), computed once.
pub(super) fn fixtures() -> &'static (Cell, DesignRecord, Estimate) {
    static F: OnceLock<(Cell, DesignRecord, Estimate)> = OnceLock::new();
    F.get_or_init(|| {
        let cell = example_cell("paper-cell.toml");
        let model = &cell.model;
        let truth = perturbed_truth(model, &Perturbation::default(), 3);
        let qs = random_configurations(model, 40, 7);
        let noise = cell.instrument.as_ref().unwrap().noise.clone();
        let data = simulate(model, &truth, &qs, Some(&noise), 9).unwrap();
        let est = identify(
            &cell,
            &data,
            &IdentifySettings {
                holdout: 0.3,
                ..Default::default()
            },
            &mut Silent,
        )
        .unwrap();
        let design = DesignRecord::new(&cell, None, "random poses", &qs, None, false).unwrap();
        (cell, design, est)
    })
}

fn count(haystack: &str, needle: &str) -> usize {
    haystack.matches(needle).count()
}

fn assert_svg(svg: &str) {
    assert!(svg.starts_with("<svg "), "{}", &svg[..svg.len().min(80)]);
    assert!(svg.trim_end().ends_with("</svg>"));
    assert_eq!(count(svg, "<svg"), 1);
    assert!(!svg.contains("http://") && !svg.contains("https://"));
    assert!(svg.contains("viewBox="));
}

#[test]
fn ellipse_semi_axes_are_k_sqrt_eigenvalues() {
    let c = [[4.0, 1.5], [1.5, 1.0]];
    let m: Matrix2<f64> = Matrix2::new(4.0, 1.5, 1.5, 1.0);
    let eig = m.symmetric_eigen();
    let (l1, l2): (f64, f64) = (eig.eigenvalues.max(), eig.eigenvalues.min());
    let k = 2.5;
    let (r1, r2, theta) = ellipse_axes(c, k);
    assert!((r1 - k * l1.sqrt()).abs() < 1e-12, "{r1}");
    assert!((r2 - k * l2.sqrt()).abs() < 1e-12, "{r2}");
    // The major axis is the eigenvector of λ₁ (up to sign).
    let v = eig.eigenvectors.column(eig.eigenvalues.imax()).into_owned();
    assert!((v[1].atan2(v[0]) - theta).sin().abs() < 1e-9);
    let inv = m.try_inverse().unwrap();
    let pts = ellipse_points(c, k, 720);
    assert_eq!(pts.len(), 721);
    let (first, last) = (pts[0], pts[720]);
    assert!((first.0 - last.0).abs() < 1e-12 && (first.1 - last.1).abs() < 1e-12);
    let (mut rmax, mut rmin) = (0.0f64, f64::INFINITY);
    for &(x, y) in &pts {
        let p = Vector2::new(x, y);
        // Every point lies on yᵀ C⁻¹ y = k².
        assert!(((p.transpose() * inv * p)[0] - k * k).abs() < 1e-9);
        rmax = rmax.max(p.norm());
        rmin = rmin.min(p.norm());
    }
    assert!((rmax - r1).abs() < 1e-9 && (rmin - r2).abs() < 1e-9);
    // A diagonal covariance: axis-aligned, semi-axes k σ.
    let (a, b, t) = ellipse_axes([[9.0, 0.0], [0.0, 0.25]], 2.0);
    assert!((a - 6.0).abs() < 1e-12 && (b - 1.0).abs() < 1e-12 && t.abs() < 1e-12);
    let (a, b, t) = ellipse_axes([[0.25, 0.0], [0.0, 9.0]], 2.0);
    assert!((a - 6.0).abs() < 1e-12 && (b - 1.0).abs() < 1e-12);
    assert!((t - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
}

#[test]
fn confidence_scale_is_the_chi_square_quantile() {
    // χ²₂(0.95) = −2 ln 0.05 exactly; χ²₃(0.95) = 7.814727903 (tables).
    assert!((confidence_scale(2, 0.95).unwrap() - (-2.0 * 0.05f64.ln()).sqrt()).abs() < 1e-9);
    assert!((confidence_scale(3, 0.95).unwrap() - 7.814727903f64.sqrt()).abs() < 1e-7);
    assert!(confidence_scale(3, 1.0).is_err() && confidence_scale(0, 0.5).is_err());
}

#[test]
fn planes_pick_the_marginal_covariance() {
    let c = Matrix3::new(1.0, 2.0, 3.0, 2.0, 5.0, 6.0, 3.0, 6.0, 9.0);
    assert_eq!(Plane::Xy.project(&c), [[1.0, 2.0], [2.0, 5.0]]);
    assert_eq!(Plane::Xz.project(&c), [[1.0, 3.0], [3.0, 9.0]]);
    assert_eq!(Plane::Yz.project(&c), [[5.0, 6.0], [6.0, 9.0]]);
}

#[test]
fn figure_builders_give_one_well_formed_svg_with_their_series() {
    let cov = |s: f64| Matrix3::new(s, 0.1, 0.0, 0.1, 0.5 * s, 0.0, 0.0, 0.0, 0.2 * s);
    let one = ellipse_figure(
        Plane::Xy,
        &[EllipseSeries {
            label: "alpha".into(),
            covariance: cov(1.0),
            dashed: false,
            colour: 0,
        }],
        2.8,
    )
    .unwrap();
    let three = ellipse_figure(
        Plane::Xz,
        &[
            EllipseSeries {
                label: "alpha".into(),
                covariance: cov(1.0),
                dashed: false,
                colour: 0,
            },
            EllipseSeries {
                label: "beta".into(),
                covariance: cov(2.0),
                dashed: false,
                colour: 1,
            },
            EllipseSeries {
                label: "gamma".into(),
                covariance: cov(0.5),
                dashed: true,
                colour: 2,
            },
        ],
        2.8,
    )
    .unwrap();
    for svg in [&one, &three] {
        assert_svg(svg);
    }
    assert!(one.contains("alpha") && one.contains("xy projection") && one.contains("δy (mm)"));
    assert!(three.contains("beta") && three.contains("gamma") && three.contains("δz (mm)"));
    // Each solid series is one polyline in its colour plus its legend line; a dashed one
    // is drawn dash by dash.
    let stroke = |svg: &str, c: usize| {
        let c = colour(c);
        let needle = format!("stroke=\"#{:02X}{:02X}{:02X}\"", c.0, c.1, c.2);
        svg.lines()
            .filter(|l| l.starts_with("<polyline") && l.contains(&needle))
            .count()
    };
    assert_eq!(stroke(&one, 0), 2);
    assert_eq!((stroke(&three, 0), stroke(&three, 1)), (2, 2));
    assert!(stroke(&three, 2) > 10, "{}", stroke(&three, 2));
    assert_eq!(stroke(&one, 1), 0);
    let cdf = cdf_figure(
        "errors",
        "error (mm)",
        &[
            ("nominal".into(), vec![1.0, 2.0, 3.0]),
            ("calibrated".into(), vec![0.1, 0.2]),
        ],
    )
    .unwrap();
    assert_svg(&cdf);
    assert!(cdf.contains("nominal") && cdf.contains("calibrated"));

    let bars = bar_figure(
        "bars",
        "mm",
        &["RMS".into(), "max".into()],
        &[("a".into(), vec![1.0, 2.0]), ("b".into(), vec![0.5, -0.25])],
        Some((1, 1)),
        false,
    )
    .unwrap();
    assert_svg(&bars);
    assert!(bars.contains("(smallest)"));
    // Logarithmic: decades as ticks; falls back to linear with a non-positive value.
    let log = bar_figure(
        "margins",
        "mm",
        &["a".into(), "b".into()],
        &[("m".into(), vec![0.05, 230.0])],
        None,
        true,
    )
    .unwrap();
    assert_svg(&log);
    for decade in ["0.01", "0.1", "1", "10", "100", "1000"] {
        assert!(log.contains(&format!("\n{decade}\n")), "{decade}");
    }
    assert!(log.contains("\n230.0\n") && log.contains("\n0.05000\n"));
    // Four bars, two legend swatches, one highlight outline; each bar labelled.
    assert!(bars.contains(">RMS") || bars.contains("RMS\n"));
    assert!(bars.contains(&number(-0.25)));

    let hist = histogram_figure(
        "hist",
        "residual (mm)",
        &[
            ("x".into(), vec![-1.0, 0.0, 0.5, 1.0]),
            ("y".into(), vec![0.0, 0.1]),
        ],
        5,
    )
    .unwrap();
    assert_svg(&hist);
    assert!(hist.contains("residual (mm)") && hist.contains("count"));

    let series = series_figure(
        "per pose",
        "pose",
        "mm",
        &[
            ("x".into(), vec![(1.0, 0.5), (2.0, -0.5)]),
            ("y".into(), vec![(1.0, 0.1), (2.0, 0.2), (3.0, 0.3)]),
        ],
        &[Reference {
            label: "zero line".into(),
            value: 0.0,
        }],
    )
    .unwrap();
    assert_svg(&series);
    assert!(series.contains("zero line"));
    // Five data points plus two legend markers.
    assert_eq!(count(&series, "<circle"), 7);

    let joints = joint_figure(
        "joints",
        &(1..=6)
            .map(|j| JointTrace {
                name: format!("joint{j}"),
                unit: "deg".into(),
                lower: -170.0,
                upper: 170.0,
                values: vec![0.0, 10.0 * j as f64, -20.0],
            })
            .collect::<Vec<_>>(),
    )
    .unwrap();
    assert_svg(&joints);
    for j in 1..=6 {
        assert!(joints.contains(&format!("joint{j} (deg)")));
    }
    // Three poses per joint.
    assert_eq!(count(&joints, "<circle"), 18);
}

#[test]
fn escaping_covers_markup_and_quotes() {
    assert_eq!(
        escape("R<&>\"bot' </script>"),
        "R&lt;&amp;&gt;&quot;bot&#39; &lt;/script&gt;"
    );
    assert_eq!(number(f64::NAN), "–");
    assert_eq!(number(-1.23456), "−1.235");
    assert_eq!(number(1234.56), "1235");
    assert_eq!(number(0.012345), "0.01235");
    assert_eq!(number(2.5e-5), "2.500e−5");
}

#[test]
fn report_is_self_contained_escaped_and_counts_its_figures() {
    let (_, design, est) = fixtures();
    let mut evil = est.clone();
    evil.cell = "cell <script>alert(1)</script>".into();
    let inputs = vec![
        Input {
            label: "R<&>bot design".into(),
            source: "design.json".into(),
            document: Document::Design(Box::new(design.clone())),
        },
        Input {
            label: "R<&>bot".into(),
            source: "a&b.json".into(),
            document: Document::Estimate(Box::new(evil)),
        },
    ];
    let page = report::page(&ReportContent {
        title: "Report <for> \"customer\"",
        subtitle: "x & y",
        inputs: &inputs,
        ..Default::default()
    })
    .unwrap();
    let html = page.render();
    assert!(html.starts_with("<!DOCTYPE html>"));
    // Figures: TCP ellipses (3 in the instrument frame, 3 in the base frame), design joints
    // (1; no clearance bars without collision constraints), estimate residual histograms,
    // per-pose residuals and held-out bars (3), held-out per axis, change / σ and the
    // correlation heatmap (3).
    assert_eq!(page.figure_count(), 13);
    let meta = format!(
        "<meta name=\"armcal-figures\" content=\"{}\">",
        page.figure_count()
    );
    assert!(html.contains(&meta), "{meta}");
    assert_eq!(count(&html, "<svg"), page.figure_count());
    assert_eq!(
        count(&html, "<figure class=\"armcal-figure\">"),
        page.figure_count()
    );
    assert_eq!(count(&html, "<figcaption>"), page.figure_count());
    // Nothing external: no URLs, no src attributes, only in-page links.
    assert!(!html.contains("http://") && !html.contains("https://"));
    assert!(!html.contains(" src="));
    for (i, _) in html.match_indices("href=\"") {
        assert_eq!(&html[i + 6..i + 7], "#", "{}", &html[i..i + 40]);
    }
    // User strings are escaped everywhere.
    assert!(!html.contains("R<&>bot") && html.contains("R&lt;&amp;&gt;bot"));
    assert!(!html.contains("<script>alert(1)") && html.contains("&lt;script&gt;alert(1)"));
    assert!(html.contains("Report &lt;for&gt; &quot;customer&quot;"));
    assert!(html.contains("a&amp;b.json"));
    for heading in [
        "TCP precision at the working pose",
        "Design: R&lt;&amp;&gt;bot design",
        "Estimate: R&lt;&amp;&gt;bot",
        "Held-out validation",
        "Constraint margins",
    ] {
        assert!(html.contains(heading), "{heading}");
    }
    // Every parameter is in the table with its σ.
    for p in est.parameters.iter().filter(|p| p.free) {
        assert!(
            html.contains(&format!("<td>{}</td>", escape(&p.name))),
            "{}",
            p.name
        );
    }
}

#[test]
fn documents_are_recognised_by_content() {
    let (_, design, est) = fixtures();
    let e = serde_json::to_string(est).unwrap();
    let d = serde_json::to_string(design).unwrap();
    assert!(matches!(
        Document::from_json(&e, "e.json").unwrap(),
        Document::Estimate(_)
    ));
    match Document::from_json(&d, "d.json").unwrap() {
        Document::Design(back) => {
            // JSON keeps the values to the last bit or so.
            for (a, b) in back
                .poses
                .iter()
                .flatten()
                .zip(design.poses.iter().flatten())
            {
                assert!((a - b).abs() <= 1e-12 * b.abs().max(1.0));
            }
            assert_eq!(back.poses.len(), design.poses.len());
            assert_eq!(back.margins.len(), design.margins.len());
        }
        other => panic!("{}", other.kind()),
    }
    let study = r#"{"study": "paper", "collisions": true, "seconds": 1.0, "rows": []}"#;
    assert!(matches!(
        Document::from_json(study, "s.json").unwrap(),
        Document::Study(_)
    ));
    for (text, needle) in [
        (
            r#"{"name": "x", "value": 1}"#,
            "not an armcal result (top-level fields: name, value)",
        ),
        ("[1, 2]", "not a JSON object"),
        ("not json", "not JSON"),
        (
            r#"{"study": "puma", "result": {}}"#,
            "study result of `puma`",
        ),
        (
            r#"{"parameters": [], "solver": {}, "uncertainty": {}, "model": {}}"#,
            "looks like an armcal estimate, but",
        ),
    ] {
        let err = Document::from_json(text, "in.json")
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("in.json: "), "{err}");
        assert!(err.contains(needle), "{needle}: {err}");
        if !needle.starts_with("looks like") {
            assert!(err.contains("expected an armcal estimate"), "{err}");
        }
    }
}

#[test]
fn design_poses_round_trip_to_internal_units() {
    let (cell, design, _) = fixtures();
    let qs = design.design_for(&cell.model).unwrap();
    assert_eq!(qs.len(), design.poses.len());
    for (q, p) in qs.iter().zip(&design.poses) {
        for (a, b) in q.iter().zip(p) {
            assert!((a.to_degrees() - b).abs() < 1e-9);
        }
    }
    let mut renamed = design.clone();
    renamed.joints[1].name = "shoulder".into();
    let err = renamed.design_for(&cell.model).unwrap_err().to_string();
    assert!(err.contains("does not fit model"), "{err}");
}

#[test]
fn incidence_margin_is_the_angle_left_to_the_limit() {
    let cell = example_cell("paper-cell-obstacles.toml");
    let model = &cell.model;
    let qs = random_configurations(model, 25, 2);
    let margins = kind_margins(&cell, &qs, true).unwrap();
    let inc = margins.iter().find(|m| m.kind == "incidence").unwrap();
    assert_eq!(inc.unit, "deg");
    // Independently: the angle between the reflector's z axis and the beam to the tracker.
    let max = cell.instrument.as_ref().unwrap().max_incidence.unwrap();
    let mut data = Data::new(model);
    let mut best = f64::INFINITY;
    for q in &qs {
        forward_kinematics(model, &mut data, &model.nominal(), q);
        let t = &data.targets[0];
        let beam = (data.instrument.trans - t.trans).normalize();
        let beta = t.rot.column(2).dot(&beam).clamp(-1.0, 1.0).acos();
        best = best.min((max - beta).to_degrees());
    }
    assert!((inc.value - best).abs() < 1e-9, "{} vs {best}", inc.value);
    // Joint limits: the closest joint to a limit, in degrees.
    let jl = margins.iter().find(|m| m.kind == "joint limits").unwrap();
    let mut best = f64::INFINITY;
    for q in &qs {
        for (v, j) in q.iter().zip(&model.joints) {
            best = best.min((v - j.lower).min(j.upper - v).to_degrees());
        }
    }
    assert!((jl.value - best).abs() < 1e-9);
    // Every distance kind of the obstacle cell is reported, in mm.
    for kind in ["self-collision", "obstacle", "half-space", "line of sight"] {
        let m = margins.iter().find(|m| m.kind == kind).unwrap();
        assert_eq!(m.unit, "mm", "{kind}");
        assert!(m.per_pose > 0 && m.pose >= 1 && m.pose <= qs.len());
    }
}

/// A study result with the three KUKA robots and the 90 notional manipulators, values
/// spread around the paper's (for the rendering only).
fn study(collisions: bool) -> PaperStudyRecord {
    let mut robots = vec!["kr15".to_string(), "kr300".into(), "kr500".into()];
    robots.extend(notional_robots());
    let rows = robots
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let (h, c, s) = (
                0.6 + 0.001 * i as f64,
                0.42 + 0.0002 * i as f64,
                0.34 + 0.0001 * i as f64,
            );
            PaperStudyRow {
                robot: r.clone(),
                collisions,
                heuristic: h,
                cp_optimal: c,
                cs_optimal: s,
                gain_vs_heuristic: 1.0 - s / h,
                gain_vs_cp: 1.0 - s / c,
                feasible: true,
                seconds: 1.0,
                error: None,
            }
        })
        .collect();
    PaperStudyRecord {
        study: "paper".into(),
        collisions,
        seconds: 0.0,
        rows,
    }
}

#[test]
fn study_section_has_tables_6_to_8_and_figure_8() {
    let inputs: Vec<Input> = [true, false]
        .map(|ca| Input {
            label: format!("study {ca}"),
            source: "study.json".into(),
            document: Document::Study(study(ca)),
        })
        .to_vec();
    let page = report::page(&ReportContent {
        title: "study",
        inputs: &inputs,
        ..Default::default()
    })
    .unwrap();
    // One Figure 8 chart per collision setting.
    assert_eq!(page.figure_count(), 2);
    let html = page.render();
    for needle in [
        "Table 6: KUKA KR 15, KR 300, KR 500",
        "Table 7: range over the notional manipulators",
        "Table 8: mean over the notional manipulators",
        // Table 6 with collision avoidance beside the paper (KR 15: 0.59 / 0.40 / 0.33).
        "<td>kr15</td><td>yes</td><td class=\"num\">0.600</td><td class=\"num\">0.59</td>",
        // Table 7 (with collision avoidance): the paper's KPI range.
        "0.34 – 0.37",
        // Table 8 means: the paper's 0.61 / 0.43 / 0.35 with collision avoidance.
        "<td class=\"num\">0.35</td>",
        "paper §4.2, mean vs heuristic: 43 %",
        // Table 6's gains as the paper states them (KR 15: 44 %, 17 %), not recomputed
        // from its rounded table (which would give 18 %).
        "<td class=\"num\">44 %</td>",
        "<td class=\"num\">17 %</td>",
        "40 % to 44 %",
        "10 % to 19 %",
    ] {
        assert!(html.contains(needle), "{needle}");
    }
    // 90 points per curve and a legend dot each, in each of the two charts.
    assert_eq!(html.matches("<circle").count(), 2 * (2 * 90 + 2));
}

/// An estimate without degrees of freedom has no variance factor and no p-value (NaN,
/// written `null`); armcal reads that file back (it refused it before: "invalid type: null,
/// expected f64").
#[test]
fn an_estimate_without_degrees_of_freedom_reads_back() {
    let (_, _, est) = fixtures();
    let mut e = est.clone();
    e.uncertainty.variance_factor = f64::NAN;
    e.uncertainty.p_value = f64::NAN;
    let text = serde_json::to_string_pretty(&e).unwrap();
    assert!(text.contains("\"variance_factor\": null"));
    match Document::from_json(&text, "estimate.json").expect("reads back") {
        Document::Estimate(again) => {
            assert!(again.uncertainty.variance_factor.is_nan());
            assert!(again.uncertainty.p_value.is_nan());
        }
        _ => panic!("not an estimate"),
    }
}

/// The report shows every working pose of a design and an estimate (a table row and its
/// own ellipse figures each), not only the first.
#[test]
fn the_tcp_section_shows_every_working_pose() {
    let (_, design, est) = fixtures();
    let (mut design, mut est) = (design.clone(), est.clone());
    let second = |t: &armcal::TcpCovariance| {
        let mut t = t.clone();
        t.name = "q_second".into();
        t.covariance *= 2.0;
        t.kpi *= 2.0;
        t
    };
    design
        .assessment
        .tcp
        .push(second(&design.assessment.tcp[0]));
    est.tcp.push(second(&est.tcp[0]));
    let inputs = vec![
        Input {
            label: "planned".into(),
            source: "design.json".into(),
            document: Document::Design(Box::new(design)),
        },
        Input {
            label: "fitted".into(),
            source: "estimate.json".into(),
            document: Document::Estimate(Box::new(est)),
        },
    ];
    let page = report::page(&ReportContent {
        title: "t",
        subtitle: "s",
        inputs: &inputs,
        ..Default::default()
    })
    .unwrap();
    let html = page.render();
    let first = &fixtures().2.tcp[0].name;
    for pose in [first.as_str(), "q_second"] {
        assert!(
            html.contains(&format!("<h3>Working pose <code>{pose}</code></h3>")),
            "{pose}"
        );
        assert!(html.contains(&format!("at `{pose}`")), "{pose}: no figure");
    }
    // Two inputs × two poses in the table; six ellipse figures (3 planes, 2 frames) per pose.
    assert_eq!(count(&html, "<td>q_second</td>"), 2);
    assert_eq!(count(&html, "data-figure=\"ellipse-instrument\""), 6);
    assert_eq!(count(&html, "data-figure=\"ellipse-base\""), 6);
}

/// A drift check record (`armcal check`) is recognised and gets its section: the χ² test,
/// the verdict and the groups' score tests with the likeliest mover marked.
#[test]
fn a_drift_check_record_is_a_report_input() {
    use armcal::{DriftCheck, DriftVerdict, GroupScore};
    let check = DriftCheck {
        cell: "paper-650-600".into(),
        calibrated_on: "data.csv".into(),
        data: "check.csv".into(),
        poses: 10,
        dof: 30,
        chi2: 95.5,
        p_value: 1.2e-8,
        alpha: 0.01,
        verdict: DriftVerdict::Drifted,
        rms_position_mm: 0.25,
        chi2_without_prediction: 101.0,
        covariance_rule: "C_p scaled by max(1, σ̂₀²)".into(),
        calibration_variance_factor: Some(1.1),
        groups: vec![
            GroupScore {
                group: "j2".into(),
                parameters: vec!["j2.theta".into(), "j2.beta".into()],
                rank: 2,
                statistic: 60.0,
                p_value: 1e-12,
            },
            GroupScore {
                group: "tool".into(),
                parameters: vec!["tool.x".into()],
                rank: 1,
                statistic: 0.5,
                p_value: 0.48,
            },
        ],
    };
    let document = Document::from_json(&check.to_json().unwrap(), "check.json").unwrap();
    assert_eq!(document.kind(), "drift check");
    let inputs = vec![Input {
        label: "after the crash".into(),
        source: "check.json".into(),
        document,
    }];
    let html = report::page(&ReportContent {
        title: "t",
        subtitle: "s",
        inputs: &inputs,
        ..Default::default()
    })
    .unwrap()
    .render();
    for needle in [
        "Drift check: after the crash",
        "10 check poses of cell <em>paper-650-600</em>",
        "drifted: the robot or the cell changed since the calibration",
        "<td>tool</td>",
        "drift check of cell <em>paper-650-600</em>, 10 poses, drifted",
    ] {
        assert!(html.contains(needle), "{needle}");
    }
}
