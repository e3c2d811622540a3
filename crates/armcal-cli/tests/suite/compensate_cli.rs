//! `armcal compensate` with bad input (rows outside the joint limits, unreachable Cartesian
//! targets, an estimate of another robot) and with the nonparametric correction.

use crate::common;
use common::{armcal, identify_paper_cell, scratch, simulate_paper_cell};
use std::path::Path;

/// The data rows of `text` whose `pose_id` is `id`.
fn row<'a>(text: &'a str, id: &str) -> &'a str {
    text.lines()
        .find(|l| l.split(',').next() == Some(id))
        .unwrap_or_else(|| panic!("no row {id} in\n{text}"))
}

#[test]
fn compensate_reports_bad_rows_and_applies_the_nonparametric_correction() {
    let dir = scratch("compensate-cli");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let (data, est) = (dir.join("data.csv"), dir.join("est.json"));
    let (ok, _, err) = armcal(&simulate_paper_cell("3", &s(&data)));
    assert!(ok, "{err}");
    let (ok, _, err) = armcal(&identify_paper_cell(&s(&data), &[], &s(&est)));
    assert!(ok, "{err}");

    // A joint program: one good row, one with q5 = 100° beyond its 87° limit.
    let program = dir.join("program.csv");
    std::fs::write(
        &program,
        "pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\n\
         good,0,-30,60,0,-60,0\n\
         limit,0,-30,60,0,100,0\n",
    )
    .unwrap();
    let out_file = dir.join("program-out.csv");
    let compensate = |targets: &Path, out: &Path, extra: &[&str]| {
        let mut args = vec![
            "compensate".to_string(),
            "--cell".into(),
            "examples/paper-cell.toml".into(),
            "--estimate".into(),
            s(&est),
            "--targets".into(),
            s(targets),
            "--out".into(),
            s(out),
            "--force".into(),
        ];
        args.extend(extra.iter().map(|a| a.to_string()));
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        armcal(&refs)
    };
    let (ok, stdout, err) = compensate(&program, &out_file, &[]);
    assert!(ok, "{err}");
    assert!(stdout.contains("1 not converged"), "{stdout}");
    let text = std::fs::read_to_string(&out_file).unwrap();
    assert!(row(&text, "good").contains(",converged,"), "{text}");
    let limit = row(&text, "limit");
    // The calibrated solution needs q5 near the asked 100° (the calibration moves it by
    // a fraction of a degree), beyond the 87° limit.
    let q5: f64 = limit
        .split(",joint-limits: q5 = ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("{limit}"));
    assert!(
        (q5 - 100.0).abs() < 1.0 && limit.contains(" > 87.000 deg,"),
        "{limit}"
    );

    // Cartesian targets: one reachable (the tool pose at the good row), one 5 m away.
    let cartesian = dir.join("cartesian.csv");
    std::fs::write(
        &cartesian,
        "pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg,x_mm,y_mm,z_mm,roll_deg,pitch_deg,yaw_deg\n\
         far,0,-30,60,0,-60,0,5000,0,0,0,0,0\n",
    )
    .unwrap();
    let (ok, _, err) = compensate(&cartesian, &out_file, &[]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&out_file).unwrap();
    assert!(
        row(&text, "far").contains(",\"unreachable: residual "),
        "{text}"
    );

    // An estimate of the paper robot given for another robot: a clear error.
    let (ok, _, err) = armcal(&[
        "compensate",
        "--cell",
        "examples/motoman-right-cell.toml",
        "--estimate",
        &s(&est),
        "--targets",
        "examples/paper-poses-random-60.csv",
        "--out",
        &s(&dir.join("x.csv")),
    ]);
    assert!(!ok && err.contains("does not belong to model"), "{err}");

    // The nonparametric correction fitted on the calibration data: its summary, and the
    // correction applied to each row in its own columns.
    let (ok, stdout, err) = compensate(
        &program,
        &out_file,
        &["--nonparametric", &s(&data), "--degree", "2"],
    );
    assert!(ok, "{err}");
    assert!(
        stdout.contains("nonparametric correction (arm-joints, degree 2, 10 terms)"),
        "{stdout}"
    );
    let text = std::fs::read_to_string(&out_file).unwrap();
    assert!(text
        .lines()
        .next()
        .unwrap()
        .contains("correction_x_mm,correction_y_mm,correction_z_mm,status,position_error_mm"));
    let good: Vec<&str> = row(&text, "good").split(',').collect();
    let correction: Vec<f64> = good[7..10].iter().map(|v| v.parse().unwrap()).collect();
    assert!(correction.iter().all(|c| c.is_finite()), "{good:?}");
    assert_eq!(good[10], "converged", "{good:?}");
    // A data file that does not exist is named in the error.
    let (ok, _, err) = compensate(&program, &out_file, &["--nonparametric", "missing.csv"]);
    assert!(!ok && err.contains("missing.csv"), "{err}");
}
