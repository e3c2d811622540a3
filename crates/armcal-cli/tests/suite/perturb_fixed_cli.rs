//! `armcal simulate --perturb-fixed` (issue 30 item 5): it perturbs the parameters the cell
//! holds fixed by their stated prior (seeded: same seed, same robot; a frame the cell does
//! not give stays exact), and the stated measurement + model-floor ellipsoid covers the true
//! TCP error at the nominal rate where C_s alone does not.

use crate::common::{armcal, scratch};
use armcal::model::{forward_kinematics, observed_position, Data, Observed};
use armcal::{Cell, Estimate, Model};
use nalgebra::{Matrix3, Vector3};
use std::collections::HashMap;

/// The true parameters of a `--truth-out` file by name (display units).
fn truth(path: &str) -> HashMap<String, f64> {
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    record["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            (
                p["name"].as_str().unwrap().to_string(),
                p["truth"].as_f64().unwrap(),
            )
        })
        .collect()
}

/// The TCP (tool origin, instrument frame) of `model` at `params`, `q`.
fn tcp(model: &Model, params: &[f64], q: &[f64]) -> Vector3<f64> {
    let mut d = Data::new(model);
    forward_kinematics(model, &mut d, params, q);
    observed_position(&d, Observed::Tool)
}

#[test]
fn perturb_fixed_draws_the_fixed_parameters_and_the_floor_covers_them() {
    let dir = scratch("perturb_fixed");
    let path = |f: &str| dir.join(f).to_str().unwrap().to_string();
    // A 0.1 mm tracker: the floor (≈ 0.4 mm from j6.a, j6.d) dominates C_s.
    let text = std::fs::read_to_string("../../examples/paper-cell.toml")
        .unwrap()
        .replace("sigma_mm = 1.0", "sigma_mm = 0.1");
    let cell_path = path("cell.toml");
    std::fs::write(&cell_path, &text).unwrap();
    let cell = Cell::from_toml(&text, "perturb-fixed", dir.as_path()).unwrap();
    let model = &cell.model;
    let simulate = |seed: &str, data: &str, truth_out: &str, fixed: bool| {
        let mut args = vec!["simulate", "--cell", &cell_path, "--poses"];
        args.extend(["examples/paper-poses-planned-60.csv", "--seed", seed]);
        args.extend(["--out", data, "--truth-out", truth_out, "--force"]);
        if fixed {
            args.push("--perturb-fixed");
        }
        let (ok, _, err) = armcal(&args);
        assert!(ok, "{err}");
        truth(truth_out)
    };
    let (data, t) = (path("data.csv"), path("truth.json"));
    let plain = simulate("7", &data, &t, false);
    let a = simulate("7", &data, &t, true);
    let b = simulate("7", &data, &t, true);
    let c = simulate("8", &data, &t, true);
    assert_eq!(a, b, "same seed, same robot");
    for name in ["j6.d", "j6.a", "j1.d", "j1.theta"] {
        let nominal = model
            .registry
            .get(model.registry.index_of(name).unwrap())
            .nominal
            * model
                .registry
                .get(model.registry.index_of(name).unwrap())
                .unit
                .display_factor();
        assert!(
            (plain[name] - nominal).abs() < 1e-12,
            "{name} fixed without the flag"
        );
        assert!((a[name] - nominal).abs() > 1e-6, "{name} perturbed with it");
        assert!(
            (a[name] - c[name]).abs() > 1e-6,
            "{name}: another seed, another robot"
        );
    }
    // The tool frame the cell does not give is a definition: exact.
    assert_eq!(a["tool.z"], 0.0);
    // The free parameters are the same draw with or without the flag.
    assert_eq!(a["j2.a"], plain["j2.a"]);

    // Coverage over 20 perturbed robots at the working pose, 95 % ellipsoids (χ²₃ 7.815).
    let work = &cell.working[0].q;
    let (mut with_floor, mut cs_alone) = (0, 0);
    let runs = 20;
    for seed in 0..runs {
        let seed = (100 + seed).to_string();
        let (data, t, est) = (path("d.csv"), path("t.json"), path("e.json"));
        let truth = simulate(&seed, &data, &t, true);
        let (ok, _, err) = armcal(&[
            "identify", "--cell", &cell_path, "--data", &data, "--out", &est, "--force",
        ]);
        assert!(ok, "{err}");
        let estimate: Estimate =
            serde_json::from_str(&std::fs::read_to_string(&est).unwrap()).unwrap();
        let truth: Vec<f64> = model
            .registry
            .iter()
            .map(|p| truth[&p.name] / p.unit.display_factor())
            .collect();
        let e = tcp(model, &estimate.params_for(model).unwrap(), work) - tcp(model, &truth, work);
        let cs = estimate.tcp[0].covariance;
        let floor = estimate.model_floor.as_ref().unwrap().tcp[0].covariance;
        let d2 = |c: Matrix3<f64>| (e.transpose() * c.try_inverse().unwrap() * e)[(0, 0)];
        with_floor += usize::from(d2(cs + floor) <= 7.815);
        cs_alone += usize::from(d2(cs) <= 7.815);
    }
    eprintln!("95 % ellipsoid covers the true TCP error: C_s + C_floor {with_floor} of {runs}, C_s alone {cs_alone}");
    // Binomial(20, 0.95): P(≤ 15) < 0.3 %.
    assert!(
        with_floor >= 16,
        "C_s + C_floor covers {with_floor} of {runs}"
    );
    assert!(
        cs_alone <= 10,
        "C_s alone covers {cs_alone} of {runs}: the fixed parameters did not move"
    );
}
