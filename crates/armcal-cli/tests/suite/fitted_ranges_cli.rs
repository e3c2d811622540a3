//! A calibration used outside the joint ranges it was fitted on: the estimate records the
//! ranges, and `predict`, `compensate` and `check` warn, naming the joint, its fitted range
//! and the farthest configuration beyond it; inside the ranges they say nothing.

use crate::common::{armcal, identify_paper_cell, scratch};

#[test]
fn a_calibration_used_outside_its_fitted_joint_ranges_warns() {
    let dir = scratch("fitted_ranges");
    let path = |f: &str| dir.join(f).to_str().unwrap().to_string();
    let (data, est) = (path("data.csv"), path("estimate.json"));
    // Random poses: they leave part of the joint ranges unmeasured.
    let (ok, _, err) = armcal(&[
        "simulate",
        "--cell",
        "examples/paper-cell.toml",
        "--poses",
        "examples/paper-poses-random-60.csv",
        "--allow-unmeasurable",
        "--out",
        &data,
    ]);
    assert!(ok, "{err}");
    let (ok, _, err) = armcal(&identify_paper_cell(&data, &[], &est));
    assert!(ok, "{err}");
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&est).unwrap()).unwrap();
    let q3 = &record["fitted_ranges"][2];
    assert_eq!(q3["joint"], "q3");
    let upper = q3["upper"].as_f64().unwrap();
    // The random poses reach q3 = 150.7° at most; the paper robot's limit is 154°.
    assert!((145.0..152.0).contains(&upper), "{q3}");
    let joints = path("joints.csv");
    std::fs::write(
        &joints,
        "pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\n\
         inside,0,-30,30,0,45,0\nbeyond,0,-30,153,0,45,0\n",
    )
    .unwrap();
    let warning = "1 of 2 configurations lie outside the joint ranges the calibration was fitted on (`q3` fitted on [";
    let inside = path("inside.csv");
    std::fs::write(
        &inside,
        "pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\ninside,0,-30,30,0,45,0\n",
    )
    .unwrap();
    for command in ["predict", "compensate"] {
        let input = if command == "predict" {
            "--joints"
        } else {
            "--targets"
        };
        let out = path(&format!("{command}.csv"));
        let run = |configurations: &str| {
            let (ok, _, err) = armcal(&[
                command,
                "--cell",
                "examples/paper-cell.toml",
                "--estimate",
                &est,
                input,
                configurations,
                "--out",
                &out,
                "--force",
            ]);
            assert!(ok, "{command}: {err}");
            err
        };
        let err = run(&joints);
        assert!(err.contains(warning), "{command}: {err}");
        let beyond = format!(
            "{upper:.3}] deg, up to {:.3} deg beyond at `beyond`",
            153.0 - upper
        );
        assert!(err.contains(&beyond), "{command}: {err}");
        // Inside the ranges: no warning.
        let err = run(&inside);
        assert!(
            !err.contains("outside the joint ranges"),
            "{command}: {err}"
        );
    }
    // `check` on check poses measured where the calibration was not fitted.
    let check_data = path("check.csv");
    let (ok, _, err) = armcal(&[
        "simulate",
        "--cell",
        "examples/paper-cell.toml",
        "--poses",
        &joints,
        "--seed",
        "1",
        "--allow-unmeasurable",
        "--out",
        &check_data,
    ]);
    assert!(ok, "{err}");
    let (_, _, err) = armcal(&[
        "check",
        "--cell",
        "examples/paper-cell.toml",
        "--estimate",
        &est,
        "--data",
        &check_data,
        "--out",
        &path("check.json"),
    ]);
    assert!(err.contains(warning), "check: {err}");
}
