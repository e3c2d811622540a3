//! The link form a calibration needs: complete and minimal (book §2.3 and §2.6, after
//! Hayati and Mirmirani; paper Table 2 does it at its joint 2).
//!
//! Standard DH places frame `i` on the common normal of axes `i` and `i+1`. When those axes
//! are parallel the common normal is anywhere along them; when they are *nearly* parallel a
//! tilt of δ moves it by about `a·δ / sin²α` along the axis, so `d` is ill-conditioned and a
//! rotation of the next axis about the link's `y` has no parameter at all: the model is not
//! complete and an identification loses a parameter (26 instead of 27 for position data of
//! a 6R arm with parallel shoulder and elbow, the rank deficit the book's §2.6 describes).
//! Hayati's form `Rz(θ+q) Tx(a) Rx(α) Ry(β)` replaces that `d` by the tilt `β` about `y`;
//! it is well conditioned exactly where DH is not (and ill-conditioned for perpendicular
//! axes, where DH is fine). Craig's modified DH has the same defect one link later; there
//! the link gets `Ry(β)` ([`Convention::MdhBeta`]).
//!
//! [`complete_minimal`] applies this to any chain, link by link, wherever two consecutive
//! revolute joint axes are within [`NEAR_PARALLEL_DEG`] of each other, and leaves
//! everything else as written. Every change is exact: the forward kinematics of the result
//! equal the input's at every joint configuration. [`in_form`] is the one entry point for
//! the link forms a cell can ask for (`[robot] convention = …`).

use crate::model::chain::{Model, ModelSpec};
use crate::model::convert::{self, axes_at_zero, hayati_link, link_pose};
use crate::model::link::{Convention, JointKind, LinkGeometry};
use crate::model::pose::{rot_z, Pose};
use crate::Error;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Two consecutive joint axes closer than this angle (degrees) count as nearly parallel and
/// get the Hayati / β form. Why 10°: the DH offset `d` of such a link moves by
/// `a / sin²α` per radian of axis tilt, which at 10° is 33·a — a 0.01° tilt of a 600 mm
/// link moves `d` by 3.5 mm, far beyond any real change of the robot — while Hayati's
/// parameters stay as well conditioned as at exactly parallel axes (`cos 10° = 0.985`
/// of the conditioning there). Real arms have their consecutive axes either parallel
/// (shoulder–elbow) or perpendicular, so any threshold between a few degrees and about
/// 30° makes the same choice on them; 10° keeps both forms far from their singularities.
pub const NEAR_PARALLEL_DEG: f64 = 10.0;

/// Below this `|sin α|` a revolute Hayati link's axes are exactly parallel, so a `Tz(s)` in
/// front of it commutes through `Rz Tx Rx(α)` into `Tz(s cos α)` after it (`dh_to_hayati`).
const EXACTLY_PARALLEL: f64 = 1e-12;

/// The link forms a cell can ask for (`[robot] convention`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LinkForm {
    /// The links as given, with the Hayati / β form wherever consecutive axes are nearly
    /// parallel (`complete_minimal`): complete and minimal. The default.
    Auto,
    /// The links exactly as the robot library or the cell file gives them.
    AsGiven,
    /// Standard DH links by the common normals of the joint axes (book §6.3.4), no Hayati
    /// links: incomplete across parallel axes.
    Dh,
    /// Craig's modified DH, from the DH form: incomplete across parallel axes.
    Mdh,
    /// The zero-reference model (book §2.8.2, product of exponentials).
    Zrp,
}

impl LinkForm {
    /// Every form, in declaration order (lists valid names in cell-file errors).
    pub const ALL: [LinkForm; 5] = [
        LinkForm::Auto,
        LinkForm::AsGiven,
        LinkForm::Dh,
        LinkForm::Mdh,
        LinkForm::Zrp,
    ];

    /// Kebab-case name used in cell files (`[robot] convention`) and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            LinkForm::Auto => "auto",
            LinkForm::AsGiven => "as-given",
            LinkForm::Dh => "dh",
            LinkForm::Mdh => "mdh",
            LinkForm::Zrp => "zrp",
        }
    }

    /// Inverse of [`LinkForm::name`]; `None` for an unknown name.
    pub fn from_name(s: &str) -> Option<LinkForm> {
        LinkForm::ALL.into_iter().find(|f| f.name() == s)
    }
}

/// One link whose form `complete_minimal` changed, and why.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FormChange {
    /// Name of the changed link.
    pub link: String,
    /// Its convention before the change (DH or MDH).
    pub from: Convention,
    /// Its convention after (Hayati or MDH with β).
    pub to: Convention,
    /// The joints whose axes are nearly parallel.
    pub joints: [String; 2],
    /// Angle between those two axes at q = 0 (deg).
    pub angle_deg: f64,
}

impl std::fmt::Display for FormChange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "link `{}`: {} → {} (axes of {} and {} are {:.2}° apart)",
            self.link, self.from, self.to, self.joints[0], self.joints[1], self.angle_deg
        )
    }
}

/// A chain in the form a cell asked for.
#[derive(Clone, Debug)]
pub struct Formed {
    /// The chain in the requested form, with the same forward kinematics as the input.
    pub spec: ModelSpec,
    /// Links whose convention changed, in chain order.
    pub changes: Vec<FormChange>,
    /// Nearly parallel axes left in an incomplete form, each as a sentence with its fix.
    pub incomplete: Vec<String>,
}

/// A pair of consecutive revolute joints (indices `i`, `i + 1`) whose axes, at q = 0 and the
/// model's nominal geometry, are within [`NEAR_PARALLEL_DEG`]; with the angle (rad) between
/// the lines (in [0, π/2]).
pub fn near_parallel_axes(model: &Model, params: &[f64]) -> Vec<(usize, f64)> {
    let (axes, _) = axes_at_zero(model, params);
    axes.windows(2)
        .enumerate()
        .filter(|(_, w)| w.iter().all(|a| a.kind == JointKind::Revolute))
        .map(|(i, w)| {
            let c = w[0].dir.dot(&w[1].dir).abs().min(1.0);
            (i, c.acos())
        })
        .filter(|&(_, angle)| angle < NEAR_PARALLEL_DEG.to_radians())
        .collect()
}

/// The chain in the requested form; forward kinematics unchanged. `Dh`, `Mdh` and `Zrp`
/// rebuild the chain from its joint axes ([`convert::zrp_to_dh`], [`convert::dh_to_mdh`],
/// [`convert::to_zrp`]): link names stay, the frames between the joints change.
pub fn in_form(spec: &ModelSpec, form: LinkForm) -> Result<Formed, Error> {
    let unchanged = |spec: ModelSpec| Formed {
        spec,
        changes: Vec::new(),
        incomplete: Vec::new(),
    };
    Ok(match form {
        LinkForm::Auto => complete_minimal(spec)?,
        LinkForm::AsGiven => unchanged(spec.clone()),
        LinkForm::Dh => unchanged(convert::zrp_to_dh(spec, None)?),
        LinkForm::Mdh => unchanged(convert::dh_to_mdh(&convert::zrp_to_dh(spec, None)?)?),
        LinkForm::Zrp => {
            let model = Model::from_spec(spec)?;
            unchanged(convert::to_zrp(&model, &model.nominal()))
        }
    })
}

/// The complete, minimal form of a chain: for every pair of consecutive revolute joints
/// `i`, `i+1` with nearly parallel axes ([`near_parallel_axes`]),
/// * the DH link of joint `i` (`Rz(θ+q) Tz(d) Tx(a) Rx(α)`, whose `Rx(α)` turns axis `i`
///   into axis `i+1`) becomes the Hayati link `Rz(θ′+q) Tx(a′) Rx(α′) Ry(β′)` that reaches
///   the same axis (book eqs. 6.31–6.40), and the next link takes the screw between the two
///   frames (see `dh_to_hayati`); for exactly parallel axes with `d = 0` the values are
///   simply `(θ, a, α, 0)`.
/// * the modified-DH link of joint `i+1` (`Rx(α) Tx(a) Rz(θ+q) Tz(d)`) becomes
///   `Rx(α) Tx(a) Ry(0) Rz(θ+q) Tz(d)`, the same transform.
///
/// A pair that cannot be changed exactly (a next link that cannot take the screw, or a link
/// form these rules do not cover) is left as it is and named in [`Formed::incomplete`] with
/// what to do.
pub fn complete_minimal(spec: &ModelSpec) -> Result<Formed, Error> {
    let model = Model::from_spec(spec)?;
    let pairs = near_parallel_axes(&model, &model.nominal());
    let joint_links: Vec<usize> = spec
        .links
        .iter()
        .enumerate()
        .filter(|(_, l)| l.joint.is_some())
        .map(|(k, _)| k)
        .collect();
    let mut out = spec.clone();
    let mut changes = Vec::new();
    let mut incomplete = Vec::new();
    for (i, angle) in pairs {
        let (k, next) = (joint_links[i], joint_links[i + 1]);
        let joints = [
            model.joints[i].name.clone(),
            model.joints[i + 1].name.clone(),
        ];
        let change = |link: &str, from, to| FormChange {
            link: link.to_string(),
            from,
            to,
            joints: joints.clone(),
            angle_deg: angle.to_degrees(),
        };
        let first = &out.links[k];
        let second = &out.links[next];
        let adjacent = next == k + 1;
        // A DH link's `Rx(α)` turns axis `i` into axis `i+1` when the next link turns about
        // the z it receives.
        let next_turns_about_z = matches!(
            second.geometry.convention,
            Convention::Dh | Convention::Hayati | Convention::SModel | Convention::BookType3
        );
        if first.geometry.convention == Convention::Dh && adjacent && next_turns_about_z {
            match dh_to_hayati(&out, k) {
                Some(formed) => {
                    changes.push(change(&first.name, Convention::Dh, Convention::Hayati));
                    out = formed;
                }
                None => incomplete.push(format!(
                    "the axes of {} and {} are {:.2}° apart, but the links after DH link `{}` \
                     cannot be re-expressed exactly in its Hayati frame; use `[robot] \
                     convention = \"zrp\"` (complete for any axes) or write `{}` as a \
                     \"hayati\" link and the next one to match",
                    joints[0],
                    joints[1],
                    angle.to_degrees(),
                    first.name,
                    first.name
                )),
            }
        } else if second.geometry.convention == Convention::Mdh && adjacent {
            let v = &second.geometry.values;
            let name = second.name.clone();
            out.links[next].geometry = LinkGeometry::mdh_beta(v[0], v[1], 0.0, v[2], v[3]);
            changes.push(change(&name, Convention::Mdh, Convention::MdhBeta));
        } else if matches!(first.geometry.convention, Convention::Dh | Convention::Mdh)
            && matches!(second.geometry.convention, Convention::Dh | Convention::Mdh)
        {
            incomplete.push(format!(
                "the axes of {} and {} are {:.2}° apart and links `{}` ({}) and `{}` ({}) have \
                 no parameter for the tilt between them; write `{}` as a \"hayati\" link or \
                 `{}` as \"mdh\" with `beta_deg`",
                joints[0],
                joints[1],
                angle.to_degrees(),
                first.name,
                first.geometry.convention,
                second.name,
                second.geometry.convention,
                first.name,
                second.name
            ));
        }
    }
    Ok(Formed {
        spec: out,
        changes,
        incomplete,
    })
}

/// `spec` with DH link `k` in Hayati form and the links after it re-expressed in its frame
/// (see [`complete_minimal`]); `None` when that cannot be done exactly.
///
/// The DH frame `k` and the Hayati frame `k′` both have their z axis on the next joint axis
/// and both move with joint `k`, so `F = T_{k′}⁻¹ T_k` is a constant screw along that axis,
/// `F = Rz(φ) Tz(s)`. The next link takes it in front: `Rz(φ)` into its θ and `Tz(s)` into
/// its `d` when it begins `Rz(θ+q) Tz(d)` (DH, S-model, prismatic Hayati); a frame6 or URDF
/// origin takes all of `F`; a revolute Hayati link takes `Rz(φ)` into θ and passes `Tz(s)`
/// on as `Tz(s cos α)` when its own axes are exactly parallel (α = 0 or π, β = 0).
fn dh_to_hayati(spec: &ModelSpec, k: usize) -> Option<ModelSpec> {
    let g = &spec.links[k].geometry;
    let kind = spec.links[k].joint.as_ref().map(|j| j.kind);
    let dh = link_pose(g, kind).ok()?;
    let next_axis = dh.rot * Vector3::z();
    let hayati = hayati_link(next_axis, dh.trans, g.values[0], &spec.links[k].name).ok()?;
    let f = link_pose(&hayati, kind).ok()?.inverse().compose(&dh);
    let screw = (f.rot[(2, 2)] - 1.0).abs() < 1e-12 && f.trans.xy().norm() < 1e-9;
    if !screw {
        return None;
    }
    let (mut phi, mut s) = (f.rot[(1, 0)].atan2(f.rot[(0, 0)]), f.trans.z);
    let mut out = spec.clone();
    out.links[k].geometry = hayati;
    for l in out.links.iter_mut().skip(k + 1) {
        let g = &mut l.geometry;
        let kind = l.joint.as_ref().map(|j| j.kind);
        match (g.convention, kind) {
            (Convention::Hayati, Some(JointKind::Revolute)) => {
                g.values[0] += phi;
                phi = 0.0;
                if s == 0.0 {
                    return Some(out);
                }
                let (alpha, beta) = (g.values[2], g.values[3]);
                if alpha.sin().abs() > EXACTLY_PARALLEL || beta != 0.0 {
                    return None;
                }
                s *= alpha.cos().round();
            }
            (Convention::Dh | Convention::SModel | Convention::Hayati, _) => {
                g.values[0] += phi;
                g.values[1] += s;
                return Some(out);
            }
            (Convention::Frame6 | Convention::Urdf, _) => {
                let v = &g.values;
                let origin = Pose::from_xyz_rpy([v[0], v[1], v[2]], [v[3], v[4], v[5]]);
                let screw = Pose {
                    rot: rot_z(phi),
                    trans: Vector3::new(0.0, 0.0, s),
                };
                let (xyz, rpy) = screw.compose(&origin).to_xyz_rpy();
                g.values[..6].copy_from_slice(&[xyz[0], xyz[1], xyz[2], rpy[0], rpy[1], rpy[2]]);
                return Some(out);
            }
            _ => return None,
        }
    }
    None
}
