//! Real data: calibration of the Motoman dual-arm robot from the Leica laser-tracker grids
//! (data/motoman-leica), with a seeded held-out third, and its position repeatability.

use armcal::measure::{csv, MeasurementKind};
use armcal::{identify, position_repeatability, Cell, IdentifySettings, Silent};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The Motoman cell `examples/motoman-{cell}.toml` and the grid of its `arm`.
pub(super) fn motoman(cell: &str, arm: &str) -> (Cell, armcal::Dataset) {
    let cell = Cell::from_file(&root().join(format!("examples/motoman-{cell}.toml"))).unwrap();
    let cols = cell.data_columns.as_ref().unwrap().joints.clone();
    let (data, _) = csv::read(
        &root().join(format!("data/motoman-leica/{arm}_arm_grid_6x6x6.csv")),
        &cell.model,
        Some(&cols),
    )
    .unwrap();
    (cell, data)
}

fn calibrate(arm: &str) -> armcal::identify::Validation {
    let (cell, data) = motoman(&format!("{arm}-cell"), arm);
    let opts = IdentifySettings {
        holdout: 1.0 / 3.0,
        seed: 1,
        ..Default::default()
    };
    let est = identify(&cell, &data, &opts, &mut Silent).unwrap();
    assert!(est.solver.status.is_converged(), "{:?}", est.solver.status);
    let v = est.validation.unwrap();
    eprintln!(
        "{arm} arm, held-out {} poses: frames only mean {:.4} RMS {:.4} max {:.4} p95 {:.4}; calibrated mean {:.4} RMS {:.4} max {:.4} p95 {:.4} (mm)",
        v.test_configurations,
        v.frames_only.mean, v.frames_only.rms, v.frames_only.max, v.frames_only.p95,
        v.calibrated.mean, v.calibrated.rms, v.calibrated.max, v.calibrated.p95
    );
    v
}

#[test]
fn motoman_right_arm_calibration_beats_frames_only_on_held_out_poses() {
    let v = calibrate("right");
    assert!(v.test_configurations >= 70);
    assert!(
        v.frames_only.rms < 0.5,
        "the nominal model is good to well under a mm"
    );
    assert!(v.calibrated.rms < 0.5 * v.frames_only.rms, "{v:?}");
    assert!(v.calibrated.max < v.frames_only.max, "{v:?}");
}

#[test]
fn motoman_left_arm_calibration_beats_frames_only_on_held_out_poses() {
    let v = calibrate("left");
    assert!(v.calibrated.rms < 0.5 * v.frames_only.rms, "{v:?}");
    assert!(v.calibrated.max < v.frames_only.max, "{v:?}");
}

#[test]
fn motoman_position_repeatability() {
    let cell = Cell::from_file(&root().join("examples/motoman-right-cell.toml")).unwrap();
    let cols = cell.data_columns.as_ref().unwrap().joints.clone();
    let (data, _) = csv::read(
        &root().join("data/motoman-leica/right_arm_repeatability_table1.csv"),
        &cell.model,
        Some(&cols),
    )
    .unwrap();
    let pts: Vec<_> = data
        .measurements
        .iter()
        .map(|m| match &m.kind {
            MeasurementKind::Position { value, .. } => *value,
            k => panic!("{k:?}"),
        })
        .collect();
    let r = position_repeatability(&pts).unwrap();
    eprintln!(
        "repeatability: n = {}, l̄ = {:.4} mm, S_l = {:.4} mm, RP = {:.4} mm",
        r.n, r.mean_distance, r.std_distance, r.rp
    );
    assert_eq!(r.n, 18);
    // A small industrial arm repeats to some hundredths of a millimetre.
    assert!(r.rp > 0.005 && r.rp < 0.2, "RP = {}", r.rp);
}
