//! `identify --refit frames --estimate E` through the binary, on the UR10 + Leica series:
//! Series B's robot carried over to Series D, and the estimates a refit refuses.

use crate::common::{armcal, identify_paper_cell, scratch, simulate_paper_cell};

const CELL: &str = "examples/ur10-leica-cell.toml";
const B: &str = "data/ipa-ur10-leica/Series_B/measurements_joint_configurations.csv";
const D: &str = "data/ipa-ur10-leica/Series_D/measurements_iso_cubes.csv";

#[test]
fn series_b_robot_refitted_on_series_d_and_the_refusals() {
    let dir = scratch("refit_cli");
    let b = dir.join("b.json").display().to_string();
    let (ok, _, err) = armcal(&[
        "identify", "--cell", CELL, "--data", B, "--quiet", "--out", &b,
    ]);
    assert!(ok, "{err}");
    let d = dir.join("d.json").display().to_string();
    let refit = |estimate: &str, out: &str| {
        armcal(&[
            "identify",
            "--cell",
            CELL,
            "--data",
            D,
            "--holdout",
            "0.3",
            "--refit",
            "frames",
            "--estimate",
            estimate,
            "--quiet",
            "--out",
            out,
        ])
    };
    let (ok, out, err) = refit(&b, &d);
    assert!(ok, "{err}");
    assert!(
        out.contains("frames refit: the 24 robot parameters kept from"),
        "{out}"
    );
    assert!(
        out.contains("frames refitted") && out.contains("orientation"),
        "{out}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&d).unwrap()).unwrap();
    assert_eq!(json["refit"]["estimate"], b.as_str());
    assert!(
        json["validation"]["orientation"]["calibrated"]["rms"]
            .as_f64()
            .unwrap()
            < 0.1
    );
    // The report shows the orientation errors, fitted and held out.
    let report = dir.join("report");
    let (ok, _, err) = armcal(&["report", &d, "--out", report.to_str().unwrap(), "--quiet"]);
    assert!(ok, "{err}");
    let page = std::fs::read_to_string(report.join("report.html")).unwrap();
    assert!(
        page.contains("<td>orientation</td>"),
        "fitted orientation row"
    );
    assert!(page.contains("Orientation error of the held-out pose measurements"));
    assert_eq!(page.matches("RMS (deg)").count(), 2);
    // An estimate of another cell (the paper robot) is refused, naming the file.
    let sim = dir.join("paper.csv").display().to_string();
    assert!(armcal(&simulate_paper_cell("1", &sim)).0);
    let paper = dir.join("paper.json").display().to_string();
    assert!(armcal(&identify_paper_cell(&sim, &["--quiet"], &paper)).0);
    let (ok, _, err) = refit(&paper, &dir.join("x.json").display().to_string());
    assert!(
        !ok && err.contains("paper.json") && err.contains("does not belong"),
        "{err}"
    );
    // --refit needs --estimate.
    let (ok, _, err) = armcal(&[
        "identify", "--cell", CELL, "--data", D, "--refit", "frames", "--out", &d, "--force",
    ]);
    assert!(!ok && err.contains("--estimate"), "{err}");
}
