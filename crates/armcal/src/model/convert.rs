//! Exact conversions between kinematic parameterisations. Every conversion returns a model
//! whose forward kinematics equal the input's for all joint values (to rounding):
//!
//! * [`dh_to_mdh`] / [`mdh_to_dh`]: standard DH `Rz(θ+q) Tz(d) Tx(a) Rx(α)` ⇄ Craig's
//!   modified DH `Rx(α) Tx(a) Rz(θ+q) Tz(d)`, by regrouping the chain
//!   `… [Rz Tz][Tx Rx][Rz Tz][Tx Rx] …` at the other bracket (`Tx(a)` and `Rx(α)` commute);
//! * [`to_zrp`]: any chain → zero-reference model / product of exponentials
//!   `T(q) = D₁(q₁) ⋯ Dₙ(qₙ) T₀` (book eq. 2.75), with the joint axes and T₀ read off at q = 0;
//! * [`zrp_to_dh`]: any chain (typically a zero-reference model) → DH, by the common normals
//!   of consecutive joint axes (book §6.3.4, eqs. 6.19–6.40), with Hayati links where a
//!   nominal model asks for them.
//!
//! Instrument and targets are copied unchanged: the tool frame is the same in both models.
//!
//! (Over 600 lines, ~75 of them tests: the three conversions share the frame
//! helpers `frame6_geometry`, `fixed_link` and `end_names`; apart they would need those
//! helpers public across files.)

use crate::model::chain::{LinkSpec, Model, ModelSpec};
use crate::model::kinematics::{forward_kinematics, Data};
use crate::model::link::{Convention, JointKind, LinkGeometry};
use crate::model::pose::{rot_x, rot_y, rot_z, Pose};
use crate::model::registry::Unit;
use crate::Error;
use nalgebra::Vector3;
use std::f64::consts::{FRAC_PI_2, PI};

/// Below this `|sin|` of the angle between consecutive axes, they are treated as parallel.
const PARALLEL: f64 = 1e-12;
/// Below this distance (mm), parallel axes are treated as coincident.
const COINCIDENT: f64 = 1e-9;
/// Hayati links need the next axis to cross the link's x–y plane: `|cos|` above this.
const HAYATI_MIN_COS: f64 = 1e-6;

/// `Tx(a) Rx(α)` (= `Rx(α) Tx(a)`): the part of a DH link that moves into the next MDH link.
fn x_screw(a: f64, alpha: f64) -> Pose<f64> {
    Pose {
        rot: rot_x(alpha),
        trans: Vector3::new(a, 0.0, 0.0),
    }
}

fn frame6_pose(g: &LinkGeometry) -> Pose<f64> {
    let v = &g.values;
    Pose::from_xyz_rpy([v[0], v[1], v[2]], [v[3], v[4], v[5]])
}

fn frame6_geometry(p: &Pose<f64>) -> LinkGeometry {
    let (xyz, rpy) = p.to_xyz_rpy();
    LinkGeometry::frame6(xyz, rpy)
}

/// Standard DH → Craig's modified DH. Each DH link `Rz(θ+q) Tz(d) Tx(a) Rx(α)` becomes the
/// MDH link `Rx(α′) Tx(a′) Rz(θ+q) Tz(d)` whose `α′, a′` are the previous DH link's `α, a`
/// (zero for the first one); the `Tx(a) Rx(α)` of a DH link followed by a fixed `frame6`
/// (typically the tool) is multiplied into that frame from the left. A revolute Hayati link
/// `Rz(θ+q) Tx(a) Rx(α) Ry(β)` (nearly parallel axes, book §2.6) regroups the same way with
/// `d = 0`: its `Tx(a) Rx(α) Ry(β) = Rx(α) Tx(a) Ry(β)` leads the next link, which becomes
/// the modified-DH link with β, `Rx(α) Tx(a) Ry(β) Rz(θ+q) Tz(d)` — so the modified-DH form
/// of a complete model is complete too, with no far common normal.
///
/// Errors when a DH or Hayati link with a non-zero trailing part is followed by anything but
/// a DH link or a fixed `frame6`, or ends the chain.
pub fn dh_to_mdh(spec: &ModelSpec) -> Result<ModelSpec, Error> {
    let mut links = Vec::with_capacity(spec.links.len());
    // The `Tx(a) Rx(α) Ry(β)` left over by the last DH or Hayati link (only when non-zero)
    // and its name.
    let mut pending: Option<(f64, f64, f64, &str)> = None;
    for l in &spec.links {
        let g = &l.geometry;
        let kind = l.joint.as_ref().map(|j| j.kind);
        let leftover = match (g.convention, kind) {
            (Convention::Dh, _) => Some((g.values[0], g.values[1], g.values[2], g.values[3], 0.0)),
            (Convention::Hayati, Some(JointKind::Revolute)) => {
                Some((g.values[0], 0.0, g.values[1], g.values[2], g.values[3]))
            }
            _ => None,
        };
        match leftover {
            Some((theta, d, a, alpha, beta)) => {
                let (a0, alpha0, beta0) = pending.map_or((0.0, 0.0, 0.0), |p| (p.0, p.1, p.2));
                let geometry = if beta0 == 0.0 {
                    LinkGeometry::mdh(alpha0, a0, theta, d)
                } else {
                    LinkGeometry::mdh_beta(alpha0, a0, beta0, theta, d)
                };
                links.push(LinkSpec {
                    geometry,
                    ..l.clone()
                });
                pending = (a != 0.0 || alpha != 0.0 || beta != 0.0).then_some((
                    a,
                    alpha,
                    beta,
                    l.name.as_str(),
                ));
            }
            None if g.convention == Convention::Frame6 && pending.is_some() => {
                let (a, alpha, beta, _) = pending.take().expect("checked");
                let screw = x_screw(a, alpha).compose(&Pose {
                    rot: rot_y(beta),
                    trans: Vector3::zeros(),
                });
                links.push(LinkSpec {
                    geometry: frame6_geometry(&screw.compose(&frame6_pose(g))),
                    ..l.clone()
                });
            }
            None => {
                if let Some((a, alpha, _, from)) = pending {
                    return Err(leftover_error(from, a, alpha, Some(l)));
                }
                links.push(l.clone());
            }
        }
    }
    if let Some((a, alpha, _, from)) = pending {
        return Err(leftover_error(from, a, alpha, None));
    }
    Ok(ModelSpec {
        compliance: None,
        periodic: None,
        payloads: Vec::new(),
        links,
        ..spec.clone()
    })
}

fn leftover_error(from: &str, a: f64, alpha: f64, next: Option<&LinkSpec>) -> Error {
    let what = match next {
        Some(l) => format!("is followed by `{}` ({})", l.name, l.geometry.convention),
        None => "ends the chain".into(),
    };
    Error::Conversion(format!(
        "DH link `{from}` leaves Tx(a) Rx(α) with a = {a} mm, α = {:.6}° for the next link, \
         but it {what}; only a DH link or a fixed frame6 can absorb it exactly",
        alpha.to_degrees()
    ))
}

/// Craig's modified DH → standard DH, the inverse regrouping of [`dh_to_mdh`]: each MDH link
/// `Rx(α) Tx(a) Rz(θ+q) Tz(d)` becomes the DH link `Rz(θ+q) Tz(d) Tx(a′) Rx(α′)` whose
/// `a′, α′` are the next MDH link's `a, α` (zero for the last one). The leading
/// `Rx(α) Tx(a)` of an MDH link that follows a fixed `frame6` (typically the base) is
/// multiplied into that frame from the right.
///
/// Errors when an MDH link with non-zero `α` or `a` follows anything but an MDH link or a
/// fixed `frame6`, or starts the chain.
pub fn mdh_to_dh(spec: &ModelSpec) -> Result<ModelSpec, Error> {
    let mut links: Vec<LinkSpec> = Vec::with_capacity(spec.links.len());
    // Whether the last output link is a DH link made from an MDH link, whose `Tx(a) Rx(α)`
    // is still free to take the next MDH link's `Rx(α) Tx(a)`.
    let mut open = false;
    for l in &spec.links {
        let g = &l.geometry;
        if g.convention != Convention::Mdh {
            links.push(l.clone());
            open = false;
            continue;
        }
        let (alpha, a, theta, d) = (g.values[0], g.values[1], g.values[2], g.values[3]);
        if alpha != 0.0 || a != 0.0 {
            match links.last_mut() {
                Some(prev) if open => {
                    prev.geometry.values[2] = a;
                    prev.geometry.values[3] = alpha;
                }
                Some(prev) if prev.geometry.convention == Convention::Frame6 => {
                    let p = frame6_pose(&prev.geometry).compose(&x_screw(a, alpha));
                    prev.geometry = frame6_geometry(&p);
                }
                prev => {
                    let what = prev.map_or("starts the chain".to_string(), |p| {
                        format!("follows `{}` ({})", p.name, p.geometry.convention)
                    });
                    return Err(Error::Conversion(format!(
                        "MDH link `{}` starts with Rx(α) Tx(a), α = {:.6}°, a = {a} mm, but it \
                         {what}; only an MDH link or a fixed frame6 before it can absorb it \
                         exactly",
                        l.name,
                        alpha.to_degrees()
                    )));
                }
            }
        }
        links.push(LinkSpec {
            geometry: LinkGeometry::dh(theta, d, 0.0, 0.0),
            ..l.clone()
        });
        open = true;
    }
    Ok(ModelSpec {
        compliance: None,
        periodic: None,
        payloads: Vec::new(),
        links,
        ..spec.clone()
    })
}

/// Names for the fixed frames at the ends: the input's own if its first/last link is fixed,
/// else `base` / `tool`.
fn end_names(spec: &ModelSpec) -> (String, String) {
    let fixed = |l: Option<&LinkSpec>, default: &str| {
        l.filter(|l| l.joint.is_none())
            .map_or(default.to_string(), |l| l.name.clone())
    };
    let base = fixed(spec.links.first(), "base");
    let tool = if spec.links.len() > 1 {
        fixed(spec.links.last(), "tool")
    } else {
        "tool".to_string()
    };
    (base, tool)
}

fn fixed_link(name: &str, geometry: LinkGeometry) -> LinkSpec {
    LinkSpec {
        name: name.into(),
        geometry,
        joint: None,
    }
}

/// A joint axis in the world at q = 0: direction (unit) and, for a revolute joint, the point
/// of the axis nearest the world origin.
pub(crate) struct Axis {
    pub(crate) kind: JointKind,
    pub(crate) dir: Vector3<f64>,
    pub(crate) point: Vector3<f64>,
}

/// The joint axes in the world and the world pose of the tool, at q = 0, of the chain alone
/// (joint corrections such as a compliance's deflection are not part of the link geometry and
/// ride along separately, [`crate::model::export::export_form`]). The world twist of
/// a revolute joint is `(ω, p × ω)` for any point `p` of its axis, so `ω × v / |ω|²` is the
/// axis point nearest the origin; a prismatic joint's twist is `(0, û)`.
pub(crate) fn axes_at_zero(model: &Model, params: &[f64]) -> (Vec<Axis>, Pose<f64>) {
    let mut data = Data::<f64>::without_corrections(model);
    forward_kinematics(model, &mut data, params, &vec![0.0; model.dof()]);
    let axes = model
        .joints
        .iter()
        .zip(&data.joint_twists)
        .map(|(j, tw)| match j.kind {
            JointKind::Revolute => {
                let n2 = tw.w.norm_squared();
                Axis {
                    kind: j.kind,
                    dir: tw.w / n2.sqrt(),
                    point: tw.w.cross(&tw.v) / n2,
                }
            }
            JointKind::Prismatic => Axis {
                kind: j.kind,
                dir: tw.v.normalize(),
                point: Vector3::zeros(),
            },
        })
        .collect();
    (axes, *data.tool())
}

/// Zero-reference model of any chain (book §2.8.2): `T(q) = D₁(q₁) ⋯ Dₙ(qₙ) T₀` (eq. 2.75)
/// with `Dᵢ = T(pᵢ) Rot(uᵢ, qᵢ) T(−pᵢ)` (eq. 2.72) for a revolute and `T(uᵢ qᵢ)` (eq. 2.74)
/// for a prismatic joint. `uᵢ` (unit) and `pᵢ` (the axis point nearest the world origin)
/// are the world joint axes at q = 0, read from the joint twists of
/// [`Data::joint_twists`]; offsets are 0 and `T₀` is the tool pose at q = 0. This is the
/// product-of-exponentials formula, so the forward kinematics are exact for all q.
///
/// The result has an identity `base` frame6, one `zrp` link per joint (named after the
/// input's joint links, with their joints and limits) and the `tool` frame6 `T₀`.
pub fn to_zrp(model: &Model, params: &[f64]) -> ModelSpec {
    let spec = model.spec_at(params);
    let (base, tool) = end_names(&spec);
    let (axes, t0) = axes_at_zero(model, params);
    let mut links = vec![fixed_link(&base, frame6_geometry(&Pose::identity()))];
    for (ls, axis) in spec.links.iter().filter(|l| l.joint.is_some()).zip(&axes) {
        let geometry = match axis.kind {
            JointKind::Revolute => LinkGeometry::zrp(axis.dir.into(), axis.point.into(), 0.0),
            JointKind::Prismatic => LinkGeometry::zrp(axis.dir.into(), [0.0; 3], 0.0),
        };
        links.push(LinkSpec {
            name: ls.name.clone(),
            geometry,
            joint: ls.joint.clone(),
        });
    }
    links.push(fixed_link(&tool, frame6_geometry(&t0)));
    ModelSpec {
        compliance: None,
        periodic: None,
        payloads: Vec::new(),
        name: spec.name,
        instrument: spec.instrument,
        links,
        targets: spec.targets,
    }
}

/// `a` wrapped into (−π, π].
pub(crate) fn wrap(a: f64) -> f64 {
    let w = (a + PI).rem_euclid(2.0 * PI) - PI;
    if w == -PI {
        PI
    } else {
        w
    }
}

/// Which link form a joint gets in [`zrp_to_dh`].
#[derive(Clone, Copy, PartialEq)]
enum Form {
    Dh,
    Hayati,
    BookType3,
}

/// Moves every angle of `g` by a multiple of 2π to lie within π of the same field of the
/// nominal link (same convention), so the values read like the nominal ones.
fn unwrap_towards(g: &mut LinkGeometry, nominal: Option<&LinkGeometry>, kind: Option<JointKind>) {
    let Some(n) = nominal.filter(|n| n.convention == g.convention) else {
        return;
    };
    for (i, (_, unit)) in g.convention.fields(kind).iter().enumerate() {
        if *unit == Unit::Rad && i < n.values.len() {
            g.values[i] = n.values[i] + wrap(g.values[i] - n.values[i]);
        }
    }
}

/// The world line of the next axis, as seen from `frame`: direction and a point. A
/// prismatic axis has no location; it is placed through the frame's origin.
fn axis_in(frame: &Pose<f64>, axis: &Axis) -> (Vector3<f64>, Vector3<f64>) {
    let rt = frame.rot.transpose();
    let u = rt * axis.dir;
    let p = match axis.kind {
        JointKind::Revolute => rt * (axis.point - frame.trans),
        JointKind::Prismatic => Vector3::zeros(),
    };
    (u, p)
}

/// DH link from the current frame (its z on the current axis) to the next axis (`u`, `p` in
/// the current frame), book eqs. 6.21–6.30: the common normal `r` from the z axis to the
/// next axis, `p = a₁ k + r + a₂ u` (6.21) with `r ⊥ k`, `r ⊥ u`; `d = a₁` (6.29), `x` along
/// `r`, `a = r·x` (signed, 6.30), `θ = atan2(x_y, x_x)` (6.27), `α` the angle from `k` to
/// `u` about `x` (6.28). The sign of `x` is chosen to keep θ within 90° of `theta_nom`
/// ("x chosen to keep θ near nominal, l signed").
///
/// Parallel axes have no unique common normal: armcal takes the one through the current
/// origin (`d = 0`); for coincident axes `x` is the nominal direction (`θ = theta_nom`,
/// `a = 0`). Nearly parallel axes give a far common normal (large `d`), the ill-conditioning
/// the Hayati form avoids.
fn dh_link(u: Vector3<f64>, p: Vector3<f64>, theta_nom: f64) -> LinkGeometry {
    let k = Vector3::z();
    let c = k.cross(&u);
    let s = c.norm();
    let (mut x, mut a, d) = if s > PARALLEL {
        let n = c / s;
        let l = p.dot(&n);
        let w = p - n * l;
        // w = a₁ k + a₂ u: dot with k and with u and solve (determinant 1 − (k·u)² = s²).
        let (ku, wu) = (u.z, w.dot(&u));
        (n, l, (w.z - ku * wu) / (s * s))
    } else {
        let r = Vector3::new(p.x, p.y, 0.0);
        let l = r.norm();
        if l > COINCIDENT {
            (r / l, l, 0.0)
        } else {
            (
                Vector3::new(theta_nom.cos(), theta_nom.sin(), 0.0),
                0.0,
                0.0,
            )
        }
    };
    let mut theta = x.y.atan2(x.x);
    if wrap(theta - theta_nom).abs() > FRAC_PI_2 {
        x = -x;
        a = -a;
        theta = x.y.atan2(x.x);
    }
    let alpha = c.dot(&x).atan2(u.z);
    LinkGeometry::dh(theta, d, a, alpha)
}

/// Hayati link `Rz(θ) Tx(l) Rx(α) Ry(β)` from the current frame to a nearly parallel next
/// axis, book eqs. 6.31–6.40: `r + a u = p` with `r·k = 0` (6.31–6.32) puts the next origin
/// where the next axis crosses the current x–y plane; `θ = atan2(r_y, r_x)` (6.40),
/// `l = |r|` (6.37), flipped together to keep θ within 90° of `theta_nom`; then with
/// `u″ = Rz(−θ) u = (sβ, −sα cβ, cα cβ)`, `α = atan2(−u″_y, u″_z)` and
/// `β = asin(u″_x)` (6.38–6.39).
pub(crate) fn hayati_link(
    u: Vector3<f64>,
    p: Vector3<f64>,
    theta_nom: f64,
    name: &str,
) -> Result<LinkGeometry, Error> {
    if u.z.abs() < HAYATI_MIN_COS {
        return Err(Error::Conversion(format!(
            "link `{name}`: the next joint axis is perpendicular to this one, a Hayati link \
             cannot reach it; use a DH link"
        )));
    }
    let r = p - u * (p.z / u.z);
    let mut l = r.norm();
    let mut theta = if l > COINCIDENT {
        r.y.atan2(r.x)
    } else {
        theta_nom
    };
    if wrap(theta - theta_nom).abs() > FRAC_PI_2 {
        theta = wrap(theta + PI);
        l = -l;
    }
    let uu = rot_z(-theta) * u;
    let alpha = (-uu.y).atan2(uu.z);
    let beta = uu.x.atan2(uu.y.hypot(uu.z));
    Ok(LinkGeometry::hayati(theta, l, alpha, beta))
}

/// The pose of a link geometry at q = 0 (a one-link model evaluated at its nominal values);
/// an error if the geometry is not a valid link (e.g. a conversion's value out of range).
pub(crate) fn link_pose(g: &LinkGeometry, kind: Option<JointKind>) -> Result<Pose<f64>, Error> {
    let joint = kind.map(|kind| crate::model::Joint {
        name: "q".into(),
        kind,
        lower: 0.0,
        upper: 0.0,
    });
    let spec = ModelSpec {
        compliance: None,
        periodic: None,
        payloads: Vec::new(),
        name: String::new(),
        instrument: None,
        links: vec![LinkSpec {
            name: "l".into(),
            geometry: g.clone(),
            joint,
        }],
        targets: vec![],
    };
    let model = Model::from_spec(&spec)
        .map_err(|e| Error::Conversion(format!("a converted link is not valid: {e}")))?;
    let mut data = Data::<f64>::new(&model);
    let q = vec![0.0; model.dof()];
    forward_kinematics(&model, &mut data, &model.nominal(), &q);
    Ok(*data.tool())
}

/// DH model of any serial chain, by the common normals of consecutive joint axes (book
/// §6.3.4; the book applies it to its zero-reference PUMA, Tables 6.7–6.10). The axes are
/// taken in the world at q = 0, so the θ (or, for prismatic joints, d) of each link is its
/// joint offset.
///
/// Output links, in order (the ends keep the names of the input's fixed end links, else
/// `base` and `tool`; joint links keep theirs):
/// * `base`: a fixed DH link from the world z axis to joint axis 1 (the book's `B→0`);
/// * one link per joint `i < n` from axis `i` to axis `i+1`, driven by joint `i`: DH
///   (eqs. 6.21–6.30), or Hayati (eqs. 6.31–6.40) where `nominal` has a Hayati link there or
///   a modified-DH link with β for joint `i+1`;
/// * the last joint: `Rz(θ+q)` as a DH link with `d = a = α = 0` and `θ` the nominal's, or,
///   if `nominal`'s last joint link is a book Type 3 (eq. 6.4), a Type 3 link that takes
///   the tool too;
/// * `tool`: the fixed frame6 that remains (identity after a Type 3 last link).
///
/// `nominal` (a model of the same robot with the same number of joints, e.g. Table 6.1)
/// also sets the sign rule: `x` is chosen to keep each θ within 90° of the nominal θ (0
/// without a nominal) and the length is signed accordingly; every angle is then moved by a
/// multiple of 2π next to the nominal's. Parallel axes take the common normal through the
/// current origin (`d = 0`), see `dh_link`. A prismatic axis, which has no location, is
/// placed through the previous frame's origin. Hayati and Type 3 forms are used for
/// revolute joints only.
///
/// Instrument and targets are copied; forward kinematics are exact for all q.
pub fn zrp_to_dh(spec: &ModelSpec, nominal: Option<&ModelSpec>) -> Result<ModelSpec, Error> {
    let model = Model::from_spec(spec)?;
    let params = model.nominal();
    let (axes, tool_world) = axes_at_zero(&model, &params);
    let n = axes.len();
    if n == 0 {
        return Err(Error::Conversion(format!(
            "model `{}` has no joint to build DH links on",
            spec.name
        )));
    }
    let joint_links: Vec<&LinkSpec> = spec.links.iter().filter(|l| l.joint.is_some()).collect();
    let nominal_base = nominal
        .and_then(|m| m.links.first())
        .filter(|l| l.joint.is_none())
        .map(|l| &l.geometry);
    let nominal_joints: Vec<&LinkSpec> = match nominal {
        Some(m) => {
            let v: Vec<&LinkSpec> = m.links.iter().filter(|l| l.joint.is_some()).collect();
            if v.len() != n {
                return Err(Error::Conversion(format!(
                    "nominal model `{}` has {} joints, `{}` has {n}",
                    m.name,
                    v.len(),
                    spec.name
                )));
            }
            v
        }
        None => Vec::new(),
    };
    let theta_of = |g: Option<&LinkGeometry>, kind: Option<JointKind>, field: &str| {
        g.and_then(|g| g.get(field, kind)).unwrap_or(0.0)
    };
    let (base_name, tool_name) = end_names(spec);

    let mut links = Vec::with_capacity(n + 2);
    let mut frame = Pose::identity();
    let (u, p) = axis_in(&frame, &axes[0]);
    let mut g = dh_link(u, p, theta_of(nominal_base, None, "theta"));
    unwrap_towards(&mut g, nominal_base, None);
    frame = frame.compose(&link_pose(&g, None)?);
    links.push(fixed_link(&base_name, g));

    for (i, (ls, axis)) in joint_links.iter().zip(&axes).enumerate() {
        let kind = axis.kind;
        let nominal_link = nominal_joints.get(i).map(|l| &l.geometry);
        // A modified-DH link with β after this joint marks the same nearly parallel pair.
        let next_has_beta = nominal_joints
            .get(i + 1)
            .is_some_and(|l| l.geometry.convention == Convention::MdhBeta);
        let form = match nominal_link.map(|g| g.convention) {
            Some(Convention::Hayati) if kind == JointKind::Revolute && i + 1 < n => Form::Hayati,
            Some(_) if next_has_beta && kind == JointKind::Revolute => Form::Hayati,
            Some(Convention::BookType3) if kind == JointKind::Revolute && i + 1 == n => {
                Form::BookType3
            }
            _ => Form::Dh,
        };
        let field = if form == Form::BookType3 {
            "tz"
        } else {
            "theta"
        };
        let theta_nom = theta_of(nominal_link, Some(kind), field);
        let mut g = match (axes.get(i + 1), form) {
            (Some(next), Form::Hayati) => {
                let (u, p) = axis_in(&frame, next);
                hayati_link(u, p, theta_nom, &ls.name)?
            }
            (Some(next), _) => {
                let (u, p) = axis_in(&frame, next);
                dh_link(u, p, theta_nom)
            }
            (None, Form::BookType3) => {
                book_type3_to(&frame.inverse().compose(&tool_world), theta_nom)
            }
            (None, _) => LinkGeometry::dh(theta_nom, 0.0, 0.0, 0.0),
        };
        unwrap_towards(&mut g, nominal_link, Some(kind));
        frame = frame.compose(&link_pose(&g, Some(kind))?);
        links.push(LinkSpec {
            name: ls.name.clone(),
            geometry: g,
            joint: ls.joint.clone(),
        });
    }
    links.push(fixed_link(
        &tool_name,
        frame6_geometry(&frame.inverse().compose(&tool_world)),
    ));
    Ok(ModelSpec {
        compliance: None,
        periodic: None,
        payloads: Vec::new(),
        name: spec.name.clone(),
        instrument: spec.instrument.clone(),
        links,
        targets: spec.targets.clone(),
    })
}

/// The book's Type 3 transform `Rz(θz) Ry(θy) Rx(θx) T(dx, dy, dz)` (eq. 6.4) equal to `m`:
/// the z–y–x angles of its rotation `R` (of the two solutions, the one with θz within 90°
/// of `tz_nom`) and `d = Rᵀ t`.
fn book_type3_to(m: &Pose<f64>, tz_nom: f64) -> LinkGeometry {
    let rot_only = Pose {
        rot: m.rot,
        trans: Vector3::zeros(),
    };
    let (_, [mut tx, mut ty, mut tz]) = rot_only.to_xyz_rpy();
    if wrap(tz - tz_nom).abs() > FRAC_PI_2 {
        // Rz(θz+π) Ry(π−θy) Rx(θx+π) is the same rotation.
        tx = wrap(tx + PI);
        ty = wrap(PI - ty);
        tz = wrap(tz + PI);
    }
    let d = m.rot.transpose() * m.trans;
    LinkGeometry::new(Convention::BookType3, vec![d.x, d.y, d.z, tx, ty, tz])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_is_half_open() {
        assert_eq!(wrap(PI), PI);
        assert_eq!(wrap(-PI), PI);
        assert!((wrap(3.0 * PI / 2.0) + FRAC_PI_2).abs() < 1e-15);
        assert!((wrap(-0.25) + 0.25).abs() < 1e-15);
    }

    #[test]
    fn book_type3_takes_the_solution_near_the_nominal() {
        let m = Pose {
            rot: rot_z(0.4) * rot_y(-0.3) * rot_x(1.2),
            trans: Vector3::new(10.0, -20.0, 30.0),
        };
        for (tz_nom, expected_tz) in [(0.0, 0.4), (PI, wrap(0.4 + PI))] {
            let g = book_type3_to(&m, tz_nom);
            assert!((g.values[5] - expected_tz).abs() < 1e-12, "{:?}", g.values);
            let p = link_pose(&g, None).unwrap();
            assert!((p.rot - m.rot).amax() < 1e-12 && (p.trans - m.trans).amax() < 1e-12);
        }
    }

    #[test]
    fn hayati_sign_rule_flips_theta_and_length_together() {
        // Next axis nearly parallel to z, crossing the x–y plane at (100, 20, 0).
        let u = Vector3::new(0.01, -0.02, 1.0).normalize();
        let p = Vector3::new(100.0, 20.0, 0.0) + u * 50.0;
        for theta_nom in [0.0, PI] {
            let g = hayati_link(u, p, theta_nom, "j").unwrap();
            let (theta, l) = (g.values[0], g.values[1]);
            assert!(wrap(theta - theta_nom).abs() <= FRAC_PI_2);
            assert!((l > 0.0) == (theta_nom == 0.0), "θ = {theta}, l = {l}");
            let f = link_pose(&g, Some(JointKind::Revolute)).unwrap();
            assert!((f.rot.column(2) - u).amax() < 1e-12, "z is the next axis");
            assert!((f.trans - Vector3::new(100.0, 20.0, 0.0)).amax() < 1e-9);
        }
        let e = hayati_link(Vector3::x(), p, 0.0, "j2")
            .unwrap_err()
            .to_string();
        assert!(e.contains("`j2`") && e.contains("perpendicular"), "{e}");
    }

    #[test]
    fn dh_link_reaches_the_next_axis() {
        // Skew, intersecting, parallel and coincident next axes.
        let cases = [
            (
                Vector3::new(0.3, -0.5, 0.8),
                Vector3::new(40.0, 70.0, -20.0),
            ),
            (Vector3::new(0.0, 1.0, 0.0), Vector3::new(0.0, 0.0, 30.0)),
            (Vector3::new(0.0, 0.0, -1.0), Vector3::new(-60.0, 80.0, 5.0)),
            (Vector3::new(0.0, 0.0, 1.0), Vector3::new(0.0, 0.0, 5.0)),
        ];
        for (u, p) in cases {
            let u = u.normalize();
            for theta_nom in [0.0, 2.5] {
                let g = dh_link(u, p, theta_nom);
                assert!(wrap(g.values[0] - theta_nom).abs() <= FRAC_PI_2);
                let f = link_pose(&g, Some(JointKind::Revolute)).unwrap();
                assert!((f.rot.column(2) - u).amax() < 1e-12, "z is the next axis");
                let off = f.trans - p;
                assert!(
                    (off - u * off.dot(&u)).amax() < 1e-9,
                    "origin on the next axis"
                );
            }
        }
    }
}
