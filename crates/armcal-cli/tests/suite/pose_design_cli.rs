//! A full-pose cell is planned and evaluated with the rows identification fits (issue 30):
//! the UR10 + Leica T-Mac cell exported after a fit of series B (`export --cell … --format
//! cell`, `measurement = "pose"`, the tool's orientation free) plans — it failed with
//! "`tool.rx` has no effect" when the design measured positions only — and the parameter
//! covariance its design predicts is the one `identify` reports when the planned poses are
//! simulated on the nominal robot (noise-free: the fit stops at the truth, where Gauss–Newton's
//! covariance is the design's inverse information; `identify` does not rescale it by σ̂₀²).

use crate::common::{armcal, identify_cell, scratch};
use serde_json::Value;

/// The UR10 cell fitted to series B and exported, with a working pose added: its path.
fn exported_ur10_cell(dir: &std::path::Path) -> (String, String) {
    let path = |f: &str| dir.join(f).to_str().unwrap().to_string();
    let (est, exported) = (path("b.json"), path("exported.toml"));
    let (ok, _, err) = armcal(&identify_cell(
        "examples/ur10-leica-cell.toml",
        "data/ipa-ur10-leica/Series_B/measurements_joint_configurations.csv",
        &["--holdout", "0.3", "--seed", "1", "--quiet"],
        &est,
    ));
    assert!(ok, "{err}");
    let (ok, _, err) = armcal(&[
        "export",
        "--estimate",
        &est,
        "--cell",
        "examples/ur10-leica-cell.toml",
        "--format",
        "cell",
        "--out",
        &exported,
    ]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&exported).unwrap();
    assert!(text.contains("measurement = \"pose\""), "{text}");
    let working = path("exported-working.toml");
    std::fs::write(
        &working,
        text + "\n[[working]]\nname = \"w\"\njoints_deg = [30, -60, 90, -120, -90, 0]\n",
    )
    .unwrap();
    (exported, working)
}

fn json(path: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn an_exported_full_pose_cell_plans_as_identify_fits() {
    let dir = scratch("pose_design_cli");
    let path = |f: &str| dir.join(f).to_str().unwrap().to_string();
    let (exported, cell) = exported_ur10_cell(&dir);
    // The export as it is (no working pose): a D-optimal plan.
    let (ok, out, err) = armcal(&[
        "plan",
        "--cell",
        &exported,
        "--poses",
        "30",
        "--criterion",
        "d",
        "--out",
        &path("d.csv"),
        "--quiet",
    ]);
    assert!(ok, "{out}{err}");
    // With a working pose: the KPI plan, its C_s and the TCP orientation's beside it.
    let (design, report) = (path("design.csv"), path("design.json"));
    let (ok, out, err) = armcal(&[
        "plan", "--cell", &cell, "--poses", "30", "--out", &design, "--quiet",
    ]);
    assert!(ok, "{out}{err}");
    assert!(out.contains("orientation (1/3) tr C_ω = "), "{out}");
    let planned = json(&report);
    let assessment = &planned["assessment"];
    let tcp = &assessment["tcp"][0];
    assert!(tcp["orientation_kpi_deg2"].as_f64().unwrap() > 0.0, "{tcp}");
    let (ok, out, err) = armcal(&["evaluate", "--cell", &cell, "--design", &design]);
    assert!(ok, "{out}{err}");
    assert!(out.contains("orientation (1/3) tr C_ω = "), "{out}");
    // The planned poses measured on the nominal robot without noise, and identified.
    let (data, est) = (path("sim.csv"), path("est.json"));
    let (ok, _, err) = armcal(&[
        "simulate",
        "--cell",
        &cell,
        "--poses",
        &design,
        "--perturb-mm",
        "0",
        "--perturb-deg",
        "0",
        "--instrument-offset-mm",
        "0",
        "--noise-free",
        "--out",
        &data,
    ]);
    assert!(ok, "{err}");
    let (ok, out, err) = armcal(&identify_cell(&cell, &data, &["--quiet"], &est));
    assert!(ok, "{out}{err}");
    let fitted = json(&est);
    let free: Vec<&Value> = fitted["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|p| p["free"].as_bool().unwrap())
        .collect();
    let names: Vec<&str> = free.iter().map(|p| p["name"].as_str().unwrap()).collect();
    let designed: Vec<&str> = assessment["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p.as_str().unwrap())
        .collect();
    assert_eq!(names, designed, "the free sets");
    assert!(names.contains(&"tool.rx"));
    // The design file holds the poses to 1e-6°; the covariances agree to that.
    for (p, s) in free.iter().zip(assessment["sigma"].as_array().unwrap()) {
        let to_display = match p["unit"].as_str().unwrap() {
            "deg" => 1f64.to_degrees(),
            _ => 1.0,
        };
        let (fit, predicted) = (
            p["sigma"].as_f64().unwrap(),
            s.as_f64().unwrap() * to_display,
        );
        assert!(
            (fit / predicted - 1.0).abs() < 1e-6,
            "{}: σ {fit} identified, {predicted} predicted",
            p["name"]
        );
    }
    let (fit, predicted) = (
        fitted["tcp"][0]["kpi"].as_f64().unwrap(),
        tcp["kpi"].as_f64().unwrap(),
    );
    assert!(
        (fit / predicted - 1.0).abs() < 1e-6,
        "C_s {fit} vs {predicted}"
    );
}

/// The UR10 export measuring positions, where every start's refinement is rejected (near
/// rank deficient: column-normalised singular-value ratio 1.5e-5–9.6e-5 < 1e-4 in the
/// j5.d/j5.alpha and j5.a/j5.theta directions): planned at σ = 1 mm and at σ = 1/16 mm (a
/// power of two, so every intermediate scales exactly), the design is the same bit for bit,
/// the rejection the same, and the value scales by exactly (1/16)² — nothing in the planner
/// compares a σ-dependent quantity with an absolute threshold.
#[test]
fn the_ur10_position_plan_does_not_depend_on_the_noise_scale() {
    let dir = scratch("pose_design_cli_scale");
    let path = |f: &str| dir.join(f).to_str().unwrap().to_string();
    let (_, cell) = exported_ur10_cell(&dir);
    let text = std::fs::read_to_string(&cell)
        .unwrap()
        .replace("measurement = \"pose\"", "measurement = \"position\"");
    let noise = "sigma_mm = [1.0, 1.0, 1.0]";
    assert!(text.contains(noise), "{text}");
    let mut plans = Vec::new();
    for (name, sigma) in [("one", "1.0"), ("sixteenth", "0.0625")] {
        let cell = path(&format!("{name}.toml"));
        let s = format!("sigma_mm = [{sigma}, {sigma}, {sigma}]");
        std::fs::write(&cell, text.replace(noise, &s)).unwrap();
        let design = path(&format!("{name}.csv"));
        let (ok, out, err) = armcal(&[
            "plan", "--cell", &cell, "--poses", "30", "--out", &design, "--quiet",
        ]);
        assert!(ok, "{out}{err}");
        plans.push(json(&path(&format!("{name}.json"))));
    }
    let (a, b) = (&plans[0], &plans[1]);
    assert_eq!(a["poses"], b["poses"]);
    assert_eq!(a["plan"]["refine_status"], b["plan"]["refine_status"]);
    let status = a["plan"]["refine_status"].as_str().unwrap();
    assert!(status.contains("rejected"), "{status}");
    let value = |p: &Value| p["plan"]["value"].as_f64().unwrap();
    assert_eq!(value(b), value(a) / 256.0);
}
