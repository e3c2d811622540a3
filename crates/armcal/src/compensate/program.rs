//! Program filtering (book §5.1): (a) a joint program taught or computed with the nominal
//! model becomes the joint program that makes the real (calibrated) robot reach what the
//! nominal model meant; (b) Cartesian targets for a controller that keeps its nominal model
//! are shifted so that its nominal inverse kinematics lands on the calibrated solution.

use crate::compensate::ik::{calibrated_ik, IkResult, IkSettings, IkTarget, IkWorkspace};
use crate::model::{forward_kinematics, Data, Model, Pose};
use serde::{Deserialize, Serialize};

/// One filtered program row.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FilteredRow {
    pub id: String,
    /// The program's joint values (nominal model).
    pub q_nominal: Vec<f64>,
    /// The solve with the calibrated model.
    pub result: IkResult,
}

/// (a) For each joint configuration of a nominal program, the joints with which the
/// calibrated robot reaches the pose the nominal model predicts there (full tool pose).
pub fn filter_joint_program(
    model: &Model,
    nominal: &[f64],
    calibrated: &[f64],
    program: &[(String, Vec<f64>)],
    settings: &IkSettings,
) -> Vec<FilteredRow> {
    let mut data = Data::new(model);
    let mut ws = IkWorkspace::new(model);
    program
        .iter()
        .map(|(id, q)| {
            forward_kinematics(model, &mut data, nominal, q);
            let target = IkTarget::Pose(*data.tool());
            FilteredRow {
                id: id.clone(),
                q_nominal: q.clone(),
                result: calibrated_ik(model, calibrated, &target, q, settings, &mut ws),
            }
        })
        .collect()
}

/// (b) For each desired tool pose, the pose to send to a controller that uses the nominal
/// model: the nominal model's pose at the calibrated solution. `seeds` are starting joints
/// (e.g. the controller's nominal solution).
pub fn corrected_cartesian_targets(
    model: &Model,
    nominal: &[f64],
    calibrated: &[f64],
    targets: &[Pose<f64>],
    seeds: &[Vec<f64>],
    settings: &IkSettings,
) -> Vec<(Pose<f64>, IkResult)> {
    let mut data = Data::new(model);
    let mut ws = IkWorkspace::new(model);
    targets
        .iter()
        .zip(seeds)
        .map(|(t, seed)| {
            let r = calibrated_ik(
                model,
                calibrated,
                &IkTarget::Pose(*t),
                seed,
                settings,
                &mut ws,
            );
            forward_kinematics(model, &mut data, nominal, &r.q);
            (*data.tool(), r)
        })
        .collect()
}
