//! Rigid transforms and twists, generic over the scalar so the same kinematics code runs on
//! `f64` and on dual numbers (for the mixed derivatives the pose-design gradients need).

use nalgebra::{Matrix3, RealField, Vector3};

/// Rigid transform `x ↦ R x + t` (a homogeneous matrix `[[R, t], [0, 1]]`, book eq. 2.5 with
/// the (4,4) entry 1 as corrected in the errata).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(bound(
    serialize = "T: serde::Serialize",
    deserialize = "T: serde::de::DeserializeOwned"
))]
pub struct Pose<T: RealField + Copy> {
    /// Rotation `R` (orthonormal, det 1) from this frame to the parent frame.
    pub rot: Matrix3<T>,
    /// Translation `t` (mm): this frame's origin in the parent frame.
    pub trans: Vector3<T>,
}

impl<T: RealField + Copy> Pose<T> {
    /// `R = I`, `t = 0`.
    pub fn identity() -> Self {
        Pose {
            rot: Matrix3::identity(),
            trans: Vector3::zeros(),
        }
    }

    /// `self · other`.
    pub fn compose(&self, other: &Pose<T>) -> Pose<T> {
        Pose {
            rot: self.rot * other.rot,
            trans: self.rot * other.trans + self.trans,
        }
    }

    /// `x ↦ Rᵀ x − Rᵀ t`.
    pub fn inverse(&self) -> Pose<T> {
        let rt = self.rot.transpose();
        Pose {
            rot: rt,
            trans: -(rt * self.trans),
        }
    }

    /// `R p + t`: the point `p` given in this frame, expressed in the parent frame (mm).
    pub fn transform_point(&self, p: &Vector3<T>) -> Vector3<T> {
        self.rot * p + self.trans
    }

    /// Homogeneous 4×4 matrix, row major, for printing and exports.
    pub fn to_matrix(&self) -> [[T; 4]; 4] {
        let z = T::zero();
        let r = &self.rot;
        let t = &self.trans;
        [
            [r[(0, 0)], r[(0, 1)], r[(0, 2)], t[0]],
            [r[(1, 0)], r[(1, 1)], r[(1, 2)], t[1]],
            [r[(2, 0)], r[(2, 1)], r[(2, 2)], t[2]],
            [z, z, z, T::one()],
        ]
    }

    /// Adjoint action on a twist given in this pose's local frame: the same infinitesimal
    /// motion expressed in the parent frame, `ω' = R ω`, `v' = R v + t × R ω`.
    pub fn adjoint(&self, local: &Twist<T>) -> Twist<T> {
        let w = self.rot * local.w;
        Twist {
            w,
            v: self.rot * local.v + self.trans.cross(&w),
        }
    }
}

impl Pose<f64> {
    /// Translation followed by the fixed-axis roll–pitch–yaw rotation `Rz(yaw) Ry(pitch) Rx(roll)`,
    /// the URDF `<origin xyz rpy>` convention. Lengths in mm, angles in rad.
    pub fn from_xyz_rpy(xyz: [f64; 3], rpy: [f64; 3]) -> Pose<f64> {
        Pose {
            rot: rot_z(rpy[2]) * rot_y(rpy[1]) * rot_x(rpy[0]),
            trans: Vector3::from(xyz),
        }
    }

    /// Inverse of [`Pose::from_xyz_rpy`]: (xyz, rpy) with pitch in [−π/2, π/2].
    pub fn to_xyz_rpy(&self) -> ([f64; 3], [f64; 3]) {
        let r = &self.rot;
        let pitch = (-r[(2, 0)]).atan2((r[(0, 0)].powi(2) + r[(1, 0)].powi(2)).sqrt());
        let (roll, yaw) = if pitch.cos().abs() < 1e-12 {
            // Gimbal lock: put the whole rotation about z into yaw.
            (0.0, (-r[(0, 1)]).atan2(r[(1, 1)]))
        } else {
            (r[(2, 1)].atan2(r[(2, 2)]), r[(1, 0)].atan2(r[(0, 0)]))
        };
        (
            [self.trans[0], self.trans[1], self.trans[2]],
            [roll, pitch, yaw],
        )
    }

    /// Rotation angle (rad) between two orientations.
    pub fn rotation_angle_to(&self, other: &Pose<f64>) -> f64 {
        let r = self.rot.transpose() * other.rot;
        ((r.trace() - 1.0) / 2.0).clamp(-1.0, 1.0).acos()
    }
}

/// Infinitesimal rigid motion: angular part `w` and linear part `v`, so that a point `p`
/// moves with velocity `w × p + v` (book §2.4 differential transformation `δ`, `d`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Twist<T: RealField + Copy> {
    /// Angular part `δ` (rad per unit of the differentiated variable).
    pub w: Vector3<T>,
    /// Linear part `d`: velocity of the frame origin (mm per unit of the variable).
    pub v: Vector3<T>,
}

impl<T: RealField + Copy> Twist<T> {
    /// `w = 0`, `v = 0`.
    pub fn zero() -> Self {
        Twist {
            w: Vector3::zeros(),
            v: Vector3::zeros(),
        }
    }

    /// Velocity of the point `p` under this twist: `w × p + v`.
    pub fn point_velocity(&self, p: &Vector3<T>) -> Vector3<T> {
        self.w.cross(p) + self.v
    }
}

/// Elementary rotation by `a` (rad) about the x axis.
pub fn rot_x<T: RealField + Copy>(a: T) -> Matrix3<T> {
    let (s, c) = a.sin_cos();
    let (o, z) = (T::one(), T::zero());
    Matrix3::new(o, z, z, z, c, -s, z, s, c)
}

/// Elementary rotation by `a` (rad) about the y axis.
pub fn rot_y<T: RealField + Copy>(a: T) -> Matrix3<T> {
    let (s, c) = a.sin_cos();
    let (o, z) = (T::one(), T::zero());
    Matrix3::new(c, z, s, z, o, z, -s, z, c)
}

/// Elementary rotation by `a` (rad) about the z axis.
pub fn rot_z<T: RealField + Copy>(a: T) -> Matrix3<T> {
    let (s, c) = a.sin_cos();
    let (o, z) = (T::one(), T::zero());
    Matrix3::new(c, -s, z, s, c, z, z, z, o)
}

/// Rotation by `angle` about the unit axis `u` (Rodrigues' formula, book eq. 2.58).
pub fn rot_axis<T: RealField + Copy>(u: &Vector3<T>, angle: T) -> Matrix3<T> {
    let (s, c) = angle.sin_cos();
    let k = u.cross_matrix();
    Matrix3::identity() + k * s + k * k * (T::one() - c)
}

/// Rotation vector φ with `exp([φ]) = R` (|φ| ≤ π), the SO(3) logarithm.
pub fn rotation_log(r: &Matrix3<f64>) -> Vector3<f64> {
    let cos = ((r.trace() - 1.0) / 2.0).clamp(-1.0, 1.0);
    let angle = cos.acos();
    let w = Vector3::new(
        r[(2, 1)] - r[(1, 2)],
        r[(0, 2)] - r[(2, 0)],
        r[(1, 0)] - r[(0, 1)],
    );
    if angle < 1e-6 {
        // sin θ ≈ θ: φ = vee(R − Rᵀ)/2 to second order.
        return w * 0.5;
    }
    if std::f64::consts::PI - angle < 1e-6 {
        // Near π: axis from the symmetric part R + I = 2 u uᵀ (θ = π).
        let b = (r + Matrix3::identity()) * 0.5;
        let k = (0..3)
            .max_by(|&i, &j| b[(i, i)].total_cmp(&b[(j, j)]))
            .unwrap_or(0);
        let mut u: Vector3<f64> = b.column(k).into_owned() / b[(k, k)].max(1e-300).sqrt();
        if u.dot(&w) < 0.0 {
            u = -u;
        }
        return u.normalize() * angle;
    }
    w * (angle / (2.0 * angle.sin()))
}

/// Inverse of the left Jacobian of SO(3) at φ: `log(exp([δ]) exp([φ])) ≈ φ + J_l⁻¹(φ) δ`.
/// `J_l⁻¹ = I − ½[φ] + (1/θ² − (1 + cos θ)/(2θ sin θ)) [φ]²`.
pub fn left_jacobian_inverse(phi: &Vector3<f64>) -> Matrix3<f64> {
    let theta = phi.norm();
    let k = phi.cross_matrix();
    let c = if theta < 1e-4 {
        1.0 / 12.0 + theta * theta / 720.0
    } else {
        1.0 / (theta * theta) - (1.0 + theta.cos()) / (2.0 * theta * theta.sin())
    };
    Matrix3::identity() - k * 0.5 + k * k * c
}

#[cfg(test)]
mod tests {
    #[test]
    fn log_inverts_rodrigues_and_left_jacobian_is_its_derivative() {
        for phi in [
            Vector3::new(0.3, -0.2, 0.5),
            Vector3::new(1e-8, 2e-8, 0.0),
            Vector3::new(0.0, 3.1, 0.01),
        ] {
            let r = rot_axis(&phi.normalize(), phi.norm());
            assert!((rotation_log(&r) - phi).norm() < 1e-9, "{phi:?}");
        }
        let phi = Vector3::new(0.4, -0.7, 0.2);
        let jinv = left_jacobian_inverse(&phi);
        let r = rot_axis(&phi.normalize(), phi.norm());
        let h = 1e-6;
        for k in 0..3 {
            let mut d = Vector3::zeros();
            d[k] = h;
            let rp = rot_axis(&d.normalize(), h) * r;
            let rm = rot_axis(&(-d).normalize(), h) * r;
            let fd = (rotation_log(&rp) - rotation_log(&rm)) / (2.0 * h);
            assert!((fd - jinv.column(k)).norm() < 1e-7, "{k}");
        }
    }

    use super::*;

    #[test]
    fn xyz_rpy_round_trip() {
        let p = Pose::from_xyz_rpy([1.0, -2.0, 3.0], [0.3, -1.1, 2.5]);
        let (xyz, rpy) = p.to_xyz_rpy();
        let q = Pose::from_xyz_rpy(xyz, rpy);
        assert!((p.rot - q.rot).norm() < 1e-12);
        assert!((p.trans - q.trans).norm() < 1e-12);
    }

    #[test]
    fn rodrigues_matches_elementary_rotations() {
        let a = 0.7;
        assert!((rot_axis(&Vector3::x(), a) - rot_x(a)).norm() < 1e-14);
        assert!((rot_axis(&Vector3::y(), a) - rot_y(a)).norm() < 1e-14);
        assert!((rot_axis(&Vector3::z(), a) - rot_z(a)).norm() < 1e-14);
    }

    #[test]
    fn inverse_composes_to_identity() {
        let p = Pose::from_xyz_rpy([10.0, 20.0, -5.0], [0.1, 0.2, 0.3]);
        let i = p.compose(&p.inverse());
        assert!((i.rot - Matrix3::identity()).norm() < 1e-14);
        assert!(i.trans.norm() < 1e-12);
    }
}
