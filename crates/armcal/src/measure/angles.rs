//! Named orientation conventions of data files: which angles or quaternion components a
//! file's columns hold, to and from a rotation matrix. A file's orientation columns are read
//! only through a convention named in the cell (`[data] orientation = { convention = … }`),
//! never a guessed one.
//!
//! | name | columns | rotation |
//! |---|---|---|
//! | `rpy` | roll, pitch, yaw | `R = Rz(yaw)·Ry(pitch)·Rx(roll)` (fixed axes x-y-z, URDF; armcal's own files) |
//! | `xyz-intrinsic` | rx, ry, rz | `R = Rx(rx)·Ry(ry')·Rz(rz'')` (moving axes X-Y'-Z'', e.g. Leica T-Mac) |
//! | `quat-xyzw` | qx, qy, qz, qw | unit quaternion, scalar last (ROS, Eigen's `coeffs()`) |
//! | `quat-wxyz` | qw, qx, qy, qz | unit quaternion, scalar first |
//!
//! Angles are in radians here (the reader applies the column's unit). For σ, the rate
//! Jacobian `E` maps angle rates to the spatial angular velocity `ω = E·ṙ` (the frame of `R`'s
//! rows, the frame of armcal's pose residual `φ = log(R_model R_measᵀ)`), so the angles'
//! covariance `Σ_r` becomes the rotation covariance `E Σ_r Eᵀ`.

use crate::model::pose::{rot_x, rot_y, rot_z};
use crate::model::Pose;
use nalgebra::{Matrix3, Quaternion, Rotation3, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

/// How a file's orientation columns describe a rotation (see the module table).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Orientation {
    /// `Rz(yaw)·Ry(pitch)·Rx(roll)`, columns roll, pitch, yaw.
    Rpy,
    /// `Rx(rx)·Ry(ry)·Rz(rz)`, columns rx, ry, rz.
    XyzIntrinsic,
    /// Quaternion, columns x, y, z, w.
    QuatXyzw,
    /// Quaternion, columns w, x, y, z.
    QuatWxyz,
}

impl Orientation {
    /// Every convention, in the order of the module table.
    pub const ALL: [Orientation; 4] = [
        Orientation::Rpy,
        Orientation::XyzIntrinsic,
        Orientation::QuatXyzw,
        Orientation::QuatWxyz,
    ];

    /// The name a cell file uses.
    pub fn name(self) -> &'static str {
        match self {
            Orientation::Rpy => "rpy",
            Orientation::XyzIntrinsic => "xyz-intrinsic",
            Orientation::QuatXyzw => "quat-xyzw",
            Orientation::QuatWxyz => "quat-wxyz",
        }
    }

    /// The convention of a name ([`Orientation::name`]).
    pub fn from_name(name: &str) -> Option<Orientation> {
        Orientation::ALL.into_iter().find(|o| o.name() == name)
    }

    /// Number of columns: 3 angles or 4 quaternion components.
    pub fn columns(self) -> usize {
        if self.is_angles() {
            3
        } else {
            4
        }
    }

    /// Whether the columns are angles (they have a unit, deg or rad).
    pub fn is_angles(self) -> bool {
        matches!(self, Orientation::Rpy | Orientation::XyzIntrinsic)
    }

    /// The rotation of `values` (angles in rad; a quaternion need not be normalised).
    /// Panics if `values` has not [`Orientation::columns`] entries.
    pub fn to_rot(self, values: &[f64]) -> Matrix3<f64> {
        assert_eq!(
            values.len(),
            self.columns(),
            "{} takes {} values",
            self.name(),
            self.columns()
        );
        let v = values;
        match self {
            Orientation::Rpy => Pose::from_xyz_rpy([0.0; 3], [v[0], v[1], v[2]]).rot,
            Orientation::XyzIntrinsic => rot_x(v[0]) * rot_y(v[1]) * rot_z(v[2]),
            Orientation::QuatXyzw => quat_rot(v[3], v[0], v[1], v[2]),
            Orientation::QuatWxyz => quat_rot(v[0], v[1], v[2], v[3]),
        }
    }

    /// The values of `r` in this convention: angles with the middle one in [−π/2, π/2] (at
    /// gimbal lock the first angle is 0), a quaternion with w ≥ 0.
    pub fn from_rot(self, r: &Matrix3<f64>) -> Vec<f64> {
        match self {
            Orientation::Rpy => Pose {
                rot: *r,
                trans: Vector3::zeros(),
            }
            .to_xyz_rpy()
            .1
            .to_vec(),
            Orientation::XyzIntrinsic => {
                // R = Rx(a) Ry(b) Rz(c): R02 = sin b, R12 = −sin a cos b, R22 = cos a cos b,
                // R01 = −cos b sin c, R00 = cos b cos c.
                let b = r[(0, 2)].clamp(-1.0, 1.0).asin();
                if b.cos().abs() < 1e-12 {
                    // Gimbal lock: a = 0, R = Ry(±π/2) Rz(c), R10 = sin c, R11 = cos c.
                    vec![0.0, b, r[(1, 0)].atan2(r[(1, 1)])]
                } else {
                    vec![
                        (-r[(1, 2)]).atan2(r[(2, 2)]),
                        b,
                        (-r[(0, 1)]).atan2(r[(0, 0)]),
                    ]
                }
            }
            Orientation::QuatXyzw | Orientation::QuatWxyz => {
                let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*r));
                let s = if q.w < 0.0 { -1.0 } else { 1.0 };
                let (w, x, y, z) = (s * q.w, s * q.i, s * q.j, s * q.k);
                if self == Orientation::QuatXyzw {
                    vec![x, y, z, w]
                } else {
                    vec![w, x, y, z]
                }
            }
        }
    }

    /// The rate Jacobian `E(r)` of an angle convention, `ω = E·ṙ` with `ω` the spatial
    /// angular velocity (`Ṙ Rᵀ = [ω]×`): for `Rx(a)Ry(b)Rz(c)`, `E = [x̂, Rx(a)ŷ,
    /// Rx(a)Ry(b)ẑ]`; for `Rz(c)Ry(b)Rx(a)`, `E = [Rz(c)Ry(b)x̂, Rz(c)ŷ, ẑ]`. `None` for
    /// quaternions.
    pub fn rate_jacobian(self, angles: &[f64; 3]) -> Option<Matrix3<f64>> {
        let [a, b, c] = *angles;
        let (x, y, z) = (Vector3::x(), Vector3::y(), Vector3::z());
        let cols = match self {
            Orientation::XyzIntrinsic => [x, rot_x(a) * y, rot_x(a) * rot_y(b) * z],
            Orientation::Rpy => [rot_z(c) * rot_y(b) * x, rot_z(c) * y, z],
            Orientation::QuatXyzw | Orientation::QuatWxyz => return None,
        };
        Some(Matrix3::from_columns(&cols))
    }

    /// σ of the three rotation rows of armcal's pose residual from the angles' σ
    /// (independent angles): the square roots of the diagonal of `E diag(σ²) Eᵀ`. The
    /// off-diagonal terms are dropped (a measurement holds per-row σ). `None` for quaternions.
    pub fn rotation_sigma(self, angles: &[f64; 3], sigma: &[f64; 3]) -> Option<[f64; 3]> {
        let e = self.rate_jacobian(angles)?;
        let cov = e * Matrix3::from_diagonal(&Vector3::from(*sigma).map(|s| s * s)) * e.transpose();
        Some([0, 1, 2].map(|k| cov[(k, k)].sqrt()))
    }
}

fn quat_rot(w: f64, x: f64, y: f64, z: f64) -> Matrix3<f64> {
    UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z))
        .to_rotation_matrix()
        .into_inner()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::pose::rotation_log;

    const ANGLES: [f64; 3] = [0.3, -1.1, 2.5];

    #[test]
    fn every_convention_round_trips_through_the_matrix() {
        for o in Orientation::ALL {
            assert_eq!(Orientation::from_name(o.name()), Some(o));
            let r = Orientation::XyzIntrinsic.to_rot(&ANGLES);
            let v = o.from_rot(&r);
            assert_eq!(v.len(), o.columns());
            assert!((o.to_rot(&v) - r).norm() < 1e-12, "{}", o.name());
            if o.is_angles() {
                // Angles with the middle one inside ±π/2 come back as they were.
                let back = o.from_rot(&o.to_rot(&ANGLES));
                assert!(back.iter().zip(ANGLES).all(|(a, b)| (a - b).abs() < 1e-12));
            }
        }
        // Gimbal lock: the whole rotation goes into the last angle.
        let lock = Orientation::XyzIntrinsic.to_rot(&[0.0, std::f64::consts::FRAC_PI_2, 0.4]);
        let v = Orientation::XyzIntrinsic.from_rot(&lock);
        assert!((Orientation::XyzIntrinsic.to_rot(&v) - lock).norm() < 1e-12);
        assert_eq!(Orientation::from_name("xyz"), None);
    }

    #[test]
    fn a_fixed_matrix_per_convention() {
        let d = f64::to_radians;
        // 90° about x, then 90° about the new y, multiplied out by hand: Rx(90)·Ry(90) = [[0,0,1],[1,0,0],[0,1,0]].
        let m = Matrix3::new(0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0);
        assert!((Orientation::XyzIntrinsic.to_rot(&[d(90.0), d(90.0), 0.0]) - m).norm() < 1e-15);
        // Rz(90)·Ry(90) (rpy with roll 0, pitch 90, yaw 90) = [[0,−1,0],[0,0,1],[−1,0,0]].
        let m = Matrix3::new(0.0, -1.0, 0.0, 0.0, 0.0, 1.0, -1.0, 0.0, 0.0);
        assert!((Orientation::Rpy.to_rot(&[0.0, d(90.0), d(90.0)]) - m).norm() < 1e-15);
        // 90° about z: q = (w, z) = (cos 45°, sin 45°).
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let rz = rot_z(d(90.0));
        assert!((Orientation::QuatXyzw.to_rot(&[0.0, 0.0, h, h]) - rz).norm() < 1e-15);
        assert!((Orientation::QuatWxyz.to_rot(&[h, 0.0, 0.0, h]) - rz).norm() < 1e-15);
        // The same four numbers read scalar first and scalar last are different rotations.
        let q = [0.1, 0.7, -0.2, 0.6];
        let angle = |a: Matrix3<f64>, b: Matrix3<f64>| rotation_log(&(a * b.transpose())).norm();
        assert!(
            angle(
                Orientation::QuatXyzw.to_rot(&q),
                Orientation::QuatWxyz.to_rot(&q)
            ) > 0.5
        );
        // And the two angle conventions differ for the same numbers.
        assert!(
            angle(
                Orientation::Rpy.to_rot(&ANGLES),
                Orientation::XyzIntrinsic.to_rot(&ANGLES)
            ) > 0.5
        );
    }

    #[test]
    fn the_rate_jacobian_is_the_spatial_angular_velocity() {
        let h = 1e-6;
        for o in [Orientation::Rpy, Orientation::XyzIntrinsic] {
            let e = o.rate_jacobian(&ANGLES).unwrap();
            for k in 0..3 {
                let mut p = ANGLES;
                let mut m = ANGLES;
                p[k] += h;
                m[k] -= h;
                // R(r + h e_k) ≈ exp([ω h]) R(r): ω = log(R(r+h) R(r−h)ᵀ) / 2h.
                let w = rotation_log(&(o.to_rot(&p) * o.to_rot(&m).transpose())) / (2.0 * h);
                assert!((w - e.column(k)).norm() < 1e-8, "{} {k}", o.name());
            }
        }
        assert!(Orientation::QuatXyzw.rate_jacobian(&ANGLES).is_none());
        // At r = 0 the intrinsic E is the identity: the σ pass through.
        let s = Orientation::XyzIntrinsic
            .rotation_sigma(&[0.0; 3], &[1.0, 2.0, 3.0])
            .unwrap();
        assert!(
            (s[0] - 1.0).abs() < 1e-15 && (s[1] - 2.0).abs() < 1e-15 && (s[2] - 3.0).abs() < 1e-15
        );
    }
}
