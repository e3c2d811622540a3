//! All or nothing (issue 12, item 2): every output path is checked before a command
//! computes, a failing command leaves no new file, and no command overwrites one of its own
//! input files, even with `--force`.

use crate::common::{armcal, identify_paper_cell, scratch, simulate_paper_cell};
use std::path::Path;
use std::time::Instant;

/// Every file under `dir` (relative paths), sorted.
fn listing(dir: &Path) -> Vec<String> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<String>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            out.push(p.strip_prefix(root).unwrap().display().to_string());
            if p.is_dir() {
                walk(root, &p, out);
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

#[test]
fn a_failing_command_leaves_no_new_file() {
    let dir = scratch("outputs-failing");
    // Poses the cell's joints cannot take: simulate fails after its plan, writing nothing
    // (not even the folder it would have made).
    let poses = dir.join("poses.csv");
    std::fs::write(
        &poses,
        "pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\n1,900,0,0,0,0,0\n",
    )
    .unwrap();
    let (data, truth) = (dir.join("new/data.csv"), dir.join("new/truth.json"));
    let (ok, _, err) = armcal(&[
        "simulate",
        "--cell",
        "examples/paper-cell.toml",
        "--poses",
        poses.to_str().unwrap(),
        "--out",
        data.to_str().unwrap(),
        "--truth-out",
        truth.to_str().unwrap(),
    ]);
    assert!(!ok, "{err}");
    assert_eq!(listing(&dir), ["poses.csv"], "{err}");

    // One refused output refuses them all: the design is not written when its report exists.
    let report = dir.join("design.json");
    std::fs::write(&report, "mine").unwrap();
    let design = dir.join("design.csv");
    let (ok, _, err) = armcal(&[
        "plan",
        "--cell",
        "examples/paper-cell.toml",
        "--poses",
        "12",
        "--out",
        design.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(!ok && err.contains("exists; pass --force"), "{err}");
    assert!(!design.exists());
    assert_eq!(std::fs::read_to_string(&report).unwrap(), "mine");
    // An output whose folder cannot be made (a file is in the way) is refused up front too.
    let (ok, _, err) = armcal(&simulate_paper_cell(
        "1",
        dir.join("poses.csv/data.csv").to_str().unwrap(),
    ));
    assert!(!ok && err.contains("not a directory"), "{err}");
    assert_eq!(listing(&dir), ["design.json", "poses.csv"]);
}

#[test]
fn an_input_file_is_never_overwritten() {
    let dir = scratch("outputs-inputs");
    let data = dir.join("data.csv");
    let d = data.to_str().unwrap();
    let (ok, _, err) = armcal(&simulate_paper_cell("1", d));
    assert!(ok, "{err}");
    let before = std::fs::read_to_string(&data).unwrap();
    // `identify --out` its own `--data`, with --force, and under another spelling of the path.
    let other = format!("{}/./data.csv", dir.display());
    for out in [d, other.as_str()] {
        let (ok, _, err) = armcal(&identify_paper_cell(d, &["--force", "--quiet"], out));
        assert!(!ok && err.contains("is an input of this command"), "{err}");
        assert_eq!(std::fs::read_to_string(&data).unwrap(), before);
    }
    // `simulate --out` its own `--poses`.
    let poses = dir.join("poses.csv");
    std::fs::copy("../../examples/paper-poses-random-60.csv", &poses)
        .or_else(|_| {
            std::fs::copy(
                concat!(
                    env!("CARGO_MANIFEST_DIR"),
                    "/../../examples/paper-poses-random-60.csv"
                ),
                &poses,
            )
        })
        .unwrap();
    let p = poses.to_str().unwrap();
    let (ok, _, err) = armcal(&[
        "simulate",
        "--cell",
        "examples/paper-cell.toml",
        "--poses",
        p,
        "--out",
        p,
        "--force",
    ]);
    assert!(!ok && err.contains("is an input of this command"), "{err}");
    assert!(std::fs::read_to_string(&poses)
        .unwrap()
        .starts_with("pose_id"));
}

#[test]
fn study_refuses_an_existing_output_before_computing() {
    let dir = scratch("outputs-study");
    std::fs::write(dir.join("study-collisions.json"), "mine").unwrap();
    let t0 = Instant::now();
    let (ok, _, err) = armcal(&["study", "paper", "--out", dir.to_str().unwrap(), "--quiet"]);
    assert!(!ok && err.contains("exists; pass --force"), "{err}");
    assert!(t0.elapsed().as_secs_f64() < 5.0, "{:?}", t0.elapsed());
    assert_eq!(listing(&dir), ["study-collisions.json"]);
}

#[test]
fn demo_refuses_a_users_file() {
    let dir = scratch("outputs-demo");
    std::fs::write(dir.join("cell.toml"), "mine").unwrap();
    let t0 = Instant::now();
    let (ok, _, err) = armcal(&["demo", "--out", dir.to_str().unwrap(), "--quiet"]);
    assert!(
        !ok && err.contains("cell.toml exists; pass --force"),
        "{err}"
    );
    assert!(t0.elapsed().as_secs_f64() < 5.0);
    assert_eq!(listing(&dir), ["cell.toml"]);
}

#[test]
fn a_relative_output_in_a_new_folder_is_written() {
    let dir = scratch("outputs-relative");
    let cell = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/paper-cell.toml"
    );
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_armcal"))
        .args([
            "plan",
            "--cell",
            cell,
            "--poses",
            "12",
            "--out",
            "out/design.csv",
            "--quiet",
        ])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(listing(&dir), ["out", "out/design.csv", "out/design.json"]);
}
