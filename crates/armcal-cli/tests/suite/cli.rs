//! The `armcal` binary end to end.

use crate::common;
use common::{armcal, scratch};

#[test]
fn model_of_the_paper_cell_reports_27_identifiable_parameters_with_reasons() {
    let (ok, out, err) = armcal(&["model", "examples/paper-cell.toml"]);
    assert!(ok, "{err}");
    assert!(
        out.contains("identifiable: 27 geometric parameters at these random"),
        "{out}"
    );
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

#[test]
fn model_converts_to_another_convention_before_the_analysis() {
    // The row of a parameter in the table: `<#> <name> <nominal> <unit> <status>`.
    let row = |out: &str, name: &str| -> Option<String> {
        out.lines()
            .find(|l| l.split_whitespace().nth(1) == Some(name))
            .map(str::to_string)
    };
    let (ok, out, err) = armcal(&["model", "puma560", "--convention", "zrp"]);
    assert!(ok, "{err}");
    assert!(out.contains("converted to zrp"), "{out}");
    for p in [
        "base.x",
        "j1.ux",
        "j1.uy",
        "j1.uz",
        "j1.px",
        "j1.py",
        "j1.pz",
        "j1.offset",
        "j6.offset",
        "tool.rz",
    ] {
        assert!(row(&out, p).is_some(), "{p} missing:\n{out}");
    }
    // The DH-family fields of `puma560` are gone.
    for p in ["j2.beta", "j6.dz", "base.theta"] {
        assert!(row(&out, p).is_none(), "{p} still there:\n{out}");
    }
    // Forward kinematics are unchanged, so a full pose still identifies 4R + 6 = 30.
    assert!(
        out.contains("identifiable: 30 geometric parameters at these random"),
        "{out}"
    );

    let (ok, out, err) = armcal(&["model", "puma560", "--convention", "dh"]);
    assert!(ok, "{err}");
    assert!(out.contains("converted to dh"), "{out}");
    for p in [
        "base.theta",
        "base.d",
        "base.a",
        "base.alpha",
        "j2.theta",
        "j2.d",
        "j2.a",
        "j2.alpha",
        "j6.theta",
        "tool.x",
    ] {
        assert!(row(&out, p).is_some(), "{p} missing:\n{out}");
    }
    for p in ["j2.beta", "j6.dz", "j1.ux"] {
        assert!(row(&out, p).is_none(), "{p} still there:\n{out}");
    }
    // Standard DH cannot describe a tilt of the parallel axes 2 and 3 and has their d's
    // dependent (book §2.6, the reason for Table 6.1's Hayati link): one parameter short.
    assert!(
        out.contains("identifiable: 29 geometric parameters at these random"),
        "{out}"
    );
    assert!(
        out.contains("- `j3.d` cannot be separated from `j2.d`"),
        "{out}"
    );

    let (ok, out, err) = armcal(&["model", "puma560", "--convention", "mdh", "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["convention"], "mdh");
    assert_eq!(v["parameters"].as_array().unwrap().len(), 4 + 6 * 4 + 6);

    let (ok, _, err) = armcal(&["model", "puma560", "--convention", "urdf"]);
    assert!(!ok);
    assert!(err.contains("dh") && err.contains("zrp"), "{err}");
}

/// `armcal … | head -1`: a closed stdout ends the command quietly (no panic, no exit 101).
/// The read end is closed before armcal has started, so its first write meets a closed pipe.
#[cfg(unix)]
#[test]
fn a_closed_stdout_is_not_a_crash() {
    use std::io::Read;
    use std::os::unix::process::ExitStatusExt;
    use std::process::{Command, Stdio};
    for args in [
        vec!["robots"],
        vec!["fk", "paper", "--joints", "0,10,20,0,30,0"],
        vec!["model", "examples/paper-cell.toml"],
    ] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_armcal"))
            .args(&args)
            .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("run armcal");
        drop(child.stdout.take());
        let mut err = String::new();
        child
            .stderr
            .take()
            .unwrap()
            .read_to_string(&mut err)
            .unwrap();
        let status = child.wait().unwrap();
        assert!(
            !err.contains("panicked") && status.code() != Some(101),
            "armcal {args:?} with a closed stdout: {status:?}, stderr: {err}"
        );
        assert!(
            status.success() || status.signal() == Some(libc::SIGPIPE),
            "armcal {args:?} ended with {status:?}: {err}"
        );
    }
}

/// A built-in robot whose capsules meet at every configuration (the IRB 120's upper arm and
/// forearm at its short elbow link) is planned for with collision avoidance: the pair is left
/// out and named, every other constraint holds.
#[test]
fn plan_names_the_capsule_pairs_in_contact_everywhere_and_plans_around_the_rest() {
    let dir = scratch("plan-irb120");
    let cell = dir.join("cell.toml");
    std::fs::write(
        &cell,
        "name = \"irb120-cell\"\n[robot]\nbuiltin = \"irb120\"\n\n[instrument]\nname = \"tracker\"\n\
         kind = \"laser-tracker\"\nxyz_mm = [2000.0, 500.0, 300.0]\nrpy_deg = [0, 0, 180]\n\
         noise = { model = \"constant\", sigma_mm = 0.05 }\nmax_incidence_deg = 40\n\n\
         [[targets]]\nname = \"smr1\"\nxyz_mm = [0.0, 0.0, 60.0]\n\n[parameters]\n\
         fixed = [\"base\", \"tool\"]\nfree = \"auto\"\nmeasurement = \"position\"\n\n\
         [[working]]\nname = \"pick\"\njoints_deg = [0, 20, 10, 0, 60, 0]\n",
    )
    .unwrap();
    let out = dir.join("design.csv");
    let (ok, stdout, err) = armcal(&[
        "plan",
        "--cell",
        cell.to_str().unwrap(),
        "--poses",
        "30",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(stdout.contains("every pose feasible"), "{stdout}");
    assert!(
        stdout.contains("not checked, in contact at every sampled configuration (shorten a capsule to check them): capsule j2#0 / j4#0"),
        "{stdout}"
    );
    assert!(
        stdout.contains("self-collision"),
        "the other pairs are checked:\n{stdout}"
    );
    // A 0.05 mm tracker: the variance is about 1e-4 mm² and keeps 3 significant digits.
    let kpi = stdout
        .lines()
        .find_map(|l| l.strip_prefix("(1/3) tr C_s at `pick`: "))
        .and_then(|l| l.split_once(" mm²").map(|(v, _)| v))
        .unwrap_or_else(|| panic!("no C_s line:\n{stdout}"));
    let digits = kpi.trim_start_matches(['0', '.']).len();
    assert!(kpi.parse::<f64>().unwrap() < 1e-3 && digits >= 3, "{kpi}");
}

/// A cell with two working poses: `plan` states the TCP variance at each, not at the first
/// alone (the second, weighted double here, was once left off the screen).
#[test]
fn plan_prints_the_tcp_variance_at_every_working_pose() {
    let dir = scratch("plan-two-working-poses");
    let cell = dir.join("cell.toml");
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/paper-cell.toml"
    ))
    .unwrap()
        + "\n[[working]]\nname = \"pick\"\njoints_deg = [30, -60, 70, 10, 40, 0]\nweight = 2\n";
    std::fs::write(&cell, text).unwrap();
    let out = dir.join("design.csv");
    let (ok, stdout, err) = armcal(&[
        "plan",
        "--cell",
        cell.to_str().unwrap(),
        "--collisions",
        "off",
        "--poses",
        "20",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    for name in ["q_work", "pick"] {
        assert!(
            stdout.contains(&format!("(1/3) tr C_s at `{name}`:")),
            "{name} missing:\n{stdout}"
        );
    }
}
