//! `armcal pivot` (issue 30 item 5): touch poses of a known tool tip, with joint noise,
//! give the tip within its stated covariance, and the cell lines state a conservative σ
//! (the fixed priors cannot carry correlations); poses rotating about one axis only are
//! refused with what to do.

use crate::common::{armcal, scratch};
use armcal::model::{forward_kinematics, Data};
use armcal::Cell;
use nalgebra::{Matrix3, Vector3};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

/// The paper robot's arm held at q1..q3 = (5, −40, 60)° with the wrist at `wrist` (deg):
/// the wrist centre does not move, so a tool tip there touches one point. Joint noise of
/// `noise_deg` on q1..q3 (seeded) moves the tip by about 0.2 mm per 0.01°.
fn touch_poses(wrist: &[[f64; 3]], noise_deg: f64, seed: u64) -> String {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let n = Normal::new(0.0, noise_deg).unwrap();
    let mut csv = String::from("pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\n");
    for (i, w) in wrist.iter().enumerate() {
        let arm = [5.0, -40.0, 60.0].map(|q: f64| q + n.sample(&mut rng));
        csv += &format!(
            "t{},{},{},{},{},{},{}\n",
            i + 1,
            arm[0],
            arm[1],
            arm[2],
            w[0],
            w[1],
            w[2]
        );
    }
    csv
}

/// The wrist centre in the paper robot's flange frame (the true tip).
fn true_tip() -> Vector3<f64> {
    let model = Cell::load("paper-650-600").unwrap().model;
    let q: Vec<f64> = [5.0f64, -40.0, 60.0, 0.0, -50.0, 0.0]
        .iter()
        .map(|d| d.to_radians())
        .collect();
    let mut d = Data::new(&model);
    forward_kinematics(&model, &mut d, &model.nominal(), &q);
    let centre = d.frames[model.link_index("j5").unwrap()].trans;
    let flange = d.frames[model.link_index("tool").unwrap() - 1];
    flange.rot.transpose() * (centre - flange.trans)
}

/// Wrist angles (q4, q5, q6 in deg) tilting the flange about several axes.
const WRIST: [[f64; 3]; 7] = [
    [0.0, -50.0, 0.0],
    [40.0, -35.0, 30.0],
    [-40.0, -65.0, -20.0],
    [70.0, -25.0, 80.0],
    [-15.0, 50.0, 45.0],
    [25.0, 35.0, -60.0],
    [-70.0, -75.0, 15.0],
];

#[test]
fn pivot_finds_a_known_tip_within_its_covariance_and_refuses_one_axis() {
    let dir = scratch("pivot_cli");
    let path = |f: &str| dir.join(f).to_str().unwrap().to_string();
    let tip = true_tip();
    let mut inside = 0;
    let seeds = 20;
    for seed in 0..seeds {
        let poses = path(&format!("touch{seed}.csv"));
        std::fs::write(&poses, touch_poses(&WRIST, 0.01, seed)).unwrap();
        let out = path(&format!("pivot{seed}.json"));
        let (ok, stdout, err) =
            armcal(&["pivot", "--cell", "paper", "--poses", &poses, "--out", &out]);
        assert!(ok, "{err}");
        let record: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
        let t = Vector3::from_iterator((0..3).map(|k| record["tool_xyz_mm"][k].as_f64().unwrap()));
        let c: Matrix3<f64> = serde_json::from_value(record["tool_covariance"].clone()).unwrap();
        let e = t - tip;
        // χ²₃ at 99 %: 11.34.
        let d2 = (e.transpose() * c.try_inverse().unwrap() * e)[(0, 0)];
        if d2 <= 11.34 {
            inside += 1;
        }
        // The stated prior: √λ_max of C on each axis, never narrower than C.
        let lmax = c.symmetric_eigen().eigenvalues.max().sqrt();
        assert!(
            stdout.contains(&format!(
                "the cell's fixed_priors carry no correlations: they state σ = √λ_max(C_tool) = {lmax:.4} mm"
            )) && stdout.contains(&format!("\"tool.z\" = {{ sigma_mm = {lmax:.4} }}")),
            "{stdout}"
        );
        assert!(e.norm() > 1e-6, "the noise moved the tip: {e}");
    }
    eprintln!("pivot: {inside} of {seeds} tips inside the stated 99 % ellipsoid");
    // 20 draws at 99 %: at least 18 inside (binomial P(≤ 17) < 0.1 %).
    assert!(
        inside >= 18,
        "{inside} of {seeds} inside the stated 99 % ellipsoid"
    );

    // Rotations about one axis only (q6): the tip along it is not separable.
    let one_axis: Vec<[f64; 3]> = [0.0, 30.0, 60.0, 90.0, 120.0]
        .iter()
        .map(|&q6| [0.0, -60.0, q6])
        .collect();
    let poses = path("one_axis.csv");
    std::fs::write(&poses, touch_poses(&one_axis, 0.0, 0)).unwrap();
    let out = path("one_axis.json");
    let (ok, _, err) = armcal(&["pivot", "--cell", "paper", "--poses", &poses, "--out", &out]);
    assert!(!ok && !std::path::Path::new(&out).exists());
    assert!(
        err.contains("the 5 poses' flange orientations spread too little to separate the tool tip from the touched point")
            && err.contains("about at least two different axes"),
        "{err}"
    );
}
