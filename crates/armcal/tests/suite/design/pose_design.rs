//! A full-pose cell (`measurement = "pose"`, the UR10 + Leica T-Mac cell) is designed with
//! the rows identification fits: 3 position and 3 rotation rows per pose, each divided by
//! its σ, over the same free set. The design's rows equal `Problem`'s on the data `predict`
//! writes at the designed poses; its predicted C_s (and the TCP orientation's) match the
//! scatter of simulated identifications; and its rotation rows identify the tool
//! orientation that position rows leave undetermined.

use crate::common::{example_cell, monte_carlo_tcp_poses, sample_covariance, ur10_pose_cell};
use armcal::design::{DesignModel, InformationWorkspace};
use armcal::identify::Problem;
use armcal::model::rotation_log;
use armcal::model::{random_configurations, Rows};
use armcal::{assess, perturbed_truth, plan, Measurement, Perturbation, PlanSettings, Silent};

#[test]
fn design_rows_are_the_rows_identification_fits() {
    for (cell, rows) in [(ur10_pose_cell(), 6), (example_cell("paper-cell.toml"), 3)] {
        let d = DesignModel::from_cell(&cell).unwrap();
        assert_eq!(d.rows(), rows, "{}", cell.name);
        let qs = random_configurations(&d.model, 12, 3);
        let poses: Vec<(String, Vec<f64>)> = qs
            .iter()
            .enumerate()
            .map(|(i, q)| (format!("{}", i + 1), q.clone()))
            .collect();
        let data = armcal::predict(&cell.model, &d.params, &poses, None, cell.measurement).unwrap();
        let problem = Problem::new(&cell.model, &data, &cell.noise()).unwrap();
        assert_eq!(problem.free, d.free, "{}", cell.name);
        assert_eq!(problem.data_rows(), rows * qs.len(), "{}", cell.name);
        let (_, j) = problem.residual_and_jacobian(&d.params);
        let mut ws = InformationWorkspace::new(&d);
        for (i, q) in qs.iter().enumerate() {
            d.jacobian(&mut ws, q);
            let theirs = j.rows(rows * i, rows);
            let scale = theirs.amax();
            let diff = (&ws.jac - theirs).amax();
            assert!(
                diff <= 1e-12 * scale,
                "{} pose {i}: design rows differ from identification's by {diff:e} (max {scale:e})",
                cell.name
            );
        }
    }
}

#[test]
fn pose_rows_identify_the_tool_orientation_position_rows_cannot() {
    let cell = ur10_pose_cell();
    let design = random_configurations(&cell.model, 30, 5);
    let a = assess(&cell, &design).unwrap();
    let rx = a.parameters.iter().position(|p| p == "tool.rx").unwrap();
    assert!(
        a.sigma[rx].to_degrees() < 0.01,
        "σ(tool.rx) = {}°",
        a.sigma[rx].to_degrees()
    );
    assert!(a.tcp[0].orientation_kpi_deg2.is_some_and(|v| v > 0.0));
    // The same free set measured in position only: the tool's orientation does not move
    // the tool origin, so its information is zero and the design says which parameter.
    let mut position = cell.clone();
    position.measurement = Measurement::Position;
    let d = DesignModel::from_cell(&position).unwrap();
    assert!(d.observed.iter().all(|(_, r)| *r == Rows::Position));
    let err = assess(&position, &design).unwrap_err().to_string();
    assert!(err.contains("`tool.rx` has no effect"), "{err}");
}

#[test]
fn pose_design_covariances_hold_in_monte_carlo() {
    let cell = ur10_pose_cell();
    let planned = plan(
        &cell,
        &armcal::PlanSettings {
            collisions: false,
            exchange_only: true,
            pool: 300,
            starts: 1,
            poses: 30,
            ..PlanSettings::default()
        },
        &[],
        &mut Silent,
    )
    .unwrap();
    let a = assess(&cell, &planned.design).unwrap();
    let truth = perturbed_truth(&cell.model, &Perturbation::default(), 4);
    let work = [cell.working[0].q.clone()];
    let runs = monte_carlo_tcp_poses(&cell, &truth, &planned.design, &work, 200, 7_000);
    let position = sample_covariance(runs.iter().map(|r| r[0].trans)).trace() / 3.0;
    let r0 = runs[0][0].rot;
    let orientation = sample_covariance(
        runs.iter()
            .map(|r| rotation_log(&(r[0].rot * r0.transpose()))),
    )
    .trace()
        / 3.0
        * 1f64.to_degrees().powi(2);
    let (predicted, predicted_orientation) = (a.tcp[0].kpi, a.tcp[0].orientation_kpi_deg2.unwrap());
    eprintln!(
        "UR10 full-pose cell, 30-pose KPI design, 200 runs: (1/3) tr C_s predicted {predicted:.6e} mm², empirical {position:.6e} mm² (ratio {:.3}); orientation predicted {predicted_orientation:.6e} deg², empirical {orientation:.6e} deg² (ratio {:.3})",
        position / predicted,
        orientation / predicted_orientation
    );
    assert!((position / predicted - 1.0).abs() <= 0.15);
    assert!((orientation / predicted_orientation - 1.0).abs() <= 0.15);
}
