//! Pivot (tool-tip) calibration against a known truth and its σ against Monte Carlo.

use armcal::identify::pivot_from_flange_poses;
use armcal::model::{forward_kinematics, Data};
use armcal::{pivot_calibration, PivotSettings};
use nalgebra::{Matrix3, Rotation3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use rayon::prelude::*;

/// Poses of the paper robot that move only its wrist (q4, q5, q6) around a fixed arm: the
/// wrist centre (the origin after `j5`, since a4 = a5 = d5 = 0) stays put, so a tool tip at
/// the wrist centre touches one point. Returns the poses, the wrist centre in the world and
/// in the flange frame of the first pose.
fn wrist_poses(
    model: &armcal::Model,
    wrist: &[[f64; 3]],
) -> (Vec<Vec<f64>>, Vector3<f64>, Vector3<f64>) {
    let params = model.nominal();
    let j5 = model.link_index("j5").unwrap();
    let tool = model.link_index("tool").unwrap();
    let poses: Vec<Vec<f64>> = wrist
        .iter()
        .map(|w| {
            [5.0, -40.0, 60.0, w[0], w[1], w[2]]
                .iter()
                .map(|x: &f64| x.to_radians())
                .collect()
        })
        .collect();
    let mut d = Data::new(model);
    forward_kinematics(model, &mut d, &params, &poses[0]);
    let centre = d.frames[j5].trans;
    let flange = d.frames[tool - 1];
    let tip = flange.rot.transpose() * (centre - flange.trans);
    (poses, centre, tip)
}

const WRIST: [[f64; 3]; 8] = [
    [0.0, -60.0, 0.0],
    [30.0, -45.0, 20.0],
    [-30.0, -70.0, -40.0],
    [60.0, -30.0, 90.0],
    [-60.0, -80.0, 10.0],
    [10.0, 40.0, -30.0],
    [-20.0, 60.0, 60.0],
    [45.0, 30.0, -90.0],
];

#[test]
fn pivot_recovers_the_wrist_centre_exactly() {
    let model = armcal::Cell::load("paper-650-600").unwrap().model;
    let (poses, centre, tip) = wrist_poses(&model, &WRIST);
    let p = pivot_calibration(&model, &model.nominal(), &poses, &PivotSettings::default()).unwrap();
    for k in 0..3 {
        assert!(
            (p.tool_xyz_mm[k] - tip[k]).abs() < 1e-8,
            "{:?} vs {tip}",
            p.tool_xyz_mm
        );
        assert!(
            (p.point_xyz_mm[k] - centre[k]).abs() < 1e-8,
            "{:?} vs {centre}",
            p.point_xyz_mm
        );
    }
    assert!(p.residual_sigma_mm < 1e-8);
    // the wrist centre lies 170 mm along the flange axis (j6.d = −170 mm)
    assert!((tip.norm() - 170.0).abs() < 1e-9, "{tip}");
}

#[test]
fn pivot_refuses_poses_about_one_axis() {
    let model = armcal::Cell::load("paper-650-600").unwrap().model;
    let about_q6: Vec<[f64; 3]> = (0..6).map(|k| [0.0, -60.0, 30.0 * k as f64]).collect();
    let (poses, _, _) = wrist_poses(&model, &about_q6);
    let e = pivot_calibration(&model, &model.nominal(), &poses, &PivotSettings::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("spread too little") && e.contains("two different axes"),
        "{e}"
    );
    let two = pivot_calibration(
        &model,
        &model.nominal(),
        &poses[..2],
        &PivotSettings::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(two.contains("at least 3 poses"), "{two}");
}

/// 400 seeded runs with N(0, 0.05² mm²) on every flange position: the stated covariance of
/// the tool tip, σ̂² (AᵀA)⁻¹, against the empirical one (trace within ±15 %), and the mean
/// σ̂ against the true 0.05 mm (±5 %). Fails if the covariance forgets σ̂² or divides ‖r‖² by
/// 3N instead of 3N − 6 (ratio 1.33 with the 8 poses here).
#[test]
fn pivot_sigma_matches_monte_carlo() {
    let t = Vector3::new(12.0, -7.0, 180.0);
    let p = Vector3::new(900.0, 150.0, -300.0);
    let flanges_true: Vec<(Matrix3<f64>, Vector3<f64>)> = WRIST
        .iter()
        .map(|w| {
            let r = Rotation3::from_euler_angles(
                w[0].to_radians(),
                w[1].to_radians() * 0.5,
                w[2].to_radians(),
            )
            .into_inner();
            (r, p - r * t)
        })
        .collect();
    let sigma = 0.05;
    let runs: Vec<(Vector3<f64>, Matrix3<f64>, f64)> = (0..400u64)
        .into_par_iter()
        .map(|seed| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let n = Normal::new(0.0, sigma).unwrap();
            let noisy: Vec<_> = flanges_true
                .iter()
                .map(|(r, f)| {
                    let e =
                        Vector3::new(n.sample(&mut rng), n.sample(&mut rng), n.sample(&mut rng));
                    (*r, f + e)
                })
                .collect();
            let c = pivot_from_flange_poses(&noisy, &PivotSettings::default()).unwrap();
            (
                Vector3::from(c.tool_xyz_mm),
                c.tool_covariance,
                c.residual_sigma_mm,
            )
        })
        .collect();
    let n = runs.len() as f64;
    let mean = runs.iter().fold(Vector3::zeros(), |a, r| a + r.0) / n;
    assert!((mean - t).norm() < 0.01, "mean {mean} vs {t}");
    let emp = runs.iter().fold(Matrix3::zeros(), |a, r| {
        a + (r.0 - mean) * (r.0 - mean).transpose()
    }) / (n - 1.0);
    let stated = runs.iter().fold(Matrix3::zeros(), |a, r| a + r.1) / n;
    let ratio = emp.trace() / stated.trace();
    let mean_sigma = runs.iter().map(|r| r.2).sum::<f64>() / n;
    eprintln!("pivot Monte Carlo: empirical / stated trace {ratio:.3}, mean σ̂ {mean_sigma:.4} mm");
    assert!((0.85..=1.15).contains(&ratio), "ratio {ratio}");
    assert!((mean_sigma / sigma - 1.0).abs() < 0.05, "σ̂ {mean_sigma}");
}
