//! Configuration bits: which of a pose's inverse-kinematics branches a controller solves it
//! on, mapped to joint signs and quadrants for any 6R arm with the regional structure of the
//! closed form ([`SphericalWristIk`]: axes 2 ∥ 3, a spherical wrist). The definitions follow
//! the vendors' manuals, stated here geometrically so that they hold for any such robot, on
//! the CONTROLLER's angles `c` (the cell's convention) and the NOMINAL model (the one the
//! controller solves with):
//!
//! * **overhead**: the wrist centre `w` lies behind axis 1 — its component perpendicular to
//!   axis 1 points against the arm's forward direction `f(q₁)`, the direction from axis 1 to
//!   the wrist centre at the controller's zero, turned with joint 1 (KUKA: "the wrist root
//!   point lies in the overhead area", x < 0 in the A1 coordinate system; ABB: "wrist centre
//!   behind axis 1");
//! * **elbow**: `c₃ ≥ φ`, φ the axis-3 angle at which the wrist centre lies on the line
//!   through axes 2 and 3 with the arm stretched (KUKA: "A3 ≥ φ", where φ depends on the
//!   offset between A3 and A4; ABB: the wrist centre "in front of the lower arm"). With
//!   `s = ω₂ · (u × v)`, `u`, `v` the components perpendicular to axis 2 of axis 3's and the
//!   wrist centre's offsets from axis 2, `∂s/∂c₃ = sign₃ (ω₂·ω₃) u·(w − r₃) > 0` at the
//!   stretched arm, so `c₃ ≥ φ ⇔ sign₃ (ω₂·ω₃) s ≥ 0`;
//! * **wrist**: the sign of `c₅` (KUKA S bit 2 = 1 for A5 ≤ 0; ABB cfx odd for axis 5
//!   negative).
//!
//! KUKA `S` = overhead + 2·elbow + 4·(c₅ ≤ 0); `T` bit k = 1 for `c_{k+1} < 0` (KUKA System
//! Software 8 operating and programming instructions, "S and T"). ABB `confdata`
//! `[cf1, cf4, cf6, cfx]`: cfⱼ = ⌊cⱼ / 90°⌋ (the quadrant, −1 for [−90°, 0)), and
//! cfx = 4·overhead + 2·(wrist centre behind the lower arm, i.e. not elbow) + (c₅ < 0) (ABB
//! RAPID reference manual, "confdata"). A robot without this structure (a UR arm: its wrist is not
//! spherical) has no such bits; a program that gives them for it is refused with the reason.

use crate::compensate::closed_form::SphericalWristIk;
use crate::model::controller::ControllerConvention;
use crate::model::pose::rot_axis;
use crate::model::{forward_kinematics, Data, Model, Pose};
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::PI;

/// A bit field as written: its value and, for a KRL binary literal `'B010'`, its digits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Bits {
    pub value: u32,
    pub binary_digits: Option<usize>,
}

impl Bits {
    /// As KRL writes it: the binary literal with its digits, or the integer.
    pub fn krl(&self) -> String {
        match self.binary_digits {
            Some(n) => format!("'B{:0n$b}'", self.value),
            None => self.value.to_string(),
        }
    }
}

/// The configuration a controller solves a Cartesian target on.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum Configuration {
    /// KUKA status and turn (KRL `S`, `T`).
    Kuka { s: Bits, t: Option<Bits> },
    /// ABB `confdata` `[cf1, cf4, cf6, cfx]`.
    Abb([i32; 4]),
    /// No configuration: the controller takes the solution nearest the robot's joints when
    /// it gets there (a UR pose, a KRL target without `S`).
    Nearest,
}

impl Configuration {
    /// Whether selecting the branch needs the robot's geometry.
    pub fn needs_geometry(&self) -> bool {
        !matches!(self, Configuration::Nearest)
    }

    /// In words, as the program writes it.
    pub fn describe(&self) -> String {
        match self {
            Configuration::Kuka { s, t } => match t {
                Some(t) => format!("S {} T {}", s.krl(), t.krl()),
                None => format!("S {}", s.krl()),
            },
            Configuration::Abb(cf) => format!("[{},{},{},{}]", cf[0], cf[1], cf[2], cf[3]),
            Configuration::Nearest => "none".into(),
        }
    }
}

/// The nominal robot's geometry that the bits are defined on.
pub(crate) struct Geometry {
    closed_form: SphericalWristIk,
    nominal: Vec<f64>,
    convention: ControllerConvention,
    /// The forward direction at the controller's zero (unit, ⟂ axis 1) and joint 1's model
    /// value there.
    forward: Vector3<f64>,
    q1_zero: f64,
}

/// A joint axis at a configuration: unit direction and a point (world, mm).
fn axis(data: &Data<f64>, k: usize) -> (Vector3<f64>, Vector3<f64>) {
    let t = &data.joint_twists[k];
    let n2 = t.w.norm_squared();
    (t.w / n2.sqrt(), t.w.cross(&t.v) / n2)
}

/// The least-squares meeting point of axes 4–6 (the wrist centre).
fn wrist_centre(data: &Data<f64>) -> Vector3<f64> {
    let (mut a, mut b) = (Matrix3::zeros(), Vector3::zeros());
    for k in 3..6 {
        let (d, p) = axis(data, k);
        let m = Matrix3::identity() - d * d.transpose();
        a += m;
        b += m * p;
    }
    a.lu().solve(&b).unwrap_or(b)
}

fn perpendicular(u: &Vector3<f64>, x: &Vector3<f64>) -> Vector3<f64> {
    x - u * u.dot(x)
}

impl Geometry {
    /// The geometry of `model` (nominal parameters `nominal`) under `convention`, or why the
    /// bits do not fit it.
    pub fn new(
        model: &Model,
        nominal: &[f64],
        convention: &ControllerConvention,
    ) -> Result<Geometry, String> {
        let closed_form = SphericalWristIk::new(model, nominal).map_err(|e| e.to_string())?;
        let zero = convention.to_model(&vec![0.0; model.dof()]);
        let mut data = Data::new(model);
        forward_kinematics(model, &mut data, nominal, &zero);
        let (w1, r1) = axis(&data, 0);
        let forward = perpendicular(&w1, &(wrist_centre(&data) - r1));
        if forward.norm() < 1.0 {
            return Err(
                "at the controller's zero the wrist centre lies on axis 1, so the bits' \
                 forward direction is undefined"
                    .into(),
            );
        }
        Ok(Geometry {
            closed_form,
            nominal: nominal.to_vec(),
            convention: convention.clone(),
            forward: forward.normalize(),
            q1_zero: zero[0],
        })
    }

    /// The configuration of the model joints `q`, written like `template` (its kind and
    /// notation).
    pub fn configuration_of(
        &self,
        model: &Model,
        q: &[f64],
        template: &Configuration,
    ) -> Configuration {
        let c = self.convention.to_controller(q);
        let mut data = Data::new(model);
        forward_kinematics(model, &mut data, &self.nominal, q);
        let w = wrist_centre(&data);
        let (w1, r1) = axis(&data, 0);
        let forward = rot_axis(&w1, q[0] - self.q1_zero) * self.forward;
        let overhead = perpendicular(&w1, &(w - r1)).dot(&forward) < 0.0;
        let ((w2, r2), (w3, r3)) = (axis(&data, 1), axis(&data, 2));
        let s = w2.dot(&perpendicular(&w2, &(r3 - r2)).cross(&perpendicular(&w2, &(w - r2))));
        let elbow = self.convention.joints[2].sign * w2.dot(&w3) * s >= 0.0;
        match template {
            Configuration::Kuka { s: s0, t: t0 } => {
                let status =
                    u32::from(overhead) | u32::from(elbow) << 1 | u32::from(c[4] <= 0.0) << 2;
                let turn = c
                    .iter()
                    .enumerate()
                    .map(|(k, v)| u32::from(*v < 0.0) << k)
                    .sum();
                Configuration::Kuka {
                    s: Bits {
                        value: status,
                        ..*s0
                    },
                    t: t0.map(|t0| Bits { value: turn, ..t0 }),
                }
            }
            Configuration::Abb(_) => {
                let quadrant = |v: f64| (v.to_degrees() / 90.0).floor() as i32;
                Configuration::Abb([
                    quadrant(c[0]),
                    quadrant(c[3]),
                    quadrant(c[5]),
                    4 * i32::from(overhead) + 2 * i32::from(!elbow) + i32::from(c[4] < 0.0),
                ])
            }
            Configuration::Nearest => Configuration::Nearest,
        }
    }

    /// Whether controller value `v` of joint `k` meets what `wanted` says of it alone (a
    /// KUKA turn bit, an ABB quadrant).
    fn joint_fits(k: usize, v: f64, wanted: &Configuration) -> bool {
        match wanted {
            Configuration::Kuka { t: Some(t), .. } => ((t.value >> k) & 1 == 1) == (v < 0.0),
            Configuration::Abb(cf) => match k {
                0 | 3 | 5 => {
                    let i = [0, 0, 0, 1, 0, 2][k];
                    (v.to_degrees() / 90.0).floor() as i32 == cf[i]
                }
                _ => true,
            },
            _ => true,
        }
    }

    /// The nominal joints (model values) the controller solves `pose` with on configuration
    /// `wanted`: the closed-form branch with those bits, each joint the whole-turn
    /// representative with its turn bit or quadrant (within the joint limits where one is);
    /// an error in words if no branch has them.
    pub fn select(
        &self,
        model: &Model,
        pose: &Pose<f64>,
        wanted: &Configuration,
    ) -> Result<Vec<f64>, String> {
        let zero = self.convention.to_model(&[0.0; 6]);
        let branches = self.closed_form.solve(pose, &zero);
        let mut best: Option<((bool, bool), Vec<f64>)> = None;
        for b in branches.as_slice() {
            let mut q = b.q.to_vec();
            let mut fits = true;
            for (k, j) in model.joints.iter().enumerate() {
                let candidates = (-2..=2).map(|n| b.q[k] + 2.0 * PI * f64::from(n));
                let pick = candidates
                    .filter(|v| {
                        let m = self.convention.joints[k];
                        Self::joint_fits(k, m.sign * (v - m.offset), wanted)
                    })
                    .min_by(|a, b| {
                        // Within the limits first, then nearest the branch's value (total
                        // order: a non-finite value sorts last, never panics).
                        let key = |v: f64| (!(j.lower..=j.upper).contains(&v), (v - q[k]).abs());
                        let (ka, kb) = (key(*a), key(*b));
                        ka.0.cmp(&kb.0).then(ka.1.total_cmp(&kb.1))
                    });
                match pick {
                    Some(v) => q[k] = v,
                    None => fits = false,
                }
            }
            if !fits || self.configuration_of(model, &q, wanted) != *wanted {
                continue;
            }
            let within = model
                .joints
                .iter()
                .zip(&q)
                .all(|(j, v)| (j.lower..=j.upper).contains(v));
            let key = (b.reach_miss > 0.0, !within);
            if best.as_ref().is_none_or(|(k, _)| key < *k) {
                best = Some((key, q));
            }
        }
        best.map(|(_, q)| q).ok_or_else(|| {
            format!(
                "no nominal solution of the pose has the configuration {} (the bits name a \
                 branch this robot's nominal model does not reach the pose on)",
                wanted.describe()
            )
        })
    }
}
