//! Residual blocks and their rows of the identification Jacobian.
//!
//! Residuals are `model − measured` (paper eq. 5 with the sign flipped, which does not
//! change the least-squares problem), each row divided by its σ (whitening, so the weight
//! is the inverse covariance).

use crate::measure::MeasurementKind;
use crate::model::pose::{left_jacobian_inverse, rotation_log};
use crate::model::Pose;
use nalgebra::{DMatrix, Vector3};

/// Model prediction for one (configuration, observed frame): its pose in the instrument
/// frame and the 6 × n identification Jacobian (position rows, then rotation rows).
#[derive(Clone, Debug)]
pub struct Prediction {
    /// Pose of the observed frame in the instrument frame (translation in mm).
    pub pose: Pose<f64>,
    /// 6 × n Jacobian of that pose with respect to the n free parameters: position rows
    /// (mm per parameter unit), then rotation rows (rad per parameter unit).
    pub jac: DMatrix<f64>,
}

impl Prediction {
    /// Identity pose and a zero 6 × `columns` Jacobian, to be filled by the model.
    pub fn new(columns: usize) -> Self {
        Prediction {
            pose: Pose::identity(),
            jac: DMatrix::zeros(6, columns),
        }
    }
}

/// Writes the unwhitened residual rows of one measurement into `r` and its Jacobian rows
/// into `jac` at row `row`. `b` is the prediction at the other configuration of a
/// distance-between-poses measurement.
pub fn residual_rows(
    kind: &MeasurementKind,
    a: &Prediction,
    b: Option<&Prediction>,
    r: &mut [f64],
    jac: &mut DMatrix<f64>,
    row: usize,
) {
    let n = jac.ncols();
    let p = a.pose.trans;
    match kind {
        MeasurementKind::Position { value, .. } => {
            let d = p - value;
            r[..3].copy_from_slice(d.as_slice());
            jac.view_mut((row, 0), (3, n)).copy_from(&a.jac.rows(0, 3));
        }
        MeasurementKind::Pose { value, .. } => {
            let d = p - value.trans;
            r[..3].copy_from_slice(d.as_slice());
            // Rotation residual φ = log(R_model R_measᵀ); d φ = J_l⁻¹(φ) dω.
            let phi = rotation_log(&(a.pose.rot * value.rot.transpose()));
            r[3..6].copy_from_slice(phi.as_slice());
            jac.view_mut((row, 0), (3, n)).copy_from(&a.jac.rows(0, 3));
            let jl = left_jacobian_inverse(&phi);
            let rot_rows = jl * a.jac.rows(3, 3);
            jac.view_mut((row + 3, 0), (3, n)).copy_from(&rot_rows);
        }
        MeasurementKind::Distance { value, .. } => {
            let b = b.expect("a distance between poses needs the second prediction");
            let d = p - b.pose.trans;
            let len = d.norm();
            r[0] = len - value;
            let u = unit_or_zero(d, len);
            for c in 0..n {
                jac[(row, c)] = (0..3).map(|k| u[k] * (a.jac[(k, c)] - b.jac[(k, c)])).sum();
            }
        }
        MeasurementKind::DistanceToPoint { point, value, .. } => {
            let d = p - point;
            let len = d.norm();
            r[0] = len - value;
            project_rows(&unit_or_zero(d, len), a, jac, row);
        }
        MeasurementKind::OnPlane { normal, offset, .. } => {
            let nn = normal.normalize();
            r[0] = nn.dot(&p) - offset;
            project_rows(&nn, a, jac, row);
        }
    }
}

fn unit_or_zero(d: Vector3<f64>, len: f64) -> Vector3<f64> {
    if len > 0.0 {
        d / len
    } else {
        Vector3::zeros()
    }
}

/// Row `uᵀ J_position`.
fn project_rows(u: &Vector3<f64>, a: &Prediction, jac: &mut DMatrix<f64>, row: usize) {
    for c in 0..jac.ncols() {
        jac[(row, c)] = (0..3).map(|k| u[k] * a.jac[(k, c)]).sum();
    }
}
