//! `simulate` → `identify` → `predict` through the binary, with the file-safety rules.

use crate::common;
use common::{armcal, identify_paper_cell, scratch, simulate_paper_cell};
use std::path::Path;

/// Running `args` again fails because its output exists, naming `--force`; with `--force`
/// appended it succeeds.
fn refuses_to_overwrite_unless_forced(args: &[&str]) {
    let (ok, _, err) = armcal(args);
    assert!(
        !ok && err.contains("exists") && err.contains("--force"),
        "{err}"
    );
    let mut forced = args.to_vec();
    forced.push("--force");
    let (ok, _, err) = armcal(&forced);
    assert!(ok, "{err}");
}

#[test]
fn simulate_identify_predict() {
    let dir = scratch("workflow");
    let data = dir.join("data.csv");
    let est = dir.join("estimate.json");
    let pred = dir.join("pred.csv");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let (data_s, est_s) = (s(&data), s(&est));
    let sim = simulate_paper_cell("4", &data_s);
    let (ok, out, err) = armcal(&sim);
    assert!(ok, "{err}");
    assert!(out.contains("simulated 60 measurements"), "{out}");
    let first = std::fs::read_to_string(&data).unwrap();
    // Same seed, same file; an existing file is not overwritten without --force.
    refuses_to_overwrite_unless_forced(&sim);
    assert_eq!(
        first,
        std::fs::read_to_string(&data).unwrap(),
        "same seed → identical file"
    );

    let (ok, out, err) = armcal(&identify_paper_cell(&data_s, &["--holdout", "0.3"], &est_s));
    assert!(ok, "{err}");
    assert!(
        out.contains("converged")
            && out.contains("held-out validation")
            && out.contains("(1/3) tr C_s"),
        "{out}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&est).unwrap()).unwrap();
    assert_eq!(json["free"].as_array().unwrap().len(), 27);
    assert!(
        json["validation"]["calibrated"]["rms"].as_f64().unwrap()
            < json["validation"]["nominal"]["rms"].as_f64().unwrap()
    );

    for method in ["gn", "kalman"] {
        let e2 = dir.join(format!("est-{method}.json"));
        let (ok, _, err) = armcal(&identify_paper_cell(
            &data_s,
            &["--method", method],
            &s(&e2),
        ));
        assert!(ok, "{method}: {err}");
    }
    let (ok, _, err) = armcal(&identify_paper_cell(
        &data_s,
        &["--robust", "huber"],
        &s(&dir.join("r.json")),
    ));
    assert!(ok, "{err}");

    let (ok, out, err) = armcal(&[
        "predict",
        "--cell",
        "examples/paper-cell.toml",
        "--estimate",
        &est_s,
        "--joints",
        "examples/paper-poses-random-60.csv",
        "--out",
        &s(&pred),
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("identified model"), "{out}");
    let header = std::fs::read_to_string(&pred)
        .unwrap()
        .lines()
        .next()
        .unwrap()
        .to_string();
    // the columns of a data file, then the σ columns of a prediction with an estimate
    assert!(
        header.starts_with(&format!("{},sigma_mm,", first.lines().next().unwrap())),
        "predictions have the columns of a data file: {header}"
    );

    // An estimate of another robot is refused with the mismatch named.
    let (ok, _, err) = armcal(&[
        "predict",
        "--cell",
        "examples/motoman-right-cell.toml",
        "--estimate",
        &est_s,
        "--joints",
        "examples/paper-poses-random-60.csv",
        "--out",
        &s(&dir.join("x.csv")),
    ]);
    assert!(!ok && err.contains("does not belong to model"), "{err}");
}

#[test]
fn compensate_export_and_accuracy() {
    let dir = scratch("compensate");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let (data, est) = (s(&dir.join("data.csv")), dir.join("est.json"));
    let (ok, _, err) = armcal(&simulate_paper_cell("2", &data));
    assert!(ok, "{err}");
    let (ok, _, err) = armcal(&identify_paper_cell(&data, &[], &s(&est)));
    assert!(ok, "{err}");
    let corrected = dir.join("corrected.csv");
    let (ok, out, err) = armcal(&[
        "compensate",
        "--cell",
        "examples/paper-cell.toml",
        "--estimate",
        &s(&est),
        "--targets",
        "examples/paper-poses-random-60.csv",
        "--out",
        &s(&corrected),
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("60 joint configurations"), "{out}");
    let text = std::fs::read_to_string(&corrected).unwrap();
    assert!(text
        .lines()
        .next()
        .unwrap()
        .ends_with("status,position_error_mm,orientation_error_deg,solution"));
    assert!(text.lines().filter(|l| l.contains(",converged,")).count() >= 50);
    for fmt in ["dh", "mdh", "zrp", "json", "urdf"] {
        let out_file = dir.join(format!("model-{fmt}.out"));
        let (ok, _, err) = armcal(&[
            "export",
            "--estimate",
            &s(&est),
            "--format",
            fmt,
            "--out",
            &s(&out_file),
        ]);
        assert!(ok, "{fmt}: {err}");
    }
    // The exported DH cell loads and still identifies 27 parameters.
    let (ok, out, err) = armcal(&[
        "model",
        &s(&dir.join("model-dh.out")),
        "--measurement",
        "position",
    ]);
    assert!(ok, "{err}");
    assert!(
        out.contains("identifiable: 27 geometric parameters at these random"),
        "{out}"
    );
    let (ok, out, err) = armcal(&[
        "accuracy",
        "--cell",
        "examples/motoman-right-cell.toml",
        "--data",
        "data/motoman-leica/right_arm_repeatability_table1.csv",
    ]);
    assert!(ok, "{err}");
    assert!(
        out.contains("1 approached 18 times") && out.contains("RP_l mean 0.0318"),
        "{out}"
    );
}

#[test]
fn axes_from_one_joint_sweeps() {
    let dir = scratch("axes");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    // Simulates the example sweeps (noise-free or with the cell's noise) into `data` and
    // runs `axes` on them with the `extra` options.
    let sweep_axes = |data: &Path, noise: &[&str], extra: &[&str]| {
        let mut sim = vec![
            "simulate",
            "--cell",
            "examples/paper-cell.toml",
            "--poses",
            "examples/paper-sweeps.csv",
            // The reflector faces away from the tracker in these sweeps.
            "--allow-unmeasurable",
            // The axes are compared with the nominal ones in the instrument frame: the
            // tracker stands where the cell says.
            "--instrument-offset-mm",
            "0",
            "--out",
        ];
        let data = s(data);
        sim.push(&data);
        sim.extend_from_slice(noise);
        let (ok, _, err) = armcal(&sim);
        assert!(ok, "{err}");
        let mut args = vec![
            "axes",
            "--cell",
            "examples/paper-cell.toml",
            "--data",
            &data,
        ];
        args.extend_from_slice(extra);
        let (ok, out, err) = armcal(&args);
        assert!(ok, "{err}");
        (out, err)
    };
    let (out, err) = sweep_axes(&dir.join("sweeps.csv"), &["--noise-free"], &[]);
    // Six axes; noise-free circles fit exactly: no residual, σ's of 0, no warning.
    let column = |row: &str, from_end: usize| -> f64 {
        row.split_whitespace()
            .rev()
            .nth(from_end)
            .unwrap()
            .parse()
            .unwrap()
    };
    assert!(out.contains("σdir°") && out.contains("σ⊥pt mm"), "{out}");
    let rows: Vec<&str> = out.lines().filter(|l| l.starts_with('q')).collect();
    assert_eq!(rows.len(), 6, "{out}");
    for r in rows {
        let (rms, sigma_dir, sigma_point) = (column(r, 4), column(r, 3), column(r, 2));
        assert!(rms < 1e-6 && sigma_dir < 1e-6 && sigma_point < 1e-6, "{r}");
    }
    assert!(!err.contains("not to be trusted"), "{err}");
    // With the cell's 1 mm tracker noise the ±30° sweeps do not fix the axes: each row
    // shows its σ's, each axis over the limits is warned about with its numbers and
    // remedies, and the JSON carries both.
    let axes_json = dir.join("axes.json");
    let (out, err) = sweep_axes(&dir.join("noisy.csv"), &[], &["--out", &s(&axes_json)]);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&axes_json).unwrap()).unwrap();
    for (r, j) in out
        .lines()
        .filter(|l| l.starts_with('q'))
        .zip(json.as_array().unwrap())
    {
        let (sigma_dir, sigma_point) = (column(r, 3), column(r, 2));
        let name = j["joint"].as_str().unwrap();
        assert!(
            (sigma_dir - j["sigma_direction_deg"].as_f64().unwrap()).abs() < 1e-3
                && (sigma_point - j["sigma_point_mm"].as_f64().unwrap()).abs() < 1e-2,
            "{r}"
        );
        // The axis lies within its σ's of the nominal one (the truth differs from it by
        // ≈ 0.1° and 0.5 mm).
        let (d_angle, d_line) = (column(r, 1), column(r, 0));
        assert!(
            d_angle < 4.0 * sigma_dir + 0.5 && d_line < 4.0 * sigma_point + 2.0,
            "{r}"
        );
        if sigma_dir > 0.5 || sigma_point > 2.0 {
            let w = j["warning"].as_str().expect("a warning");
            let line = format!("warning: {w}");
            assert!(err.contains(&line), "{name}: {err}");
            // 13 points of the joint's sweep and the zero pose of each of the other five.
            assert!(
                w.starts_with(&format!(
                    "{name} axis not to be trusted (18 points over 60.0°"
                )) && w.contains(&format!("σ direction {sigma_dir:.3}°"))
                    && w.contains("Remedy:"),
                "{w}"
            );
        }
    }
    assert!(err.matches("warning: q").count() >= 3, "{err}");
    // Random poses move several joints at once: refused with the line named.
    let (ok, _, err) = armcal(&[
        "axes",
        "--cell",
        "examples/paper-cell.toml",
        "--data",
        "examples/paper-poses-random-60.csv",
    ]);
    assert!(!ok);
    assert!(
        err.contains("sweeps move one joint at a time") || err.contains("x, y, z"),
        "{err}"
    );
}

#[test]
fn demo_writes_every_file_and_is_reproducible() {
    let dir = scratch("demo");
    let out = dir.join("run");
    let s = out.to_str().unwrap();
    let (ok, stdout, err) = armcal(&["demo", "--out", s, "--quiet"]);
    assert!(ok, "{err}");
    for needle in [
        "TCP σ at the working pose, predicted",
        "held-out error RMS",
        "compensated",
        "13 files",
        "report.html",
    ] {
        assert!(stdout.contains(needle), "{needle}: {stdout}");
    }
    let read_all = || {
        let mut files: Vec<(String, String)> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().path())
            .map(|p| {
                (
                    p.file_name().unwrap().to_string_lossy().into_owned(),
                    std::fs::read_to_string(&p).unwrap(),
                )
            })
            .collect();
        files.sort();
        files
    };
    let first = read_all();
    assert_eq!(first.len(), 14, "13 files and the marker");
    // The report is among the compared files: one self-contained page whose figure count
    // matches its inline SVGs, with the 3D view of both designs.
    let html = &first.iter().find(|f| f.0 == "report.html").unwrap().1;
    let figures = html.matches("<svg").count();
    assert!(
        html.contains(&format!(
            "<meta name=\"armcal-figures\" content=\"{figures}\">"
        )),
        "{figures} figures"
    );
    assert!(figures >= 12, "{figures}");
    assert!(!html.contains("http://") && !html.contains("https://"));
    assert!(html.contains("class=\"cell-view\"") && html.contains("heuristic design"));
    // `armcal report` on the demo's JSON files gives the same sections and figures.
    let mut args = vec!["report".to_string()];
    args.extend(
        first
            .iter()
            .filter(|f| f.0.ends_with(".json"))
            .map(|f| out.join(&f.0).to_str().unwrap().to_string()),
    );
    args.extend([
        "--out".into(),
        dir.join("rep").to_str().unwrap().to_string(),
    ]);
    let (ok, stdout, err) = armcal(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(ok, "{err}");
    assert!(
        stdout.contains(&format!("({figures} figures, 3D view")),
        "{stdout}"
    );
    let again = std::fs::read_to_string(dir.join("rep").join("report.html")).unwrap();
    assert!(again.contains("Summary: KPI design vs heuristic design"));
    let (ok, _, err) = armcal(&["demo", "--out", s, "--quiet"]);
    assert!(ok, "a demo folder may be rewritten: {err}");
    assert_eq!(first, read_all(), "same seed → identical files");
    // The summary comes from the files: the KPI design's predicted TCP σ is in its estimate.
    let summary: serde_json::Value =
        serde_json::from_str(&first.iter().find(|f| f.0 == "summary.json").unwrap().1).unwrap();
    let est: serde_json::Value =
        serde_json::from_str(&first.iter().find(|f| f.0 == "estimate-kpi.json").unwrap().1)
            .unwrap();
    let kpi = est["tcp"][0]["kpi"].as_f64().unwrap();
    assert!((summary["kpi"]["tcp_sigma_predicted"].as_f64().unwrap() - kpi.sqrt()).abs() < 1e-12);
    assert!(
        summary["kpi"]["tcp_sigma_predicted"].as_f64().unwrap()
            < summary["heuristic"]["tcp_sigma_predicted"]
                .as_f64()
                .unwrap()
    );
}

#[test]
fn report_from_identify_and_plan_files() {
    let dir = scratch("report");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let (data, est, design) = (
        dir.join("data.csv"),
        dir.join("est.json"),
        dir.join("design.csv"),
    );
    let (data_s, est_s) = (s(&data), s(&est));
    for args in [
        simulate_paper_cell("4", &data_s).to_vec(),
        identify_paper_cell(&data_s, &["--holdout", "0.3"], &est_s),
        vec![
            "plan",
            "--cell",
            "examples/paper-cell.toml",
            "--poses",
            "30",
            "--starts",
            "1",
            "--out",
            &s(&design),
        ],
    ] {
        let (ok, _, err) = armcal(&args);
        assert!(ok, "{args:?}: {err}");
    }
    let out = dir.join("report");
    let design_json = dir.join("design.json");
    let report = ["report", &est_s, &s(&design_json), "--out", &s(&out)];
    let (ok, stdout, err) = armcal(&report);
    assert!(ok, "{err}");
    assert!(
        stdout.contains("report →") && stdout.contains("3D view"),
        "{stdout}"
    );
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    let figures = html.matches("<svg").count();
    // TCP ellipses (3 in the instrument frame, 3 in the base frame), design joints and
    // clearances (2), residual histograms, per-pose residuals and held-out bars (3), held-out
    // error per axis, change / σ and the correlation heatmap (3).
    assert_eq!(figures, 14, "{stdout}");
    assert!(html.contains("<meta name=\"armcal-figures\" content=\"14\">"));
    assert!(html.contains("<section id=\"verdict\">"));
    assert!(!html.contains("http://") && !html.contains("https://"));
    for needle in [
        "Estimate: est",
        "Design: design",
        "TCP precision at the working pose",
        "Held-out validation",
        "optimality bound",
        "class=\"cell-view\"",
    ] {
        assert!(html.contains(needle), "{needle}");
    }
    // Never overwritten without --force.
    refuses_to_overwrite_unless_forced(&report);
    assert_eq!(
        html,
        std::fs::read_to_string(out.join("report.html")).unwrap()
    );
    // Files armcal did not write are refused with the file name and what was expected.
    let other = dir.join("other.json");
    std::fs::write(&other, r#"{"hello": 1, "world": [2]}"#).unwrap();
    for (file, needle) in [
        (
            s(&other),
            "not an armcal result (top-level fields: hello, world)",
        ),
        (s(&data), "not JSON"),
    ] {
        let (ok, _, err) = armcal(&["report", &file, "--out", &s(&dir.join("r2"))]);
        assert!(!ok, "{file}");
        assert!(
            err.contains(&file)
                && err.contains(needle)
                && err.contains("expected an armcal estimate"),
            "{err}"
        );
    }
    assert!(!dir.join("r2").join("report.html").exists());
}

#[test]
fn identify_validates_on_a_test_file_and_checks_the_holdout_flag() {
    let dir = scratch("test-file");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let (data, test, est) = (
        s(&dir.join("data.csv")),
        dir.join("test.csv"),
        s(&dir.join("est.json")),
    );
    let test_s = s(&test);
    assert!(armcal(&simulate_paper_cell("4", &data)).0);
    // Same robot (seed), other poses: the joint sweeps.
    let mut sweeps = simulate_paper_cell("4", &test_s).to_vec();
    sweeps[4] = "examples/paper-sweeps.csv";
    sweeps.push("--allow-unmeasurable");
    let (ok, _, err) = armcal(&sweeps);
    assert!(ok, "{err}");
    // The user's own test file, with its own pose ids.
    let renamed: String = std::fs::read_to_string(&test)
        .unwrap()
        .lines()
        .enumerate()
        .map(|(k, l)| {
            if k == 0 {
                format!("{l}\n")
            } else {
                format!("T{l}\n")
            }
        })
        .collect();
    std::fs::write(&test, renamed).unwrap();
    let (ok, out, err) = armcal(&identify_paper_cell(&data, &["--test", &test_s], &est));
    assert!(ok, "{err}");
    assert!(
        out.contains("held-out validation: 78 configurations (fit on 60)"),
        "{out}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&est).unwrap()).unwrap();
    let v = &json["validation"];
    assert!(
        v["test_data"].as_str().unwrap().ends_with("test.csv"),
        "{v}"
    );
    assert_eq!(v["test_ids"][0], "T1");
    assert_eq!(v["train_ids"][0], "1");
    assert!(v["calibrated"]["rms"].as_f64().unwrap() < v["nominal"]["rms"].as_f64().unwrap());
    // A fraction and a test file together, and fractions outside [0, 1), name the flag.
    let (ok, _, err) = armcal(&identify_paper_cell(
        &data,
        &["--holdout", "0.3", "--test", &test_s, "--force"],
        &est,
    ));
    assert!(
        !ok && err.contains("--holdout") && err.contains("--test"),
        "{err}"
    );
    for h in ["NaN", "-0.1", "1.0"] {
        let (ok, _, err) = armcal(&identify_paper_cell(
            &data,
            &["--holdout", h, "--force"],
            &est,
        ));
        assert!(
            !ok && err.contains("--holdout") && err.contains("[0, 1)"),
            "{h}: {err}"
        );
    }
}
