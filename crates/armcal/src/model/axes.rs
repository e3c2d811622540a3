//! Joint-axis identification by circle point analysis (book §4.6, after Stone): a target on
//! the arm is measured while one joint moves and the others stand still. A revolute joint
//! moves the target on a circle whose normal through its centre is the joint axis; a
//! prismatic joint moves it on a line parallel to the joint axis. From the axes found
//! with every other joint at its zero reference, the zero-reference model (book §2.8.2)
//! follows directly ([`axes_to_zrp`]), from it the DH model ([`axes_to_dh`], by
//! [`convert::zrp_to_dh`]), and Stone's S-model from frames placed on the axes
//! ([`axes_to_s_model`], book §4.6.5.1).
//!
//! Fits (all in the measuring instrument's frame, mm):
//! * [`fit_plane`]: total least squares plane through the centred points (SVD, book
//!   §4.6.2's principal axis method);
//! * [`fit_circle`]: plane fit, then the algebraic (Kåsa) circle in the plane — linear least
//!   squares on `x² + y² + D x + E y + F = 0` — refined by Gauss–Newton on the geometric
//!   distances `|pᵢ − c| − r` in the plane. Kåsa alone is biased towards small radii on a
//!   short, noisy arc; the geometric refinement removes that bias. (Stone's formulation,
//!   book eqs. 4.284–4.290, minimises the 3-D distance to the circle with the plane and
//!   sphere constraints; the plane-then-circle fit used here coincides with it for
//!   noise-free points and is close to it for small noise.)
//! * [`fit_line`]: total least squares line (first principal axis).

use crate::model::chain::{LinkSpec, Model, ModelSpec};
use crate::model::convert;
use crate::model::link::{Convention, Joint, JointKind, LinkGeometry};
use crate::model::pose::Pose;
use crate::Error;
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

/// A circle in space.
#[derive(Clone, Debug, PartialEq)]
pub struct Circle {
    pub centre: Vector3<f64>,
    /// Unit normal, oriented so that the points, in the order given, turn positively
    /// (right-handed) about it.
    pub normal: Vector3<f64>,
    pub radius: f64,
    /// RMS distance of the points from the circle (in-plane and out-of-plane parts), mm.
    pub rms: f64,
}

/// Centroid and right singular vectors of the centred points, with singular values in
/// descending order.
fn principal_axes(points: &[Vector3<f64>]) -> (Vector3<f64>, [Vector3<f64>; 3], [f64; 3]) {
    let n = points.len();
    let centroid = points.iter().sum::<Vector3<f64>>() / n as f64;
    // Zero rows (for fewer than 3 points) change neither singular vectors nor values.
    let m = DMatrix::from_fn(n.max(3), 3, |i, j| {
        if i < n {
            points[i][j] - centroid[j]
        } else {
            0.0
        }
    });
    let svd = m.svd(false, true);
    let vt = svd.v_t.expect("computed");
    let sv = &svd.singular_values;
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| sv[b].total_cmp(&sv[a]));
    let vec = |k: usize| Vector3::new(vt[(k, 0)], vt[(k, 1)], vt[(k, 2)]);
    (
        centroid,
        [vec(order[0]), vec(order[1]), vec(order[2])],
        [sv[order[0]], sv[order[1]], sv[order[2]]],
    )
}

fn check_finite(points: &[Vector3<f64>], min: usize, what: &str) -> Result<(), Error> {
    if points.len() < min {
        return Err(Error::Input(format!(
            "{what} needs at least {min} points, got {}",
            points.len()
        )));
    }
    if let Some(i) = points.iter().position(|p| !p.iter().all(|x| x.is_finite())) {
        return Err(Error::Input(format!(
            "{what}: point {} is not finite",
            i + 1
        )));
    }
    Ok(())
}

/// Total least squares plane: `(unit normal, centroid, rms distance)`. The normal is the
/// right singular vector of the smallest singular value of the centred points; its sign is
/// arbitrary. Needs at least 3 points.
pub fn fit_plane(points: &[Vector3<f64>]) -> Result<(Vector3<f64>, Vector3<f64>, f64), Error> {
    check_finite(points, 3, "a plane fit")?;
    let (centroid, axes, s) = principal_axes(points);
    Ok((axes[2], centroid, s[2] / (points.len() as f64).sqrt()))
}

/// Total least squares line: `(unit direction, point, rms distance)`. The point is the
/// centroid; the direction is oriented from the first point towards the last. Needs at
/// least 2 distinct points.
pub fn fit_line(points: &[Vector3<f64>]) -> Result<(Vector3<f64>, Vector3<f64>, f64), Error> {
    check_finite(points, 2, "a line fit")?;
    let (centroid, axes, s) = principal_axes(points);
    if s[0] <= 0.0 {
        return Err(Error::Input("a line fit needs two distinct points".into()));
    }
    let mut d = axes[0];
    if d.dot(&(points[points.len() - 1] - points[0])) < 0.0 {
        d = -d;
    }
    let rms = (s[1] * s[1] + s[2] * s[2]).sqrt() / (points.len() as f64).sqrt();
    Ok((d, centroid, rms))
}

/// Circle through points in space: plane fit, algebraic (Kåsa) circle in the plane, then
/// at most 20 Gauss–Newton steps on the in-plane geometric distance (see the module
/// documentation). The normal is oriented so that consecutive points turn positively about
/// it. Needs at least 3 points that are not collinear.
pub fn fit_circle(points: &[Vector3<f64>]) -> Result<Circle, Error> {
    check_finite(points, 3, "a circle fit")?;
    let n = points.len();
    let (centroid, axes, s) = principal_axes(points);
    if s[1] <= 1e-12 * s[0].max(f64::MIN_POSITIVE) {
        return Err(Error::Input(
            "a circle fit needs points that are not collinear".into(),
        ));
    }
    let (e1, e2, mut normal) = (axes[0], axes[1], axes[2]);
    let xy: Vec<(f64, f64)> = points
        .iter()
        .map(|p| {
            let d = p - centroid;
            (d.dot(&e1), d.dot(&e2))
        })
        .collect();
    // Kåsa: x² + y² + D x + E y + F = 0, linear least squares.
    let a = DMatrix::from_fn(n, 3, |i, j| match j {
        0 => xy[i].0,
        1 => xy[i].1,
        _ => 1.0,
    });
    let b = DVector::from_fn(n, |i, _| -(xy[i].0 * xy[i].0 + xy[i].1 * xy[i].1));
    let sol = a
        .svd(true, true)
        .solve(&b, 1e-14)
        .map_err(|e| Error::Input(format!("circle fit: {e}")))?;
    let (mut cx, mut cy) = (-sol[0] / 2.0, -sol[1] / 2.0);
    let r2 = cx * cx + cy * cy - sol[2];
    if !(r2 > 0.0 && r2.is_finite()) {
        return Err(Error::Input(
            "circle fit: the points do not lie near a circle".into(),
        ));
    }
    let mut r = r2.sqrt();
    // Gauss–Newton on dᵢ = |(xᵢ, yᵢ) − c| − r.
    for _ in 0..20 {
        let mut jtj = Matrix3::zeros();
        let mut jtd = Vector3::zeros();
        for &(x, y) in &xy {
            let (dx, dy) = (x - cx, y - cy);
            let rho = (dx * dx + dy * dy).sqrt();
            if rho == 0.0 {
                continue;
            }
            let j = Vector3::new(-dx / rho, -dy / rho, -1.0);
            jtj += j * j.transpose();
            jtd += j * (rho - r);
        }
        let Some(step) = jtj.cholesky().map(|c| c.solve(&(-jtd))) else {
            break;
        };
        cx += step[0];
        cy += step[1];
        r += step[2];
        if step.norm() <= 1e-15 * (r + cx.abs() + cy.abs()) {
            break;
        }
    }
    let centre = centroid + e1 * cx + e2 * cy;
    let turn: Vector3<f64> = points
        .windows(2)
        .map(|w| (w[0] - centre).cross(&(w[1] - centre)))
        .sum();
    if turn.dot(&normal) < 0.0 {
        normal = -normal;
    }
    let ss: f64 = points
        .iter()
        .map(|p| {
            let d = p - centre;
            let h = d.dot(&normal);
            let rho = (d - normal * h).norm();
            h * h + (rho - r) * (rho - r)
        })
        .sum();
    Ok(Circle {
        centre,
        normal,
        radius: r,
        rms: (ss / n as f64).sqrt(),
    })
}

/// Measurements of one joint's motion: full joint vectors in which only `joint` varies,
/// and the measured target position (instrument frame, mm) at each.
#[derive(Clone, Debug, PartialEq)]
pub struct JointSweep {
    /// Index of the swept joint (0-based).
    pub joint: usize,
    pub q: Vec<Vec<f64>>,
    pub points: Vec<Vector3<f64>>,
}

/// One identified joint axis, in the instrument frame, valid for the configuration
/// `reference` of the other joints.
#[derive(Clone, Debug, PartialEq)]
pub struct JointAxis {
    /// Name of the joint's link in the model (e.g. `j3`).
    pub link: String,
    pub joint: Joint,
    /// Unit direction: a positive joint motion turns positively about it (revolute) or
    /// moves along it (prismatic).
    pub direction: Vector3<f64>,
    /// A point on the axis: the circle centre (revolute) or the centroid of the points
    /// (prismatic: the line has no location that matters).
    pub point: Vector3<f64>,
    /// Unit vector perpendicular to `direction`: from the centre towards the point of the
    /// lowest joint value, projected on the plane of rotation (revolute, book eq. 4.299), or
    /// any perpendicular (prismatic). The x axis of the joint's S-model frame.
    pub x_axis: Vector3<f64>,
    /// Circle radius (revolute) or 0 (prismatic), mm.
    pub radius: f64,
    /// RMS residual of the circle or line fit, mm.
    pub rms: f64,
    /// The joint vector of the sweep with the swept joint set to 0: the configuration the
    /// axis belongs to.
    pub reference: Vec<f64>,
}

/// The axes of all joints, in joint order.
#[derive(Clone, Debug, PartialEq)]
pub struct AxesResult {
    pub model: String,
    pub axes: Vec<JointAxis>,
}

/// Identifies every joint axis of `model` from one sweep per joint (circle point analysis,
/// book §4.6.3–4.6.4). The points of each sweep are sorted by the joint value, so the
/// direction is signed by the positive joint motion; a revolute sweep needs at least 3
/// distinct joint values, a prismatic one 2.
///
/// The points of joint i's sweep are measured with the other joints at the sweep's values,
/// so the axis found is joint i's axis *in that configuration* (`JointAxis::reference`).
/// For a zero-reference model ([`axes_to_zrp`]) every joint must be swept with all others
/// at 0; sweeps made in the book's sequential way (joints j+1… at arbitrary values) still
/// give correct axes here, but only those with the others at 0 build a zero-reference model.
///
/// Errors: a joint not swept or swept twice, mismatched lengths, a joint vector of the
/// wrong size, another joint that moves during a sweep, or a degenerate fit.
pub fn identify_axes(model: &Model, sweeps: &[JointSweep]) -> Result<AxesResult, Error> {
    let dof = model.dof();
    let mut found: Vec<Option<JointAxis>> = vec![None; dof];
    for (k, s) in sweeps.iter().enumerate() {
        let what = format!("sweep {} (joint {})", k + 1, s.joint + 1);
        if s.joint >= dof {
            return Err(Error::Input(format!(
                "{what}: model `{}` has {dof} joints",
                model.name
            )));
        }
        if found[s.joint].is_some() {
            return Err(Error::Input(format!("{what}: joint swept twice")));
        }
        if s.q.len() != s.points.len() {
            return Err(Error::Input(format!(
                "{what}: {} joint vectors but {} points",
                s.q.len(),
                s.points.len()
            )));
        }
        if s.q.is_empty() {
            return Err(Error::Input(format!("{what}: no measurements")));
        }
        let mut reference = s.q[0].clone();
        if reference.len() != dof {
            return Err(Error::Input(format!(
                "{what}: joint vectors need {dof} values, got {}",
                reference.len()
            )));
        }
        reference[s.joint] = 0.0;
        for (i, q) in s.q.iter().enumerate() {
            if q.len() != dof {
                return Err(Error::Input(format!(
                    "{what}: joint vector {} has {} values, the model {dof}",
                    i + 1,
                    q.len()
                )));
            }
            if !q.iter().all(|v| v.is_finite()) {
                return Err(Error::Input(format!(
                    "{what}: joint vector {} is not finite",
                    i + 1
                )));
            }
            if let Some(j) = (0..dof).find(|&j| j != s.joint && q[j] != reference[j]) {
                return Err(Error::Input(format!(
                    "{what}: joint {} moves ({} then {}); only the swept joint may move",
                    j + 1,
                    reference[j],
                    q[j]
                )));
            }
        }
        let mut order: Vec<usize> = (0..s.q.len()).collect();
        order.sort_by(|&a, &b| s.q[a][s.joint].total_cmp(&s.q[b][s.joint]));
        let pts: Vec<Vector3<f64>> = order.iter().map(|&i| s.points[i]).collect();
        let distinct = order
            .windows(2)
            .filter(|w| s.q[w[0]][s.joint] != s.q[w[1]][s.joint])
            .count()
            + 1;
        let joint = model.joints[s.joint].clone();
        let link = model
            .links
            .iter()
            .find(|l| l.joint == Some(s.joint))
            .map(|l| l.spec.name.clone())
            .unwrap_or_else(|| format!("j{}", s.joint + 1));
        let axis = match joint.kind {
            JointKind::Revolute => {
                if distinct < 3 {
                    return Err(Error::Input(format!(
                        "{what}: a revolute joint needs at least 3 distinct joint values"
                    )));
                }
                let c = fit_circle(&pts).map_err(|e| Error::Input(format!("{what}: {e}")))?;
                let d = pts[0] - c.centre;
                JointAxis {
                    link,
                    joint,
                    x_axis: (d - c.normal * d.dot(&c.normal)).normalize(),
                    direction: c.normal,
                    point: c.centre,
                    radius: c.radius,
                    rms: c.rms,
                    reference,
                }
            }
            JointKind::Prismatic => {
                if distinct < 2 {
                    return Err(Error::Input(format!(
                        "{what}: a prismatic joint needs at least 2 distinct joint values"
                    )));
                }
                let (d, p, rms) =
                    fit_line(&pts).map_err(|e| Error::Input(format!("{what}: {e}")))?;
                JointAxis {
                    link,
                    joint,
                    x_axis: any_perpendicular(&d),
                    direction: d,
                    point: p,
                    radius: 0.0,
                    rms,
                    reference,
                }
            }
        };
        found[s.joint] = Some(axis);
    }
    let axes = found
        .into_iter()
        .enumerate()
        .map(|(j, a)| a.ok_or_else(|| Error::Input(format!("joint {} was not swept", j + 1))))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(AxesResult {
        model: model.name.clone(),
        axes,
    })
}

/// Tolerance on the other joints being at the zero reference (rad or mm).
const AT_ZERO: f64 = 1e-12;

/// Errors unless every axis was swept with all other joints at 0.
fn check_zero_reference(axes: &AxesResult) -> Result<(), Error> {
    for (i, a) in axes.axes.iter().enumerate() {
        if let Some(j) = a.reference.iter().position(|v| v.abs() > AT_ZERO) {
            return Err(Error::Input(format!(
                "joint {} was swept with joint {} at {} instead of 0: a model at the zero \
                 reference needs every joint swept with all others at 0",
                i + 1,
                j + 1,
                a.reference[j]
            )));
        }
    }
    Ok(())
}

/// A unit vector perpendicular to the unit vector `d`.
fn any_perpendicular(d: &Vector3<f64>) -> Vector3<f64> {
    let e = if d.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    (e - d * d.dot(&e)).normalize()
}

/// Zero-reference model from the identified axes: identity `base` frame6, one `zrp` link
/// per joint (axis `u` = direction, `p` = the axis point, offset 0) and the `tool` frame6
/// `tool_pose_at_zero`, the measured target frame at q = 0. Its world is the instrument
/// frame the points were measured in, so the spec has no instrument and no targets.
///
/// Errors unless every axis was swept with all other joints at 0 (see [`identify_axes`]).
pub fn axes_to_zrp(axes: &AxesResult, tool_pose_at_zero: &Pose<f64>) -> Result<ModelSpec, Error> {
    let mut links = vec![LinkSpec {
        name: "base".into(),
        geometry: LinkGeometry::frame6([0.0; 3], [0.0; 3]),
        joint: None,
    }];
    check_zero_reference(axes)?;
    for a in &axes.axes {
        let p = match a.joint.kind {
            JointKind::Revolute => a.point.into(),
            JointKind::Prismatic => [0.0; 3],
        };
        links.push(LinkSpec {
            name: a.link.clone(),
            geometry: LinkGeometry::zrp(a.direction.into(), p, 0.0),
            joint: Some(a.joint.clone()),
        });
    }
    let (xyz, rpy) = tool_pose_at_zero.to_xyz_rpy();
    links.push(LinkSpec {
        name: "tool".into(),
        geometry: LinkGeometry::frame6(xyz, rpy),
        joint: None,
    });
    let spec = ModelSpec {
        name: format!("{}-cpa", axes.model),
        instrument: None,
        links,
        targets: vec![],
    };
    Model::from_spec(&spec)?;
    Ok(spec)
}

/// Below this `sin α` consecutive S-model z axes are treated as parallel.
const S_PARALLEL: f64 = 1e-9;

/// Stone's S-model link parameters `(β, r, l, α, γ, b)` of a relative transform
/// `B = Rz(β) Tz(r) Tx(l) Rx(α) Rz(γ) Tz(b)` (book eq. 4.304 with `Tz(b)`, errata 8).
/// With the next z axis not parallel (`sin α` above [`S_PARALLEL`]), β and γ come from
/// the third row and column of the rotation (eqs. 4.314–4.316, 4.310, 4.313) and `r, l, b`
/// from `p = r z + l Rz(β) x + b a`; with parallel z axes `b = 0`, `l` is the in-plane
/// distance and β its direction (the common normal through the origin).
fn s_model_params(b: &Pose<f64>) -> [f64; 6] {
    let (n, a, p) = (b.rot.column(0), b.rot.column(2), b.trans);
    let sin_alpha = a.x.hypot(a.y);
    let alpha = sin_alpha.atan2(a.z);
    if sin_alpha > S_PARALLEL {
        let beta = a.x.atan2(-a.y);
        let gamma = n.z.atan2(b.rot[(2, 1)]);
        let xb = Vector3::new(beta.cos(), beta.sin(), 0.0);
        let m = Matrix3::from_columns(&[Vector3::z(), xb, a.into_owned()]);
        let rlb = m.lu().solve(&p).unwrap_or_else(Vector3::zeros);
        return [beta, rlb[0], rlb[1], alpha, gamma, rlb[2]];
    }
    // Rz(β) Rx(α) Rz(γ) with α = 0 or π: the x column turns by β + γ or β − γ.
    let l = p.x.hypot(p.y);
    let beta = if l > 0.0 { p.y.atan2(p.x) } else { 0.0 };
    let nx = n.y.atan2(n.x);
    let gamma = if a.z > 0.0 { nx - beta } else { beta - nx };
    [beta, p.z, l, alpha, gamma, 0.0]
}

/// Stone's S-model from the identified axes (book §4.6.5.1): frame j on axis j with its
/// origin at the circle centre (prismatic: the mean point), z along the signed axis and x
/// towards the first measured point ([`JointAxis::x_axis`]); `base` is the fixed frame6 of
/// frame 1 in the instrument frame (the book's `B₀ B₁`), each joint link the S-model link
/// `Sⱼ⁻¹ Sⱼ₊₁` (eq. 4.302) and the last joint's link `Sₙ⁻¹ T₀` to the measured target frame
/// at q = 0 (`tool_pose_at_zero`), followed by an identity `tool`. Forward kinematics are
/// exact for all q. Errors unless every axis was swept with all other joints at 0.
pub fn axes_to_s_model(
    axes: &AxesResult,
    tool_pose_at_zero: &Pose<f64>,
) -> Result<ModelSpec, Error> {
    check_zero_reference(axes)?;
    let frames: Vec<Pose<f64>> = axes
        .axes
        .iter()
        .map(|a| {
            let z = a.direction.normalize();
            let x = (a.x_axis - z * a.x_axis.dot(&z)).normalize();
            Pose {
                rot: Matrix3::from_columns(&[x, z.cross(&x), z]),
                trans: a.point,
            }
        })
        .collect();
    let Some(first) = frames.first() else {
        return Err(Error::Input("no joint axes to build an S-model on".into()));
    };
    let frame6 = |name: &str, pose: &Pose<f64>| {
        let (xyz, rpy) = pose.to_xyz_rpy();
        LinkSpec {
            name: name.into(),
            geometry: LinkGeometry::frame6(xyz, rpy),
            joint: None,
        }
    };
    let mut links = vec![frame6("base", first)];
    for (i, a) in axes.axes.iter().enumerate() {
        let next = frames.get(i + 1).unwrap_or(tool_pose_at_zero);
        let rel = frames[i].inverse().compose(next);
        links.push(LinkSpec {
            name: a.link.clone(),
            geometry: LinkGeometry::new(Convention::SModel, s_model_params(&rel).to_vec()),
            joint: Some(a.joint.clone()),
        });
    }
    links.push(frame6("tool", &Pose::identity()));
    let spec = ModelSpec {
        name: format!("{}-cpa-s", axes.model),
        instrument: None,
        links,
        targets: vec![],
    };
    Model::from_spec(&spec)?;
    Ok(spec)
}

/// DH model from the identified axes: [`axes_to_zrp`] then [`convert::zrp_to_dh`] (with
/// `nominal` choosing Hayati links and the signs, as there).
pub fn axes_to_dh(
    axes: &AxesResult,
    tool_pose_at_zero: &Pose<f64>,
    nominal: Option<&ModelSpec>,
) -> Result<ModelSpec, Error> {
    convert::zrp_to_dh(&axes_to_zrp(axes, tool_pose_at_zero)?, nominal)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::kinematics::{forward_kinematics, tool_pose, Data};
    use crate::robots;
    use crate::sim::{perturbed_truth, Perturbation};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    /// The paper robot with a point target 300 mm off the flange and off axis 6.
    fn paper_with_target() -> Model {
        let mut spec = robots::robot("paper").unwrap().spec;
        spec.targets.push(LinkSpec {
            name: "smr".into(),
            geometry: LinkGeometry::point([120.0, -80.0, 300.0]),
            joint: None,
        });
        Model::from_spec(&spec).unwrap()
    }

    /// Sweeps every joint over ±30° (clamped to its limits) in 15 steps, others at 0.
    fn sweeps(model: &Model, truth: &[f64], sigma: f64, seed: u64) -> Vec<JointSweep> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let normal = Normal::new(0.0, 1.0).unwrap();
        let mut data = Data::<f64>::new(model);
        let (lo, hi) = model.joint_limits();
        (0..model.dof())
            .map(|j| {
                let a = lo[j].max(-30f64.to_radians());
                let b = hi[j].min(30f64.to_radians());
                let mut s = JointSweep {
                    joint: j,
                    q: vec![],
                    points: vec![],
                };
                for i in 0..15 {
                    let mut q = vec![0.0; model.dof()];
                    q[j] = a + (b - a) * i as f64 / 14.0;
                    forward_kinematics(model, &mut data, truth, &q);
                    let noise = Vector3::from_fn(|_, _| sigma * normal.sample(&mut rng));
                    s.points.push(data.targets[0].trans + noise);
                    s.q.push(q);
                }
                s
            })
            .collect()
    }

    /// True axes at q = 0: direction `w`, point `w × v / |w|²`.
    fn true_axes(model: &Model, truth: &[f64]) -> Vec<(Vector3<f64>, Vector3<f64>)> {
        let mut data = Data::<f64>::new(model);
        forward_kinematics(model, &mut data, truth, &vec![0.0; model.dof()]);
        data.joint_twists
            .iter()
            .map(|t| {
                let n2 = t.w.norm_squared();
                (t.w / n2.sqrt(), t.w.cross(&t.v) / n2)
            })
            .collect()
    }

    /// (angle between directions, distance of the fitted point from the true line).
    fn axis_errors(a: &JointAxis, t: &(Vector3<f64>, Vector3<f64>)) -> (f64, f64) {
        let angle = a.direction.cross(&t.0).norm().atan2(a.direction.dot(&t.0));
        let dist = (a.point - t.1).cross(&t.0).norm();
        (angle, dist)
    }

    fn target_at_zero(model: &Model, truth: &[f64]) -> Pose<f64> {
        let mut data = Data::<f64>::new(model);
        forward_kinematics(model, &mut data, truth, &vec![0.0; model.dof()]);
        data.targets[0]
    }

    /// Largest FK difference (mm; rotation matrices, Frobenius ≈ √2 × angle) between `spec`'s tool and the truth's target.
    fn fk_error(model: &Model, truth: &[f64], spec: &ModelSpec) -> (f64, f64) {
        let m = Model::from_spec(spec).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let (lo, hi) = model.joint_limits();
        let mut data = Data::<f64>::new(model);
        let (mut dp, mut dr) = (0.0f64, 0.0f64);
        for _ in 0..50 {
            let q: Vec<f64> = (0..model.dof())
                .map(|j| rng.random_range(lo[j]..=hi[j]))
                .collect();
            forward_kinematics(model, &mut data, truth, &q);
            let t = data.targets[0];
            let p = tool_pose(&m, &m.nominal(), &q);
            dp = dp.max((p.trans - t.trans).norm());
            // Frobenius norm: `rotation_angle_to` (an arccos) bottoms out near 1e-8.
            dr = dr.max((p.rot - t.rot).norm());
        }
        (dp, dr)
    }

    fn truth(model: &Model) -> Vec<f64> {
        let p = Perturbation {
            all: true,
            ..Default::default()
        };
        perturbed_truth(model, &p, 11)
    }

    #[test]
    fn noise_free_axes_are_exact_and_rebuild_the_robot() {
        let model = paper_with_target();
        let truth = truth(&model);
        let result = identify_axes(&model, &sweeps(&model, &truth, 0.0, 1)).unwrap();
        let t = true_axes(&model, &truth);
        for (a, t) in result.axes.iter().zip(&t) {
            let (angle, dist) = axis_errors(a, t);
            eprintln!(
                "noise-free {}: angle {angle:.2e} rad, distance {dist:.2e} mm, r {:.1} mm, rms {:.1e}",
                a.link, a.radius, a.rms
            );
            assert!(angle < 1e-9 && dist < 1e-9, "{}: {angle} {dist}", a.link);
        }
        let tool = target_at_zero(&model, &truth);
        let zrp = axes_to_zrp(&result, &tool).unwrap();
        let (dp, dr) = fk_error(&model, &truth, &zrp);
        eprintln!("noise-free ZRP FK error: {dp:.2e} mm, {dr:.2e} rad");
        assert!(dp < 1e-6 && dr < 1e-9, "{dp} {dr}");
        let nominal = robots::robot("paper").unwrap().spec;
        let dh = axes_to_dh(&result, &tool, Some(&nominal)).unwrap();
        let (dp, dr) = fk_error(&model, &truth, &dh);
        eprintln!("noise-free DH FK error: {dp:.2e} mm, {dr:.2e} rad");
        assert!(dp < 1e-6 && dr < 1e-9, "{dp} {dr}");
        let sm = axes_to_s_model(&result, &tool).unwrap();
        let (dp, dr) = fk_error(&model, &truth, &sm);
        eprintln!("noise-free S-model FK error: {dp:.2e} mm, {dr:.2e} rad");
        assert!(dp < 1e-6 && dr < 1e-9, "{dp} {dr}");
    }

    /// Linearised precision of a circle fit with n points of noise σ per coordinate on an
    /// arc: the plane tilts about the chord by ≈ σ/s₂ and the centre moves along the arc's
    /// bisector by ≈ σ r/s₂, where s₂ = √n × (RMS in-plane spread of the points across the
    /// chord) is the second singular value of the centred points (the centre and radius
    /// columns of the geometric Jacobian differ only by that spread). For ±30°, 15 points,
    /// r = 300 mm: s₂ ≈ 45 mm, σ = 0.01 → 2e-4 rad, 0.07 mm. The test allows 5 of these
    /// (and √2 for the distance, which has a tilt and an in-plane part).
    #[test]
    fn noisy_axes_are_within_their_precision() {
        let model = paper_with_target();
        let truth = truth(&model);
        let sigma = 0.01;
        let sw = sweeps(&model, &truth, sigma, 2);
        let result = identify_axes(&model, &sw).unwrap();
        let t = true_axes(&model, &truth);
        for ((a, t), s) in result.axes.iter().zip(&t).zip(&sw) {
            let (_, _, sv) = principal_axes(&s.points);
            let (angle, dist) = axis_errors(a, t);
            let angle_bound = 5.0 * sigma / sv[1];
            let dist_bound = 5.0 * 2f64.sqrt() * sigma * a.radius / sv[1];
            eprintln!(
                "σ = {sigma} mm {}: angle {angle:.2e} rad (bound {angle_bound:.2e}), distance \
                 {dist:.2e} mm (bound {dist_bound:.2e}), rms {:.2e} mm",
                a.link, a.rms
            );
            assert!(angle < angle_bound, "{}: angle {angle}", a.link);
            assert!(dist < dist_bound, "{}: distance {dist}", a.link);
            assert!(a.rms < 3.0 * sigma, "{}: rms {}", a.link, a.rms);
        }
        let tool = target_at_zero(&model, &truth);
        let nominal = robots::robot("paper").unwrap().spec;
        for (what, spec) in [
            ("ZRP", axes_to_zrp(&result, &tool).unwrap()),
            ("DH", axes_to_dh(&result, &tool, Some(&nominal)).unwrap()),
            ("S-model", axes_to_s_model(&result, &tool).unwrap()),
        ] {
            let (dp, dr) = fk_error(&model, &truth, &spec);
            eprintln!("σ = {sigma} mm {what} FK error (exact tool at 0): {dp:.3} mm, {dr:.2e}");
        }
    }

    #[test]
    fn circle_sign_follows_point_order() {
        let pts: Vec<Vector3<f64>> = (0..5)
            .map(|i| {
                let a = 0.3 * i as f64;
                Vector3::new(1.0 + 2.0 * a.cos(), 2.0 * a.sin(), 3.0)
            })
            .collect();
        let c = fit_circle(&pts).unwrap();
        assert!((c.normal - Vector3::z()).norm() < 1e-12);
        assert!((c.centre - Vector3::new(1.0, 0.0, 3.0)).norm() < 1e-12);
        assert!((c.radius - 2.0).abs() < 1e-12);
        let rev: Vec<_> = pts.iter().rev().copied().collect();
        assert!((fit_circle(&rev).unwrap().normal + Vector3::z()).norm() < 1e-12);
        assert!(fit_circle(&pts[..2]).is_err());
        let line: Vec<_> = (0..4).map(|i| Vector3::new(i as f64, 0.0, 0.0)).collect();
        assert!(fit_circle(&line).is_err());
        let (d, _, rms) = fit_line(&line).unwrap();
        assert!((d - Vector3::x()).norm() < 1e-12 && rms < 1e-12);
        let (n, c, rms) = fit_plane(&pts).unwrap();
        assert!(n.cross(&Vector3::z()).norm() < 1e-12 && (c.z - 3.0).abs() < 1e-12);
        assert!(rms < 1e-12);
    }

    #[test]
    fn prismatic_axis_and_zero_reference_check() {
        let spec = ModelSpec {
            name: "rp".into(),
            instrument: None,
            links: vec![
                LinkSpec {
                    name: "base".into(),
                    geometry: LinkGeometry::frame6([0.0; 3], [0.0; 3]),
                    joint: None,
                },
                LinkSpec {
                    name: "j1".into(),
                    geometry: LinkGeometry::zrp([0.1, 0.0, 1.0], [10.0, 20.0, 0.0], 0.0),
                    joint: Some(Joint {
                        name: "q1".into(),
                        kind: JointKind::Revolute,
                        lower: -3.0,
                        upper: 3.0,
                    }),
                },
                LinkSpec {
                    name: "j2".into(),
                    geometry: LinkGeometry::zrp([1.0, 0.2, 0.1], [0.0; 3], 0.0),
                    joint: Some(Joint {
                        name: "d2".into(),
                        kind: JointKind::Prismatic,
                        lower: -500.0,
                        upper: 500.0,
                    }),
                },
                LinkSpec {
                    name: "tool".into(),
                    geometry: LinkGeometry::frame6([300.0, 50.0, 40.0], [0.1, 0.2, 0.3]),
                    joint: None,
                },
            ],
            targets: vec![],
        };
        let model = Model::from_spec(&spec).unwrap();
        let params = model.nominal();
        let sweep = |j: usize, vals: &[f64], other: f64| {
            let q: Vec<Vec<f64>> = vals
                .iter()
                .map(|&v| {
                    let mut q = vec![other; 2];
                    q[j] = v;
                    q
                })
                .collect();
            let points = q
                .iter()
                .map(|q| tool_pose(&model, &params, q).trans)
                .collect();
            JointSweep {
                joint: j,
                q,
                points,
            }
        };
        // Joint values out of order: the sign comes from the joint values, not the order.
        let sw = vec![
            sweep(0, &[0.2, -0.3, 0.0, 0.4], 0.0),
            sweep(1, &[50.0, -20.0, 10.0], 0.0),
        ];
        let r = identify_axes(&model, &sw).unwrap();
        let t = true_axes(&model, &params);
        assert!(axis_errors(&r.axes[0], &t[0]).0 < 1e-12);
        assert!(axis_errors(&r.axes[0], &t[0]).1 < 1e-9);
        let d = r.axes[1].direction;
        assert!((d - Vector3::new(1.0, 0.2, 0.1).normalize()).norm() < 1e-12);
        let zrp = axes_to_zrp(&r, &tool_pose(&model, &params, &[0.0, 0.0])).unwrap();
        let m = Model::from_spec(&zrp).unwrap();
        let s =
            Model::from_spec(&axes_to_s_model(&r, &tool_pose(&model, &params, &[0.0; 2])).unwrap())
                .unwrap();
        for q in [[0.5, 100.0], [-1.0, -30.0]] {
            let a = tool_pose(&m, &m.nominal(), &q);
            let b = tool_pose(&model, &params, &q);
            assert!((a.trans - b.trans).norm() < 1e-9);
            let c = tool_pose(&s, &s.nominal(), &q);
            assert!((c.trans - b.trans).norm() < 1e-9 && (c.rot - b.rot).norm() < 1e-12);
        }
        // Swept with the other joint away from zero: axes come out, a ZRP build refuses.
        let sw = vec![
            sweep(0, &[0.2, -0.3, 0.0], 0.0),
            sweep(1, &[50.0, -20.0, 10.0], 0.5),
        ];
        let r = identify_axes(&model, &sw).unwrap();
        assert!(axes_to_zrp(&r, &Pose::identity()).is_err());
        assert!(axes_to_s_model(&r, &Pose::identity()).is_err());
        // Another joint moving within a sweep, a missing joint.
        let mut bad = sweep(0, &[0.2, -0.3, 0.0], 0.0);
        bad.q[1][1] = 1.0;
        assert!(identify_axes(&model, &[bad, sweep(1, &[1.0, 2.0], 0.0)]).is_err());
        assert!(identify_axes(&model, &[sweep(1, &[1.0, 2.0], 0.0)]).is_err());
    }
}
