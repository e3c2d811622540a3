//! Scale: `plan` refuses a design too large to plan, early and with the reason; progress
//! is drawn only on a terminal (these tests run without one, so stderr holds no progress).

use crate::common::{armcal, identify_paper_cell, scratch, simulate_paper_cell};
use std::time::Instant;

#[test]
fn plan_refuses_100000_poses_at_once_with_the_reason() {
    let dir = scratch("plan-100000");
    let out = dir.join("design.csv");
    let t0 = Instant::now();
    let (ok, _, err) = armcal(&[
        "plan",
        "--cell",
        "examples/paper-cell.toml",
        "--poses",
        "100000",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok, "{err}");
    assert!(
        err.contains("100000 poses") && err.contains("plan at most 5000 poses"),
        "{err}"
    );
    assert!(err.contains("1/N"), "the reason is given: {err}");
    assert!(t0.elapsed().as_secs() < 20, "refused before planning");
    assert!(
        std::fs::read_dir(&dir).unwrap().next().is_none(),
        "no file left"
    );
}

/// Whether `stderr` holds anything but warnings and notes (a progress line, a carriage
/// return or a terminal escape).
fn progress_in(stderr: &str) -> bool {
    stderr.contains('\r')
        || stderr.contains('\u{1b}')
        || stderr
            .lines()
            .any(|l| !(l.starts_with("warning:") || l.starts_with("note:")))
}

#[test]
fn progress_is_silent_when_stderr_is_not_a_terminal() {
    let dir = scratch("progress-silent");
    let data = dir.join("data.csv");
    let est = dir.join("est.json");
    let design = dir.join("design.csv");
    let (d, e, p) = (
        data.to_str().unwrap(),
        est.to_str().unwrap(),
        design.to_str().unwrap(),
    );
    let runs: Vec<Vec<&str>> = vec![
        simulate_paper_cell("2", d).to_vec(),
        identify_paper_cell(d, &["--holdout", "0.2"], e),
        vec!["report", e, "--out", dir.to_str().unwrap()],
        vec![
            "plan",
            "--cell",
            "examples/paper-cell.toml",
            "--poses",
            "30",
            "--out",
            p,
        ],
    ];
    for args in runs {
        let (ok, _, err) = armcal(&args);
        assert!(ok, "{args:?}: {err}");
        assert!(!progress_in(&err), "{args:?} drew progress:\n{err}");
    }
}
