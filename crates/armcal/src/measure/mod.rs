//! Measurements and their residual blocks (book ch. 3–4, paper eqs. 3 and 5–6).
//!
//! A [`Dataset`] holds joint configurations and measurements taken at them. Each
//! measurement is one residual block with its own covariance (diagonal, σ per row):
//! a position of a target in the instrument frame (laser tracker, paper eq. 3), a full
//! 6-D pose (book ch. 6; e.g. from three tooling balls, [`pose_from_three_points`]), the
//! distance between a target at two configurations (ball bar, two-socket tools), the
//! distance to a fixed point, or a point on a plane. Blocks of different kinds mix freely
//! in one least-squares problem.

pub mod angles;
pub(crate) mod arrays;
mod columns;
pub mod csv;
pub(crate) mod dataset;
pub mod format;
pub(crate) mod noise;
pub(crate) mod pose_ids;
pub(crate) mod read_report;
pub(crate) mod residual;
pub mod stations;

pub(crate) use dataset::Dataset;
pub use noise::NoiseModel;

use crate::model::{Observed, Pose, Rows};
use nalgebra::{Matrix3, Matrix4, Vector3};
use serde::{Deserialize, Serialize};

/// What one measurement observed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum MeasurementKind {
    /// Position of the observed point in the instrument frame (mm).
    Position {
        /// Measured position (mm, instrument frame).
        value: Vector3<f64>,
        /// σ per axis (mm) from the data file, if it gives one.
        sigma: Option<Vector3<f64>>,
    },
    /// Full pose of the observed frame in the instrument frame: position (mm) and rotation.
    /// Residual rows: position error, then the rotation vector of `R_model R_measᵀ` (rad).
    Pose {
        /// Measured pose of the observed frame (instrument frame; translation in mm).
        value: Pose<f64>,
        /// σ of the 3 position rows (mm) and the 3 rotation rows (rad).
        sigma: Option<[f64; 6]>,
    },
    /// Distance between the observed point at this configuration and at configuration
    /// `other` (mm): a ball bar or a two-socket tool between two poses.
    Distance {
        /// Index of the other configuration in [`Dataset::configurations`].
        other: usize,
        /// Measured distance (mm).
        value: f64,
        /// σ of the distance (mm) from the data file, if it gives one.
        sigma: Option<f64>,
    },
    /// Distance from the observed point to a fixed point given in the instrument frame (mm):
    /// a ball bar on a fixed pivot.
    DistanceToPoint {
        /// The fixed point (mm, instrument frame).
        point: Vector3<f64>,
        /// Measured distance (mm).
        value: f64,
        /// σ of the distance (mm) from the data file, if it gives one.
        sigma: Option<f64>,
    },
    /// The observed point lies on the plane `normal · x = offset` (instrument frame, mm).
    OnPlane {
        /// Plane normal (instrument frame; normalised before use).
        normal: Vector3<f64>,
        /// Signed distance of the plane from the instrument origin along the unit normal
        /// (mm); the residual is `n̂ · x − offset`.
        offset: f64,
        /// σ of the distance to the plane (mm) from the data file, if it gives one.
        sigma: Option<f64>,
    },
}

impl MeasurementKind {
    /// Number of residual rows.
    pub fn rows(&self) -> usize {
        match self {
            MeasurementKind::Position { .. } => 3,
            MeasurementKind::Pose { .. } => 6,
            _ => 1,
        }
    }

    /// The identification Jacobian rows of the kind's residual at a zero residual: a
    /// position's 3 rows, a pose's 6 (position, then rotation: `J_l⁻¹(φ)` of
    /// `residual::residual_rows` is the identity at φ = 0); `None` for the one-row kinds,
    /// whose rows are projections (`residual::residual_rows`).
    pub fn jacobian_rows(&self) -> Option<Rows> {
        match self {
            MeasurementKind::Position { .. } => Some(Rows::Position),
            MeasurementKind::Pose { .. } => Some(Rows::Pose),
            _ => None,
        }
    }

    /// The kind's name, as in the serialised `kind` tag (`position`, `distance-to-point`, …).
    pub fn name(&self) -> &'static str {
        match self {
            MeasurementKind::Position { .. } => "position",
            MeasurementKind::Pose { .. } => "pose",
            MeasurementKind::Distance { .. } => "distance",
            MeasurementKind::DistanceToPoint { .. } => "distance-to-point",
            MeasurementKind::OnPlane { .. } => "on-plane",
        }
    }
}

/// One measurement: configuration index, observed frame, what was measured, and where it
/// came from (for messages).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Measurement {
    /// Index into [`Dataset::configurations`].
    pub config: usize,
    /// The target or tool frame that was measured.
    pub observed: Observed,
    /// What was measured, with value and optional σ.
    pub kind: MeasurementKind,
    /// Line in the data file (1-based, header = 1), 0 for synthetic data.
    pub line: usize,
    /// What else the file recorded with the measurement (not used by identification yet).
    #[serde(default, skip_serializing_if = "Covariates::is_empty")]
    pub covariates: Covariates,
}

impl Measurement {
    /// A noise-free simulated measurement (no σ, line 0) of `observed` at configuration
    /// `config`: the frame's `pose` if `as_pose`, else its position.
    pub(crate) fn simulated(
        config: usize,
        observed: Observed,
        pose: Pose<f64>,
        as_pose: bool,
    ) -> Measurement {
        Measurement {
            config,
            observed,
            kind: if as_pose {
                MeasurementKind::Pose {
                    value: pose,
                    sigma: None,
                }
            } else {
                MeasurementKind::Position {
                    value: pose.trans,
                    sigma: None,
                }
            },
            line: 0,
            covariates: Default::default(),
        }
    }
}

/// Conditions recorded with a measurement that a model may use as covariates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Covariates {
    /// Air temperature at the measurement (°C).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperature_c: Option<f64>,
}

impl Covariates {
    /// Whether nothing was recorded.
    pub fn is_empty(&self) -> bool {
        self.temperature_c.is_none()
    }
}

/// Pose of a body from three measured tooling balls (book §6.2, eqs. 6.35–6.40): with the
/// ball centres known in the body frame (`body`) and measured in the world (`world`), a
/// fourth point `r4 = (r2 − r1) × (r3 − r1) + r1` completes each set and
/// `T = [r1w r2w r3w r4w] [r1b r2b r3b r4b]⁻¹`. Exact for exact data; `None` if the balls
/// are collinear. The rotation is re-orthonormalised (polar decomposition) for noisy data.
pub fn pose_from_three_points(
    body: &[Vector3<f64>; 3],
    world: &[Vector3<f64>; 3],
) -> Option<Pose<f64>> {
    let complete = |r: &[Vector3<f64>; 3]| -> Matrix4<f64> {
        let r4 = (r[1] - r[0]).cross(&(r[2] - r[0])) + r[0];
        let mut m = Matrix4::zeros();
        for (c, v) in [r[0], r[1], r[2], r4].iter().enumerate() {
            m[(0, c)] = v[0];
            m[(1, c)] = v[1];
            m[(2, c)] = v[2];
            m[(3, c)] = 1.0;
        }
        m
    };
    let b = complete(body);
    let t = complete(world) * b.try_inverse()?;
    let r: Matrix3<f64> = t.fixed_view::<3, 3>(0, 0).into_owned();
    let svd = r.svd(true, true);
    let (u, vt) = (svd.u?, svd.v_t?);
    let rot = u * vt;
    if rot.determinant() < 0.0 {
        return None;
    }
    Some(Pose {
        rot,
        trans: t.fixed_view::<3, 1>(0, 3).into_owned(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_tooling_balls_recover_a_rigid_transform() {
        // Book check 7: exact recovery of a synthetic transform.
        let truth = Pose::from_xyz_rpy([100.0, -20.0, 300.0], [0.3, -0.2, 1.1]);
        let body = [
            Vector3::new(50.0, 0.0, 0.0),
            Vector3::new(0.0, 60.0, 10.0),
            Vector3::new(-20.0, -30.0, 80.0),
        ];
        let world = body.map(|b| truth.transform_point(&b));
        let t = pose_from_three_points(&body, &world).unwrap();
        assert!((t.rot - truth.rot).norm() < 1e-12);
        assert!((t.trans - truth.trans).norm() < 1e-10);
        let collinear = [Vector3::zeros(), Vector3::x(), Vector3::x() * 2.0];
        assert!(pose_from_three_points(&collinear, &collinear).is_none());
    }
}
