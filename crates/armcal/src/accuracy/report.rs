//! Accuracy of a model against measurements, and the ISO 9283 pose characteristics of every
//! commanded pose (§7.2 accuracy, §7.3 repeatability; position and, with pose measurements,
//! orientation).
//!
//! The attained poses are the measurements brought into the robot's world (base) frame with
//! the model's instrument pose; the command of a pose is the model's prediction at the
//! joints the robot reported, averaged over the pose's approaches (they differ by the
//! encoder and servo spread). With the nominal robot that is the pose the controller
//! believes it reaches; with a calibrated model, the pose a controller compensated with the
//! calibration would reach exactly. AP and RP components are along the world axes (ISO
//! 9283's base coordinate system).

use crate::accuracy::iso9283::{
    orientation_accuracy, orientation_repeatability, position_accuracy, position_repeatability,
    Accuracy, OrientationAccuracy, OrientationRepeatability, Repeatability,
};
use crate::accuracy::same_pose::CommandedPoses;
use crate::accuracy::ErrorStats;
use crate::measure::{Dataset, MeasurementKind};
use crate::model::jacobian::observed_world;
use crate::model::pose::{rot_axis, rotation_log};
use crate::model::{forward_kinematics, observed_position, Data, Model, Observed};
use crate::Error;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// ISO 9283 figures of one commanded pose and observed frame.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PoseFigures {
    /// Configuration id (from the dataset) of the first approach of the pose.
    pub pose_id: String,
    /// The frame measured: `tool` or a target's name.
    pub observed: String,
    /// Number of approaches `n` (measurements of this frame at this pose).
    pub approaches: usize,
    /// The commanded position `x_c` (mm, world frame).
    pub command_mm: [f64; 3],
    /// AP_P and AP_x, AP_y, AP_z against the command (§7.2.1).
    pub accuracy: Accuracy,
    /// RP_l (§7.3.1); `None` for a pose approached once (RP needs at least two approaches;
    /// ISO 9283 asks 30).
    pub repeatability: Option<Repeatability>,
    /// Orientation AP and RP; `None` without pose measurements of this frame here.
    pub orientation: Option<OrientationFigures>,
}

/// Orientation accuracy and repeatability of one pose.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct OrientationFigures {
    /// AP_a, AP_b, AP_c (§7.2.2).
    pub accuracy: OrientationAccuracy,
    /// RP_a, RP_b, RP_c (§7.3.2); `None` for a pose approached once.
    pub repeatability: Option<OrientationRepeatability>,
}

/// The figures over all poses.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Iso9283Summary {
    /// Number of (pose, observed frame) entries.
    pub poses: usize,
    /// Of those, approached at least twice (with RP).
    pub repeated: usize,
    /// Of those, approached at least [`ISO_CYCLES`](crate::ISO_CYCLES)
    /// times, as ISO 9283 asks.
    pub iso_cycles: usize,
    /// AP_P over the poses (mm).
    pub ap: ErrorStats,
    /// RP_l over the repeated poses (mm); `None` if no pose was approached twice.
    pub rp: Option<ErrorStats>,
    /// Largest |AP_a|, |AP_b|, |AP_c| over the poses (deg); `None` without orientation.
    pub ap_abc_max_deg: Option<[f64; 3]>,
    /// Largest RP_a, RP_b, RP_c over the repeated poses (deg); `None` without them.
    pub rp_abc_max_deg: Option<[f64; 3]>,
}

/// Accuracy of a model on a dataset of position or pose measurements.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct AccuracyReport {
    /// |measured − predicted| of every position or pose measurement (mm).
    pub errors: ErrorStats,
    /// Angle between measured and predicted orientation of every pose measurement (deg);
    /// `None` without pose measurements.
    pub orientation_errors: Option<ErrorStats>,
    /// ISO 9283 figures per commanded pose and observed frame, in data order.
    pub poses: Vec<PoseFigures>,
    /// The figures over all poses.
    pub summary: Iso9283Summary,
}

/// Whether orientation figures must be given.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Orientation {
    /// Orientation AP and RP where the data have pose measurements.
    #[default]
    IfMeasured,
    /// Refuse data without pose measurements.
    Required,
}

/// `exp([φ])`, the rotation of rotation vector φ.
fn rotation_exp(phi: &Vector3<f64>) -> Matrix3<f64> {
    let angle = phi.norm();
    if angle == 0.0 {
        return Matrix3::identity();
    }
    rot_axis(&(phi / angle), angle)
}

/// The mean of rotations close to each other: `exp(mean log(R_j R_0ᵀ)) R_0`.
fn mean_rotation(rots: &[Matrix3<f64>]) -> Matrix3<f64> {
    let r0 = rots[0];
    let mean = rots.iter().fold(Vector3::zeros(), |a, r| {
        a + rotation_log(&(r * r0.transpose()))
    }) / rots.len() as f64;
    rotation_exp(&mean) * r0
}

/// The predictions and measurements of one observed frame at one commanded pose, in the
/// world frame.
#[derive(Default)]
struct Samples {
    predicted: Vec<Vector3<f64>>,
    attained: Vec<Vector3<f64>>,
    predicted_rot: Vec<Matrix3<f64>>,
    attained_rot: Vec<Matrix3<f64>>,
}

/// The name of an observed frame.
fn observed_name(model: &Model, o: Observed) -> String {
    match o {
        Observed::Tool => "tool".into(),
        Observed::Target(k) => model.targets[k].spec.name.clone(),
    }
}

/// Compares the model with parameters `params` with every position and pose measurement of
/// `data` and gives the ISO 9283 figures of each of the commanded `poses` (found by
/// [`commanded_poses`](crate::commanded_poses)). Fails on data with no
/// position or pose measurement, and on data without pose measurements if orientation is
/// [`Orientation::Required`].
pub fn accuracy_report(
    model: &Model,
    params: &[f64],
    data: &Dataset,
    poses: &CommandedPoses,
    orientation: Orientation,
) -> Result<AccuracyReport, Error> {
    let has = |pose: bool| {
        data.measurements.iter().any(|m| match m.kind {
            MeasurementKind::Pose { .. } => true,
            MeasurementKind::Position { .. } => !pose,
            _ => false,
        })
    };
    if !has(false) {
        return Err(Error::Input(format!(
            "{}: ISO 9283 accuracy and repeatability need position or pose measurements; \
             these data have none (distances and planes give no attained position)",
            data.source
        )));
    }
    if orientation == Orientation::Required && !has(true) {
        return Err(Error::Input(format!(
            "{}: orientation accuracy and repeatability (ISO 9283 AP_a, AP_b, AP_c, RP_a, \
             RP_b, RP_c) need pose measurements, and these data measure positions only: \
             measure the tool's full pose (a 6-D probe, or three points per pose), or ask \
             for position figures only",
            data.source
        )));
    }
    let mut by_config = vec![Vec::new(); data.configurations.len()];
    for m in &data.measurements {
        by_config[m.config].push(m);
    }
    let payloads = data.model_payloads(model)?;
    let mut fk = Data::new(model);
    let (mut errors, mut angle_errors) = (Vec::new(), Vec::new());
    let mut figures = Vec::new();
    for group in &poses.groups {
        let mut samples: Vec<(Observed, Samples)> = Vec::new();
        for &c in group {
            fk.payload = payloads[c];
            forward_kinematics(model, &mut fk, params, &data.configurations[c]);
            for m in &by_config[c] {
                let (value, rot) = match &m.kind {
                    MeasurementKind::Position { value, .. } => (*value, None),
                    MeasurementKind::Pose { value, .. } => (value.trans, Some(value.rot)),
                    _ => continue,
                };
                errors.push((value - observed_position(&fk, m.observed)).norm());
                let world = *observed_world(&fk, m.observed);
                let s = match samples.iter().position(|(o, _)| *o == m.observed) {
                    Some(k) => &mut samples[k].1,
                    None => {
                        samples.push((m.observed, Samples::default()));
                        &mut samples.last_mut().expect("just pushed").1
                    }
                };
                s.predicted.push(world.trans);
                s.attained.push(fk.instrument.transform_point(&value));
                if let Some(r) = rot {
                    let attained = fk.instrument.rot * r;
                    angle_errors.push(
                        rotation_log(&(attained * world.rot.transpose()))
                            .norm()
                            .to_degrees(),
                    );
                    s.predicted_rot.push(world.rot);
                    s.attained_rot.push(attained);
                }
            }
        }
        for (obs, s) in samples {
            let n = s.attained.len();
            let command = s.predicted.iter().fold(Vector3::zeros(), |a, p| a + p) / n as f64;
            let Some(accuracy) = position_accuracy(&command, &s.attained) else {
                continue;
            };
            let orientation = (!s.attained_rot.is_empty()).then(|| {
                let c = mean_rotation(&s.predicted_rot);
                OrientationFigures {
                    accuracy: orientation_accuracy(&c, &s.attained_rot)
                        .expect("non-empty attained rotations"),
                    repeatability: orientation_repeatability(&c, &s.attained_rot),
                }
            });
            figures.push(PoseFigures {
                pose_id: data.config_ids[group[0]].clone(),
                observed: observed_name(model, obs),
                approaches: n,
                command_mm: [command[0], command[1], command[2]],
                accuracy,
                repeatability: position_repeatability(&s.attained),
                orientation,
            });
        }
    }
    let summary = summarise(&figures);
    Ok(AccuracyReport {
        errors: ErrorStats::of(&errors),
        orientation_errors: (!angle_errors.is_empty()).then(|| ErrorStats::of(&angle_errors)),
        poses: figures,
        summary,
    })
}

/// The largest of each of three values over the items that have them.
fn max3(values: impl Iterator<Item = [f64; 3]>) -> Option<[f64; 3]> {
    values.fold(None, |acc, v| {
        Some(acc.map_or(v, |a: [f64; 3]| [0, 1, 2].map(|k| a[k].max(v[k]))))
    })
}

fn summarise(figures: &[PoseFigures]) -> Iso9283Summary {
    let rp: Vec<f64> = figures
        .iter()
        .filter_map(|p| p.repeatability.as_ref().map(|r| r.rp))
        .collect();
    let orient = || figures.iter().filter_map(|p| p.orientation.as_ref());
    Iso9283Summary {
        poses: figures.len(),
        repeated: rp.len(),
        iso_cycles: figures
            .iter()
            .filter(|p| p.approaches >= crate::accuracy::iso9283::ISO_CYCLES)
            .count(),
        ap: ErrorStats::of(&figures.iter().map(|p| p.accuracy.ap).collect::<Vec<_>>()),
        rp: (!rp.is_empty()).then(|| ErrorStats::of(&rp)),
        ap_abc_max_deg: max3(orient().map(|o| {
            let a = &o.accuracy;
            [a.apa_deg.abs(), a.apb_deg.abs(), a.apc_deg.abs()]
        })),
        rp_abc_max_deg: max3(
            orient()
                .filter_map(|o| o.repeatability.as_ref())
                .map(|r| [r.rpa_deg, r.rpb_deg, r.rpc_deg]),
        ),
    }
}
