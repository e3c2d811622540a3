//! Program filtering (book §5.1): (a) a joint program taught or computed with the nominal
//! model becomes the joint program that makes the real (calibrated) robot reach what the
//! nominal model meant; (b) Cartesian targets for a controller that keeps its nominal model
//! are shifted so that its nominal inverse kinematics lands on the calibrated solution.
//!
//! Every row carries its own status ([`IkResult::describe`]): a row outside the joint limits
//! or out of reach is reported, never an error for the whole program. With a
//! [`ResidualCorrection`] (book §5.4) the remaining, non-kinematic position error it
//! predicts is compensated too: the calibrated model is asked to reach `t − ê(q)` so that
//! the real robot, which lands at `FK_cal(q) + e(q)`, reaches `t`.

use crate::compensate::ik::{CalibratedIk, IkResult, IkSettings, IkTarget};
use crate::compensate::nonparametric::ResidualCorrection;
use crate::model::{forward_kinematics, Data, Model, Pose};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Fixed-point passes of the nonparametric correction: `q_{k+1} = IK(t − ê(q_k))`. The
/// correction changes little over the joint step it causes, so two passes settle it far
/// below its own accuracy.
const CORRECTION_PASSES: usize = 2;

/// One filtered program row.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FilteredRow {
    pub id: String,
    /// The program's joint values (nominal model).
    pub q_nominal: Vec<f64>,
    /// The solve with the calibrated model.
    pub result: IkResult,
    /// The nonparametric correction applied to the target position (world, mm): the
    /// negated predicted residual error at the solution, zero without a correction.
    pub correction: Vector3<f64>,
}

/// Applies the nonparametric correction to a solve for `pose` that gave `first`: re-solves
/// for the target position shifted by `−ê(q)` (book §5.4), seeded with the previous
/// solution. Returns the final result and the shift applied (zero without a correction).
fn apply_correction(
    ik: &mut CalibratedIk,
    model: &Model,
    calibrated: &[f64],
    pose: &Pose<f64>,
    first: IkResult,
    correction: Option<&ResidualCorrection>,
    data: &mut Data<f64>,
) -> (IkResult, Vector3<f64>) {
    let Some(corr) = correction else {
        return (first, Vector3::zeros());
    };
    let mut result = first;
    let mut shift = Vector3::zeros();
    for _ in 0..CORRECTION_PASSES {
        forward_kinematics(model, data, calibrated, &result.q);
        shift = -corr.predict(&result.q, &data.tool().trans);
        let shifted = Pose {
            rot: pose.rot,
            trans: pose.trans + shift,
        };
        let seed = std::mem::take(&mut result.q);
        result = ik.solve_from(&IkTarget::Pose(shifted), &seed);
    }
    (result, shift)
}

/// (a) For each joint configuration of a nominal program, the joints with which the
/// calibrated robot reaches the pose the nominal model predicts there (full tool pose).
/// The row's own joints seed the solve: they are the exact nominal solution of that pose
/// (the branch the program chose), so no closed form is needed.
pub fn filter_joint_program(
    model: &Model,
    nominal: &[f64],
    calibrated: &[f64],
    program: &[(String, Vec<f64>)],
    settings: &IkSettings,
) -> Vec<FilteredRow> {
    filter_joint_program_corrected(model, nominal, calibrated, program, settings, None)
}

/// [`filter_joint_program`] with an optional nonparametric correction of the residual.
pub fn filter_joint_program_corrected(
    model: &Model,
    nominal: &[f64],
    calibrated: &[f64],
    program: &[(String, Vec<f64>)],
    settings: &IkSettings,
    correction: Option<&ResidualCorrection>,
) -> Vec<FilteredRow> {
    let mut data = Data::new(model);
    let mut ik = CalibratedIk::new(model, nominal, calibrated, settings.clone());
    program
        .iter()
        .map(|(id, q)| {
            forward_kinematics(model, &mut data, nominal, q);
            let target = *data.tool();
            let first = ik.solve_from(&IkTarget::Pose(target), q);
            let (result, applied) = apply_correction(
                &mut ik, model, calibrated, &target, first, correction, &mut data,
            );
            FilteredRow {
                id: id.clone(),
                q_nominal: q.clone(),
                result,
                correction: applied,
            }
        })
        .collect()
}

/// One corrected Cartesian target.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CorrectedTarget {
    /// The pose to send to the controller (its nominal model's pose at the solution).
    pub pose: Pose<f64>,
    pub result: IkResult,
    /// The nonparametric correction applied to the target position (world, mm).
    pub correction: Vector3<f64>,
}

/// (b) For each desired tool pose, the pose to send to a controller that uses the nominal
/// model: the nominal model's pose at the calibrated solution. The solve starts from the
/// nominal closed-form branch nearest `references[i]` (e.g. the controller's current or
/// nominal joints) where the robot has a closed form, from `references[i]` otherwise.
pub fn corrected_cartesian_targets(
    model: &Model,
    nominal: &[f64],
    calibrated: &[f64],
    targets: &[Pose<f64>],
    references: &[Vec<f64>],
    settings: &IkSettings,
    correction: Option<&ResidualCorrection>,
) -> Vec<CorrectedTarget> {
    let mut data = Data::new(model);
    let mut ik = CalibratedIk::new(model, nominal, calibrated, settings.clone());
    targets
        .iter()
        .zip(references)
        .map(|(t, reference)| {
            let first = ik.solve(&IkTarget::Pose(*t), reference);
            let (result, correction) =
                apply_correction(&mut ik, model, calibrated, t, first, correction, &mut data);
            forward_kinematics(model, &mut data, nominal, &result.q);
            CorrectedTarget {
                pose: *data.tool(),
                result,
                correction,
            }
        })
        .collect()
}
