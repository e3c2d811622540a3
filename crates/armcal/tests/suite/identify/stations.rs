//! Instrument stations (`model::station`): one fit over data measured from several
//! instrument poses, the robot shared. The Jacobian of a station's parameters against
//! finite differences, a two-station truth recovered from noise-free data, the held-out gain
//! over one shared instrument pose on noisy data, and a bad `station` value's error.

use crate::common;
use armcal::identify::*;
use armcal::measure::{csv, Measurement, MeasurementKind};
use armcal::model::{
    forward_kinematics, identification_jacobian, observed_pose, random_configurations, Data,
    Observed, Pose, Rows,
};
use armcal::{
    identify, perturbed_truth, Acceptance, Cell, Dataset, FramesRefit, IdentifySettings, Model,
    Perturbation, Silent,
};
use nalgebra::{DMatrix, Vector3};
use rand::Rng;
use rand_distr::StandardNormal;

const STATIONS: [&str; 2] = ["S1", "S2"];

/// The UR10 + T-Mac cell with two tracker stations, and a true robot that differs from the
/// nominal in the parameters the cell identifies, measured from two tracker poses that
/// differ by `moved` (mm, and deg about each axis) from the first.
fn stationed_truth(moved: [f64; 2]) -> (Cell, Model, Vec<f64>) {
    let cell = common::example_cell("ur10-leica-cell.toml");
    let names: Vec<String> = STATIONS.iter().map(|s| s.to_string()).collect();
    let model = cell.model.with_stations(&names).unwrap();
    let perturbed = perturbed_truth(&model, &Perturbation::default(), 3);
    let mut truth = model.nominal();
    for (i, t) in truth.iter_mut().enumerate() {
        if model.registry.get(i).status.is_free() {
            *t = perturbed[i];
        }
    }
    let first = [400.0, -3200.0, 200.0, 0.5, -0.3, 20.0];
    let (dx, dr) = (moved[0], moved[1]);
    let second = [
        first[0] + dx,
        first[1] - dx,
        first[2] + 0.5 * dx,
        first[3] + dr,
        first[4] - dr,
        first[5] + dr,
    ];
    for (station, pose) in STATIONS.iter().zip([first, second]) {
        for (k, field) in ["x", "y", "z", "rx", "ry", "rz"].iter().enumerate() {
            let i = model
                .registry
                .require(&format!("tracker@{station}.{field}"))
                .unwrap();
            truth[i] = if k < 3 { pose[k] } else { pose[k].to_radians() };
        }
    }
    (cell, model, truth)
}

/// Pose measurements of the tool frame at `n` random configurations per station (different
/// ones at each), with noise σ `sigma` (mm, and mrad on the rotation) drawn with `seed`.
fn station_data(model: &Model, truth: &[f64], n: usize, sigma: f64, seed: u64) -> Dataset {
    let mut data = Dataset {
        source: format!("simulated poses from two stations (seed {seed})"),
        ..Default::default()
    };
    let mut rng = common::rng(seed);
    let mut fk = Data::new(model);
    for (s, name) in STATIONS.iter().enumerate() {
        let station = data.station_index(name);
        for q in random_configurations(model, n, seed + 10 * s as u64) {
            fk.station = station;
            forward_kinematics(model, &mut fk, truth, &q);
            let mut value = observed_pose(&fk, Observed::Tool);
            let mut draw = || Vector3::from_fn(|_, _| sigma * rng.sample::<f64, _>(StandardNormal));
            value.trans += draw();
            value.rot = nalgebra::Rotation3::new(draw() * 1e-3).into_inner() * value.rot;
            let id = format!("{}", data.configurations.len() + 1);
            let config = data.push_configuration(id, q);
            data.config_stations[config] = station;
            data.measurements.push(Measurement {
                config,
                observed: Observed::Tool,
                kind: MeasurementKind::Pose { value, sigma: None },
                line: config + 2,
                covariates: Default::default(),
            });
        }
    }
    data
}

#[test]
fn a_stations_jacobian_columns_match_finite_differences_and_others_are_zero() {
    let (_, model, truth) = stationed_truth([3.0, 0.5]);
    let q = random_configurations(&model, 1, 7).remove(0);
    let columns: Vec<usize> = (0..model.param_count()).collect();
    let mut fk = Data::new(&model);
    fk.station = 1;
    forward_kinematics(&model, &mut fk, &truth, &q);
    let mut jac = DMatrix::zeros(6, columns.len());
    identification_jacobian(
        &model,
        &fk,
        Observed::Tool,
        Rows::Pose,
        &columns,
        &mut jac,
        0,
    );
    let pose_at = |params: &[f64]| -> Pose<f64> {
        let mut d = Data::new(&model);
        d.station = 1;
        forward_kinematics(&model, &mut d, params, &q);
        observed_pose(&d, Observed::Tool)
    };
    for (c, &i) in columns.iter().enumerate() {
        let name = &model.registry.get(i).name;
        let fd = common::fd_pose(
            |h| {
                let mut p = truth.clone();
                p[i] += h;
                pose_at(&p)
            },
            1e-6,
        );
        for (r, v) in fd.iter().enumerate() {
            common::assert_close(jac[(r, c)], *v, 1e-5, &format!("{name} row {r}"));
        }
        if name.starts_with("tracker@S1.") {
            assert!(
                jac.column(c).norm() == 0.0,
                "{name} moves station S2's pose"
            );
        }
    }
}

#[test]
fn two_stations_noise_free_recover_the_truth() {
    let (cell, model, truth) = stationed_truth([250.0, 10.0]);
    let data = station_data(&model, &truth, 30, 0.0, 1);
    let e = identify(&cell, &data, &IdentifySettings::default(), &mut Silent).unwrap();
    assert!(e.solver.status.is_converged(), "{:?}", e.solver.status);
    let stations: Vec<&str> = e
        .free
        .iter()
        .filter(|n| n.contains('@'))
        .map(|n| n.as_str())
        .collect();
    assert_eq!(
        stations.len(),
        12,
        "both stations' poses estimated: {stations:?}"
    );
    assert!(e.parameters.iter().all(|p| !p.name.starts_with("tracker.")));
    common::assert_estimate_is(&model, &e, &truth);
    // the generic count grows by one instrument pose: 30 + 6
    let v = e.verdicts.as_ref().unwrap();
    assert!(
        v.identifiability.meaning.contains("all 36 parameters"),
        "{}",
        v.identifiability.meaning
    );
}

#[test]
fn with_noise_a_pose_per_station_beats_one_shared_pose_on_held_out_data() {
    // The tracker bumped between two sessions: 1 mm and 0.02° — small enough that a shared
    // instrument pose lets the robot's parameters absorb part of it.
    let (cell, model, truth) = stationed_truth([1.0, 0.02]);
    let sigma = 0.02;
    let data = station_data(&model, &truth, 60, sigma, 2);
    let opts = IdentifySettings {
        holdout: 0.3,
        seed: 1,
        ..Default::default()
    };
    let held_out = |data: &Dataset| {
        let e = identify(&cell, data, &opts, &mut Silent).unwrap();
        assert!(e.solver.status.is_converged(), "{:?}", e.solver.status);
        e.validation.unwrap()
    };
    let stations = held_out(&data);
    let shared = held_out(&Dataset {
        stations: Vec::new(),
        config_stations: Vec::new(),
        ..data.clone()
    });
    let by_station = held_out::by_station(&stations.errors);
    assert_eq!(by_station.len(), 2);
    assert_eq!(stations.test_configurations, shared.test_configurations);
    println!(
        "held-out RMS, pose per station {:.4} mm, shared pose {:.4} mm (noise σ {sigma} mm per axis)",
        stations.calibrated.rms, shared.calibrated.rms
    );
    // noise alone: √3 σ per position, and the fit's own prediction error on top
    assert!(stations.calibrated.rms < 2.0 * 3f64.sqrt() * sigma);
    assert!(
        stations.calibrated.rms < 0.5 * shared.calibrated.rms,
        "{} vs {}",
        stations.calibrated.rms,
        shared.calibrated.rms
    );
}

#[test]
fn a_bad_station_value_is_an_error_with_file_line_and_field() {
    let cell = common::example_cell("paper-cell.toml");
    let header = "pose_id,station,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg,x_mm,y_mm,z_mm";
    let row = |id: &str, station: &str| format!("{id},{station},0,10,20,0,30,0,100,200,300");
    for (bad, why) in [
        ("", "cannot be empty"),
        ("S 2", "cannot contain"),
        ("S.2", "cannot contain"),
    ] {
        let text = format!("{header}\n{}\n{}\n", row("1", "S1"), row("2", bad));
        let e = csv::read_str(&text, "two-stations.csv", &cell.model, None)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("two-stations.csv")
                && e.contains("line 3")
                && e.contains("`station`")
                && e.contains(why),
            "{e}"
        );
    }
    // Rows of one pose_id at two stations are two configurations; the stations are the data's.
    let text = format!("{header}\n{}\n{}\n", row("1", "S1"), row("1", "S2"));
    let (data, _) = csv::read_str(&text, "two-stations.csv", &cell.model, None).unwrap();
    assert_eq!(data.stations, ["S1", "S2"]);
    assert_eq!(data.config_stations, [0, 1]);
    // a station needs an instrument whose pose it sets
    let robot = Cell::from_robot("ur10").unwrap();
    let text = "pose_id,station,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg,x_mm,y_mm,z_mm\n1,S1,0,10,20,0,30,0,100,200,300\n";
    let e = csv::read_str(text, "robot.csv", &robot.model, None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("line 2") && e.contains("no [instrument]"), "{e}");
}

#[test]
fn a_frames_refit_fits_every_stations_pose_with_the_robot_held() {
    let (cell, model, truth) = stationed_truth([250.0, 10.0]);
    let first = identify(
        &cell,
        &station_data(&model, &truth, 30, 0.0, 1),
        &IdentifySettings::default(),
        &mut Silent,
    )
    .unwrap();
    // Both trackers set up again elsewhere: the robot is the same.
    let mut moved = truth.clone();
    for (station, shift) in STATIONS.iter().zip([150.0, -300.0]) {
        for field in ["x", "y"] {
            moved[model
                .registry
                .require(&format!("tracker@{station}.{field}"))
                .unwrap()] += shift;
        }
        moved[model
            .registry
            .require(&format!("tracker@{station}.rz"))
            .unwrap()] += 0.2;
    }
    let refit = FramesRefit {
        estimate: first.clone(),
        origin: "two-stations.json".into(),
        acceptance: Acceptance {
            accepted: false,
            accept: "--accept-unconverged",
            raise_iterations: "--max-iterations",
        },
    };
    let opts = IdentifySettings {
        refit: Some(refit),
        ..Default::default()
    };
    let e = identify(
        &cell,
        &station_data(&model, &moved, 30, 0.0, 5),
        &opts,
        &mut Silent,
    )
    .unwrap();
    assert!(e.solver.status.is_converged(), "{:?}", e.solver.status);
    common::assert_estimate_is(&model, &e, &moved);
    // the estimate of two stations gives a model without stations its first station's pose
    let one = first.params_for(&cell.model).unwrap();
    let x = cell.model.registry.require("tracker.x").unwrap();
    assert!((one[x] - truth[model.registry.require("tracker@S1.x").unwrap()]).abs() < 1e-6);
}
