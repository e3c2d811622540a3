//! A bad fit cannot flow downstream unnoticed, and an estimate knows its model (issue #10
//! items 4, 5), through the binary: every command that uses an estimate refuses an
//! unconverged one unless `--accept-unconverged`, and then every file it writes says so;
//! a cell with other geometry than the estimate's is refused with the difference named.

use crate::common;
use common::{armcal, identify_paper_cell, scratch, simulate_paper_cell};
use std::path::{Path, PathBuf};

fn s(p: &Path) -> String {
    p.to_str().unwrap().to_string()
}

/// Every consumer of `est`: its arguments (without the flag) and the files it writes.
fn consumers(dir: &Path, est: &str, data: &str) -> Vec<(Vec<String>, Vec<PathBuf>)> {
    let args = |a: &[&str]| a.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    let mut out = Vec::new();
    for (format, file) in [
        ("dh", "model.toml"),
        ("json", "model.json"),
        ("urdf", "model.urdf"),
    ] {
        let path = dir.join(file);
        let mut written = vec![path.clone()];
        if format == "dh" {
            written.push(path.with_extension("csv"));
        }
        out.push((
            args(&[
                "export",
                "--estimate",
                est,
                "--format",
                format,
                "--out",
                &s(&path),
            ]),
            written,
        ));
    }
    let cell = "examples/paper-cell.toml";
    let joints = "examples/paper-poses-random-60.csv";
    let pred = dir.join("pred.csv");
    out.push((
        args(&[
            "predict",
            "--cell",
            cell,
            "--estimate",
            est,
            "--joints",
            joints,
            "--out",
            &s(&pred),
        ]),
        vec![pred],
    ));
    let comp = dir.join("comp.csv");
    out.push((
        args(&[
            "compensate",
            "--cell",
            cell,
            "--estimate",
            est,
            "--targets",
            joints,
            "--out",
            &s(&comp),
        ]),
        vec![comp],
    ));
    out.push((
        args(&[
            "accuracy",
            "--cell",
            cell,
            "--estimate",
            est,
            "--data",
            data,
        ]),
        vec![],
    ));
    let report = dir.join("report");
    out.push((
        args(&["report", est, "--out", &s(&report)]),
        vec![report.join("report.html")],
    ));
    out
}

#[test]
fn every_consumer_refuses_an_unconverged_estimate() {
    let dir = scratch("unconverged");
    let (data, est) = (s(&dir.join("data.csv")), dir.join("est.json"));
    let (ok, _, err) = armcal(&simulate_paper_cell("5", &data));
    assert!(ok, "{err}");
    // One iteration: the estimate is written, and identify itself fails naming the status.
    let (ok, _, err) = armcal(&identify_paper_cell(
        &data,
        &["--max-iterations", "1"],
        &s(&est),
    ));
    assert!(!ok && err.contains("did not converge"), "{err}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&est).unwrap()).unwrap();
    assert_eq!(json["verdicts"]["solver"]["status"], "max-iterations");

    for (args, files) in consumers(&dir, &s(&est), &data) {
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        let (ok, _, err) = armcal(&refs);
        assert!(
            !ok && err.contains("did not converge: stopped at the iteration limit")
                && err.contains("--accept-unconverged"),
            "{args:?}: {err}"
        );
        assert!(files.iter().all(|f| !f.exists()), "{args:?} wrote a file");
        let mut accepted = refs.clone();
        accepted.push("--accept-unconverged");
        let (ok, out, err) = armcal(&accepted);
        assert!(ok, "{args:?}: {err}");
        let said =
            "did not converge (stopped at the iteration limit), used with --accept-unconverged";
        assert!(err.contains(said), "{args:?}: {err}");
        if files.is_empty() {
            assert!(out.contains(said), "{args:?}: {out}");
        }
        for f in files {
            let text = std::fs::read_to_string(&f).unwrap();
            // An XML comment cannot hold `--`.
            let said = if f.extension().is_some_and(|e| e == "urdf") {
                said.replace("--", "- -")
            } else {
                said.to_string()
            };
            assert!(text.contains(&said), "{} does not say so", f.display());
        }
    }

    // armcal still reads what it wrote: the prediction as data, the exported cell, the URDF
    // in a cell, the JSON model.
    let (ok, _, err) = armcal(&[
        "accuracy",
        "--cell",
        "examples/paper-cell.toml",
        "--data",
        &s(&dir.join("pred.csv")),
    ]);
    assert!(ok, "the noted prediction reads as data: {err}");
    let (ok, out, err) = armcal(&[
        "model",
        &s(&dir.join("model.toml")),
        "--measurement",
        "position",
    ]);
    assert!(
        ok && out.contains("identifiable: 27 geometric parameters at these random"),
        "{err}"
    );
    let urdf_cell = dir.join("urdf-cell.toml");
    std::fs::write(
        &urdf_cell,
        "name = \"u\"\n\n[robot]\nurdf = \"model.urdf\"\n",
    )
    .unwrap();
    let (ok, _, err) = armcal(&["model", &s(&urdf_cell)]);
    assert!(ok, "the noted URDF loads: {err}");
    let model: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("model.json")).unwrap()).unwrap();
    assert!(model["armcal_note"]
        .as_str()
        .unwrap()
        .contains("did not converge"));
    assert_eq!(model["links"].as_array().unwrap().len(), 8);
}

#[test]
fn an_estimate_used_with_another_lambda_names_the_difference() {
    let dir = scratch("changed-cell");
    let (data, est) = (s(&dir.join("data.csv")), s(&dir.join("est.json")));
    let (ok, _, err) = armcal(&simulate_paper_cell("6", &data));
    assert!(ok, "{err}");
    let (ok, _, err) = armcal(&identify_paper_cell(&data, &[], &est));
    assert!(ok, "{err}");
    // The same parameter names, λ = 700 mm instead of 650.
    let cell = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/paper-cell.toml"
    ))
    .unwrap()
    .replace("builtin = \"paper-650-600\"", "builtin = \"paper-700-600\"");
    let other = dir.join("cell-700.toml");
    std::fs::write(&other, cell).unwrap();
    let other = s(&other);
    let joints = "examples/paper-poses-random-60.csv";
    let out = s(&dir.join("x.csv"));
    for args in [
        vec![
            "predict",
            "--cell",
            &other,
            "--estimate",
            &est,
            "--joints",
            joints,
            "--out",
            &out,
        ],
        vec![
            "compensate",
            "--cell",
            &other,
            "--estimate",
            &est,
            "--targets",
            joints,
            "--out",
            &out,
        ],
        vec![
            "accuracy",
            "--cell",
            &other,
            "--estimate",
            &est,
            "--data",
            &data,
        ],
    ] {
        let (ok, _, err) = armcal(&args);
        assert!(
            !ok && err.contains(&est)
                && err.contains("`j2` a: 650 mm in the estimate's cell, 700 mm in this cell"),
            "{}: {err}",
            args[0]
        );
        assert!(!Path::new(&out).exists());
    }
}
