//! `armcal check`: check poses of the calibrated robot are "consistent", the same poses on a
//! robot whose tracker moved 5 mm are "drifted" with the tracker first; the record is
//! written; a bad check file is refused with its file and line.

use crate::common::{armcal, paper_estimate, scratch};

#[test]
fn check_prints_its_verdict_writes_its_record_and_refuses_a_bad_file() {
    let dir = scratch("check-cli");
    let p = |n: &str| dir.join(n).to_str().unwrap().to_string();
    let (_, est) = paper_estimate();
    let record = p("check.json");
    // Check poses: 10 new KPI poses, measured on the same robot (seed-3 truth).
    let (check_data, poses) = (p("check.csv"), p("check-poses.csv"));
    let (ok, _, err) = armcal(&[
        "plan",
        "--cell",
        "examples/paper-cell.toml",
        "--poses",
        "10",
        "--seed",
        "5",
        "--out",
        &poses,
        "--quiet",
    ]);
    assert!(ok, "{err}");
    let (ok, _, err) = armcal(&[
        "simulate",
        "--cell",
        "examples/paper-cell.toml",
        "--poses",
        &poses,
        "--seed",
        "3",
        "--out",
        &check_data,
    ]);
    assert!(ok, "{err}");
    let check_with = |data: &str, out: &str, extra: &[&str]| {
        let mut args = vec![
            "check",
            "--cell",
            "examples/paper-cell.toml",
            "--estimate",
            est,
            "--data",
            data,
            "--out",
            out,
        ];
        args.extend_from_slice(extra);
        armcal(&args)
    };
    let check = |data: &str, out: &str| check_with(data, out, &["--force"]);
    let (ok, out, err) = check(&check_data, &record);
    assert!(ok, "{err}");
    assert!(
        out.contains("check of 10 poses (30 residual components)"),
        "{out}"
    );
    assert!(out.contains(": consistent"), "{out}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&record).unwrap()).unwrap();
    assert_eq!(json["verdict"], "consistent");
    assert_eq!(json["dof"], 30);
    assert!(json["groups"].as_array().unwrap().len() >= 7);

    // The tracker moved 5 mm along its own x after the calibration: every measured x_mm
    // (instrument frame) is 5 mm off.
    let text = std::fs::read_to_string(&check_data).unwrap();
    let header = text.lines().next().unwrap();
    let x = header.split(',').position(|c| c == "x_mm").unwrap();
    let moved: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == 0 {
                return l.to_string();
            }
            let mut f: Vec<String> = l.split(',').map(String::from).collect();
            f[x] = format!("{:.6}", f[x].parse::<f64>().unwrap() + 5.0);
            f.join(",")
        })
        .collect();
    let moved_path = p("moved.csv");
    std::fs::write(&moved_path, moved.join("\n") + "\n").unwrap();
    let (ok, out, err) = check(&moved_path, &p("moved.json"));
    assert!(ok, "{err}");
    assert!(out.contains(": drifted"), "{out}");
    assert!(out.contains("most likely moved"), "{out}");
    let first = out
        .lines()
        .skip_while(|l| !l.starts_with("most likely moved"))
        .nth(1)
        .unwrap();
    assert!(first.trim_start().starts_with("tracker"), "{out}");

    // With --campaign: a consistent check starts nothing; the drifted one starts a
    // campaign with the old estimate as prior, the tracker released, the check poses its
    // first step, and `campaign status` reads it.
    let with_campaign = |data: &str, out: &str, dir: &str| {
        check_with(data, out, &["--campaign", dir, "--target-sigma-mm", "0.3"])
    };
    let (ok, out, err) = with_campaign(&check_data, &p("c1.json"), &p("none"));
    assert!(ok, "{err}");
    assert!(out.contains("no campaign started"), "{out}");
    assert!(!dir.join("none").exists());
    let (ok, out, err) = with_campaign(&moved_path, &p("c2.json"), &p("again"));
    assert!(ok, "{err}");
    assert!(out.contains("released: tracker"), "{out}");
    assert!(out.contains("step 1: 10 poses measured (+10)"), "{out}");
    let state: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("again/campaign.json")).unwrap())
            .unwrap();
    assert_eq!(state["settings"]["prior"]["released"][0], "tracker");
    assert!(dir.join("again/estimate.json").exists());
    let (ok, out, err) = armcal(&["campaign", "status", &p("again")]);
    assert!(ok, "{err}");
    assert!(out.contains("10"), "{out}");
    eprintln!("{out}");

    // A check file with a broken number: file and line.
    let mut bad: Vec<String> = text.lines().map(String::from).collect();
    bad[3] = bad[3].replacen(',', ",x", 2);
    let bad_path = p("bad.csv");
    std::fs::write(&bad_path, bad.join("\n") + "\n").unwrap();
    let (ok, _, err) = check(&bad_path, &p("bad.json"));
    assert!(!ok);
    assert!(err.contains("bad.csv") && err.contains("line 4"), "{err}");
    assert!(!dir.join("bad.json").exists());
}
