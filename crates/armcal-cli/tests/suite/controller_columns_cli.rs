//! Controller angles in the CSV files armcal writes and reads (issue 33 item 1): for a cell
//! whose `[robot.controller]` negates and offsets axes, `simulate`, `plan` and `compensate`
//! write `q<i>_controller_deg` beside `q<i>_deg`; `identify` and `compensate` read either set
//! to the same result; a row whose two sets disagree is refused with its line and columns.

use crate::common::{armcal, scratch};
use std::path::Path;

/// The paper cell with axes 2 and 5 negated and axis 2's zero 90° off.
fn cell_with_convention(dir: &Path) -> String {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
    let text = std::fs::read_to_string(Path::new(root).join("examples/paper-cell.toml")).unwrap();
    let path = dir.join("cell.toml");
    std::fs::write(
        &path,
        format!(
            "{text}\n[robot.controller]\nq2 = {{ sign = -1, offset_deg = -90 }}\nq5 = {{ sign = -1 }}\n"
        ),
    )
    .unwrap();
    path.to_str().unwrap().to_string()
}

/// `text` (a CSV) without the columns whose names `drop` accepts.
fn without_columns(text: &str, drop: impl Fn(&str) -> bool) -> String {
    let keep: Vec<bool> = text
        .lines()
        .next()
        .unwrap()
        .split(',')
        .map(|h| !drop(h))
        .collect();
    text.lines()
        .map(|l| {
            let fields: Vec<&str> = l
                .split(',')
                .zip(&keep)
                .filter(|(_, k)| **k)
                .map(|(f, _)| f)
                .collect();
            fields.join(",") + "\n"
        })
        .collect()
}

/// A column's values by name.
fn column(text: &str, name: &str) -> Vec<f64> {
    let c = text
        .lines()
        .next()
        .unwrap()
        .split(',')
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no `{name}` in {text}"));
    text.lines()
        .skip(1)
        .map(|l| l.split(',').nth(c).unwrap().parse().unwrap())
        .collect()
}

#[test]
fn controller_columns_are_written_and_either_set_reads_to_the_same_fit() {
    let dir = scratch("controller-columns");
    let cell = cell_with_convention(&dir);
    let p = |f: &str| dir.join(f).to_str().unwrap().to_string();
    let (data, est_both, est_controller) = (p("data.csv"), p("both.json"), p("controller.json"));
    let (ok, _, err) = armcal(&[
        "simulate",
        "--cell",
        &cell,
        "--poses",
        "examples/paper-poses-planned-60.csv",
        "--seed",
        "5",
        "--out",
        &data,
    ]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&data).unwrap();
    let header = text.lines().next().unwrap();
    assert!(
        header.contains("q6_deg,q1_controller_deg,q2_controller_deg"),
        "{header}"
    );
    // q2_controller = −(q2 − (−90°)), q5_controller = −q5, q3 unchanged
    for (model, controller) in column(&text, "q2_deg")
        .iter()
        .zip(column(&text, "q2_controller_deg"))
    {
        assert!(
            (controller + model + 90.0).abs() < 2e-9,
            "{model} {controller}"
        );
    }
    for (model, controller) in column(&text, "q5_deg")
        .iter()
        .zip(column(&text, "q5_controller_deg"))
    {
        assert!((controller + model).abs() < 2e-9);
    }
    assert_eq!(column(&text, "q3_deg"), column(&text, "q3_controller_deg"));

    let controller_only = p("controller-only.csv");
    std::fs::write(
        &controller_only,
        without_columns(&text, |h| h.starts_with('q') && !h.contains("controller")),
    )
    .unwrap();
    for (file, out) in [(&data, &est_both), (&controller_only, &est_controller)] {
        let (ok, _, err) = armcal(&[
            "identify", "--cell", &cell, "--data", file, "--out", out, "--quiet",
        ]);
        assert!(ok, "{file}: {err}");
    }
    let params = |f: &str| -> Vec<f64> {
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(f).unwrap()).unwrap();
        v["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p["estimate"].as_f64().unwrap())
            .collect()
    };
    let (a, b) = (params(&est_both), params(&est_controller));
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() <= 1e-6 * (1.0 + x.abs()), "{x} vs {y}");
    }

    // compensate a joint program given in controller angles only: the output's controller
    // columns are what to send, and its model columns agree with them
    let program = p("program.csv");
    std::fs::write(
        &program,
        "pose_id,q1_controller_deg,q2_controller_deg,q3_controller_deg,q4_controller_deg,q5_controller_deg,q6_controller_deg\n\
         a,10,-60,30,5,45,0\nb,-20,-45,20,-10,30,15\n",
    )
    .unwrap();
    let compensated = p("compensated.csv");
    let (ok, _, err) = armcal(&[
        "compensate",
        "--cell",
        &cell,
        "--estimate",
        &est_both,
        "--targets",
        &program,
        "--out",
        &compensated,
    ]);
    assert!(ok, "{err}");
    let out = std::fs::read_to_string(&compensated).unwrap();
    let (q2, q2c) = (column(&out, "q2_deg"), column(&out, "q2_controller_deg"));
    for ((m, c), asked) in q2.iter().zip(&q2c).zip([-60.0, -45.0]) {
        assert!((c + m + 90.0).abs() < 2e-6, "{m} {c}");
        // a calibration moves a joint by a fraction of a degree, not by a sign or a zero
        assert!((c - asked).abs() < 1.0, "asked {asked}, send {c}");
    }
}

#[test]
fn a_row_whose_two_joint_sets_disagree_is_refused() {
    let dir = scratch("controller-columns-disagree");
    let cell = cell_with_convention(&dir);
    let data = dir.join("data.csv");
    let (ok, _, err) = armcal(&[
        "simulate",
        "--cell",
        &cell,
        "--poses",
        "examples/paper-poses-planned-60.csv",
        "--seed",
        "5",
        "--out",
        data.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&data).unwrap();
    let c = text
        .lines()
        .next()
        .unwrap()
        .split(',')
        .position(|h| h == "q5_controller_deg")
        .unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let mut fields: Vec<String> = lines[4].split(',').map(str::to_string).collect();
    fields[c] = format!("{}", fields[c].parse::<f64>().unwrap() + 1.0);
    lines[4] = fields.join(",");
    std::fs::write(&data, lines.join("\n") + "\n").unwrap();
    let out = dir.join("estimate.json");
    let (ok, _, err) = armcal(&[
        "identify",
        "--cell",
        &cell,
        "--data",
        data.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok);
    assert!(
        err.contains("line 5")
            && err.contains("`q5_controller_deg`")
            && err.contains("`q5_deg`")
            && err.contains("disagree"),
        "{err}"
    );
    assert!(!out.exists(), "a failed identify writes nothing");
}
