//! `armcal deploy` (the alias of `export`) writes the vendor files of issue 33: each file is
//! written, says what it does not hold on the terminal and in the file, and the conservative
//! URDF lists the corrections it dropped with `--k-sigma`.

use crate::common::{armcal, paper_estimate, scratch};

#[test]
fn deploy_writes_every_vendor_format_and_says_what_it_leaves_out() {
    let dir = scratch("deploy_cli");
    let (_, est) = paper_estimate();
    let out = |f: &str| dir.join(f).to_str().unwrap().to_string();
    for (format, file, needle) in [
        ("urdf-calibration", "cal.urdf", "<calibration rising="),
        ("ros-params", "corrections.yaml", "ros__parameters:"),
    ] {
        let (ok, stdout, err) = armcal(&[
            "deploy",
            "--estimate",
            est,
            "--format",
            format,
            "--out",
            &out(file),
        ]);
        assert!(ok, "{format}: {err}");
        assert!(stdout.contains(&out(file)), "{stdout}");
        let text = std::fs::read_to_string(out(file)).unwrap();
        assert!(text.contains(needle), "{format}: {text}");
    }
    // The UR file: the hash is not the controller's, and every "not held" line of the
    // terminal is in the file.
    let (ok, _, err) = armcal(&[
        "deploy",
        "--estimate",
        est,
        "--format",
        "ur-yaml",
        "--out",
        &out("ur.yaml"),
    ]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(out("ur.yaml")).unwrap();
    assert!(
        text.contains("kinematics:") && text.contains("NOT the controller's"),
        "{text}"
    );
    for line in err
        .lines()
        .filter_map(|l| l.strip_prefix("warning: not held: "))
    {
        assert!(
            text.contains(&format!("# not held: {line}")),
            "{line}\n{text}"
        );
    }
    // Conservative: a large k drops corrections, each listed with its σ.
    let (ok, _, err) = armcal(&[
        "export",
        "--estimate",
        est,
        "--format",
        "urdf-conservative",
        "--k-sigma",
        "1000",
        "--out",
        &out("cons.urdf"),
    ]);
    assert!(ok, "{err}");
    assert!(
        err.contains("note: conservative: kept the corrections beyond 1000 σ"),
        "{err}"
    );
    let dropped = err
        .lines()
        .filter(|l| l.starts_with("note: dropped "))
        .count();
    assert!(dropped > 5, "{err}");
    let text = std::fs::read_to_string(out("cons.urdf")).unwrap();
    assert_eq!(text.matches("<!-- dropped ").count(), dropped, "{text}");
}
