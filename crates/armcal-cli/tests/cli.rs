//! The `armcal` binary end to end.

use std::process::Command;

fn armcal(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_armcal"))
        .args(args)
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .output()
        .expect("run armcal");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn model_of_the_paper_cell_reports_27_identifiable_parameters_with_reasons() {
    let (ok, out, err) = armcal(&["model", "examples/paper-cell.toml"]);
    assert!(ok, "{err}");
    assert!(out.contains("identifiable: 27 parameters"), "{out}");
    assert!(out.contains("4R + 2P + 6 = 30"), "{out}");
    assert!(out.contains("not identifiable (6)"), "{out}");
    for p in ["j1.theta", "j1.d", "j6.theta", "j6.d", "j6.a", "j6.alpha"] {
        assert!(
            out.contains(&format!("- `{p}` cannot be separated from")),
            "{p} needs a reason:\n{out}"
        );
    }
    // The q5 = -90° working pose is outside the paper's range: a warning, not an error.
    assert!(err.contains("warning") && err.contains("q5"), "{err}");
}

#[test]
fn model_json_is_machine_readable() {
    let (ok, out, err) = armcal(&["model", "paper", "--json", "--measurement", "position"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["parameters"].as_array().unwrap().len(), 6 * 4 + 12);
    // Position of the tool origin of a 6R with base and tool frames would identify
    // 4·6 + 3 = 27, but the paper robot's tool origin lies on axis 6: 25 (book Prop. 4.7.3).
    assert_eq!(
        v["identifiability"]["identifiable"]
            .as_array()
            .unwrap()
            .len(),
        25
    );
    assert_eq!(
        v["identifiability"]["completeness"]["expected_for_measurement"],
        27
    );
}

#[test]
fn fk_prints_frames_and_rejects_bad_joints() {
    let (ok, out, err) = armcal(&["fk", "paper", "--joints", "0,0,0,0,0,0"]);
    assert!(ok, "{err}");
    let tool = out.lines().find(|l| l.starts_with("tool")).unwrap();
    assert!(
        tool.contains("1770.0000") && tool.contains("-145.0000"),
        "{tool}"
    );

    let (ok, _, err) = armcal(&["fk", "paper", "--joints", "0,0,0"]);
    assert!(!ok);
    assert!(
        err.contains("3 values given") && err.contains("6 joints"),
        "{err}"
    );
    let (ok, _, err) = armcal(&["fk", "paper", "--joints", "0,0,0,0,95,0"]);
    assert!(!ok);
    assert!(
        err.contains("`q5`") && err.contains("outside its limits"),
        "{err}"
    );
    let (ok, _, err) = armcal(&["fk", "nonexistent-robot", "--joints", "0"]);
    assert!(!ok);
    assert!(err.contains("unknown robot"), "{err}");
}

#[test]
fn robots_lists_the_library() {
    let (ok, out, _) = armcal(&["robots"]);
    assert!(ok);
    assert!(out.contains("paper"));
}
