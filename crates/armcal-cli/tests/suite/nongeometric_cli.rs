//! Non-geometric terms on the command line (issue 14): `simulate` draws a truth with
//! compliance and periodic errors at the magnitudes its flags give.

use crate::common::*;
use serde_json::Value;
use std::path::Path;

/// The paper cell with compliance on `q2`, `q3` and periodic errors on `q1`–`q3`, in `dir`.
fn nongeometric_cell(dir: &Path) -> String {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper-cell.toml"),
    )
    .unwrap()
    .replace(
        "measurement = \"position\"",
        "measurement = \"position\"\ncompliance = [\"q2\", \"q3\"]\n\
         periodic = { joints = [\"q1\", \"q2\", \"q3\"], harmonics = [1, 2] }",
    );
    let path = dir.join("cell.toml");
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

/// The true values (display units) of the parameters whose unit is `unit`.
fn truth_of(file: &Path, unit: &str) -> Vec<(String, f64)> {
    let v: Value = serde_json::from_str(&std::fs::read_to_string(file).unwrap()).unwrap();
    v["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|p| p["unit"] == unit)
        .map(|p| {
            (
                p["name"].as_str().unwrap().into(),
                p["truth"].as_f64().unwrap(),
            )
        })
        .collect()
}

#[test]
fn simulate_draws_compliance_and_periodic_errors_at_the_given_magnitudes() {
    let dir = scratch("nongeometric-simulate");
    let cell = nongeometric_cell(&dir);
    let run = |tag: &str, kappa: &str, arcsec: &str| {
        let (out, truth) = (
            dir.join(format!("{tag}.csv")),
            dir.join(format!("{tag}.json")),
        );
        let (ok, stdout, stderr) = armcal(&[
            "simulate",
            "--cell",
            &cell,
            "--poses",
            "examples/paper-poses-planned-60.csv",
            "--seed",
            "7",
            "--perturb-urad-per-m",
            kappa,
            "--perturb-arcsec",
            arcsec,
            "--allow-unmeasurable",
            "--out",
            out.to_str().unwrap(),
            "--truth-out",
            truth.to_str().unwrap(),
        ]);
        assert!(ok, "{stdout}{stderr}");
        (truth_of(&truth, "µrad/m"), truth_of(&truth, "arcsec"))
    };
    let (k1, p1) = run("one", "500", "30");
    let (k2, p2) = run("two", "1000", "60");
    assert_eq!(k1.len(), 3, "{k1:?}");
    assert_eq!(p1.len(), 12, "{p1:?}");
    // a sagging arm: every free κ > 0; a free amplitude of 30″-class magnitude
    let drawn = |v: &[(String, f64)]| v.iter().filter(|x| x.1 != 0.0).count();
    assert!(k1.iter().all(|x| x.1 >= 0.0) && drawn(&k1) >= 2, "{k1:?}");
    assert!(drawn(&p1) >= 10, "{p1:?}");
    assert!(p1.iter().all(|x| x.1.abs() < 5.0 * 30.0), "{p1:?}");
    // same seed, twice the σ: every drawn value doubles (nominal 0)
    for (a, b) in k1.iter().zip(&k2).chain(p1.iter().zip(&p2)) {
        assert!(
            (2.0 * a.1 - b.1).abs() <= 1e-9 * b.1.abs().max(1.0),
            "{a:?} {b:?}"
        );
    }
    let (ok, _, stderr) = armcal(&[
        "simulate",
        "--cell",
        &cell,
        "--poses",
        "examples/paper-poses-planned-60.csv",
        "--perturb-arcsec=-1",
        "--out",
        dir.join("bad.csv").to_str().unwrap(),
    ]);
    assert!(!ok && stderr.contains("--perturb-arcsec"), "{stderr}");
}

/// On a strongly compliant truth (2000 µrad/m, no periodic error, noise-free: the cell's
/// σ = 1 mm would hide the sag) `--nongeometric auto`
/// keeps the compliance, prints every candidate's cross-validated table and records it;
/// `--nongeometric none` leaves every term out with its reason.
#[test]
fn identify_chooses_the_nongeometric_terms_by_cross_validation() {
    let dir = scratch("nongeometric-identify");
    let cell = nongeometric_cell(&dir);
    let data = dir.join("data.csv");
    let (ok, stdout, stderr) = armcal(&[
        "simulate",
        "--cell",
        &cell,
        "--poses",
        "examples/paper-pool-500.csv",
        "--seed",
        "3",
        "--perturb-urad-per-m",
        "2000",
        "--perturb-arcsec",
        "0",
        "--noise-free",
        "--allow-unmeasurable",
        "--out",
        data.to_str().unwrap(),
    ]);
    assert!(ok, "{stdout}{stderr}");
    let identify = |options: &[&str], out: &Path| {
        let mut args = vec![
            "identify",
            "--cell",
            &cell,
            "--data",
            data.to_str().unwrap(),
        ];
        args.extend_from_slice(options);
        args.extend(["--quiet", "--out", out.to_str().unwrap()]);
        let (ok, stdout, stderr) = armcal(&args);
        assert!(ok, "{stdout}{stderr}");
        stdout
    };
    let out = dir.join("auto.json");
    let stdout = identify(
        &["--holdout", "0.3", "--nongeometric", "auto", "--folds", "4"],
        &out,
    );
    assert!(
        stdout.contains("4-fold cross-validation") && stdout.contains("+ compliance + periodic"),
        "{stdout}"
    );
    let chosen = stdout
        .lines()
        .find(|l| l.contains("← chosen"))
        .unwrap_or_else(|| panic!("{stdout}"));
    assert!(chosen.contains("+ compliance"), "{chosen}");
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let c = &v["nongeometric_choice"];
    assert_eq!(c["candidates"].as_array().unwrap().len(), 4, "{c}");
    let rms = |k: usize| c["candidates"][k]["held_out"]["rms"].as_f64().unwrap();
    assert!(rms(1) < 0.5 * rms(0), "compliance pays: {c}");
    let stdout = identify(&["--nongeometric", "none"], &dir.join("none.json"));
    assert!(
        stdout.contains("`q2.compliance.elbow` left out: the non-geometric model is `kinematic`"),
        "{stdout}"
    );
}
