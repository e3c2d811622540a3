//! `armcal predict` with an estimate gives each row's 1-σ (issue 30 item 7): the σ of the
//! row's predicted point and of the TCP from the estimate's C_p, checked against a Monte
//! Carlo of the model at parameters drawn from C_p, and the model floor beside it, equal to
//! the floor `identify` states at the working pose (Monte-Carlo-checked in the library's
//! `identify/model_floor.rs`).

use crate::common::{armcal, scratch, simulate_and_identify_variant};
use armcal::model::{forward_kinematics, observed_position, Data, Observed};
use armcal::{Cell, Estimate, Model};
use nalgebra::{DVector, Matrix3, Vector3};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use std::collections::HashMap;

/// The CSV `text` as one map column → value per row.
fn rows(text: &str) -> Vec<HashMap<String, String>> {
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    lines
        .map(|l| {
            header
                .iter()
                .cloned()
                .zip(l.split(',').map(String::from))
                .collect()
        })
        .collect()
}

/// √((1/3) tr) of the sample covariance of `points`.
fn rms_sigma(points: &[Vector3<f64>]) -> f64 {
    let n = points.len() as f64;
    let mean = points.iter().sum::<Vector3<f64>>() / n;
    let c: Matrix3<f64> = points
        .iter()
        .map(|p| (p - mean) * (p - mean).transpose())
        .sum::<Matrix3<f64>>()
        / (n - 1.0);
    (c.trace() / 3.0).sqrt()
}

/// `runs` parameter sets drawn from N(p̂, C_p) over the estimate's free parameters
/// (seeded), the others at the estimate.
fn parameter_draws(model: &Model, estimate: &Estimate, runs: usize) -> Vec<Vec<f64>> {
    let params = estimate.params_for(model).unwrap();
    let free: Vec<usize> = estimate
        .free
        .iter()
        .map(|n| model.registry.index_of(n).unwrap())
        .collect();
    let l = estimate
        .uncertainty
        .covariance
        .clone()
        .cholesky()
        .unwrap()
        .l();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(17);
    (0..runs)
        .map(|_| {
            let z: DVector<f64> =
                DVector::from_fn(free.len(), |_, _| StandardNormal.sample(&mut rng));
            let dp = &l * z;
            let mut p = params.clone();
            for (c, &i) in free.iter().enumerate() {
                p[i] += dp[c];
            }
            p
        })
        .collect()
}

/// The spread of the target's and the TCP's positions at `q` over `runs` parameter sets
/// drawn from C_p ([`parameter_draws`]).
fn monte_carlo(model: &Model, estimate: &Estimate, q: &[f64], runs: usize) -> (f64, f64) {
    let mut data = Data::new(model);
    let (mut target, mut tcp) = (Vec::new(), Vec::new());
    for p in parameter_draws(model, estimate, runs) {
        forward_kinematics(model, &mut data, &p, q);
        target.push(observed_position(&data, Observed::Target(0)));
        tcp.push(observed_position(&data, Observed::Tool));
    }
    (rms_sigma(&target), rms_sigma(&tcp))
}

#[test]
fn predict_states_each_rows_sigma_as_monte_carlo_and_identify_give_it() {
    let dir = scratch("predict_sigma");
    let path = |f: &str| dir.join(f).to_str().unwrap().to_string();
    // The paper cell with its working pose inside the joint limits (predict refuses a
    // configuration outside them), so that predict can be asked at it.
    let text = std::fs::read_to_string("../../examples/paper-cell.toml")
        .unwrap()
        .replace(
            "joints_deg = [0, -30, 30, 0, -90, 0]",
            "joints_deg = [0, -30, 30, 0, -80, 0]",
        );
    let [cell_path, _, est] = simulate_and_identify_variant(&dir, &text, "5", false);
    let joints = path("joints.csv");
    std::fs::write(
        &joints,
        "pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\n\
         work,0,-30,30,0,-80,0\nside,60,10,20,-120,30,45\n",
    )
    .unwrap();
    let out = path("predicted.csv");
    let (ok, stdout, err) = armcal(&[
        "predict",
        "--cell",
        &cell_path,
        "--estimate",
        &est,
        "--joints",
        &joints,
        "--out",
        &out,
    ]);
    assert!(ok, "{err}");
    assert!(
        stdout.contains("σ of each row from the estimate's C_p (sigma_mm): largest ")
            && stdout.contains("with the model floor of the fixed parameters (total_sigma_mm)"),
        "{stdout}"
    );
    let table = rows(&std::fs::read_to_string(&out).unwrap());
    let value = |row: usize, column: &str| -> f64 {
        table[row][column]
            .parse()
            .unwrap_or_else(|_| panic!("{column}: {:?}", table[row]))
    };
    let cell = Cell::from_toml(&text, "predict-sigma", dir.as_path()).unwrap();
    let estimate: Estimate = serde_json::from_str(&std::fs::read_to_string(&est).unwrap()).unwrap();
    // At the working pose: the TCP's σ and floor are identify's.
    let kpi = estimate.tcp[0].kpi;
    let floor = estimate.model_floor.as_ref().unwrap().tcp[0].kpi;
    assert!(
        floor > 0.01,
        "the paper cell's tool is fixed with a prior: {floor}"
    );
    let close = |a: f64, b: f64, tol: f64| (a - b).abs() <= tol * b;
    assert!(close(value(0, "tcp_sigma_mm"), kpi.sqrt(), 1e-6));
    assert!(close(value(0, "tcp_floor_sigma_mm"), floor.sqrt(), 1e-6));
    assert!(close(
        value(0, "tcp_total_sigma_mm"),
        (kpi + floor).sqrt(),
        1e-6
    ));
    // The reflector's offset absorbs the fixed flange parameters: no floor at the target.
    assert!(value(0, "floor_sigma_mm") < 1e-6 * value(0, "sigma_mm"));
    // Monte Carlo of the model at parameters drawn from C_p, at both configurations:
    // 4000 draws give √((1/3) tr C) to about ±1 %; the linearisation is exact to far less.
    for (row, q) in [
        [0.0, -30.0, 30.0, 0.0, -80.0, 0.0],
        [60.0, 10.0, 20.0, -120.0, 30.0, 45.0],
    ]
    .iter()
    .enumerate()
    {
        let q: Vec<f64> = q.iter().map(|d: &f64| d.to_radians()).collect();
        let (target, tcp) = monte_carlo(&cell.model, &estimate, &q, 4000);
        for (column, mc) in [("sigma_mm", target), ("tcp_sigma_mm", tcp)] {
            let stated = value(row, column);
            assert!(
                close(stated, mc, 0.05),
                "row {row} {column}: stated {stated:.5} mm, Monte Carlo {mc:.5} mm"
            );
        }
    }
    // A data file's reader ignores the σ columns: the prediction reads back as data.
    let (read, report) = armcal::measure::csv::read_with(
        std::path::Path::new(&out),
        &cell.model,
        &cell.data_format(),
    )
    .unwrap();
    assert_eq!(read.measurements.len(), 2);
    assert!(
        report.ignored.iter().any(|c| c == "tcp_total_sigma_mm"),
        "{:?}",
        report.ignored
    );
}

#[test]
fn predict_states_the_orientation_sigma_of_a_full_pose_cell() {
    let dir = scratch("predict_sigma_pose");
    let path = |f: &str| dir.join(f).to_str().unwrap().to_string();
    let cell_path = "examples/ur10-leica-cell.toml";
    let data = "data/ipa-ur10-leica/Series_B/measurements_joint_configurations.csv";
    let (est, out) = (path("estimate.json"), path("predicted.csv"));
    let (ok, _, err) = armcal(&[
        "identify",
        "--cell",
        cell_path,
        "--data",
        data,
        "--holdout",
        "0.3",
        "--seed",
        "1",
        "--out",
        &est,
    ]);
    assert!(ok, "{err}");
    // The data file's own configurations, read with the cell's data columns.
    let (ok, _, err) = armcal(&[
        "predict",
        "--cell",
        cell_path,
        "--estimate",
        &est,
        "--joints",
        data,
        "--out",
        &out,
    ]);
    assert!(ok, "{err}");
    let table = rows(&std::fs::read_to_string(&out).unwrap());
    let text = std::fs::read_to_string(format!("../../{cell_path}")).unwrap();
    let cell = Cell::from_toml(&text, "ur10", std::path::Path::new("../../examples")).unwrap();
    let model = &cell.model;
    let estimate: Estimate = serde_json::from_str(&std::fs::read_to_string(&est).unwrap()).unwrap();
    let params = estimate.params_for(model).unwrap();
    let draws = parameter_draws(model, &estimate, 4000);
    for row in [0, table.len() / 2] {
        let q: Vec<f64> = model
            .joints
            .iter()
            .map(|j| {
                table[row][&format!("{}_deg", j.name)]
                    .parse::<f64>()
                    .unwrap()
                    .to_radians()
            })
            .collect();
        let mut data = Data::new(model);
        forward_kinematics(model, &mut data, &params, &q);
        let r0 = armcal::model::observed_pose(&data, Observed::Tool).rot;
        let (mut positions, mut rotations) = (Vec::new(), Vec::new());
        for p in &draws {
            forward_kinematics(model, &mut data, p, &q);
            let pose = armcal::model::observed_pose(&data, Observed::Tool);
            positions.push(pose.trans);
            let d = nalgebra::Rotation3::from_matrix_unchecked(pose.rot * r0.transpose());
            rotations.push(d.scaled_axis().map(f64::to_degrees));
        }
        let value = |c: &str| -> f64 { table[row][c].parse().unwrap() };
        for (column, mc) in [
            ("sigma_mm", rms_sigma(&positions)),
            ("sigma_deg", rms_sigma(&rotations)),
        ] {
            let stated = value(column);
            assert!(
                (stated - mc).abs() <= 0.05 * mc,
                "row {row} {column}: stated {stated:.6}, Monte Carlo {mc:.6}"
            );
        }
        assert!(value("total_sigma_deg") >= value("sigma_deg"));
    }
}
