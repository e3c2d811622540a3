//! `armcal axes` as a library call: the one-joint-at-a-time sweeps read from a data set,
//! circle point analysis of every joint axis ([`identify_axes`], book §4.6) and each axis
//! compared with the model's nominal axis at q = 0 (instrument frame), as the record the
//! command writes.

use super::{identify_axes, JointSweep};
use crate::measure::{Dataset, MeasurementKind};
use crate::model::{forward_kinematics, Data, JointKind, Model};
use crate::Error;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// One identified axis with its σ, beside the nominal axis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AxisRecord {
    /// The joint's name.
    pub joint: String,
    /// Unit direction (instrument frame).
    pub direction: [f64; 3],
    /// A point on the axis (instrument frame, mm).
    pub point_mm: [f64; 3],
    /// Circle radius (revolute) or 0 (prismatic).
    pub radius_mm: f64,
    /// RMS residual of the circle or line fit.
    pub rms_mm: f64,
    /// Number of points of the sweep.
    pub points: usize,
    /// Range of the swept joint's values, in `span_unit` (`°` or `mm`).
    pub span: f64,
    /// The unit of `span`.
    pub span_unit: String,
    /// Point noise per coordinate estimated from the fit's residuals (none for an exact fit).
    pub sigma_noise_mm: Option<f64>,
    /// Degrees of freedom of that estimate.
    pub dof: Option<usize>,
    /// σ of the direction (deg).
    pub sigma_direction_deg: Option<f64>,
    /// σ of the point across the axis (mm).
    pub sigma_point_mm: Option<f64>,
    /// The basis `(x, u × x)` of the covariances below.
    pub covariance_basis: [[f64; 3]; 2],
    /// Covariance of the direction's small rotation in `covariance_basis` (rad²).
    pub direction_covariance_rad2: Option<[[f64; 2]; 2]>,
    /// Covariance of the point across the axis in `covariance_basis` (mm²).
    pub point_covariance_mm2: Option<[[f64; 2]; 2]>,
    /// Why the axis is not to be trusted, if it is not.
    pub warning: Option<String>,
    /// Angle between the identified and the nominal direction (deg).
    pub angle_to_nominal_deg: f64,
    /// Distance of the identified point from the nominal axis (mm; 0 for a prismatic
    /// joint, whose axis has no location).
    pub distance_to_nominal_mm: f64,
}

/// The axes of all joints, in joint order, and the warnings of those not to be trusted.
#[derive(Clone, Debug, PartialEq)]
pub struct AxesRecord {
    /// One record per joint, in joint order.
    pub axes: Vec<AxisRecord>,
    /// The warnings of the axes not to be trusted.
    pub warnings: Vec<String>,
}

impl AxesRecord {
    /// The axes as a JSON array (keys in alphabetical order, see `crate::json`).
    pub fn to_json(&self) -> Result<String, Error> {
        crate::json::sorted_pretty(&self.axes)
    }
}

/// The sweeps of `data`: each configuration moves at most one joint, the others at zero (a
/// configuration at q = 0 belongs to every joint's sweep); position and pose measurements
/// give the points.
pub fn sweeps(model: &Model, data: &Dataset) -> Result<Vec<JointSweep>, Error> {
    let dof = model.dof();
    let mut sweeps: Vec<JointSweep> = (0..dof)
        .map(|joint| JointSweep {
            joint,
            q: Vec::new(),
            points: Vec::new(),
        })
        .collect();
    for m in &data.measurements {
        let point = match &m.kind {
            MeasurementKind::Position { value, .. } => *value,
            MeasurementKind::Pose { value, .. } => value.trans,
            _ => continue,
        };
        let q = &data.configurations[m.config];
        let moving: Vec<usize> = (0..dof).filter(|&j| q[j].abs() > 1e-9).collect();
        let targets: Vec<usize> = match moving.as_slice() {
            [] => (0..dof).collect(),
            [j] => vec![*j],
            _ => return Err(Error::Input(format!(
                "line {}: the configuration moves joints {}; sweeps move one joint at a time with the others at zero",
                m.line,
                moving.iter().map(|j| model.joints[*j].name.clone()).collect::<Vec<_>>().join(", ")
            ))),
        };
        for j in targets {
            sweeps[j].q.push(q.clone());
            sweeps[j].points.push(point);
        }
    }
    Ok(sweeps)
}

/// The axes identified from the sweeps in `data` (`sweeps`, [`identify_axes`]), each
/// compared with the nominal axis at q = 0 in the instrument frame.
pub fn axes_record(model: &Model, data: &Dataset) -> Result<AxesRecord, Error> {
    let axes = identify_axes(model, &sweeps(model, data)?)?;
    let mut fk = Data::new(model);
    forward_kinematics(model, &mut fk, &model.nominal(), &vec![0.0; model.dof()]);
    let rt = fk.instrument.rot.transpose();
    let records = axes
        .axes
        .iter()
        .zip(&fk.joint_twists)
        .map(|(ax, tw)| {
            let (du, dp) = if tw.w.norm() > 0.0 {
                let u = tw.w.normalize();
                let p = u.cross(&tw.v) / tw.w.norm_squared();
                (rt * u, rt * (p - fk.instrument.trans))
            } else {
                (rt * tw.v.normalize(), Vector3::zeros())
            };
            let dist = if tw.w.norm() > 0.0 {
                (ax.point - dp).cross(&du).norm()
            } else {
                0.0
            };
            let (span, unit) = match ax.joint.kind {
                JointKind::Revolute => (ax.span.to_degrees(), "°"),
                JointKind::Prismatic => (ax.span, "mm"),
            };
            let cov = ax.covariance.as_ref();
            let m2 = |m: &nalgebra::Matrix2<f64>| [[m[(0, 0)], m[(0, 1)]], [m[(1, 0)], m[(1, 1)]]];
            let v3 = |v: &Vector3<f64>| [v[0], v[1], v[2]];
            AxisRecord {
                joint: ax.joint.name.clone(),
                direction: v3(&ax.direction),
                point_mm: v3(&ax.point),
                radius_mm: ax.radius,
                rms_mm: ax.rms,
                points: ax.points,
                span,
                span_unit: unit.into(),
                sigma_noise_mm: cov.map(|c| c.sigma_noise),
                dof: cov.map(|c| c.dof),
                sigma_direction_deg: cov.map(|c| c.sigma_direction().to_degrees()),
                sigma_point_mm: cov.map(|c| c.sigma_point()),
                covariance_basis: [v3(&ax.x_axis), v3(&ax.direction.cross(&ax.x_axis))],
                direction_covariance_rad2: cov.map(|c| m2(&c.direction)),
                point_covariance_mm2: cov.map(|c| m2(&c.point)),
                warning: ax.warning.clone(),
                angle_to_nominal_deg: ax.direction.angle(&du).to_degrees(),
                distance_to_nominal_mm: dist,
            }
        })
        .collect();
    Ok(AxesRecord {
        axes: records,
        warnings: axes.warnings().map(String::from).collect(),
    })
}
