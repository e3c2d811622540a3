//! A frames refit (`IdentifySettings::refit`, `identify --refit frames`): the robot of an
//! estimate carried over to a new set-up, only the tracker and tool frames fitted; the
//! orientation error statistic of pose measurements; and the estimates a refit refuses.

use crate::common;
use armcal::identify::*;
use armcal::measure::{Measurement, MeasurementKind};
use armcal::model::{forward_kinematics, observed_pose, random_configurations, Data, Observed};
use armcal::{
    identify, Acceptance, Estimate, FramesRefit, IdentifySettings, LmSettings, ToleranceSettings,
};
use armcal::{perturbed_truth, Cell, Dataset, Perturbation, Silent};
use nalgebra::UnitQuaternion;

/// The UR10 + T-Mac cell and a true robot that differs from the nominal in the parameters
/// the cell identifies (the others are the nominal: a fit then recovers the truth itself,
/// not an equivalent), with the tracker 3 m away.
fn cell_and_truth() -> (Cell, Vec<f64>) {
    let cell = common::example_cell("ur10-leica-cell.toml");
    let model = &cell.model;
    let perturbed = perturbed_truth(model, &Perturbation::default(), 3);
    let mut truth = model.nominal();
    for (i, t) in truth.iter_mut().enumerate() {
        if model.registry.get(i).status.is_free() {
            *t = perturbed[i];
        }
    }
    set(
        &cell,
        &mut truth,
        "tracker",
        [400.0, -3200.0, 200.0],
        [0.5, -0.3, 20.0],
    );
    (cell, truth)
}

/// Sets the frame `frame`'s x, y, z (mm) and rx, ry, rz (deg) in `params`.
fn set(cell: &Cell, params: &mut [f64], frame: &str, xyz: [f64; 3], r_deg: [f64; 3]) {
    for (field, v) in ["x", "y", "z"].iter().zip(xyz) {
        params[cell
            .model
            .registry
            .require(&format!("{frame}.{field}"))
            .unwrap()] = v;
    }
    for (field, v) in ["rx", "ry", "rz"].iter().zip(r_deg) {
        params[cell
            .model
            .registry
            .require(&format!("{frame}.{field}"))
            .unwrap()] = v.to_radians();
    }
}

/// Noise-free pose measurements of the tool frame at `n` random configurations.
fn pose_data(cell: &Cell, truth: &[f64], n: usize, seed: u64) -> Dataset {
    let model = &cell.model;
    let mut data = Dataset {
        source: format!("simulated poses (seed {seed})"),
        ..Default::default()
    };
    let mut fk = Data::new(model);
    for (c, q) in random_configurations(model, n, seed)
        .into_iter()
        .enumerate()
    {
        forward_kinematics(model, &mut fk, truth, &q);
        let value = observed_pose(&fk, Observed::Tool);
        let config = data.push_configuration(format!("{}", c + 1), q);
        data.measurements.push(Measurement {
            config,
            observed: Observed::Tool,
            kind: MeasurementKind::Pose { value, sigma: None },
            line: c + 2,
            covariates: Default::default(),
        });
    }
    data
}

fn refit_of(estimate: &Estimate) -> FramesRefit {
    FramesRefit {
        estimate: estimate.clone(),
        origin: "b.json".into(),
        acceptance: Acceptance {
            accepted: false,
            accept: "--accept-unconverged",
            raise_iterations: "--max-iterations",
        },
    }
}

#[test]
fn a_frames_refit_recovers_a_moved_tracker_with_the_robot_held() {
    let (cell, truth) = cell_and_truth();
    let first = identify(
        &cell,
        &pose_data(&cell, &truth, 40, 1),
        &IdentifySettings::default(),
        &mut Silent,
    )
    .unwrap();
    assert!(
        first.solver.status.is_converged(),
        "{:?}",
        first.solver.status
    );
    common::assert_estimate_is(&cell.model, &first, &truth);
    // The tracker re-installed elsewhere and the probe re-mounted: new data.
    let mut moved = truth.clone();
    set(
        &cell,
        &mut moved,
        "tracker",
        [-900.0, 2800.0, 350.0],
        [-0.4, 0.6, -135.0],
    );
    set(
        &cell,
        &mut moved,
        "tool",
        [0.8, -0.5, 93.4],
        [0.1, -0.05, -89.7],
    );
    let data = pose_data(&cell, &moved, 30, 2);
    let opts = IdentifySettings {
        holdout: 0.3,
        refit: Some(refit_of(&first)),
        ..Default::default()
    };
    let refit = identify(&cell, &data, &opts, &mut Silent).unwrap();
    assert!(refit.solver.status.is_converged());
    let record = refit
        .refit
        .as_ref()
        .expect("the estimate records the refit");
    assert_eq!(record.estimate, "b.json");
    assert_eq!(record.data, first.data);
    for (p, q) in refit.parameters.iter().zip(&first.parameters) {
        let i = cell.model.registry.require(&p.name).unwrap();
        let f = cell.model.registry.get(i).unit.display_factor();
        if is_frame_parameter(&cell.model, i) {
            assert!(
                (p.estimate - moved[i] * f).abs() < 1e-6,
                "{} = {} vs the moved truth {}",
                p.name,
                p.estimate,
                moved[i] * f
            );
        } else {
            assert!(!p.free, "{} is the robot's: held", p.name);
            assert_eq!(p.estimate, q.estimate, "{} kept from the estimate", p.name);
        }
    }
    let robot = (0..cell.model.param_count())
        .filter(|&i| !is_frame_parameter(&cell.model, i))
        .count();
    assert_eq!(record.kept, robot);
    assert!(refit
        .free
        .iter()
        .all(|n| n.starts_with("tracker.") || n.starts_with("tool.")));
    // Noise-free: the held-out error of the refit is nil, the nominal robot's is not.
    let v = refit.validation.as_ref().unwrap();
    let o = v
        .orientation
        .as_ref()
        .expect("pose data: orientation errors");
    assert!(
        v.calibrated.max < 1e-6 && o.calibrated.max < 1e-7,
        "{:?} {:?}",
        v.calibrated,
        o.calibrated
    );
    assert!(
        v.frames_only.rms > 0.1 && o.frames_only.rms > 1e-3,
        "{:?} {:?}",
        v.frames_only,
        o.frames_only
    );
}

#[test]
fn the_orientation_error_is_the_angle_between_measured_and_predicted_quaternions() {
    let (cell, truth) = cell_and_truth();
    let data = pose_data(&cell, &truth, 25, 4);
    // Evaluated at the nominal robot with the truth's frames: errors of a few tenths of a degree.
    let mut params = cell.model.nominal();
    for (i, p) in params.iter_mut().enumerate() {
        if is_frame_parameter(&cell.model, i) {
            *p = truth[i];
        }
    }
    let problem = Problem::new(&cell.model, &data, &cell.noise()).unwrap();
    let angles = problem.orientation_errors(&mut problem.workspace(), &params);
    let mut fk = Data::new(&cell.model);
    let mut independent = Vec::new();
    for (m, angle) in data.measurements.iter().zip(&angles) {
        forward_kinematics(
            &cell.model,
            &mut fk,
            &params,
            &data.configurations[m.config],
        );
        let predicted = observed_pose(&fk, Observed::Tool);
        let MeasurementKind::Pose { value, .. } = &m.kind else {
            unreachable!()
        };
        let qp = UnitQuaternion::from_matrix(&predicted.rot);
        let qm = UnitQuaternion::from_matrix(&value.rot);
        // θ = 2 acos |⟨q_p, q_m⟩|, the angle of q_p q_m⁻¹.
        let dot = qp.coords.dot(&qm.coords).abs().min(1.0);
        let theta = 2.0 * dot.acos();
        independent.push(theta.to_degrees());
        let angle = angle.expect("a pose measurement has an orientation error");
        assert!((angle - theta).abs() < 1e-9, "{angle} vs {theta}");
    }
    assert!(independent.iter().any(|&d| d > 0.01), "{independent:?}");
    let stats =
        armcal::identify::residuals::orientation_stats(&problem, &mut problem.workspace(), &params)
            .unwrap();
    let expected = armcal::ErrorStats::of(&independent);
    for (a, b) in [
        (stats.mean, expected.mean),
        (stats.rms, expected.rms),
        (stats.max, expected.max),
        (stats.p95, expected.p95),
    ] {
        assert!((a - b).abs() < 1e-7, "{a} vs {b}");
    }
}

#[test]
fn a_refit_refuses_an_unconverged_estimate_and_one_of_another_robot() {
    let (cell, truth) = cell_and_truth();
    let data = pose_data(&cell, &truth, 30, 5);
    let short = IdentifySettings {
        lm: LmSettings {
            tolerances: ToleranceSettings {
                max_iterations: 1,
                ..Default::default()
            },
            ..Default::default()
        },
        ..Default::default()
    };
    let unconverged = identify(&cell, &data, &short, &mut Silent).unwrap();
    assert!(!unconverged.solver.status.is_converged());
    let opts = |e: &Estimate| IdentifySettings {
        refit: Some(refit_of(e)),
        ..Default::default()
    };
    let err = identify(&cell, &data, &opts(&unconverged), &mut Silent)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("b.json")
            && err.contains("did not converge")
            && err.contains("--accept-unconverged"),
        "{err}"
    );
    // Accepted, it is used (and the refit converges).
    let mut accepted = refit_of(&unconverged);
    accepted.acceptance.accepted = true;
    let est = identify(
        &cell,
        &data,
        &IdentifySettings {
            refit: Some(accepted),
            ..Default::default()
        },
        &mut Silent,
    )
    .unwrap();
    assert!(est.solver.status.is_converged());
    // An estimate of the paper robot is not one of this cell.
    let paper = common::example_cell("paper-cell.toml");
    let qs = random_configurations(&paper.model, 30, 1);
    let pdata = armcal::simulate(&paper.model, &paper.model.nominal(), &qs, None, 1).unwrap();
    let other = identify(&paper, &pdata, &IdentifySettings::default(), &mut Silent).unwrap();
    let err = identify(&cell, &data, &opts(&other), &mut Silent)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("b.json") && err.contains("does not belong"),
        "{err}"
    );
}
