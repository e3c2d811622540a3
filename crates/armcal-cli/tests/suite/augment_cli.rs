//! `armcal plan --measured`: a design that augments poses already measured prints the
//! criterion and C_s of the measured and new poses together (what the calibration will have),
//! and numbers its poses on from the measured ones.

use crate::common::{armcal, scratch};

#[test]
fn plan_measured_prints_the_combined_precision_and_continues_the_pose_ids() {
    let dir = scratch("plan_measured");
    let out = dir.join("more.csv");
    let measured = "examples/paper-poses-planned-60.csv";
    let (ok, stdout, stderr) = armcal(&[
        "plan",
        "--cell",
        "examples/paper-cell.toml",
        "--poses",
        "3",
        "--starts",
        "1",
        "--measured",
        measured,
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    // Three poses alone do not identify the 27 parameters: the old record assessed them alone
    // and failed.
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("the 60 measured poses (examples/paper-poses-planned-60.csv) are augmented; the new poses are numbered 61 to 63"),
        "{stdout}"
    );
    let text = std::fs::read_to_string(&out).unwrap();
    let ids: Vec<&str> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap())
        .collect();
    assert_eq!(ids, ["61", "62", "63"]);
    let kpi = |s: &str, prefix: &str| -> f64 {
        let line = s
            .lines()
            .find(|l| l.contains(prefix))
            .unwrap_or_else(|| panic!("{s}"));
        let at = line.find(prefix).unwrap() + prefix.len();
        line[at..]
            .split(" mm²")
            .next()
            .unwrap()
            .trim()
            .parse()
            .unwrap()
    };
    let planned = kpi(&stdout, "(1/3) tr C_s at `q_work` with the 60 measured: ");
    // The same figure from `evaluate` on the measured and the new poses in one file.
    let both = dir.join("both.csv");
    let measured_text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../..")
            .join(measured),
    )
    .unwrap();
    let new_rows: Vec<&str> = text.lines().skip(1).collect();
    std::fs::write(
        &both,
        format!("{}\n{}\n", measured_text.trim_end(), new_rows.join("\n")),
    )
    .unwrap();
    let (ok, stdout, stderr) = armcal(&[
        "evaluate",
        "--cell",
        "examples/paper-cell.toml",
        "--design",
        both.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("63 poses"), "{stdout}");
    let evaluated = kpi(&stdout, "(1/3) tr C_s at `q_work` = ");
    assert!(
        (planned - evaluated).abs() <= 1e-4 * evaluated,
        "plan printed {planned}, evaluate of all 63 poses {evaluated}"
    );
}
