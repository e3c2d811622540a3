//! Margins a real cell survives (issue 30 item 2). The paper cell with the default `[design]`
//! incidence and line-of-sight margins (the paper's zero margins deleted): a planned design
//! stays measurable with the tracker 50 mm off in the worst direction for every pose
//! (`evaluate --tracker-shift-mm 50`), where the paper's own zero-margin design loses most of
//! its poses; and README's loop `campaign start → simulate → campaign step …` runs to its stop.

use crate::common::{armcal, cell_with_default_margins, scratch};

/// The count line of `evaluate --tracker-shift-mm`: (measurable, poses).
fn measurable_count(stdout: &str) -> (usize, usize) {
    let line = stdout
        .lines()
        .find(|l| l.starts_with("tracker up to 50 mm off"))
        .unwrap_or_else(|| panic!("{stdout}"));
    let words: Vec<&str> = line.split_whitespace().collect();
    let of = words.iter().position(|w| *w == "of").unwrap();
    (
        words[of - 1].parse().unwrap(),
        words[of + 1].parse().unwrap(),
    )
}

#[test]
fn a_design_planned_with_the_default_margins_survives_a_tracker_50_mm_off() {
    let dir = scratch("margins-shift");
    let cell = cell_with_default_margins(&dir);
    let design = dir.join("design.csv");
    let (ok, out, err) = armcal(&[
        "plan",
        "--cell",
        cell.to_str().unwrap(),
        "--poses",
        "40",
        "--out",
        design.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(ok, "{err}");
    // The plan keeps the margins the cell asks for.
    let incidence = out
        .lines()
        .find(|l| l.trim_start().starts_with("incidence"))
        .unwrap_or_else(|| panic!("{out}"));
    assert!(incidence.contains("required   2.000  met"), "{incidence}");
    let evaluate = |cell: &str, design: &str| {
        let (ok, out, err) = armcal(&[
            "evaluate",
            "--cell",
            cell,
            "--design",
            design,
            "--tracker-shift-mm",
            "50",
        ]);
        assert!(ok, "{err}");
        out
    };
    let out = evaluate(cell.to_str().unwrap(), design.to_str().unwrap());
    assert_eq!(measurable_count(&out), (40, 40), "{out}");
    // The paper's design (no margin, poses on the 30° limit) with the same shift: most of its
    // poses are lost, each named with its worst incidence.
    let out = evaluate(
        "examples/paper-cell.toml",
        "examples/paper-poses-planned-60.csv",
    );
    let (measurable, poses) = measurable_count(&out);
    assert_eq!(poses, 60);
    assert!(measurable < 30, "{out}");
    assert!(out.contains("incidence 30."), "{out}");
}

#[test]
fn readmes_campaign_loop_runs_to_its_stop_with_the_default_margins() {
    let dir = scratch("margins-campaign");
    let cell = cell_with_default_margins(&dir);
    let cell = cell.to_str().unwrap();
    let state = dir.join("c");
    let state_s = state.to_str().unwrap();
    let (ok, _, err) = armcal(&[
        "campaign",
        "start",
        "--cell",
        cell,
        "--target-sigma-mm",
        "1.0",
        "--out",
        state_s,
    ]);
    assert!(ok, "{err}");
    for k in 1..=10 {
        let batch = dir.join(format!("b{k}.csv"));
        let (ok, _, err) = armcal(&[
            "simulate",
            "--cell",
            cell,
            "--poses",
            state.join("next.csv").to_str().unwrap(),
            "--seed",
            "3",
            "--out",
            batch.to_str().unwrap(),
        ]);
        assert!(ok, "batch {k}: {err}");
        let (ok, out, err) = armcal(&[
            "campaign",
            "step",
            state_s,
            "--data",
            batch.to_str().unwrap(),
        ]);
        assert!(ok, "step {k}: {err}");
        if out.contains("→ stop: target reached") {
            assert!(k >= 3, "{out}");
            return;
        }
        assert!(out.contains("measure the next batch"), "{out}");
    }
    panic!("no stop after 10 steps");
}
