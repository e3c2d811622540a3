//! `armcal simulate --instrument-offset-mm` (issue 30 item 2), as `campaign simulate`'s:
//! the virtual tracker stands off the cell's position by σ = 20 mm per axis by default, 0
//! places it exactly, its orientation and the robot's draw are unchanged, and a negative
//! distance is refused.

use crate::common::{armcal, scratch};
use std::collections::HashMap;

#[test]
fn simulate_places_the_tracker_off_by_the_stated_sigma() {
    let dir = scratch("instrument_offset");
    let path = |f: &str| dir.join(f).to_str().unwrap().to_string();
    let truth = |seed: &str, offset: Option<&str>| -> HashMap<String, (f64, f64)> {
        let (data, t) = (path("d.csv"), path("t.json"));
        let mut args = vec!["simulate", "--cell", "examples/paper-cell.toml", "--poses"];
        args.extend(["examples/paper-poses-planned-60.csv", "--seed", seed]);
        args.extend(["--out", &data, "--truth-out", &t, "--force"]);
        if let Some(o) = offset {
            args.extend(["--instrument-offset-mm", o]);
        }
        let (ok, _, err) = armcal(&args);
        assert!(ok, "{err}");
        let record: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&t).unwrap()).unwrap();
        record["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| {
                let v = |k: &str| p[k].as_f64().unwrap();
                (
                    p["name"].as_str().unwrap().into(),
                    (v("nominal"), v("truth")),
                )
            })
            .collect()
    };
    let mut squares = Vec::new();
    for seed in 1..=10 {
        let seed = seed.to_string();
        let default = truth(&seed, None);
        let exact = truth(&seed, Some("0"));
        for axis in ["tracker.x", "tracker.y", "tracker.z"] {
            let (nominal, off) = default[axis];
            squares.push((off - nominal).powi(2));
            assert_eq!(exact[axis].1, nominal, "{axis} with 0");
        }
        // Only the tracker's position changes with the flag.
        for (name, (_, t)) in &default {
            if !name.starts_with("tracker.") || name.contains(".r") {
                assert_eq!(exact[name].1, *t, "{name}");
            }
        }
    }
    // 30 draws of N(0, 20²): their RMS lies within ±40 % of 20 mm (far beyond 4 σ of the
    // RMS's own scatter, ≈ 13 %).
    let rms = (squares.iter().sum::<f64>() / squares.len() as f64).sqrt();
    assert!(
        (12.0..28.0).contains(&rms),
        "RMS tracker offset {rms:.2} mm"
    );
    let (ok, _, err) = armcal(&[
        "simulate",
        "--cell",
        "examples/paper-cell.toml",
        "--poses",
        "examples/paper-poses-planned-60.csv",
        "--instrument-offset-mm=-5",
        "--out",
        &path("never.csv"),
    ]);
    assert!(
        !ok && err.contains("--instrument-offset-mm -5: give a magnitude ≥ 0"),
        "{err}"
    );
}
