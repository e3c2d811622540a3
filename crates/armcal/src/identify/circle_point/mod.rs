//! Joint-axis identification by circle point analysis (book §4.6, after Stone): a target on
//! the arm is measured while one joint moves and the others stand still. A revolute joint
//! moves the target on a circle whose normal through its centre is the joint axis; a
//! prismatic joint moves it on a line parallel to the joint axis. From the axes found
//! with every other joint at its zero reference, the zero-reference model (book §2.8.2)
//! follows directly ([`axes_to_zrp`]), from it the DH model ([`axes_to_dh`], by
//! [`convert::zrp_to_dh`]), and Stone's S-model from frames placed on the axes
//! ([`axes_to_s_model`], book §4.6.5.1).
//!
//! The plane, circle and line fits and the covariance of a fitted axis are geometry:
//! `crate::geometry::fit`.

pub(crate) mod record;

use crate::geometry::fit::{fit_circle, fit_line, planned_circle_covariance, AxisCovariance};
use crate::model::chain::{LinkSpec, Model, ModelSpec};
use crate::model::convert;
use crate::model::link::{Convention, Joint, JointKind, LinkGeometry};
use crate::model::pose::Pose;
use crate::Error;
use nalgebra::{Matrix3, Vector3};

/// The shortest sweep (rad, at most a full turn) of `n` evenly spread points at radius `r`
/// and noise σ whose planned σ's (`planned_circle_covariance`) are within
/// [`MAX_SIGMA_DIRECTION_DEG`] and [`MAX_SIGMA_POINT_MM`]; `None` if not even a full turn
/// reaches them. Bisection to 0.1°, the σ's falling with the span.
pub fn span_for_limits(r: f64, n: usize, sigma: f64) -> Option<f64> {
    let within = |span: f64| {
        planned_circle_covariance(r, n, span, sigma).is_some_and(|c| {
            c.sigma_direction() <= MAX_SIGMA_DIRECTION_DEG.to_radians()
                && c.sigma_point() <= MAX_SIGMA_POINT_MM
        })
    };
    let full = 2.0 * std::f64::consts::PI * (n.max(2) - 1) as f64 / n.max(2) as f64;
    if !within(full) {
        return None;
    }
    let (mut lo, mut hi) = (0.0, full);
    while hi - lo > 0.1f64.to_radians() {
        let mid = 0.5 * (lo + hi);
        if within(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

/// Measurements of one joint's motion: full joint vectors in which only `joint` varies,
/// and the measured target position (instrument frame, mm) at each.
#[derive(Clone, Debug, PartialEq)]
pub struct JointSweep {
    /// Index of the swept joint (0-based).
    pub joint: usize,
    /// Full joint vector of each measurement (rad, mm).
    pub q: Vec<Vec<f64>>,
    /// Measured target position at each joint vector (instrument frame, mm).
    pub points: Vec<Vector3<f64>>,
}

/// One identified joint axis, in the instrument frame, valid for the configuration
/// `reference` of the other joints.
#[derive(Clone, Debug, PartialEq)]
pub struct JointAxis {
    /// Name of the joint's link in the model (e.g. `j3`).
    pub link: String,
    /// The model's joint: name, kind and limits.
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
    /// Number of points of the sweep.
    pub points: usize,
    /// Range of the swept joint's values (largest − smallest), rad or mm.
    pub span: f64,
    /// Linearised covariance of `direction` and `point` in the basis (`x_axis`,
    /// `direction × x_axis`); `None` for an exact fit (3 points on a circle, 2 on a line).
    pub covariance: Option<AxisCovariance>,
    /// Why the axis is not to be trusted, how badly, and what to do ([`trust_warning`]);
    /// `None` for a trustworthy axis.
    pub warning: Option<String>,
}

/// The axes of all joints, in joint order.
#[derive(Clone, Debug, PartialEq)]
pub struct AxesResult {
    /// Name of the model the axes were identified for.
    pub model: String,
    /// One axis per joint, in joint order.
    pub axes: Vec<JointAxis>,
}

impl AxesResult {
    /// The warnings of the axes not to be trusted, in joint order.
    pub fn warnings(&self) -> impl Iterator<Item = &str> {
        self.axes.iter().filter_map(|a| a.warning.as_deref())
    }
}

/// A revolute sweep shorter than this (deg) gets a warning even when its σ's are small: the
/// axis then rests on the arc's sagitta `r (1 − cos(span/2))` (3.4 % of the radius at 30°),
/// and its σ's grow like 1/span² (the points' spread across the chord, which fixes the
/// plane's tilt and the centre, is ≈ 0.15 r θ² √n for a half-span θ), so a systematic point
/// error `e` that the residuals do not show (a target mount's eccentricity, a wobbling
/// joint) tilts the axis by ≈ e / sagitta rad, unseen by the σ's.
pub const MIN_REVOLUTE_SPAN_DEG: f64 = 30.0;
/// Largest RMS direction error of a trustworthy axis, deg (9 mm at 1 m).
pub const MAX_SIGMA_DIRECTION_DEG: f64 = 0.5;
/// Largest RMS error of a trustworthy revolute axis' position across the axis, mm.
pub const MAX_SIGMA_POINT_MM: f64 = 2.0;
/// Largest residual RMS per radius of a trustworthy revolute axis: above it the target is
/// too close to the axis for the noise.
pub const MAX_RMS_PER_RADIUS: f64 = 0.01;
/// Fewest degrees of freedom of σ̂ for a trustworthy σ: σ̂²ν/σ² is χ²(ν), so σ̂ is uncertain
/// by ≈ ±1/√(2ν) (±25 % at ν = 8).
pub const MIN_NOISE_DOF: usize = 8;

/// The warning for an axis not to be trusted, or `None`: an exact fit (no σ), a σ of the
/// direction above [`MAX_SIGMA_DIRECTION_DEG`] or of the point above [`MAX_SIGMA_POINT_MM`]
/// (revolute; a prismatic axis' location does not matter), σ̂ from fewer than
/// [`MIN_NOISE_DOF`] degrees of freedom, a revolute sweep shorter than
/// [`MIN_REVOLUTE_SPAN_DEG`], or a residual RMS above [`MAX_RMS_PER_RADIUS`] of the radius.
/// It names the joint, the sweep, the σ's against their limits and the remedies, sized to
/// reach the limits with the same σ̂: the sweep from the planned σ's ([`span_for_limits`]),
/// a prismatic travel by σ ∝ 1/travel, the points by σ ∝ 1/√n (exact for repeated poses),
/// and — when only the direction is over its limit — the target's distance from the axis by
/// σ_dir ∝ 1/radius (exact: scaling the points by k scales the normal's columns of `J` by k
/// and leaves the centre's and the radius' alone).
pub fn trust_warning(a: &JointAxis) -> Option<String> {
    let revolute = a.joint.kind == JointKind::Revolute;
    let (span, unit) = if revolute {
        (a.span.to_degrees(), "°")
    } else {
        (a.span, " mm")
    };
    let (params, what) = if revolute { (6, "circle") } else { (4, "line") };
    // Points for ν = 2n − params ≥ MIN_NOISE_DOF.
    let min_points = (MIN_NOISE_DOF + params).div_ceil(2);
    let mut problems = Vec::new();
    let mut fixes = Vec::new();
    let mut sigmas = String::new();
    match &a.covariance {
        None => {
            problems.push(format!(
                "{} points fit a {what} exactly, so neither the noise nor the σ's can be estimated",
                a.points
            ));
            fixes.push(format!("measure at least {min_points} points"));
        }
        Some(cov) => {
            let sd = cov.sigma_direction().to_degrees();
            let sp = cov.sigma_point();
            sigmas = format!(", σ direction {sd:.3}°");
            if revolute {
                sigmas += &format!(", σ point across the axis {sp:.3} mm");
            }
            let k_dir = sd / MAX_SIGMA_DIRECTION_DEG;
            let k_point = if revolute {
                sp / MAX_SIGMA_POINT_MM
            } else {
                0.0
            };
            if k_dir > 1.0 {
                problems.push(format!(
                    "σ direction {sd:.3}° is {k_dir:.1} × the limit {MAX_SIGMA_DIRECTION_DEG}°"
                ));
            }
            if k_point > 1.0 {
                problems.push(format!(
                    "σ point {sp:.3} mm is {k_point:.1} × the limit {MAX_SIGMA_POINT_MM} mm"
                ));
            }
            let k = k_dir.max(k_point);
            if k > 1.0 {
                let mut ways = vec![
                    if !revolute {
                        format!("a travel of about {:.0} mm (σ ∝ 1/travel)", span * k)
                    } else if let Some(s) = span_for_limits(a.radius, a.points, cov.sigma_noise) {
                        format!(
                            "a sweep of {:.0}° with as many points",
                            s.to_degrees().ceil()
                        )
                    } else {
                        "(not even a full turn with as many points)".into()
                    },
                    format!(
                        "about {:.0} points (σ ∝ 1/√n)",
                        (a.points as f64 * k * k).ceil()
                    ),
                ];
                if revolute && k_point <= 1.0 {
                    ways.push(format!(
                        "a target about {:.0} mm from the axis (σ direction ∝ 1/radius)",
                        a.radius * k_dir
                    ));
                }
                fixes.push(format!("to reach the limits: {}", ways.join(", or ")));
            }
            if cov.dof < MIN_NOISE_DOF {
                problems.push(format!(
                    "σ̂ = {:.3} mm rests on {} degrees of freedom (±{:.0} %)",
                    cov.sigma_noise,
                    cov.dof,
                    100.0 / (2.0 * cov.dof as f64).sqrt()
                ));
                fixes.push(format!("measure at least {min_points} points"));
            }
        }
    }
    if revolute && span < MIN_REVOLUTE_SPAN_DEG {
        let sagitta = a.radius * (1.0 - (a.span / 2.0).cos());
        problems.push(format!(
            "the sweep is shorter than {MIN_REVOLUTE_SPAN_DEG}°: the axis rests on the arc's \
             {sagitta:.2} mm sagitta, so a systematic point error of e mm that the residuals do \
             not show tilts it by about e/{sagitta:.2} rad"
        ));
        fixes.push(format!("sweep at least {MIN_REVOLUTE_SPAN_DEG}°"));
    }
    if revolute && a.rms > MAX_RMS_PER_RADIUS * a.radius {
        problems.push(format!(
            "the residual RMS is {:.1} % of the radius (limit {:.0} %)",
            100.0 * a.rms / a.radius,
            100.0 * MAX_RMS_PER_RADIUS
        ));
        fixes.push("put the target farther from the axis".into());
    }
    if problems.is_empty() {
        return None;
    }
    let radius = if revolute {
        format!(", radius {:.1} mm", a.radius)
    } else {
        String::new()
    };
    Some(format!(
        "{} axis not to be trusted ({} points over {span:.1}{unit}{radius}, residual RMS {:.3} mm{sigmas}): {}. Remedy: {}.",
        a.joint.name,
        a.points,
        a.rms,
        problems.join("; "),
        fixes.join("; ")
    ))
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
/// Each axis carries the linearised covariance of its fit (`AxisCovariance`) and, if it
/// is not to be trusted, a warning ([`trust_warning`]).
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
        let span = s.q[order[order.len() - 1]][s.joint] - s.q[order[0]][s.joint];
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
                JointAxis {
                    link,
                    joint,
                    x_axis: c.x_axis,
                    direction: c.normal,
                    point: c.centre,
                    radius: c.radius,
                    rms: c.rms,
                    reference,
                    points: pts.len(),
                    span,
                    covariance: c.covariance,
                    warning: None,
                }
            }
            JointKind::Prismatic => {
                if distinct < 2 {
                    return Err(Error::Input(format!(
                        "{what}: a prismatic joint needs at least 2 distinct joint values"
                    )));
                }
                let l = fit_line(&pts).map_err(|e| Error::Input(format!("{what}: {e}")))?;
                JointAxis {
                    link,
                    joint,
                    x_axis: l.x_axis,
                    direction: l.direction,
                    point: l.point,
                    radius: 0.0,
                    rms: l.rms,
                    reference,
                    points: pts.len(),
                    span,
                    covariance: l.covariance,
                    warning: None,
                }
            }
        };
        let warning = trust_warning(&axis);
        found[s.joint] = Some(JointAxis { warning, ..axis });
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
        compliance: None,
        periodic: None,
        payloads: Vec::new(),
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
        compliance: None,
        periodic: None,
        payloads: Vec::new(),
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
mod tests;
