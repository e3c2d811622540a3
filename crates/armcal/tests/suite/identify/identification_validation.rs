//! Validation the user controls: a held-out split recorded by the data file's pose ids, the
//! user's own test file, the frames-only row of a frames-only cell, and bad fractions.

use crate::common;
use armcal::identify::*;
use armcal::model::random_configurations;
use armcal::{
    identify, perturbed_truth, simulate, Dataset, ErrorStats, IdentifySettings, Perturbation,
    Silent,
};

/// Noisy data of the paper cell at `n` random poses whose ids are not their numbers
/// (`P` + a descending number), so that an index reported as an id shows.
fn paper_data(n: usize, seed: u64) -> (armcal::Cell, Dataset) {
    let cell = common::example_cell("paper-cell.toml");
    let truth = perturbed_truth(&cell.model, &Perturbation::default(), 2);
    let qs = random_configurations(&cell.model, n, seed);
    let noise = cell.instrument.as_ref().unwrap().noise.clone();
    let mut data = simulate(&cell.model, &truth, &qs, Some(&noise), seed).unwrap();
    for (k, id) in data.config_ids.iter_mut().enumerate() {
        *id = format!("P{}", 1000 - 7 * k);
    }
    (cell, data)
}

#[test]
fn the_holdout_split_is_recorded_by_the_files_pose_ids() {
    let (cell, data) = paper_data(60, 4);
    let opts = IdentifySettings {
        holdout: 0.3,
        seed: 5,
        ..Default::default()
    };
    let est = identify(&cell, &data, &opts, &mut Silent).unwrap();
    let v = est.validation.unwrap();
    let (train, test) = holdout_split(60, 0.3, 5);
    let ids = |idx: &[usize]| -> Vec<String> {
        idx.iter().map(|&c| data.config_ids[c].clone()).collect()
    };
    assert_eq!(v.train_ids, ids(&train));
    assert_eq!(v.test_ids, ids(&test));
    assert_eq!(
        (v.train_configurations, v.test_configurations),
        (train.len(), test.len())
    );
    assert!(v.test_data.contains("seed 5"), "{}", v.test_data);
    // Every residual names its configuration by the file's id and the file's numbering.
    assert_eq!(est.residuals.per_measurement.len(), est.measurements);
    for m in &est.residuals.per_measurement {
        assert_eq!(m.pose_id, data.config_ids[m.pose - 1], "{m:?}");
        assert!(v.train_ids.contains(&m.pose_id), "{m:?}");
    }
}

#[test]
fn a_test_file_validates_the_fit_of_the_whole_data_file() {
    let (cell, data) = paper_data(60, 4);
    let (_, mut test) = paper_data(25, 9);
    test.source = "my-test-poses.csv".into();
    for id in &mut test.config_ids {
        *id = format!("T-{id}");
    }
    let opts = IdentifySettings {
        test: Some(test.clone()),
        ..Default::default()
    };
    let est = identify(&cell, &data, &opts, &mut Silent).unwrap();
    let v = est
        .validation
        .as_ref()
        .expect("validation on the test file");
    assert_eq!(v.test_data, "my-test-poses.csv");
    assert_eq!(v.train_ids, data.config_ids);
    assert_eq!(v.test_ids, test.config_ids);
    assert_eq!((v.train_configurations, v.test_configurations), (60, 25));
    assert_eq!(est.configurations, 60, "the whole data file is fitted");
    // The calibrated row is the estimate's error on the test file.
    let model = &cell.model;
    let noise = cell.instrument.as_ref().unwrap().noise.clone();
    let problem = Problem::new(model, &test, &noise).unwrap();
    let mut ws = problem.workspace();
    let direct = ErrorStats::of(&problem.errors(&mut ws, &est.params_for(model).unwrap()));
    assert!(
        (direct.rms - v.calibrated.rms).abs() <= 1e-9 * direct.rms,
        "{direct:?} vs {:?}",
        v.calibrated
    );
    assert!(v.calibrated.rms < v.nominal.rms);
    // A fraction and a test file together are refused.
    let both = IdentifySettings {
        holdout: 0.2,
        ..opts
    };
    let e = identify(&cell, &data, &both, &mut Silent)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("not both"), "{e}");
}

#[test]
fn frames_fitted_row_of_a_frames_only_cell_is_the_calibration() {
    let (cell, truth) = common::unplaced_tracker_paper_cell(true, 3);
    let qs = random_configurations(&cell.model, 60, 11);
    let noise = cell.instrument.as_ref().unwrap().noise.clone();
    let data = simulate(&cell.model, &truth, &qs, Some(&noise), 6).unwrap();
    let opts = IdentifySettings {
        holdout: 0.3,
        ..Default::default()
    };
    let est = identify(&cell, &data, &opts, &mut Silent).unwrap();
    assert!(est.solver.status.is_converged(), "{:?}", est.solver.status);
    let v = est.validation.unwrap();
    assert!(
        (v.frames_only.rms - v.calibrated.rms).abs() <= 1e-6 * v.calibrated.rms,
        "frames fitted {:?} vs calibrated {:?}",
        v.frames_only,
        v.calibrated
    );
    assert!(v.calibrated.rms < 1e-2 * v.nominal.rms, "{v:?}");
}

#[test]
fn a_holdout_fraction_outside_0_1_is_an_error() {
    let (cell, data) = paper_data(30, 4);
    for h in [f64::NAN, -0.1, 1.0, 1.5] {
        let opts = IdentifySettings {
            holdout: h,
            ..Default::default()
        };
        let e = identify(&cell, &data, &opts, &mut Silent)
            .err()
            .unwrap_or_else(|| panic!("holdout {h} was accepted"))
            .to_string();
        assert!(
            e.contains("holdout fraction") && e.contains("[0, 1)") && !e.contains("--"),
            "{h}: {e}"
        );
    }
}
