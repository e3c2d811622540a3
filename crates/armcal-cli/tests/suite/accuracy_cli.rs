//! `armcal accuracy` on the UR10 cubes (Series D) and on bad input: the poses found, the
//! figures table written through the outputs plan, a pose approached once, orientation asked
//! of position data, a tolerance that is no number.

use crate::common::{armcal, scratch};

const CELL: &str = "examples/ur10-leica-cell.toml";
const SERIES_D: &str = "data/ipa-ur10-leica/Series_D/measurements_iso_cubes.csv";

#[test]
fn series_d_cubes_with_a_table_of_every_pose() {
    let dir = scratch("accuracy-cubes");
    let table = dir.join("iso9283.csv");
    let t = table.to_str().unwrap();
    let (ok, out, err) = armcal(&["accuracy", "--cell", CELL, "--data", SERIES_D, "--out", t]);
    assert!(ok, "{err}");
    assert!(
        out.contains("632 configurations, 574 commanded poses")
            && out.contains("543 approached once, 6 approached twice, 24 approached 3 times, 1 approached 5 times"),
        "{out}"
    );
    // Most poses are approached once: AP only, and said so.
    assert!(
        out.contains("543 poses approached once have AP only (RP needs at least 2 approaches; ISO 9283 asks 30)"),
        "{out}"
    );
    let text = std::fs::read_to_string(&table).unwrap();
    let mut lines = text.lines();
    assert!(lines
        .next()
        .unwrap()
        .starts_with("model,pose_id,observed,approaches,command_x_mm"));
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 574, "one row per pose, before only");
    // A pose approached once has empty RP fields.
    assert!(rows.iter().any(|r| r.contains(",1,") && r.contains(",,,,")));
    // The JSON record has both the grouping and the figures.
    let (ok, json, err) = armcal(&["accuracy", "--cell", CELL, "--data", SERIES_D, "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["grouping"]["poses"], 574);
    assert!(v["before"]["report"]["poses"][0]["orientation"]["accuracy"]["apa_deg"].is_number());
    assert!(v["after"].is_null());
}

#[test]
fn bad_input_is_refused_with_what_to_do() {
    let motoman = [
        "accuracy",
        "--cell",
        "examples/motoman-right-cell.toml",
        "--data",
        "data/motoman-leica/right_arm_repeatability_table1.csv",
    ];
    let mut with = motoman.to_vec();
    with.push("--orientation");
    let (ok, _, err) = armcal(&with);
    assert!(
        !ok && err.contains("right_arm_repeatability_table1.csv")
            && err.contains("need pose measurements")
            && err.contains("positions only"),
        "{err}"
    );
    let mut with = motoman.to_vec();
    with.extend(["--same-pose-mm", "0"]);
    let (ok, _, err) = armcal(&with);
    assert!(
        !ok && err.contains("--same-pose-mm") && err.contains("positive"),
        "{err}"
    );
    // One pose, 18 approaches: the frames fitted for "before" take its AP, and it says so.
    let (ok, out, err) = armcal(&motoman);
    assert!(ok, "{err}");
    assert!(
        out.contains("the frames were fitted to these 1 pose:"),
        "{out}"
    );
}
