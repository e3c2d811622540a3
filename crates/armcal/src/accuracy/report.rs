//! Accuracy of a model against measurements, and ISO 9283 figures per commanded pose.

use crate::accuracy::iso9283::{
    position_accuracy, position_repeatability, Accuracy, Repeatability,
};
use crate::accuracy::ErrorStats;
use crate::measure::{Dataset, MeasurementKind};
use crate::model::{forward_kinematics, observed_position, Data, Model};
use serde::{Deserialize, Serialize};

/// ISO 9283 figures of one commanded pose (a configuration measured several times).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PoseFigures {
    /// Configuration id (from the dataset) of the first measurement of the pose.
    pub pose_id: String,
    /// RP of the positions attained at this pose; `None` if measured only once.
    pub repeatability: Option<Repeatability>,
    /// AP against the model's prediction (the commanded position).
    pub accuracy: Accuracy,
}

/// Accuracy of a model on a dataset of position measurements.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct AccuracyReport {
    /// |measured − predicted| of every position measurement (mm).
    pub errors: ErrorStats,
    /// ISO 9283 figures per commanded pose and observed point.
    pub poses: Vec<PoseFigures>,
    /// Largest RP over poses measured at least twice (mm).
    pub worst_rp: Option<f64>,
}

/// Joint distance (rad or mm, largest over the joints) within which two configurations
/// count as the same commanded pose: repeated approaches read slightly different encoder
/// values.
pub const SAME_POSE: f64 = 1e-3;

/// Groups configurations that are the same commanded pose (within [`SAME_POSE`]).
fn commanded_poses(data: &Dataset) -> Vec<Vec<usize>> {
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for (c, q) in data.configurations.iter().enumerate() {
        let same = |g: &Vec<usize>| {
            data.configurations[g[0]]
                .iter()
                .zip(q)
                .all(|(a, b)| (a - b).abs() <= SAME_POSE)
        };
        match groups.iter_mut().find(|g| same(g)) {
            Some(g) => g.push(c),
            None => groups.push(vec![c]),
        }
    }
    groups
}

/// Compares the model with parameters `params` with every position measurement of `data`;
/// configurations within [`SAME_POSE`] of each other are one commanded pose (ISO 9283 RP
/// and AP, the command being the model's prediction at the first of them).
pub fn accuracy_report(model: &Model, params: &[f64], data: &Dataset) -> AccuracyReport {
    let mut fk = Data::new(model);
    let mut errors = Vec::new();
    let mut poses = Vec::new();
    for group in commanded_poses(data) {
        let c = group[0];
        forward_kinematics(model, &mut fk, params, &data.configurations[c]);
        let mut by_target: Vec<(crate::model::Observed, Vec<nalgebra::Vector3<f64>>)> = Vec::new();
        for m in data
            .measurements
            .iter()
            .filter(|m| group.contains(&m.config))
        {
            let value = match &m.kind {
                MeasurementKind::Position { value, .. } => *value,
                MeasurementKind::Pose { value, .. } => value.trans,
                _ => continue,
            };
            errors.push((value - observed_position(&fk, m.observed)).norm());
            match by_target.iter_mut().find(|(o, _)| *o == m.observed) {
                Some((_, v)) => v.push(value),
                None => by_target.push((m.observed, vec![value])),
            }
        }
        for (obs, pts) in by_target {
            let commanded = observed_position(&fk, obs);
            if let Some(accuracy) = position_accuracy(&commanded, &pts) {
                poses.push(PoseFigures {
                    pose_id: data.config_ids[c].clone(),
                    repeatability: position_repeatability(&pts),
                    accuracy,
                });
            }
        }
    }
    let worst_rp = poses
        .iter()
        .filter_map(|p| p.repeatability.as_ref().map(|r| r.rp))
        .fold(None, |a: Option<f64>, b| Some(a.map_or(b, |a| a.max(b))));
    AccuracyReport {
        errors: ErrorStats::of(&errors),
        poses,
        worst_rp,
    }
}
