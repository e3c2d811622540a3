//! `armcal compensate` with bad input (rows outside the joint limits, unreachable Cartesian
//! targets, an estimate of another robot) and with the nonparametric correction.

use crate::common;
use common::{armcal, paper_estimate, scratch};
use std::path::Path;

/// The data rows of `text` whose `pose_id` is `id`.
fn row<'a>(text: &'a str, id: &str) -> &'a str {
    text.lines()
        .find(|l| l.split(',').next() == Some(id))
        .unwrap_or_else(|| panic!("no row {id} in\n{text}"))
}

/// `armcal compensate` of the paper cell with the shared estimate ([`paper_estimate`]):
/// `targets` to `out` (overwritten) with the `extra` options.
fn compensate(targets: &Path, out: &Path, extra: &[&str]) -> (bool, String, String) {
    let mut args = vec![
        "compensate",
        "--cell",
        "examples/paper-cell.toml",
        "--estimate",
        &paper_estimate().1,
        "--targets",
        targets.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--force",
    ];
    args.extend_from_slice(extra);
    armcal(&args)
}

#[test]
fn compensate_reports_bad_rows_and_applies_the_nonparametric_correction() {
    let dir = scratch("compensate-cli");
    let (data, est) = paper_estimate();

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
        est,
        "--targets",
        "examples/paper-poses-random-60.csv",
        "--out",
        dir.join("x.csv").to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("does not belong to model"), "{err}");

    // The nonparametric correction fitted on the calibration data: its summary, and the
    // correction applied to each row in its own columns.
    let (ok, stdout, err) = compensate(
        &program,
        &out_file,
        &["--nonparametric", data, "--degree", "2"],
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

/// A joint program through the paper robot's wrist singularity (q5 = 2° … 0 … −5°, with q4
/// and q6 apart, as a path is taught) and two regular rows, compensated with an estimate of
/// the paper cell. Before the joint-change limit the calibrated IK swung q4 and q6 by up to
/// 135° near q5 = 0 and marked those rows `converged`; now every joint changes by at most
/// the limit, every row that cannot meet the tolerance within it has the status
/// `joint-change-limit` and is counted, and the regular rows are compensated as before.
#[test]
fn compensation_never_whips_the_wrist() {
    let dir = scratch("compensate-whip");
    let path = [
        2.0, 1.0, 0.5, 0.2, 0.1, 0.0, -0.1, -0.2, -0.5, -1.0, -2.0, -5.0,
    ];
    let mut program = "pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\n".to_string();
    for (i, q5) in path.iter().enumerate() {
        program += &format!("w{i},10,-30,60,20,{q5},10\n");
    }
    program += "regular1,0,-30,60,0,-60,0\nregular2,-20,-45,70,30,45,-20\n";
    let program_file = dir.join("path.csv");
    std::fs::write(&program_file, &program).unwrap();
    let out_file = dir.join("path-out.csv");
    let run = |extra: &[&str]| {
        let (ok, stdout, err) = compensate(&program_file, &out_file, extra);
        assert!(ok, "{err}");
        (stdout, std::fs::read_to_string(&out_file).unwrap())
    };
    // Each row: (id, largest joint change in deg, status, position and orientation error,
    // solution).
    let rows = |text: &str| -> Vec<(String, f64, String, f64, f64, String)> {
        let nominal: Vec<Vec<f64>> = program
            .lines()
            .skip(1)
            .map(|l| l.split(',').skip(1).map(|v| v.parse().unwrap()).collect())
            .collect();
        let mut out = Vec::new();
        for (line, q0) in text
            .lines()
            .filter(|l| !l.starts_with('#'))
            .skip(1)
            .zip(&nominal)
        {
            // The status may be quoted (it holds commas): split it off first.
            let (head, rest) = match line.split_once(",\"") {
                Some((h, r)) => {
                    let (status, tail) = r.split_once("\",").unwrap();
                    (h.to_string(), (status.to_string(), tail.to_string()))
                }
                None => {
                    let f: Vec<&str> = line.split(',').collect();
                    (f[..7].join(","), (f[7].to_string(), f[8..].join(",")))
                }
            };
            let f: Vec<&str> = head.split(',').collect();
            let change = f[1..7]
                .iter()
                .zip(q0)
                .map(|(v, n)| (v.parse::<f64>().unwrap() - n).abs())
                .fold(0.0, f64::max);
            let tail: Vec<&str> = rest.1.split(',').collect();
            out.push((
                f[0].to_string(),
                change,
                rest.0,
                tail[0].parse().unwrap(),
                tail[1].parse().unwrap(),
                tail[2].to_string(),
            ));
        }
        out
    };

    let (stdout, text) = run(&[]);
    let rows_default = rows(&text);
    let limited: Vec<_> = rows_default
        .iter()
        .filter(|r| r.2.starts_with("joint-change-limit: "))
        .collect();
    for r in &rows_default {
        eprintln!("{r:?}");
        assert!(r.1 <= 5.0 + 1e-6, "{r:?} changes a joint beyond 5°\n{text}");
        if r.2 == "converged" {
            assert!(r.3 <= 1e-6 && r.4 <= 1e-6, "{r:?}");
        } else {
            assert!(r.2.starts_with("joint-change-limit: "), "{r:?}");
            // Position priority: the position is kept, the orientation gives way.
            assert!(r.3 < 1e-3 && r.5 == "position-priority", "{r:?}");
        }
    }
    // The rows near q5 = 0 cannot be compensated within 5°, and are counted.
    assert!(limited.len() >= 8, "{text}");
    assert!(
        limited.iter().any(|r| r.2.contains(" near a singularity;")),
        "{text}"
    );
    assert!(
        stdout.contains(&format!("({} not converged;", limited.len())),
        "{stdout}"
    );
    assert!(
        stdout.contains(&format!(
            "{} of them beyond the tolerance (status joint-change-limit)",
            limited.len()
        )),
        "{stdout}"
    );
    // The regular rows are compensated exactly, by the unlimited calibrated IK.
    for id in ["regular1", "regular2", "w11"] {
        let r = rows_default.iter().find(|r| r.0 == id).unwrap();
        assert!(
            r.2 == "converged" && r.5 == "calibrated-ik" && r.1 < 5.0,
            "{r:?}"
        );
    }

    // With a limit of 200°, the exact solution is kept: it swings the wrist by far more
    // than 5° near q5 = 0 (what happened before the limit), and the regular rows are the
    // same to the digit.
    let (_, wide) = run(&["--max-joint-change-deg", "200"]);
    let rows_wide = rows(&wide);
    let whip = rows_wide.iter().map(|r| r.1).fold(0.0, f64::max);
    assert!(whip > 30.0, "{wide}");
    for id in ["regular1", "regular2", "w11"] {
        let line = |t: &str| {
            t.lines()
                .find(|l| l.starts_with(&format!("{id},")))
                .unwrap()
                .to_string()
        };
        assert_eq!(line(&wide), line(&text));
    }

    // A limit that is not a positive number is refused.
    let never = dir.join("never.csv");
    let (ok, _, err) = compensate(&program_file, &never, &["--max-joint-change-deg", "0"]);
    assert!(
        !ok && err
            .contains("--max-joint-change-deg 0: the joint-change limit must be a positive number"),
        "{err}"
    );
    assert!(!never.exists());
}

/// `--program`: a KRL program is filtered in place with a summary per target; a malformed
/// target, an unknown extension or an unconverged estimate writes nothing.
#[test]
fn compensate_filters_a_controller_program_and_writes_nothing_on_error() {
    let dir = scratch("compensate-program-cli");
    let est = &paper_estimate().1;
    let run = |program: &Path, out: &Path, extra: &[&str]| {
        let mut args = vec![
            "compensate",
            "--cell",
            "examples/paper-cell.toml",
            "--estimate",
            est,
            "--program",
            program.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        armcal(&args)
    };
    let sample = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/programs/paper.src"
    ));
    let out = dir.join("paper.src");
    let (ok, stdout, err) = run(sample, &out, &[]);
    assert!(ok, "{err}");
    assert!(
        stdout.contains("6 motion targets, 5 compensated, 1 left unchanged"),
        "{stdout}"
    );
    assert!(stdout.contains("line   18  LIN_REL"), "{stdout}");
    let (a, b) = (
        std::fs::read_to_string(sample).unwrap(),
        std::fs::read_to_string(&out).unwrap(),
    );
    assert_ne!(a, b);
    assert_eq!(a.lines().count(), b.lines().count());
    for (x, y) in a.lines().zip(b.lines()) {
        if !x.starts_with("PTP {") && !x.starts_with("LIN {") {
            assert_eq!(x, y);
        }
    }
    // The joint targets written as joints, a Cartesian PTP converted.
    let joints = dir.join("joints.src");
    let (ok, stdout, err) = run(sample, &joints, &["--to-joints"]);
    assert!(ok, "{err}");
    assert!(stdout.contains("written as joints"), "{stdout}");
    assert!(stdout.contains("kept Cartesian"), "{stdout}");

    let bad = dir.join("bad.src");
    std::fs::write(&bad, "DEF bad()\nLIN {X 1,Y 2,Z abc,A 0,B 0,C 0}\nEND\n").unwrap();
    let none = dir.join("none.src");
    let (ok, _, err) = run(&bad, &none, &[]);
    assert!(
        !ok && err.contains("line 2: `Z`: `abc` is not a number"),
        "{err}"
    );
    assert!(!none.exists());
    let txt = dir.join("prog.txt");
    std::fs::write(&txt, "x").unwrap();
    let (ok, _, err) = run(&txt, &none, &[]);
    assert!(!ok && err.contains("--language"), "{err}");
    assert!(!none.exists());
}
