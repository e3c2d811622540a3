//! `armcal campaign start | step | status` on the paper cell: a step takes exactly the
//! poses of next.csv but those declared unmeasurable (a batch with a pose missing or extra
//! is refused, naming them, and the campaign's files stay as they were), rewrites the state
//! and next.csv, and `status` prints where the campaign stands.

use crate::common::{armcal, scratch};

#[test]
fn a_campaign_steps_through_its_files_and_refuses_a_wrong_batch() {
    let step = |dir: &str, data: &str, extra: &[&str]| {
        let mut args = vec!["campaign", "step", dir, "--data", data];
        args.extend_from_slice(extra);
        armcal(&args)
    };
    let dir = scratch("campaign-cli");
    let c = dir.join("c");
    let c_s = c.to_str().unwrap();
    let next = c.join("next.csv");
    let state = c.join("campaign.json");
    let (ok, out, err) = armcal(&[
        "campaign",
        "start",
        "--cell",
        "examples/paper-cell.toml",
        "--target-sigma-mm",
        "0.7",
        "--out",
        c_s,
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("first batch: 9 poses"), "{out}");
    let batch = dir.join("b1.csv");
    let simulate = |poses: &std::path::Path, out: &std::path::Path| {
        let (ok, _, err) = armcal(&[
            "simulate",
            "--cell",
            "examples/paper-cell.toml",
            "--poses",
            poses.to_str().unwrap(),
            "--seed",
            "3",
            "--out",
            out.to_str().unwrap(),
            "--force",
        ]);
        assert!(ok, "{err}");
    };
    simulate(&next, &batch);

    // A batch with pose 9 left out and a pose 99 in its place is refused.
    let text = std::fs::read_to_string(&batch).unwrap();
    let wrong: String = text
        .lines()
        .map(|l| match l.strip_prefix("9,") {
            Some(rest) => format!("99,{rest}"),
            None => l.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n");
    let wrong_path = dir.join("wrong.csv");
    std::fs::write(&wrong_path, wrong + "\n").unwrap();
    let before = (
        std::fs::read_to_string(&state).unwrap(),
        std::fs::read_to_string(&next).unwrap(),
    );
    let (ok, _, err) = step(c_s, wrong_path.to_str().unwrap(), &[]);
    assert!(!ok);
    assert!(
        err.contains("missing poses 9") && err.contains("poses not in next.csv: 99"),
        "{err}"
    );
    let after = (
        std::fs::read_to_string(&state).unwrap(),
        std::fs::read_to_string(&next).unwrap(),
    );
    assert_eq!(before, after, "a failed step changed the campaign");
    assert!(!c.join("estimate.json").exists());

    // A controller that reports its joints to 0.05°: every q1 0.03° off the plan is refused
    // with the default tolerance (0.01°, named with the flag) and taken with
    // --joint-tolerance-deg 0.05 (in a copy of the campaign, which stays as it was).
    assert!(text.starts_with("pose_id,q1_deg,"));
    let moved: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            let mut f: Vec<String> = l.split(',').map(String::from).collect();
            if i > 0 {
                // towards the inside of the joint range: a pose at a limit stays inside
                let q1 = f[1].parse::<f64>().unwrap();
                f[1] = format!("{}", q1 - 0.03 * q1.signum());
            }
            f.join(",")
        })
        .collect();
    let moved_path = dir.join("moved.csv");
    std::fs::write(&moved_path, moved.join("\n") + "\n").unwrap();
    let moved_s = moved_path.to_str().unwrap();
    let (ok, _, err) = step(c_s, moved_s, &[]);
    assert!(!ok);
    assert!(
        err.contains("joint `q1` is 0.0300 from the planned value")
            && err.contains("--joint-tolerance-deg"),
        "{err}"
    );
    let copy = dir.join("c_copy");
    std::fs::create_dir_all(&copy).unwrap();
    for f in ["campaign.json", "next.csv"] {
        std::fs::copy(c.join(f), copy.join(f)).unwrap();
    }
    let copy_s = copy.to_str().unwrap();
    let (ok, out, err) = step(copy_s, moved_s, &["--joint-tolerance-deg", "0.05"]);
    assert!(ok, "{err}");
    assert!(out.contains("step 1: 9 poses measured"), "{out}");
    let (ok, _, err) = step(copy_s, moved_s, &["--joint-tolerance-deg=-1"]);
    assert!(
        !ok && err.contains("joint tolerance -1: give a number ≥ 0"),
        "{err}"
    );

    // The right batch: a step, a new next.csv of 5 poses numbered on from 10.
    let (ok, out, err) = step(c_s, batch.to_str().unwrap(), &[]);
    assert!(ok, "{err}");
    assert!(out.contains("step 1: 9 poses measured"), "{out}");
    assert!(out.contains("measure the next batch"), "{out}");
    let next_text = std::fs::read_to_string(&next).unwrap();
    let ids: Vec<&str> = next_text
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap())
        .collect();
    assert_eq!(ids, ["10", "11", "12", "13", "14"]);
    assert!(c.join("estimate.json").exists());
    // The same batch again is not the new next.csv.
    let (ok, _, err) = step(c_s, batch.to_str().unwrap(), &[]);
    assert!(!ok);
    assert!(err.contains("missing poses 10, 11, 12, 13, 14"), "{err}");

    let (ok, out, err) = armcal(&["campaign", "status", c_s]);
    assert!(ok, "{err}");
    assert!(out.contains("9 poses measured in 1 steps"), "{out}");
    assert!(out.contains("predicted poses still needed: about"), "{out}");

    // Poses 12 and 13 could not be measured: the batch without them is refused until they
    // are declared (an id not in next.csv is refused too), then taken; the next batch is
    // numbered on after 14, not after the 12 poses measured.
    let b2 = dir.join("b2.csv");
    simulate(&next, &b2);
    let partial: String = std::fs::read_to_string(&b2)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with("12,") && !l.starts_with("13,"))
        .map(|l| format!("{l}\n"))
        .collect();
    let partial_path = dir.join("partial.csv");
    std::fs::write(&partial_path, partial).unwrap();
    let partial_s = partial_path.to_str().unwrap();
    let (ok, _, err) = step(c_s, partial_s, &[]);
    assert!(!ok);
    assert!(
        err.contains("missing poses 12, 13") && err.contains("--unmeasurable"),
        "{err}"
    );
    let (ok, _, err) = step(c_s, partial_s, &["--unmeasurable", "12,13,77"]);
    assert!(
        !ok && err.contains("declared unmeasurable but not in next.csv: 77"),
        "{err}"
    );
    let (ok, out, err) = step(c_s, partial_s, &["--unmeasurable", "12,13"]);
    assert!(ok, "{err}");
    assert!(out.contains("step 2: 12 poses measured (+3)"), "{out}");
    assert!(
        out.contains("not measured (the instrument could not): poses 12, 13"),
        "{out}"
    );
    let ids: Vec<String> = std::fs::read_to_string(&next)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().to_string())
        .collect();
    assert_eq!(ids, ["15", "16", "17", "18", "19"]);
}
