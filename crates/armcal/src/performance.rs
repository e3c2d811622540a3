//! A robot's pose performance before and after calibration: the ISO 9283 pose accuracy and
//! repeatability (ISO 9283:1998 §7.2–7.3, position and orientation) of a test's commanded
//! poses, for the nominal robot and for a calibrated model (book ch. 7, proof of accuracy).
//!
//! What "command" means in each (ISO 9283 compares the attained pose with the commanded
//! pose, as the controller knows it):
//! * **before**: the nominal robot, i.e. the pose the controller believes it reaches at the
//!   joints it reports. The measurements are in the instrument's frame, which the nominal
//!   robot does not know: its instrument, base, tool and target frames are fitted to these
//!   data first, the robot's own parameters kept nominal ("nominal + frames fitted", as
//!   `identify` reports it, [`frames_only_fit`]). So AP before is the best the uncalibrated
//!   robot can do once its set-up is measured; it absorbs whatever part of the robot's error
//!   a frame can, more so the fewer poses the test has.
//! * **after**: the calibrated model's prediction at the same joints, i.e. the pose a
//!   controller compensated with the calibration would reach exactly. The calibrated model
//!   must hold the instrument and tool frames of this set-up: an estimate identified on
//!   these data, or another set-up's robot with only the frames refitted to these data.
//!
//! The commanded poses — which rows are repeated approaches of one pose — are found once,
//! from the nominal model ([`commanded_poses`]), and are the same before and after.

use crate::accuracy::report::{accuracy_report, AccuracyReport, Orientation};
use crate::accuracy::same_pose::{commanded_poses, GroupingSummary, SamePose};
use crate::cell::Cell;
use crate::identify::{frames_only_fit, IdentifySettings};
use crate::measure::Dataset;
use crate::progress::Observer;
use crate::Error;
use serde::{Deserialize, Serialize};

/// What a performance test computes.
#[derive(Clone, Copy, Debug, Default)]
pub struct PerformanceSettings {
    /// The tolerance within which two configurations are one commanded pose.
    pub same_pose: SamePose,
    /// Whether orientation figures are required (data without poses are then refused).
    pub orientation: Orientation,
}

/// A calibrated model to test: its parameters and what they are (e.g. the estimate file).
pub struct Calibrated<'a> {
    /// What the parameters are, for the record.
    pub name: String,
    /// The parameters, in the cell model's order (internal units).
    pub params: &'a [f64],
}

/// The ISO 9283 figures of one model.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ModelPerformance {
    /// Which model: the nominal robot with frames fitted, or the calibration's name.
    pub model: String,
    /// Its errors and per-pose figures.
    pub report: AccuracyReport,
}

/// The performance record (`armcal accuracy --json`): the commanded poses found, and the
/// ISO 9283 figures before and after calibration.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PerformanceRecord {
    /// The data tested.
    pub data: String,
    /// How the commanded poses were found.
    pub grouping: GroupingSummary,
    /// The nominal robot, its frames fitted to these data.
    pub before: ModelPerformance,
    /// The calibrated model, if one was given.
    pub after: Option<ModelPerformance>,
}

/// The description of the "before" model in the record.
pub const BEFORE: &str = "nominal robot, frames fitted to these data";

/// The ISO 9283 test of `data` (measured on `cell`'s robot) before calibration and, given
/// `calibrated`, after it.
///
/// ```
/// use armcal::model::random_configurations;
/// use armcal::{performance, perturbed_truth, simulate, Calibrated, PerformanceSettings};
/// use armcal::{Perturbation, Silent};
///
/// # fn main() -> armcal::Result<()> {
/// let cell = armcal::cell::builtin::paper_cell()?;
/// let model = &cell.model;
/// // A robot unlike its drawing visits 5 commanded poses 6 times each (measured
/// // without noise).
/// let truth = perturbed_truth(model, &Perturbation::default(), 3);
/// let poses = random_configurations(model, 5, 1);
/// let visits: Vec<Vec<f64>> = (0..6).flat_map(|_| poses.clone()).collect();
/// let data = simulate(model, &truth, &visits, None, 2)?;
/// let calibrated = Calibrated { name: "the true parameters".into(), params: &truth };
/// let settings = PerformanceSettings::default();
/// let record = performance(&cell, &data, Some(calibrated), &settings, &mut Silent)?;
/// assert_eq!(record.grouping.poses, 5);
/// // The true parameters predict what was measured; the drawing, frames fitted, does not.
/// let after = record.after.expect("a calibrated model was given");
/// assert!(after.report.errors.rms < 1e-6);
/// assert!(record.before.report.errors.rms > 1e-3);
/// # Ok(())
/// # }
/// ```
pub fn performance(
    cell: &Cell,
    data: &Dataset,
    calibrated: Option<Calibrated>,
    settings: &PerformanceSettings,
    observer: &mut dyn Observer,
) -> Result<PerformanceRecord, Error> {
    let model = &cell.model;
    observer.start("commanded poses", None);
    let poses = commanded_poses(
        model,
        &data.configurations,
        &data.config_ids,
        &settings.same_pose,
    );
    observer.finish();
    observer.start("frames of the nominal robot", None);
    let frames = frames_only_fit(model, data, &cell.noise(), &IdentifySettings::default());
    observer.finish();
    let report =
        |params: &[f64]| accuracy_report(model, params, data, &poses, settings.orientation);
    let before = ModelPerformance {
        model: BEFORE.into(),
        report: report(&frames?)?,
    };
    let after = calibrated
        .map(|c| {
            Ok::<_, Error>(ModelPerformance {
                report: report(c.params)?,
                model: c.name,
            })
        })
        .transpose()?;
    Ok(PerformanceRecord {
        data: data.source.clone(),
        grouping: poses.summary,
        before,
        after,
    })
}
