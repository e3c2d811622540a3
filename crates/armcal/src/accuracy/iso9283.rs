//! ISO 9283 pose accuracy AP and pose repeatability RP (ISO 9283:1998 §7.2 accuracy, §7.3
//! repeatability; book ch. 7), position and orientation, from the `n` attained poses of one
//! commanded pose.
//!
//! Orientation is taken as the small rotation of each attained pose from the command,
//! `φ_j = log(R_j R_cᵀ)` (a rotation vector in the base frame), with components
//! `(a_j, b_j, c_j)` about the base x, y and z axes. ISO 9283 writes the angles of the
//! attained and the commanded orientation and subtracts (`ā − a_c`); for the small
//! deviations of a robot the two agree to first order when the commanded orientation is the
//! identity, and the rotation vector has no gimbal lock (Series D of the UR10 data commands
//! half its cubes at pitch 90°, where roll and yaw are one angle) and no wrap at ±180°.

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// The number of cycles ISO 9283 §7.1 prescribes for AP and RP (each pose approached 30
/// times); fewer still give figures, from fewer samples.
pub const ISO_CYCLES: usize = 30;

/// Position repeatability of `n` attained positions of one commanded pose:
/// barycentre x̄, distances `l_j = |x_j − x̄|`, `l̄ = mean l_j`,
/// `S_l = √(Σ(l_j − l̄)²/(n − 1))`, and `RP = l̄ + 3 S_l`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Repeatability {
    /// Number of attained positions `n`.
    pub n: usize,
    /// Barycentre x̄ of the attained positions (mm, measurement frame).
    pub barycentre: Vector3<f64>,
    /// Mean distance l̄ of the positions from the barycentre (mm).
    pub mean_distance: f64,
    /// Sample standard deviation S_l of those distances, with `n − 1` (mm).
    pub std_distance: f64,
    /// RP = l̄ + 3 S_l (mm).
    pub rp: f64,
}

/// ISO 9283 RP. `None` for fewer than two positions.
pub fn position_repeatability(points: &[Vector3<f64>]) -> Option<Repeatability> {
    let n = points.len();
    if n < 2 {
        return None;
    }
    let bary = points.iter().fold(Vector3::zeros(), |a, p| a + p) / n as f64;
    let l: Vec<f64> = points.iter().map(|p| (p - bary).norm()).collect();
    let mean = l.iter().sum::<f64>() / n as f64;
    let s = (l.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n as f64 - 1.0)).sqrt();
    Some(Repeatability {
        n,
        barycentre: bary,
        mean_distance: mean,
        std_distance: s,
        rp: mean + 3.0 * s,
    })
}

/// Position accuracy: `AP = |x̄ − x_c|` with components, between the barycentre of the
/// attained positions and the commanded position.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Accuracy {
    /// AP = |x̄ − x_c| (mm).
    pub ap: f64,
    /// x component of x̄ − x_c (mm).
    pub apx: f64,
    /// y component of x̄ − x_c (mm).
    pub apy: f64,
    /// z component of x̄ − x_c (mm).
    pub apz: f64,
}

/// ISO 9283 AP. `None` without positions.
///
/// ```
/// use armcal::{position_accuracy, position_repeatability};
/// use armcal::nalgebra::Vector3;
///
/// let commanded = Vector3::new(1000.0, 0.0, 500.0);
/// // Three approaches that land 0.3 mm off in x, 0.02 mm apart.
/// let attained = [
///     Vector3::new(1000.28, 0.0, 500.0),
///     Vector3::new(1000.30, 0.02, 500.0),
///     Vector3::new(1000.32, -0.02, 500.0),
/// ];
/// let ap = position_accuracy(&commanded, &attained).unwrap();
/// assert!((ap.ap - 0.30).abs() < 1e-9 && (ap.apx - 0.30).abs() < 1e-9);
/// let rp = position_repeatability(&attained).unwrap();
/// assert!(rp.rp > rp.mean_distance);
/// assert!(position_accuracy(&commanded, &[]).is_none());
/// ```
pub fn position_accuracy(commanded: &Vector3<f64>, attained: &[Vector3<f64>]) -> Option<Accuracy> {
    if attained.is_empty() {
        return None;
    }
    let bary = attained.iter().fold(Vector3::zeros(), |a, p| a + p) / attained.len() as f64;
    let d = bary - commanded;
    Some(Accuracy {
        ap: d.norm(),
        apx: d[0],
        apy: d[1],
        apz: d[2],
    })
}

/// Orientation accuracy (ISO 9283 §7.2.2): `AP_a = ā − a_c`, `AP_b = b̄ − b_c`,
/// `AP_c = c̄ − c_c`, here the means of the deviation angles `(a_j, b_j, c_j)` of
/// `log(R_j R_cᵀ)` about the base x, y, z axes (module note).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct OrientationAccuracy {
    /// AP_a, mean deviation about the base x axis (deg).
    pub apa_deg: f64,
    /// AP_b, mean deviation about the base y axis (deg).
    pub apb_deg: f64,
    /// AP_c, mean deviation about the base z axis (deg).
    pub apc_deg: f64,
}

/// Orientation repeatability (ISO 9283 §7.3.2): `RP_a = ±3 S_a` with
/// `S_a = √(Σ(a_j − ā)²/(n − 1))`, and the same for b and c.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct OrientationRepeatability {
    /// Number of attained orientations `n`.
    pub n: usize,
    /// S_a, sample standard deviation of the angle about x (deg).
    pub sa_deg: f64,
    /// S_b, sample standard deviation of the angle about y (deg).
    pub sb_deg: f64,
    /// S_c, sample standard deviation of the angle about z (deg).
    pub sc_deg: f64,
    /// RP_a = ±3 S_a (deg; the half-width of the band).
    pub rpa_deg: f64,
    /// RP_b = ±3 S_b (deg).
    pub rpb_deg: f64,
    /// RP_c = ±3 S_c (deg).
    pub rpc_deg: f64,
}

/// The deviation angles `(a_j, b_j, c_j)` (rad) of attained rotations from the commanded one:
/// the rotation vector of `R_j R_cᵀ`, in the base frame.
fn deviations(commanded: &Matrix3<f64>, attained: &[Matrix3<f64>]) -> Vec<Vector3<f64>> {
    attained
        .iter()
        .map(|r| crate::model::pose::rotation_log(&(r * commanded.transpose())))
        .collect()
}

/// ISO 9283 AP_a, AP_b, AP_c of attained rotations against the commanded rotation. `None`
/// without attained rotations.
pub fn orientation_accuracy(
    commanded: &Matrix3<f64>,
    attained: &[Matrix3<f64>],
) -> Option<OrientationAccuracy> {
    if attained.is_empty() {
        return None;
    }
    let d = deviations(commanded, attained);
    let mean = d.iter().fold(Vector3::zeros(), |a, p| a + p) / d.len() as f64;
    Some(OrientationAccuracy {
        apa_deg: mean[0].to_degrees(),
        apb_deg: mean[1].to_degrees(),
        apc_deg: mean[2].to_degrees(),
    })
}

/// ISO 9283 RP_a, RP_b, RP_c of attained rotations, their deviations taken from `commanded`
/// (the spread does not depend on it to first order). `None` for fewer than two.
pub fn orientation_repeatability(
    commanded: &Matrix3<f64>,
    attained: &[Matrix3<f64>],
) -> Option<OrientationRepeatability> {
    let n = attained.len();
    if n < 2 {
        return None;
    }
    let d = deviations(commanded, attained);
    let mean = d.iter().fold(Vector3::zeros(), |a, p| a + p) / n as f64;
    let s = |k: usize| {
        (d.iter().map(|v| (v[k] - mean[k]).powi(2)).sum::<f64>() / (n as f64 - 1.0))
            .sqrt()
            .to_degrees()
    };
    let (sa, sb, sc) = (s(0), s(1), s(2));
    Some(OrientationRepeatability {
        n,
        sa_deg: sa,
        sb_deg: sb,
        sc_deg: sc,
        rpa_deg: 3.0 * sa,
        rpb_deg: 3.0 * sb,
        rpc_deg: 3.0 * sc,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn repeatability_of_a_known_spread() {
        // Four points on a circle of radius 1 around (1, 2, 3): l̄ = 1, S_l = 0, RP = 1.
        let c = Vector3::new(1.0, 2.0, 3.0);
        let pts: Vec<_> = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)]
            .iter()
            .map(|&(x, y)| c + Vector3::new(x, y, 0.0))
            .collect();
        let r = position_repeatability(&pts).unwrap();
        assert!((r.rp - 1.0).abs() < 1e-12 && (r.barycentre - c).norm() < 1e-12);
        let a = position_accuracy(&Vector3::new(1.0, 2.0, 2.5), &pts).unwrap();
        assert!((a.ap - 0.5).abs() < 1e-12 && (a.apz - 0.5).abs() < 1e-12);
        assert!(position_repeatability(&pts[..1]).is_none());
    }

    #[test]
    fn orientation_of_rotations_about_one_axis() {
        // Attained: the command turned about the base z axis by 1°, 2° and 3°: AP_c = 2°,
        // S_c = 1°, RP_c = ±3°, and nothing about x and y — also at a commanded pitch of 90°,
        // where roll-pitch-yaw angles cannot tell roll from yaw.
        use crate::model::pose::{rot_y, rot_z};
        let c = rot_y(std::f64::consts::FRAC_PI_2);
        let att: Vec<_> = [1.0f64, 2.0, 3.0]
            .iter()
            .map(|d| rot_z(d.to_radians()) * c)
            .collect();
        let a = orientation_accuracy(&c, &att).unwrap();
        assert!((a.apc_deg - 2.0).abs() < 1e-9 && a.apa_deg.abs() < 1e-9 && a.apb_deg.abs() < 1e-9);
        let r = orientation_repeatability(&c, &att).unwrap();
        assert!((r.sc_deg - 1.0).abs() < 1e-9 && (r.rpc_deg - 3.0).abs() < 1e-9);
        assert!(r.rpa_deg < 1e-9 && orientation_repeatability(&c, &att[..1]).is_none());
    }
}
