//! `armcal simulate` and `armcal identify` of a tree cell (issue 32): the dual-arm example
//! measured arm by arm, fitted as one tree; what a tree fit and a tree estimate refuse.

use crate::common::{armcal, scratch};

/// Poses of the dual-arm example: every tree joint (torso, right arm, left arm), degrees.
fn poses(n: usize, seed: u64) -> String {
    let joints = [
        "torso", "r_s", "r_l", "r_u", "r_r", "r_b", "r_t", "l_s", "l_l", "l_u", "l_r", "l_b", "l_t",
    ];
    let mut text = String::from("pose_id");
    for j in joints {
        text += &format!(",{j}_deg");
    }
    text.push('\n');
    // a small deterministic pseudo-random walk within ±60° (the limits are ±110° or wider)
    let mut x = seed;
    for i in 0..n {
        text += &format!("{}", i + 1);
        for _ in joints {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let u = (x >> 11) as f64 / (1u64 << 53) as f64;
            text += &format!(",{:.3}", 120.0 * u - 60.0);
        }
        text.push('\n');
    }
    text
}

#[test]
fn a_dual_arm_tree_measured_arm_by_arm_is_fitted_as_one_tree() {
    let dir = scratch("tree-cli");
    let cell = "examples/dual-arm-tree-cell.toml";
    let mut files = Vec::new();
    for (arm, target, seed) in [("right", "smr_r", 3), ("left", "smr_l", 4)] {
        let p = dir.join(format!("{arm}-poses.csv"));
        std::fs::write(&p, poses(40, seed)).unwrap();
        let out = dir.join(format!("{arm}.csv"));
        let (ok, stdout, stderr) = armcal(&[
            "simulate",
            "--cell",
            cell,
            "--poses",
            p.to_str().unwrap(),
            "--target",
            target,
            "--seed",
            "5",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(ok, "{stderr}");
        assert!(stdout.contains("simulated 40 measurements"), "{stdout}");
        let text = std::fs::read_to_string(&out).unwrap();
        assert!(text.lines().next().unwrap().contains(",target,"), "{text}");
        files.push(out);
    }
    let est = dir.join("tree.json");
    let (ok, stdout, stderr) = armcal(&[
        "identify",
        "--cell",
        cell,
        "--data",
        files[0].to_str().unwrap(),
        "--data",
        files[1].to_str().unwrap(),
        "--holdout",
        "0.25",
        "--quiet",
        "--out",
        est.to_str().unwrap(),
    ]);
    assert!(ok, "{stdout}\n{stderr}");
    assert!(
        stdout.contains("(a tree): 60 measurements at 60 configurations"),
        "{stdout}"
    );
    for t in ["smr_r", "smr_l"] {
        let line = stdout
            .lines()
            .find(|l| l.trim_start().starts_with(&format!("{t} ")))
            .unwrap();
        // held-out RMS of the calibrated tree at the noise level (σ 0.05 mm), far below the
        // frames-only model's
        let nums: Vec<f64> = line
            .split(|c: char| c.is_whitespace() || c == '/')
            .filter_map(|w| w.parse().ok())
            .collect();
        assert_eq!(nums.len(), 5, "{line}");
        assert!(nums[2] < 0.15 && nums[4] > 3.0 * nums[2], "{line}");
    }
    let json = std::fs::read_to_string(&est).unwrap();
    assert!(json.contains("\"kind\": \"tree-estimate\""));
    // a tree estimate is refused by the commands that read a serial one, by name
    let (ok, _, stderr) = armcal(&[
        "predict",
        "--cell",
        "examples/paper-cell.toml",
        "--estimate",
        est.to_str().unwrap(),
        "--joints",
        "examples/paper-poses-planned-60.csv",
        "--out",
        dir.join("p.csv").to_str().unwrap(),
    ]);
    assert!(!ok);
    assert!(
        stderr.contains("the estimate of a kinematic tree"),
        "{stderr}"
    );
    // what a tree fit does not take yet is refused by name
    let (ok, _, stderr) = armcal(&[
        "identify",
        "--cell",
        cell,
        "--data",
        files[0].to_str().unwrap(),
        "--method",
        "kalman",
        "--out",
        dir.join("k.json").to_str().unwrap(),
    ]);
    assert!(!ok);
    assert!(
        stderr.contains("does not take the Kalman filter"),
        "{stderr}"
    );
    // a file of one arm given by target name
    let (ok, stdout, stderr) = armcal(&[
        "identify",
        "--cell",
        cell,
        "--data",
        &format!("smr_r={}", files[0].display()),
        "--quiet",
        "--out",
        dir.join("right.json").to_str().unwrap(),
    ]);
    assert!(ok, "{stdout}\n{stderr}");
    // the tree estimate exported: one URDF file of the whole tree, and a tree cell that the
    // tree commands read back
    let urdf = dir.join("tree.urdf");
    let (ok, stdout, stderr) = armcal(&[
        "export",
        "--estimate",
        est.to_str().unwrap(),
        "--format",
        "urdf",
        "--out",
        urdf.to_str().unwrap(),
    ]);
    assert!(ok, "{stdout}\n{stderr}");
    assert!(stderr.contains("instrument frame `tracker`"), "{stderr}");
    let xml = std::fs::read_to_string(&urdf).unwrap();
    for j in ["torso", "r_t", "l_t", "smr_r_fixed", "smr_l_fixed"] {
        assert!(xml.contains(&format!("name=\"{j}\"")), "{j}: {xml}");
    }
    let exported = dir.join("tree-cell.toml");
    let (ok, stdout, stderr) = armcal(&[
        "export",
        "--estimate",
        est.to_str().unwrap(),
        "--format",
        "cell",
        "--cell",
        cell,
        "--out",
        exported.to_str().unwrap(),
    ]);
    assert!(ok, "{stdout}\n{stderr}");
    let (ok, stdout, stderr) = armcal(&["model", exported.to_str().unwrap()]);
    assert!(ok, "{stdout}\n{stderr}");
    assert!(
        stdout.contains("smr_r") && stdout.contains("smr_l"),
        "{stdout}"
    );
    // a serial format is refused for a tree, by name
    let (ok, _, stderr) = armcal(&[
        "export",
        "--estimate",
        est.to_str().unwrap(),
        "--format",
        "dh",
        "--out",
        dir.join("tree-dh.toml").to_str().unwrap(),
    ]);
    assert!(!ok);
    assert!(
        stderr.contains("a tree exports as `urdf`") && !dir.join("tree-dh.toml").exists(),
        "{stderr}"
    );
}

#[test]
fn a_urdf_with_a_mimic_joint_is_a_tree_cell() {
    let (ok, stdout, stderr) = armcal(&["model", "examples/dual-arm-urdf-tree-cell.toml"]);
    assert!(ok, "{stdout}\n{stderr}");
    assert!(stdout.contains("torso_level"), "{stdout}");
}
