//! `simulate` measures only what the instrument can measure (issue 12, item 4), and
//! `evaluate` shows the margins against the cell's `[design]` (item 5).

use crate::common::{armcal, scratch};

#[test]
fn simulate_refuses_the_old_random_poses_and_lists_them() {
    let dir = scratch("measurable");
    let out = dir.join("data.csv");
    let args = [
        "simulate",
        "--cell",
        "examples/paper-cell.toml",
        "--poses",
        "examples/paper-poses-random-60.csv",
        "--out",
        out.to_str().unwrap(),
    ];
    let (ok, _, err) = armcal(&args);
    assert!(!ok, "{err}");
    assert!(!out.exists(), "nothing written");
    // "N of 60 poses … cannot be measured", then one line per pose with its constraint.
    let head = err
        .lines()
        .find(|l| {
            l.contains("of 60 poses in examples/paper-poses-random-60.csv cannot be measured")
        })
        .unwrap_or_else(|| panic!("{err}"));
    let n: usize = head
        .trim_start_matches("error: ")
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let listed: Vec<&str> = err.lines().filter(|l| l.starts_with("  pose ")).collect();
    assert_eq!(listed.len(), n, "{err}");
    assert!(n > 40, "{err}");
    // Pose ids as the file gives them, each with a named constraint and its value.
    let file = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/paper-poses-random-60.csv"
    ))
    .unwrap();
    let ids: Vec<&str> = file
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap())
        .collect();
    for l in &listed {
        let id = l.trim_start_matches("  pose ").split(':').next().unwrap();
        assert!(ids.contains(&id), "{l}");
        assert!(l.contains("° > 30°") || l.contains(" mm ("), "{l}");
    }
    assert!(err.contains("--allow-unmeasurable"), "{err}");

    // Anyway: simulated, with the count on stderr.
    let mut anyway = args.to_vec();
    anyway.push("--allow-unmeasurable");
    let (ok, stdout, err) = armcal(&anyway);
    assert!(ok, "{err}");
    assert!(stdout.contains("simulated 60 measurements"), "{stdout}");
    assert!(
        err.contains(&format!("{n} of 60 poses cannot be measured")),
        "{err}"
    );
}

#[test]
fn simulate_measures_the_planned_poses_without_a_word() {
    let dir = scratch("measurable-planned");
    let out = dir.join("data.csv");
    let (ok, stdout, err) = armcal(&[
        "simulate",
        "--cell",
        "examples/paper-cell.toml",
        "--poses",
        "examples/paper-poses-planned-60.csv",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(!err.contains("cannot be measured"), "{err}");
    assert!(stdout.contains("simulated 60 measurements"), "{stdout}");
}

#[test]
fn evaluate_shows_the_margins_against_the_required_clearance() {
    let (ok, stdout, err) = armcal(&[
        "evaluate",
        "--cell",
        "examples/paper-cell-obstacles.toml",
        "--design",
        "examples/paper-poses-planned-60.csv",
    ]);
    assert!(ok, "{err}");
    // Planned without the car and the mount beam: some poses run into them.
    let obstacle = stdout
        .lines()
        .find(|l| l.trim_start().starts_with("obstacle"))
        .unwrap_or_else(|| panic!("{stdout}"));
    assert!(obstacle.contains("NOT MET"), "{stdout}");
    let incidence = stdout
        .lines()
        .find(|l| l.trim_start().starts_with("incidence"))
        .unwrap();
    assert!(incidence.contains(" met "), "{stdout}");
}
