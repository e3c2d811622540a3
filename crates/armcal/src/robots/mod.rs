//! Built-in robots: nominal geometry, joint limits, link capsules for collision checks, and
//! a note on where the numbers come from and what is approximate.
//!
//! A robot is a [`ModelSpec`] with base frame, links and tool frame (no instrument and no
//! targets: those belong to a cell). Lengths in mm, angles in rad, as everywhere inside
//! armcal.

pub mod bounding;
pub mod controller;
mod irb120;
mod kuka;
mod motoman;
mod paper;
pub mod puma560;
pub(crate) mod skeleton;
mod ur10;

use crate::model::{Joint, JointKind, LinkGeometry, LinkSpec, ModelSpec};
use crate::Error;
use serde::{Deserialize, Serialize};

/// A capsule (segment `a`–`b` swept by a sphere of `radius`) fixed to a chain frame, in that
/// frame's coordinates (mm).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Capsule {
    /// Name of the chain frame (`base`, `j1`, …, `tool`) the capsule moves with.
    pub frame: String,
    /// First end of the axis segment (mm, in `frame`).
    pub a: [f64; 3],
    /// Second end of the axis segment (mm, in `frame`).
    pub b: [f64; 3],
    /// Radius of the swept sphere (mm).
    pub radius: f64,
}

/// A robot of the library.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Robot {
    /// Library name (`armcal robots` lists them).
    pub name: String,
    /// One line: what the robot is.
    pub summary: String,
    /// Where the numbers come from and what is approximate.
    pub source: String,
    /// Base frame, links, tool frame; joint limits inside.
    pub spec: ModelSpec,
    /// Link capsules for collision checks.
    pub capsules: Vec<Capsule>,
    /// Where the capsules come from, in words (`plan` and `model` print it): hand-made, the
    /// cell's `[[robot.capsules]]`, the URDF's `<collision>` shapes or the skeleton
    /// (`skeleton`) with its radius.
    #[serde(default)]
    pub collision: String,
}

/// [`Robot::collision`] of the built-in robots.
pub(crate) const HAND_MADE: &str =
    "hand-made capsules of the built-in robot, sized from its outline drawings";

/// `capsules`, fixed to frames of `from`, re-expressed in the same-named frames of `to`, an
/// equivalent chain (same forward kinematics, e.g. [`crate::model::complete::in_form`]). A
/// frame of either chain moves with the body its last joint drives, so the transform
/// between the two frames of one name is constant; it is read at q = 0:
/// `p_to = T_to(0)⁻¹ T_from(0) p_from`. A frame `to` does not have is an error.
pub fn transfer_capsules(
    from: &crate::model::Model,
    to: &crate::model::Model,
    capsules: &[Capsule],
) -> Result<Vec<Capsule>, Error> {
    use crate::model::{forward_kinematics, Data};
    let q = vec![0.0; from.dof()];
    let frames = |m: &crate::model::Model| {
        let mut data = Data::new(m);
        forward_kinematics(m, &mut data, &m.nominal(), &q);
        data.frames
    };
    let (old, new) = (frames(from), frames(to));
    capsules
        .iter()
        .map(|c| {
            let missing = || {
                Error::Model(format!(
                    "capsule on frame `{}`: the converted chain has no frame of that name",
                    c.frame
                ))
            };
            let i = from.link_index(&c.frame).ok_or_else(missing)?;
            let j = to.link_index(&c.frame).ok_or_else(missing)?;
            let t = new[j].inverse().compose(&old[i]);
            let map = |p: [f64; 3]| {
                let v = t.transform_point(&nalgebra::Vector3::from(p));
                [v.x, v.y, v.z]
            };
            Ok(Capsule {
                a: map(c.a),
                b: map(c.b),
                ..c.clone()
            })
        })
        .collect()
}

/// Name and summary of every built-in robot.
pub(crate) fn list() -> Vec<(String, String)> {
    NAMES
        .iter()
        .map(|n| {
            let r = robot(n).expect("library robots build");
            (r.name, r.summary)
        })
        .collect()
}

/// Library names (the notional family also answers to `paper-<λ>-<μ>`).
pub const NAMES: &[&str] = &[
    "paper",
    "puma560",
    "puma560-zrp",
    "kr15",
    "kr300",
    "kr500",
    "irb120",
    "ur10",
    "motoman-right",
    "motoman-left",
];

/// A built-in robot by name.
pub fn robot(name: &str) -> Result<Robot, Error> {
    if let Some(rest) = name.strip_prefix("paper-") {
        let (l, m) = rest.split_once('-').ok_or_else(|| {
            Error::Input(format!(
                "`{name}`: the notional robot is named paper-<λ mm>-<μ mm>, e.g. paper-650-600"
            ))
        })?;
        let parse = |s: &str| {
            s.parse::<f64>()
                .map_err(|_| Error::Input(format!("`{name}`: `{s}` is not a length in mm")))
        };
        return Ok(paper::notional(parse(l)?, parse(m)?));
    }
    match name {
        "paper" => Ok(paper::notional(650.0, 600.0)),
        "puma560" => Ok(puma560::puma560()),
        "puma560-zrp" => Ok(puma560::puma560_zrp()),
        "kr15" => Ok(kuka::kr15()),
        "kr300" => Ok(kuka::kr300()),
        "kr500" => Ok(kuka::kr500()),
        "irb120" => Ok(irb120::irb120()),
        "ur10" => Ok(ur10::ur10()),
        "motoman-right" => Ok(motoman::motoman(motoman::Arm::Right)),
        "motoman-left" => Ok(motoman::motoman(motoman::Arm::Left)),
        _ => Err(Error::Input(format!(
            "unknown robot `{name}`; built-in robots: {}",
            NAMES.join(", ")
        ))),
    }
}

pub(crate) fn deg(x: f64) -> f64 {
    x.to_radians()
}

/// A revolute joint with limits in degrees.
pub(crate) fn revolute(name: &str, lower_deg: f64, upper_deg: f64) -> Joint {
    Joint {
        name: name.into(),
        kind: JointKind::Revolute,
        lower: deg(lower_deg),
        upper: deg(upper_deg),
    }
}

/// A link spec with a revolute joint `q<i>` named after the link `j<i>`.
pub(crate) fn joint_link(i: usize, geometry: LinkGeometry, limits_deg: (f64, f64)) -> LinkSpec {
    LinkSpec {
        name: format!("j{i}"),
        geometry,
        joint: Some(revolute(&format!("q{i}"), limits_deg.0, limits_deg.1)),
    }
}

/// A fixed frame link (base, tool) from xyz (mm) and roll-pitch-yaw (deg).
pub fn frame_link(name: &str, xyz: [f64; 3], rpy_deg: [f64; 3]) -> LinkSpec {
    LinkSpec {
        name: name.into(),
        geometry: LinkGeometry::frame6(xyz, rpy_deg.map(deg)),
        joint: None,
    }
}

pub(crate) fn capsule(frame: &str, a: [f64; 3], b: [f64; 3], radius: f64) -> Capsule {
    Capsule {
        frame: frame.into(),
        a,
        b,
        radius,
    }
}

/// Capsules along the two segments of a DH link `Rz(θ+q) Tz(d) Tx(a) Rx(α)`: from the
/// previous frame's origin along `z_{i−1}` by `d`, then along `x_i` by `a`. In the frame at the
/// end of the link those points are `(−a, −d sin α, −d cos α)`, `(−a, 0, 0)` and the origin
/// (θ and q do not enter). Zero-length segments are left out.
pub(crate) fn dh_capsules(frame: &str, d: f64, a: f64, alpha: f64, radius: f64) -> Vec<Capsule> {
    let start = [-a, -d * alpha.sin(), -d * alpha.cos()];
    let corner = [-a, 0.0, 0.0];
    let mut out = Vec::new();
    if d != 0.0 {
        out.push(capsule(frame, start, corner, radius));
    }
    if a != 0.0 {
        out.push(capsule(frame, corner, [0.0; 3], radius));
    }
    out
}
