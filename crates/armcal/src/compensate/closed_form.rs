//! Closed-form inverse kinematics of the nominal robot, the seed of calibrated IK (book §5.2:
//! start from the nominal solution, in closed form where the nominal robot has one).
//!
//! The solver is built from the nominal model itself, not from per-robot constants. At the
//! zero configuration the forward kinematics is the product of exponentials
//! `T(q) = e^{ξ̂₁q₁} ⋯ e^{ξ̂₆q₆} M` (Murray, Li, Sastry 1994, eq. 3.3), where joint i turns
//! about the world line (axis ωᵢ through point rᵢ) that [`forward_kinematics`] reports as
//! its twist at q = 0, and `M` is the tool pose there. Base frame, tool offset, joint
//! offsets and the link convention are all folded into ξᵢ and `M`.
//!
//! A closed form exists for the classic regional structure of KUKA KR, PUMA and the paper's
//! notional robots, which [`SphericalWristIk::new`] detects numerically:
//! six revolute joints, axes 4, 5, 6 meeting in one point (the wrist centre `c`), axes
//! 2 ∥ 3, axis 1 not parallel to axis 2. The wrist joints do not move `c`, so with
//! `g = T_target M⁻¹` the wrist centre must reach `w = g c` by joints 1–3 alone:
//!
//! 1. **q1**: joints 2 and 3 turn about parallel axes and keep the component of `c` along
//!    ω₂, so `(R₁(q₁) ω₂)·(w − r₁) = ω₂·(c − r₁)`, i.e. `A cos q₁ + B sin q₁ = C` — two
//!    solutions (shoulder in front of / behind axis 1);
//! 2. **q3**: joint 2 keeps the distance to a point r₂ on its axis, so
//!    `‖e^{ξ̂₃q₃} c − r₂‖ = ‖e^{−ξ̂₁q₁} w − r₂‖` (Paden–Kahan subproblem 3) — two solutions
//!    (elbow up / down);
//! 3. **q2**: the rotation about axis 2 that takes `e^{ξ̂₃q₃} c` to `e^{−ξ̂₁q₁} w`
//!    (subproblem 1);
//! 4. **q4, q5**: with `R_w = (R₁R₂R₃)ᵀ R_g`, the two rotations about ω₄, ω₅ that take ω₆ to
//!    `R_w ω₆` (subproblem 2) — two solutions (wrist flip);
//! 5. **q6**: the rotation about ω₆ that completes `R₄R₅R₆ = R_w` (subproblem 1).
//!
//! At a singular configuration the free angle (q1 with the wrist centre on axis 1, q4 with
//! axes 4 and 6 aligned) is taken from the reference configuration. A wrist centre out of
//! reach gives the nearest configurations with the distance it misses by, as seeds for a
//! calibrated robot that may reach a little further than the nominal one.

use crate::model::{forward_kinematics, Data, JointKind, Model, Pose};
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::PI;

/// Distance (mm) under which lines are taken to meet, and angle (rad) under which axes are
/// taken to be parallel, when detecting the structure on a nominal model (exact up to
/// rounding).
const LINE_TOLERANCE: f64 = 1e-6;
const ANGLE_TOLERANCE: f64 = 1e-9;
/// Slack on cosines of the subproblems before a target counts as out of reach.
const COSINE_SLACK: f64 = 1e-9;
/// Elbow bend (rad) of the seed for a wrist centre beyond the stretched (or folded) elbow:
/// the exact stretch is a stationary point of the error (no gradient along the elbow), from
/// which damped least squares cannot leave towards a calibrated robot that does reach.
const BOUNDARY_BEND: f64 = 0.0175;

/// Why a model has no closed-form solution of this kind.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NoClosedForm {
    /// Which structural condition failed (e.g. wrist axes not meeting in one point).
    pub reason: String,
}

impl std::fmt::Display for NoClosedForm {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "no closed-form inverse kinematics: {}", self.reason)
    }
}

impl std::error::Error for NoClosedForm {}

fn no(reason: String) -> NoClosedForm {
    NoClosedForm { reason }
}

/// A joint axis at the zero configuration (world frame): unit direction and a point (mm).
#[derive(Clone, Copy, Debug)]
struct Axis {
    dir: Vector3<f64>,
    point: Vector3<f64>,
}

impl Axis {
    /// The rigid motion `e^{ξ̂θ}` applied to a point, `r + R(ω, θ)(x − r)`, given
    /// `(sin θ, cos θ)`.
    fn apply(&self, sc: (f64, f64), x: &Vector3<f64>) -> Vector3<f64> {
        self.point + rotate(&self.dir, sc, &(x - self.point))
    }

    /// Distance of a point from the axis line.
    fn distance(&self, x: &Vector3<f64>) -> f64 {
        perpendicular(&self.dir, &(x - self.point)).norm()
    }
}

/// `R(u, θ) v` by Rodrigues' formula (book eq. 2.58) on the vector, given `(sin θ, cos θ)`:
/// `v cos θ + (u × v) sin θ + u (u·v)(1 − cos θ)`.
fn rotate(u: &Vector3<f64>, (s, c): (f64, f64), v: &Vector3<f64>) -> Vector3<f64> {
    v * c + u.cross(v) * s + u * (u.dot(v) * (1.0 - c))
}

/// `(sin, cos)` of `−θ` from those of θ.
fn inverse((s, c): (f64, f64)) -> (f64, f64) {
    (-s, c)
}

/// Component of `x` perpendicular to the unit vector `u`.
fn perpendicular(u: &Vector3<f64>, x: &Vector3<f64>) -> Vector3<f64> {
    x - u * u.dot(x)
}

/// Paden–Kahan subproblem 1: the angle θ of the rotation about the unit axis `u` that takes
/// the direction of `x` to that of `y` (their components perpendicular to `u`).
fn rotation_angle(u: &Vector3<f64>, x: &Vector3<f64>, y: &Vector3<f64>) -> f64 {
    let (xp, yp) = (perpendicular(u, x), perpendicular(u, y));
    u.dot(&xp.cross(&yp)).atan2(xp.dot(&yp))
}

/// One closed-form solution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Branch {
    /// Joint values (rad), each the representative modulo 2π within the joint limits that
    /// is nearest the reference (nearest the limits if none is within them).
    pub q: [f64; 6],
    /// The sign choices: shoulder (step 1), elbow (step 2), wrist flip (step 4), each 0 or 1.
    pub config: [u8; 3],
    /// Whether every joint value is within its limits.
    pub within_limits: bool,
    /// How far (mm) the wrist centre target lies beyond the reach of joints 1–3; 0 for an
    /// exact solution. Otherwise the branch is the nearest configuration (arm stretched or
    /// folded towards the target, elbow bent by about 1°), a seed, not a solution.
    pub reach_miss: f64,
}

impl Branch {
    /// Squared joint-space distance to `reference`.
    pub fn distance2(&self, reference: &[f64]) -> f64 {
        self.q
            .iter()
            .zip(reference)
            .map(|(a, b)| (a - b) * (a - b))
            .sum()
    }
}

/// The solutions of one target (at most 8), without allocation.
#[derive(Clone, Copy, Debug)]
pub struct Branches {
    list: [Branch; 8],
    len: usize,
}

impl Branches {
    fn push(&mut self, b: Branch) {
        if self.len < self.list.len() {
            self.list[self.len] = b;
            self.len += 1;
        }
    }

    /// The branches found (at most 8: shoulder × elbow × wrist flip), in solve order.
    pub fn as_slice(&self) -> &[Branch] {
        &self.list[..self.len]
    }

    /// The branches in order of preference: exact before out-of-reach ones, within the
    /// limits before outside, smaller `reach_miss`, then nearer `reference` in joint space.
    pub fn ordered(&self, reference: &[f64]) -> Branches {
        let key = |b: &Branch| {
            (
                b.reach_miss > 0.0,
                !b.within_limits,
                b.reach_miss,
                b.distance2(reference),
            )
        };
        let keys: [_; 8] = std::array::from_fn(|k| key(&self.list[k]));
        let mut order: [usize; 8] = std::array::from_fn(|k| k);
        // Insertion sort of at most 8 indices by their precomputed keys.
        for i in 1..self.len {
            let mut j = i;
            while j > 0
                && keys[order[j]].partial_cmp(&keys[order[j - 1]]) == Some(std::cmp::Ordering::Less)
            {
                order.swap(j, j - 1);
                j -= 1;
            }
        }
        let mut out = *self;
        for (slot, &k) in out.list[..self.len].iter_mut().zip(&order) {
            *slot = self.list[k];
        }
        out
    }

    /// The preferred branch ([`Branches::ordered`]); `None` only for a non-finite target.
    pub fn nearest(&self, reference: &[f64]) -> Option<Branch> {
        self.ordered(reference).as_slice().first().copied()
    }
}

/// Closed-form IK of a 6R arm with a spherical wrist and parallel axes 2, 3 (module docs).
#[derive(Clone, Debug)]
pub struct SphericalWristIk {
    axes: [Axis; 6],
    /// Inverse of the tool pose at q = 0, `M⁻¹`.
    home_inverse: Pose<f64>,
    /// Wrist centre at q = 0 (world, mm).
    wrist_centre: Vector3<f64>,
    lower: [f64; 6],
    upper: [f64; 6],
}

impl SphericalWristIk {
    /// Detects the structure on `model` with parameters `params` (normally the nominal
    /// values) and derives the solver's constants from its kinematics at q = 0.
    pub fn new(model: &Model, params: &[f64]) -> Result<Self, NoClosedForm> {
        if model.dof() != 6 {
            return Err(no(format!(
                "model `{}` has {} joints (the spherical-wrist solution needs 6)",
                model.name,
                model.dof()
            )));
        }
        if let Some(j) = model.joints.iter().find(|j| j.kind != JointKind::Revolute) {
            return Err(no(format!("joint `{}` is not revolute", j.name)));
        }
        let mut data: Data<f64> = Data::new(model);
        forward_kinematics(model, &mut data, params, &[0.0; 6]);
        let axes: [Axis; 6] = std::array::from_fn(|i| {
            let t = &data.joint_twists[i];
            let n2 = t.w.norm_squared();
            // v = r × ω for a point r on the axis; the point nearest the origin is ω × v / |ω|².
            Axis {
                dir: t.w / n2.sqrt(),
                point: t.w.cross(&t.v) / n2,
            }
        });
        // Wrist centre: least-squares meeting point of axes 4–6, Σ Pᵢ x = Σ Pᵢ rᵢ with
        // Pᵢ = I − ωᵢωᵢᵀ.
        let (mut a, mut b) = (Matrix3::zeros(), Vector3::zeros());
        for ax in &axes[3..] {
            let p = Matrix3::identity() - ax.dir * ax.dir.transpose();
            a += p;
            b += p * ax.point;
        }
        let parallel = |i: usize, j: usize| axes[i].dir.cross(&axes[j].dir).norm();
        for (i, j) in [(3, 4), (4, 5)] {
            if parallel(i, j) < 1e-6 {
                return Err(no(format!("axes {} and {} are parallel", i + 1, j + 1)));
            }
        }
        let centre = a
            .lu()
            .solve(&b)
            .ok_or_else(|| no("axes 4, 5, 6 have no common point".into()))?;
        let miss = axes[3..]
            .iter()
            .map(|ax| ax.distance(&centre))
            .fold(0.0, f64::max);
        if miss > LINE_TOLERANCE {
            return Err(no(format!(
                "axes 4, 5, 6 do not meet in one point (no spherical wrist: their nearest \
                 common point is {miss:.3} mm from one of them)"
            )));
        }
        if parallel(1, 2) > ANGLE_TOLERANCE {
            return Err(no(format!(
                "axes 2 and 3 are not parallel ({:.3e} rad apart)",
                parallel(1, 2).asin()
            )));
        }
        if axes[1].distance(&axes[2].point) < LINE_TOLERANCE {
            return Err(no("axes 2 and 3 coincide".into()));
        }
        if parallel(0, 1) < 1e-6 {
            return Err(no("axes 1 and 2 are parallel".into()));
        }
        if axes[2].distance(&centre) < LINE_TOLERANCE {
            return Err(no("the wrist centre lies on axis 3".into()));
        }
        let lower = std::array::from_fn(|i| model.joints[i].lower);
        let upper = std::array::from_fn(|i| model.joints[i].upper);
        Ok(SphericalWristIk {
            axes,
            home_inverse: data.tool().inverse(),
            wrist_centre: centre,
            lower,
            upper,
        })
    }

    /// Every solution for the tool pose `target` (world frame), each joint value taken
    /// modulo 2π nearest `reference` within the limits. A wrist centre out of reach gives
    /// the nearest configurations instead, with [`Branch::reach_miss`] > 0. `reference`
    /// (6 values) also fixes the free angle at a singular configuration.
    pub fn solve(&self, target: &Pose<f64>, reference: &[f64]) -> Branches {
        let mut out = Branches {
            list: [Branch {
                q: [0.0; 6],
                config: [0; 3],
                within_limits: false,
                reach_miss: 0.0,
            }; 8],
            len: 0,
        };
        let g = target.compose(&self.home_inverse);
        let w = g.transform_point(&self.wrist_centre);
        let [a1, a2, a3, ..] = &self.axes;
        // Step 1: A cos q1 + B sin q1 = C.
        let v = w - a1.point;
        let u_par = a1.dir * a1.dir.dot(&a2.dir);
        let u_perp = a2.dir - u_par;
        let (a, b) = (v.dot(&u_perp), v.dot(&a1.dir.cross(&u_perp)));
        let c = a2.dir.dot(&(self.wrist_centre - a1.point)) - v.dot(&u_par);
        let rho = a.hypot(b);
        let shoulder_miss = (c.abs() - rho).max(0.0);
        let q1s: [f64; 2] = if rho <= LINE_TOLERANCE {
            [reference[0]; 2]
        } else {
            let d = (c / rho).clamp(-1.0, 1.0).acos();
            let phi = b.atan2(a);
            [phi + d, phi - d]
        };
        // Step 2 constants: subproblem 3 about axis 3 for the point c and the centre r₂.
        let p = perpendicular(&a3.dir, &(self.wrist_centre - a3.point));
        let r = perpendicular(&a3.dir, &(a2.point - a3.point));
        let axial = a3.dir.dot(&(self.wrist_centre - a2.point));
        let theta0 = rotation_angle(&a3.dir, &p, &r);
        // Step 4 needs R_w ω₆ and R_w e (e ⟂ ω₆), R_w = R₃ᵀR₂ᵀR₁ᵀR_g: rotate the vectors back.
        let e = perpendicular(&self.axes[5].dir, &self.axes[4].dir);
        let (g6, ge) = (g.rot * self.axes[5].dir, g.rot * e);
        for (shoulder, &q1) in q1s.iter().enumerate() {
            let back1 = inverse(q1.sin_cos());
            let w1 = a1.apply(back1, &w);
            let (g6, ge) = (rotate(&a1.dir, back1, &g6), rotate(&a1.dir, back1, &ge));
            let delta = ((w1 - a2.point).norm_squared() - axial * axial)
                .max(0.0)
                .sqrt();
            let (pn, rn) = (p.norm(), r.norm());
            // The elbow reaches distances from |p − r| (folded) to p + r (stretched).
            let elbow_miss = (delta - (pn + rn)).max((pn - rn).abs() - delta).max(0.0);
            let cos = (pn * pn + rn * rn - delta * delta) / (2.0 * pn * rn);
            // Beyond the stretched (cos < −1) or folded (cos > 1) elbow: bend off it.
            let d = if cos < -1.0 - COSINE_SLACK {
                PI - BOUNDARY_BEND
            } else if cos > 1.0 + COSINE_SLACK {
                BOUNDARY_BEND
            } else {
                cos.clamp(-1.0, 1.0).acos()
            };
            if !d.is_finite() {
                continue;
            }
            for (elbow, q3) in [theta0 - d, theta0 + d].into_iter().enumerate() {
                let sc3 = q3.sin_cos();
                let p3 = a3.apply(sc3, &self.wrist_centre);
                let q2 = rotation_angle(&a2.dir, &(p3 - a2.point), &(w1 - a2.point));
                let back2 = inverse(q2.sin_cos());
                let back =
                    |v: &Vector3<f64>| rotate(&a3.dir, inverse(sc3), &rotate(&a2.dir, back2, v));
                let (w6, we) = (back(&g6), back(&ge));
                for wrist in 0..2 {
                    let Some([q4, q5, q6]) = self.wrist(&w6, &we, &e, reference[3], wrist == 1)
                    else {
                        continue;
                    };
                    let raw = [q1, q2, q3, q4, q5, q6];
                    let mut q = [0.0; 6];
                    let mut within = true;
                    for i in 0..6 {
                        let (x, ok) = self.representative(i, raw[i], reference[i]);
                        q[i] = x;
                        within &= ok;
                    }
                    out.push(Branch {
                        q,
                        config: [shoulder as u8, elbow as u8, wrist as u8],
                        within_limits: within,
                        reach_miss: shoulder_miss.max(elbow_miss),
                    });
                }
            }
        }
        out
    }

    /// Steps 4–5: `R₄R₅R₆ = R_w`. Subproblem 2 (Murray et al. §2.3): `z = R₅ω₆ = R₄ᵀ R_w ω₆`
    /// satisfies ω₅·z = ω₅·ω₆ and ω₄·z = ω₄·(R_w ω₆), so
    /// `z = αω₄ + βω₅ ± γ(ω₄ × ω₅)` with `α = (c ω₅·p − ω₄·q)/(c² − 1)`,
    /// `β = (c ω₄·q − ω₅·p)/(c² − 1)`, `γ² = (|p|² − α² − β² − 2αβc)/|ω₄ × ω₅|²`,
    /// `c = ω₄·ω₅`, p = ω₆, q = R_w ω₆. Then q6 turns e into `R₅ᵀR₄ᵀ R_w e`; `rw_e` is
    /// `R_w e`.
    fn wrist(
        &self,
        q: &Vector3<f64>,
        rw_e: &Vector3<f64>,
        e: &Vector3<f64>,
        reference4: f64,
        flip: bool,
    ) -> Option<[f64; 3]> {
        let (u4, u5, u6) = (&self.axes[3].dir, &self.axes[4].dir, &self.axes[5].dir);
        let p = *u6;
        let c = u4.dot(u5);
        let denom = c * c - 1.0;
        let alpha = (c * u5.dot(&p) - u4.dot(q)) / denom;
        let beta = (c * u4.dot(q) - u5.dot(&p)) / denom;
        let n = u4.cross(u5);
        let gamma2 = (p.norm_squared() - alpha * alpha - beta * beta - 2.0 * alpha * beta * c)
            / n.norm_squared();
        if gamma2 < -COSINE_SLACK {
            return None;
        }
        let gamma = gamma2.max(0.0).sqrt() * if flip { -1.0 } else { 1.0 };
        let z = u4 * alpha + u5 * beta + n * gamma;
        // Axes 4 and 6 aligned (q ∥ ω₄): q4 is free; take the reference's.
        let q4 = if perpendicular(u4, q).norm() < ANGLE_TOLERANCE {
            reference4
        } else {
            rotation_angle(u4, &z, q)
        };
        let back4 = inverse(q4.sin_cos());
        let z = rotate(u4, back4, q);
        let q5 = rotation_angle(u5, &p, &z);
        let f = rotate(u5, inverse(q5.sin_cos()), &rotate(u4, back4, rw_e));
        let q6 = rotation_angle(u6, e, &f);
        Some([q4, q5, q6])
    }

    /// The value `theta + 2πk` within the limits of joint `i` nearest `reference`, and
    /// `true`; if no such value is within them, the one nearest the limits and `false`.
    fn representative(&self, i: usize, theta: f64, reference: f64) -> (f64, bool) {
        let (lo, hi) = (self.lower[i], self.upper[i]);
        let (tol, turn) = (1e-9, 2.0 * PI);
        // Nearest `reference`; the whole turns k with base + k·2π within [lo, hi] are
        // kmin ≤ k ≤ kmax, and the nearest of them to the reference is k = 0 clamped.
        let base = theta + turn * ((reference - theta) / turn).round();
        let kmin = ((lo - tol - base) / turn).ceil();
        let kmax = ((hi + tol - base) / turn).floor();
        if kmin <= kmax {
            return (base + turn * 0f64.clamp(kmin, kmax), true);
        }
        // None within: the value just below lo or just above hi, whichever is nearer.
        let (below, above) = (base + turn * kmax, base + turn * kmin);
        (
            if lo - below <= above - hi {
                below
            } else {
                above
            },
            false,
        )
    }
}
