//! URDF import and export (urdf-rs 0.10).
//!
//! **Import** ([`read_urdf`], [`from_urdf_str`], [`from_urdf_robot`]) takes the serial chain
//! from the root link (the one link that is no joint's child) to a tip link (by default the
//! single leaf). Every joint on it becomes one link of the model, named after the URDF joint
//! (`.` and `*`, which armcal reserves for parameter patterns, become `_`):
//!
//! - revolute, continuous, prismatic: a [`Convention::Urdf`] link, origin
//!   `T(x, y, z) Rz(yaw) Ry(pitch) Rx(roll)` then a rotation about (translation along) the unit
//!   `axis` by `q + offset`, offset 0; its joint carries the URDF joint's name and limits;
//! - fixed: a [`Convention::Frame6`] link with the same origin (`Frame6` is the URDF origin).
//!
//! URDF lengths are metres, armcal's millimetres. Limits: revolute `[lower, upper]` rad as
//! given (an omitted limit, URDF ≥ 1.2, means ±[`CONTINUOUS_RANGE`]); continuous joints get
//! ±[`CONTINUOUS_RANGE`] = ±2π; prismatic joints need finite limits (m → mm). An identity
//! `base` frame precedes the chain and an identity `tool` frame ends it, so the result has the
//! shape of every armcal robot. Inertia, geometry, mimic targets off the chain, and links off
//! the chain are ignored.
//!
//! **Export** ([`to_urdf`]) writes any chain, in any convention, as a URDF serial chain. Every
//! link transform is split at its joint motion, `T_i(q) = A_i · J(q) · B_i`, with `A_i` the
//! elementary factors up to and including the joint's own factor at its nominal value, `J` the
//! unit joint motion (about / along the axis `e` of that factor) and `B_i` the factors after
//! it (for the zero-reference model `T(p) Rot(û, off + q) T(−p)`: `A = T(p) Rot(û, off)`,
//! `J = Rot(û, q)`, `B = T(−p)`). The fixed transforms between two joint motions,
//! `B_{i−1} · (fixed links) · A_i`, become joint `i`'s `<origin>`, `e` its `<axis>`, and its
//! limits are kept (mm → m). The chain ends in a fixed joint to a link named after the last
//! chain link (the tool), and every target hangs off that link with a fixed joint. The
//! instrument frame belongs to a cell, not to the robot, and is not exported. The intermediate
//! URDF links are the joint frames, not armcal's link-end frames; the end of the chain and the
//! targets are exact.

use crate::model::chain::{LinkSpec, Model, ModelSpec};
use crate::model::link::{Convention, Joint, JointKind, LinkGeometry, Motion};
use crate::model::pose::{rot_axis, rot_x, rot_y, rot_z, Pose};
use crate::Error;
use nalgebra::{Matrix3, Vector3};
use std::collections::{HashMap, HashSet};
use std::path::Path;

/// Joint range given to continuous joints and to revolute joints without limits: ±2π rad.
pub const CONTINUOUS_RANGE: f64 = 2.0 * std::f64::consts::PI;

/// Metres per millimetre.
const M_PER_MM: f64 = 1e-3;

/// Reads a URDF file and imports the chain from its root to `tip` (default: the single leaf
/// link). Errors name the file.
pub fn read_urdf(path: impl AsRef<Path>, tip: Option<&str>) -> Result<ModelSpec, Error> {
    let path = path.as_ref();
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| Error::File {
        file: file.clone(),
        message: format!("cannot read the URDF file: {e}"),
    })?;
    from_urdf_str(&text, tip).map_err(|e| Error::File {
        file,
        message: match e {
            Error::Input(m) => m,
            other => other.to_string(),
        },
    })
}

/// Parses URDF text and imports the chain from its root to `tip` (default: the single leaf).
pub fn from_urdf_str(xml: &str, tip: Option<&str>) -> Result<ModelSpec, Error> {
    let robot = urdf_rs::read_from_string(xml)
        .map_err(|e| Error::Input(format!("not a valid URDF document: {e}")))?;
    from_urdf_robot(&robot, tip)
}

/// Imports the serial chain of a parsed URDF robot from its root link to `tip` (default: the
/// single leaf link).
pub fn from_urdf_robot(robot: &urdf_rs::Robot, tip: Option<&str>) -> Result<ModelSpec, Error> {
    let err = |m: String| Error::Input(format!("URDF robot `{}`: {m}", robot.name));
    if robot.links.is_empty() {
        return Err(err("has no links".into()));
    }
    let mut links = HashSet::new();
    for l in &robot.links {
        if !links.insert(l.name.as_str()) {
            return Err(err(format!("link `{}` is defined twice", l.name)));
        }
    }
    // parent joint of every child link, and the joints leaving every link
    let mut parent_joint: HashMap<&str, &urdf_rs::Joint> = HashMap::new();
    let mut has_children: HashSet<&str> = HashSet::new();
    for j in &robot.joints {
        for end in [&j.parent.link, &j.child.link] {
            if !links.contains(end.as_str()) {
                return Err(err(format!(
                    "joint `{}` refers to unknown link `{end}`",
                    j.name
                )));
            }
        }
        if let Some(other) = parent_joint.insert(&j.child.link, j) {
            return Err(err(format!(
                "link `{}` is the child of two joints, `{}` and `{}` (a URDF is a tree)",
                j.child.link, other.name, j.name
            )));
        }
        has_children.insert(&j.parent.link);
    }
    let roots: Vec<&str> = robot
        .links
        .iter()
        .map(|l| l.name.as_str())
        .filter(|l| !parent_joint.contains_key(l))
        .collect();
    let root = match roots.as_slice() {
        [r] => *r,
        [] => return Err(err("has no root link: its joints form a cycle".into())),
        _ => {
            return Err(err(format!(
                "has several root links ({}): the links are not connected into one tree",
                roots.join(", ")
            )))
        }
    };
    let tip = match tip {
        Some(t) => {
            if !links.contains(t) {
                let mut known: Vec<&str> = links.iter().copied().collect();
                known.sort_unstable();
                return Err(err(format!(
                    "unknown tip link `{t}`; links: {}",
                    known.join(", ")
                )));
            }
            t
        }
        None => {
            let leaves: Vec<&str> = robot
                .links
                .iter()
                .map(|l| l.name.as_str())
                .filter(|l| !has_children.contains(l))
                .collect();
            match leaves.as_slice() {
                [l] => *l,
                _ => {
                    return Err(err(format!(
                        "the tree branches into several leaf links ({}); choose the tip link \
                         the chain ends in",
                        leaves.join(", ")
                    )))
                }
            }
        }
    };
    // Walk up from the tip to the root.
    let mut path = Vec::new();
    let mut link = tip;
    let mut seen = HashSet::new();
    while let Some(j) = parent_joint.get(link) {
        if !seen.insert(link) {
            return Err(err(format!("the joints above link `{tip}` form a cycle")));
        }
        path.push(*j);
        link = &j.parent.link;
    }
    debug_assert_eq!(link, root);
    path.reverse();

    let mut names: HashSet<String> = ["base".to_string(), "tool".to_string()].into();
    let mut out = vec![identity_frame("base")];
    for j in path {
        let name = unique(&sanitise(&j.name), &mut names);
        out.push(import_joint(j, name).map_err(|m| err(format!("joint `{}`: {m}", j.name)))?);
    }
    if out.iter().all(|l| l.joint.is_none()) {
        return Err(err(format!(
            "no movable joint between the root link `{root}` and the tip link `{tip}`"
        )));
    }
    out.push(identity_frame("tool"));
    Ok(ModelSpec {
        name: robot.name.clone(),
        instrument: None,
        links: out,
        targets: Vec::new(),
    })
}

/// One URDF joint as a link spec (lengths in mm).
fn import_joint(j: &urdf_rs::Joint, name: String) -> Result<LinkSpec, String> {
    use urdf_rs::JointType as T;
    let xyz = j.origin.xyz.0.map(|v| v / M_PER_MM);
    let rpy = j.origin.rpy.0;
    if !xyz.iter().chain(&rpy).all(|v| v.is_finite()) {
        return Err(format!("origin xyz {xyz:?} mm / rpy {rpy:?} is not finite"));
    }
    let kind = match j.joint_type {
        T::Fixed => {
            return Ok(LinkSpec {
                name,
                geometry: LinkGeometry::frame6(xyz, rpy),
                joint: None,
            })
        }
        T::Revolute | T::Continuous => JointKind::Revolute,
        T::Prismatic => JointKind::Prismatic,
        ref other => {
            return Err(format!(
                "joint type `{}` is not supported (revolute, continuous, prismatic, fixed)",
                format!("{other:?}").to_lowercase()
            ))
        }
    };
    if let Some(m) = &j.mimic {
        return Err(format!(
            "mimics `{}`: mimic joints are not supported (every chain joint is independent)",
            m.joint
        ));
    }
    let axis = Vector3::from(j.axis.xyz.0);
    if !axis.iter().all(|v| v.is_finite()) || axis.norm() < 1e-12 {
        return Err(format!(
            "axis {:?} must be a finite, non-zero vector",
            j.axis.xyz.0
        ));
    }
    let axis = axis.normalize();
    let (lower, upper) = match j.joint_type {
        T::Continuous => (-CONTINUOUS_RANGE, CONTINUOUS_RANGE),
        T::Revolute => {
            let (l, u) = (j.limit.lower, j.limit.upper);
            (
                if l.is_finite() { l } else { -CONTINUOUS_RANGE },
                if u.is_finite() { u } else { CONTINUOUS_RANGE },
            )
        }
        _ => {
            let (l, u) = (j.limit.lower, j.limit.upper);
            if !(l.is_finite() && u.is_finite()) {
                return Err(format!(
                    "a prismatic joint needs finite limits, got [{l}, {u}] m"
                ));
            }
            (l / M_PER_MM, u / M_PER_MM)
        }
    };
    if lower.is_nan() || upper.is_nan() || lower >= upper {
        return Err(format!(
            "empty joint range [{}, {}] {} (is <limit> missing? use a fixed joint for a \
             locked axis)",
            j.limit.lower,
            j.limit.upper,
            if kind == JointKind::Prismatic {
                "m"
            } else {
                "rad"
            }
        ));
    }
    let mut values = xyz.to_vec();
    values.extend(rpy);
    values.push(0.0);
    Ok(LinkSpec {
        name: name.clone(),
        geometry: LinkGeometry {
            convention: Convention::Urdf,
            values,
            axis: Some([axis.x, axis.y, axis.z]),
        },
        joint: Some(Joint {
            name,
            kind,
            lower,
            upper,
        }),
    })
}

fn identity_frame(name: &str) -> LinkSpec {
    LinkSpec {
        name: name.into(),
        geometry: LinkGeometry::frame6([0.0; 3], [0.0; 3]),
        joint: None,
    }
}

/// A URDF name as an armcal frame name: `.` and `*` become `_`; empty becomes `joint`.
fn sanitise(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| if c == '.' || c == '*' { '_' } else { c })
        .collect();
    if s.is_empty() {
        "joint".into()
    } else {
        s
    }
}

/// `name`, or `name_2`, `name_3`, … if taken; records the result as taken.
fn unique(name: &str, taken: &mut HashSet<String>) -> String {
    let mut candidate = name.to_string();
    let mut k = 1;
    while taken.contains(&candidate) {
        k += 1;
        candidate = format!("{name}_{k}");
    }
    taken.insert(candidate.clone());
    candidate
}

/// Writes the chain (base … tool) and its targets as a URDF document. See the module
/// documentation for how link transforms become joint origins.
pub fn to_urdf(spec: &ModelSpec) -> Result<String, Error> {
    let model = Model::from_spec(spec)?;
    let mut joint_names = HashSet::new();
    for j in &model.joints {
        if !joint_names.insert(j.name.clone()) {
            return Err(Error::Model(format!(
                "URDF export: joint name `{}` is used twice",
                j.name
            )));
        }
    }
    let mut link_names: HashSet<String> = model
        .links
        .iter()
        .chain(&model.targets)
        .map(|l| l.spec.name.clone())
        .collect();
    let root = unique(&format!("{}_root", spec.name), &mut link_names);
    let mut urdf_links = vec![empty_link(&root)];
    let mut urdf_joints = Vec::new();
    let mut parent = root;
    let mut pending = Pose::identity();
    let last = model.links.len() - 1;
    for link in &model.links {
        let ls = &link.spec;
        match &ls.joint {
            None => pending = pending.compose(&fixed_pose(&ls.geometry)),
            Some(joint) => {
                let (a, axis, b) = split_at_joint(&ls.geometry, joint.kind);
                let child = ls.name.clone();
                let scale = match joint.kind {
                    JointKind::Revolute => 1.0,
                    JointKind::Prismatic => M_PER_MM,
                };
                urdf_joints.push(urdf_joint(
                    &joint.name,
                    match joint.kind {
                        JointKind::Revolute => urdf_rs::JointType::Revolute,
                        JointKind::Prismatic => urdf_rs::JointType::Prismatic,
                    },
                    &parent,
                    &child,
                    &pending.compose(&a),
                    axis,
                    Some((joint.lower * scale, joint.upper * scale)),
                ));
                urdf_links.push(empty_link(&child));
                parent = child;
                pending = b;
            }
        }
    }
    // The end of the chain: a link named after the last chain link.
    let last_spec = &model.links[last].spec;
    let end = if last_spec.joint.is_none() {
        last_spec.name.clone()
    } else {
        unique(&format!("{}_end", last_spec.name), &mut link_names)
    };
    let mut fixed = |name: &str, parent: &str, child: &str, pose: &Pose<f64>| {
        let name = unique(&format!("{name}_fixed"), &mut joint_names);
        urdf_joint(
            &name,
            urdf_rs::JointType::Fixed,
            parent,
            child,
            pose,
            Vector3::x(),
            None,
        )
    };
    urdf_joints.push(fixed(&end, &parent, &end, &pending));
    urdf_links.push(empty_link(&end));
    for t in &model.targets {
        let name = &t.spec.name;
        urdf_joints.push(fixed(name, &end, name, &fixed_pose(&t.spec.geometry)));
        urdf_links.push(empty_link(name));
    }
    let robot = urdf_rs::Robot {
        name: spec.name.clone(),
        version: None,
        links: urdf_links,
        joints: urdf_joints,
        materials: Vec::new(),
    };
    urdf_rs::write_to_string(&robot)
        .map_err(|e| Error::Model(format!("URDF export of `{}`: {e}", spec.name)))
}

fn empty_link(name: &str) -> urdf_rs::Link {
    urdf_rs::Link {
        name: name.into(),
        inertial: Default::default(),
        visual: Vec::new(),
        collision: Vec::new(),
    }
}

/// A URDF joint with origin `pose` (mm → m), `axis` and optional limits (m or rad).
fn urdf_joint(
    name: &str,
    joint_type: urdf_rs::JointType,
    parent: &str,
    child: &str,
    pose: &Pose<f64>,
    axis: Vector3<f64>,
    limits: Option<(f64, f64)>,
) -> urdf_rs::Joint {
    let (xyz, rpy) = pose.to_xyz_rpy();
    let limit = match limits {
        Some((lower, upper)) => urdf_rs::JointLimit {
            lower,
            upper,
            ..Default::default()
        },
        None => Default::default(),
    };
    urdf_rs::Joint {
        name: name.into(),
        joint_type,
        origin: urdf_rs::Pose {
            // `+ 0.0` turns −0 into 0 in the text
            xyz: urdf_rs::Vec3(xyz.map(|v| v * M_PER_MM + 0.0)),
            rpy: urdf_rs::Vec3(rpy.map(|v| v + 0.0)),
        },
        parent: urdf_rs::LinkName {
            link: parent.into(),
        },
        child: urdf_rs::LinkName { link: child.into() },
        axis: urdf_rs::Axis {
            xyz: urdf_rs::Vec3([axis.x, axis.y, axis.z]),
        },
        limit,
        calibration: None,
        dynamics: None,
        mimic: None,
        safety_controller: None,
    }
}

/// Transform of one elementary motion by `value` (mm or rad).
fn motion_pose(motion: Motion, value: f64, axis: &Vector3<f64>) -> Pose<f64> {
    let rotation = |rot: Matrix3<f64>| Pose {
        rot,
        trans: Vector3::zeros(),
    };
    let translation = |trans: Vector3<f64>| Pose {
        rot: Matrix3::identity(),
        trans,
    };
    match motion {
        Motion::Rx => rotation(rot_x(value)),
        Motion::Ry => rotation(rot_y(value)),
        Motion::Rz => rotation(rot_z(value)),
        Motion::RotAxis => rotation(rot_axis(axis, value)),
        Motion::Tx => translation(Vector3::x() * value),
        Motion::Ty => translation(Vector3::y() * value),
        Motion::Tz => translation(Vector3::z() * value),
        Motion::TransAxis => translation(axis * value),
    }
}

/// Unit direction of an elementary motion in its own frame.
fn motion_axis(motion: Motion, axis: &Vector3<f64>) -> Vector3<f64> {
    match motion {
        Motion::Rx | Motion::Tx => Vector3::x(),
        Motion::Ry | Motion::Ty => Vector3::y(),
        Motion::Rz | Motion::Tz => Vector3::z(),
        Motion::RotAxis | Motion::TransAxis => *axis,
    }
}

/// Zero-reference parts: unit axis û and point p.
fn zrp_axis_point(g: &LinkGeometry) -> (Vector3<f64>, Vector3<f64>) {
    let v = &g.values;
    (
        Vector3::new(v[0], v[1], v[2]).normalize(),
        Vector3::new(v[3], v[4], v[5]),
    )
}

/// Transform of a link without a joint (all factors at their values).
fn fixed_pose(g: &LinkGeometry) -> Pose<f64> {
    match g.convention.motions(None) {
        Some(motions) => {
            let axis = g.axis_vector();
            motions.iter().fold(Pose::identity(), |p, &(m, f)| {
                p.compose(&motion_pose(m, g.values[f], &axis))
            })
        }
        None => {
            let (u, p) = zrp_axis_point(g);
            let r = rot_axis(&u, g.values[6]);
            Pose {
                rot: r,
                trans: p - r * p,
            }
        }
    }
}

/// Splits a jointed link `T(q) = A · J(q) · B`: returns `A` (factors up to and including the
/// joint's factor at its nominal value), the unit joint direction in the frame after `A`,
/// and `B` (the factors after the joint's).
fn split_at_joint(g: &LinkGeometry, kind: JointKind) -> (Pose<f64>, Vector3<f64>, Pose<f64>) {
    let joint_field = g
        .convention
        .joint_field(kind)
        .expect("Model::from_spec accepted the joint");
    match g.convention.motions(Some(kind)) {
        Some(motions) => {
            let axis = g.axis_vector();
            let k = motions
                .iter()
                .position(|&(_, f)| f == joint_field)
                .expect("every joint field has its motion");
            let product = |ms: &[(Motion, usize)]| {
                ms.iter().fold(Pose::identity(), |p, &(m, f)| {
                    p.compose(&motion_pose(m, g.values[f], &axis))
                })
            };
            (
                product(&motions[..=k]),
                motion_axis(motions[k].0, &axis),
                product(&motions[k + 1..]),
            )
        }
        None => {
            let (u, p) = zrp_axis_point(g);
            let offset = g.values[6];
            match kind {
                JointKind::Revolute => (
                    Pose {
                        rot: rot_axis(&u, offset),
                        trans: p,
                    },
                    u,
                    Pose {
                        rot: Matrix3::identity(),
                        trans: -p,
                    },
                ),
                JointKind::Prismatic => (
                    Pose {
                        rot: Matrix3::identity(),
                        trans: u * offset,
                    },
                    u,
                    Pose::identity(),
                ),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::kinematics::tool_pose;
    use crate::robots;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// ABB IRB 120 as a URDF (joint origins and limits as in the ROS-Industrial
    /// abb_irb120_support model: axes at 0.29, +0.27, +0.07 m up, wrist 0.302 m and flange
    /// 0.072 m forward), ending in ABB's `tool0` (`Ry(90°)`).
    const IRB120: &str = r#"<?xml version="1.0"?>
<robot name="irb120">
  <link name="base_link"/> <link name="link_1"/> <link name="link_2"/> <link name="link_3"/>
  <link name="link_4"/> <link name="link_5"/> <link name="link_6"/> <link name="tool0"/>
  <joint name="joint_1" type="revolute">
    <origin xyz="0 0 0" rpy="0 0 0"/> <parent link="base_link"/> <child link="link_1"/>
    <axis xyz="0 0 1"/> <limit lower="-2.87979" upper="2.87979" effort="0" velocity="4.4"/>
  </joint>
  <joint name="joint_2" type="revolute">
    <origin xyz="0 0 0.29" rpy="0 0 0"/> <parent link="link_1"/> <child link="link_2"/>
    <axis xyz="0 1 0"/> <limit lower="-1.91986" upper="1.91986" effort="0" velocity="4.4"/>
  </joint>
  <joint name="joint_3" type="revolute">
    <origin xyz="0 0 0.27" rpy="0 0 0"/> <parent link="link_2"/> <child link="link_3"/>
    <axis xyz="0 1 0"/> <limit lower="-1.91986" upper="1.22173" effort="0" velocity="4.4"/>
  </joint>
  <joint name="joint_4" type="revolute">
    <origin xyz="0 0 0.07" rpy="0 0 0"/> <parent link="link_3"/> <child link="link_4"/>
    <axis xyz="1 0 0"/> <limit lower="-2.79253" upper="2.79253" effort="0" velocity="5.6"/>
  </joint>
  <joint name="joint_5" type="revolute">
    <origin xyz="0.302 0 0" rpy="0 0 0"/> <parent link="link_4"/> <child link="link_5"/>
    <axis xyz="0 1 0"/> <limit lower="-2.094395" upper="2.094395" effort="0" velocity="5.6"/>
  </joint>
  <joint name="joint_6" type="revolute">
    <origin xyz="0.072 0 0" rpy="0 0 0"/> <parent link="link_5"/> <child link="link_6"/>
    <axis xyz="1 0 0"/> <limit lower="-6.98132" upper="6.98132" effort="0" velocity="7.3"/>
  </joint>
  <joint name="link_6-tool0" type="fixed">
    <origin xyz="0 0 0" rpy="0 1.5707963267948966 0"/>
    <parent link="link_6"/> <child link="tool0"/>
  </joint>
</robot>"#;

    fn random_q(spec: &ModelSpec, r: &mut ChaCha8Rng) -> Vec<f64> {
        spec.links
            .iter()
            .filter_map(|l| l.joint.as_ref())
            .map(|j| r.random_range(j.lower..j.upper))
            .collect()
    }

    /// |Δt| in mm and the rotation angle in rad (from the Frobenius norm, which unlike
    /// `acos` stays accurate for tiny angles: ‖R₁ − R₂‖ = 2√2 sin(θ/2)).
    fn pose_error(a: &Pose<f64>, b: &Pose<f64>) -> (f64, f64) {
        let f = (a.rot - b.rot).norm() / (2.0 * 2f64.sqrt());
        ((a.trans - b.trans).norm(), 2.0 * f.min(1.0).asin())
    }

    fn assert_same_fk(x: &ModelSpec, y: &ModelSpec, seed: u64, tol_mm: f64, tol_rad: f64) {
        let (mx, my) = (Model::from_spec(x).unwrap(), Model::from_spec(y).unwrap());
        assert_eq!(mx.dof(), my.dof());
        let mut r = ChaCha8Rng::seed_from_u64(seed);
        for _ in 0..50 {
            let q = random_q(x, &mut r);
            let (px, py) = (
                tool_pose(&mx, &mx.nominal(), &q),
                tool_pose(&my, &my.nominal(), &q),
            );
            let (dt, dr) = pose_error(&px, &py);
            assert!(
                dt < tol_mm && dr < tol_rad,
                "q = {q:?}: Δt = {dt:e} mm, Δr = {dr:e} rad"
            );
        }
    }

    #[test]
    fn urdf_irb120_equals_the_library_dh_model() {
        let imported = from_urdf_str(IRB120, None).unwrap();
        let names: Vec<&str> = imported.links.iter().map(|l| l.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "base",
                "joint_1",
                "joint_2",
                "joint_3",
                "joint_4",
                "joint_5",
                "joint_6",
                "link_6-tool0",
                "tool"
            ]
        );
        let library = robots::robot("irb120").unwrap().spec;
        // the URDF limits are the library's, rounded to 1e-5 rad
        let lim = |s: &ModelSpec| -> Vec<(f64, f64)> {
            s.links
                .iter()
                .filter_map(|l| l.joint.as_ref())
                .map(|j| (j.lower, j.upper))
                .collect()
        };
        for (a, b) in lim(&imported).iter().zip(lim(&library)) {
            assert!((a.0 - b.0).abs() < 1e-5 && (a.1 - b.1).abs() < 1e-5);
        }
        assert_same_fk(&imported, &library, 1, 1e-9, 1e-12);
    }

    /// A rail (prismatic), a fixed mount, a revolute joint about a tilted axis and a
    /// continuous joint, against the product of the URDF transforms written out by hand.
    #[test]
    fn urdf_prismatic_fixed_and_continuous_joints() {
        let xml = r#"<robot name="rail.bot">
          <link name="floor"/> <link name="carriage"/> <link name="mount"/>
          <link name="arm"/> <link name="hand"/>
          <joint name="rail.x" type="prismatic">
            <origin xyz="0.1 0.2 0.3" rpy="0 0 0.5"/> <parent link="floor"/>
            <child link="carriage"/> <axis xyz="2 0 0"/>
            <limit lower="-0.5" upper="1.5" effort="1" velocity="1"/>
          </joint>
          <joint name="mount*" type="fixed">
            <origin xyz="0 0.05 0.4" rpy="0.1 -0.2 0.3"/>
            <parent link="carriage"/> <child link="mount"/>
          </joint>
          <joint name="shoulder" type="revolute">
            <origin xyz="0.02 0 0.1" rpy="0.4 0.3 -0.2"/> <parent link="mount"/>
            <child link="arm"/> <axis xyz="0 0.6 0.8"/>
            <limit lower="-2" upper="1" effort="1" velocity="1"/>
          </joint>
          <joint name="wrist" type="continuous">
            <origin xyz="0.5 0 0" rpy="0 0 0"/> <parent link="arm"/> <child link="hand"/>
            <axis xyz="0 0 -1"/>
          </joint>
        </robot>"#;
        let spec = from_urdf_str(xml, None).unwrap();
        let names: Vec<&str> = spec.links.iter().map(|l| l.name.as_str()).collect();
        assert_eq!(
            names,
            ["base", "rail_x", "mount_", "shoulder", "wrist", "tool"]
        );
        let joints: Vec<&Joint> = spec.links.iter().filter_map(|l| l.joint.as_ref()).collect();
        assert_eq!(joints[0].kind, JointKind::Prismatic);
        assert_eq!((joints[0].lower, joints[0].upper), (-500.0, 1500.0));
        assert_eq!((joints[1].lower, joints[1].upper), (-2.0, 1.0));
        assert_eq!(
            (joints[2].lower, joints[2].upper),
            (-CONTINUOUS_RANGE, CONTINUOUS_RANGE)
        );
        let model = Model::from_spec(&spec).unwrap();
        let origin = |xyz: [f64; 3], rpy: [f64; 3]| Pose::from_xyz_rpy(xyz, rpy);
        let rot = |axis: [f64; 3], a: f64| Pose {
            rot: rot_axis(&Vector3::from(axis).normalize(), a),
            trans: Vector3::zeros(),
        };
        let mut r = ChaCha8Rng::seed_from_u64(2);
        for _ in 0..20 {
            let q = random_q(&spec, &mut r);
            let expected = origin([100.0, 200.0, 300.0], [0.0, 0.0, 0.5])
                .compose(&origin([q[0], 0.0, 0.0], [0.0; 3]))
                .compose(&origin([0.0, 50.0, 400.0], [0.1, -0.2, 0.3]))
                .compose(&origin([20.0, 0.0, 100.0], [0.4, 0.3, -0.2]))
                .compose(&rot([0.0, 0.6, 0.8], q[1]))
                .compose(&origin([500.0, 0.0, 0.0], [0.0; 3]))
                .compose(&rot([0.0, 0.0, -1.0], q[2]));
            let (dt, dr) = pose_error(&tool_pose(&model, &model.nominal(), &q), &expected);
            assert!(dt < 1e-9 && dr < 1e-12, "Δt = {dt:e} mm, Δr = {dr:e} rad");
        }
    }

    #[test]
    fn export_reimport_paper_robot() {
        let paper = robots::robot("paper").unwrap().spec;
        let xml = to_urdf(&paper).unwrap();
        let back = from_urdf_str(&xml, None).unwrap();
        assert_same_fk(&paper, &back, 3, 1e-9, 1e-12);
        let lim = |s: &ModelSpec| -> Vec<(String, f64, f64)> {
            s.links
                .iter()
                .filter_map(|l| l.joint.as_ref())
                .map(|j| (j.name.clone(), j.lower, j.upper))
                .collect()
        };
        assert_eq!(lim(&back), lim(&paper));
    }

    /// A chain with every convention, revolute and prismatic, fixed links in between, a
    /// fixed `Zrp` link and a chain that ends in a joint.
    fn every_convention_spec(seed: u64) -> ModelSpec {
        let mut r = ChaCha8Rng::seed_from_u64(seed);
        let mut geometry = |c: Convention, kind: Option<JointKind>| {
            let values = c
                .fields(kind)
                .iter()
                .map(|(_, u)| match u {
                    crate::model::Unit::Mm => r.random_range(-400.0..400.0),
                    crate::model::Unit::Rad => r.random_range(-3.0..3.0),
                    crate::model::Unit::Unitless => r.random_range(0.2..1.5),
                })
                .collect();
            let mut g = LinkGeometry::new(c, values);
            if c == Convention::Urdf {
                g.axis = Some([0.3, -0.5, 0.8]);
            }
            g
        };
        let mut links = vec![LinkSpec {
            name: "base".into(),
            geometry: geometry(Convention::Frame6, None),
            joint: None,
        }];
        let mut n = 0;
        for c in [
            Convention::Dh,
            Convention::Hayati,
            Convention::Mdh,
            Convention::MdhBeta,
            Convention::SModel,
            Convention::BookType3,
            Convention::Urdf,
            Convention::Zrp,
        ] {
            for kind in [JointKind::Revolute, JointKind::Prismatic] {
                n += 1;
                let (lower, upper) = match kind {
                    JointKind::Revolute => (-3.0, 3.0),
                    JointKind::Prismatic => (-250.0, 250.0),
                };
                links.push(LinkSpec {
                    name: format!("j{n}"),
                    geometry: geometry(c, Some(kind)),
                    joint: Some(Joint {
                        name: format!("q{n}"),
                        kind,
                        lower,
                        upper,
                    }),
                });
            }
            links.push(LinkSpec {
                name: format!("fixed{n}"),
                geometry: geometry(
                    if n == 14 {
                        Convention::Zrp
                    } else {
                        Convention::Point
                    },
                    None,
                ),
                joint: None,
            });
        }
        links.push(LinkSpec {
            name: "last".into(),
            geometry: geometry(Convention::Dh, Some(JointKind::Revolute)),
            joint: Some(Joint {
                name: "q_last".into(),
                kind: JointKind::Revolute,
                lower: -1.0,
                upper: 1.0,
            }),
        });
        ModelSpec {
            name: "every".into(),
            instrument: None,
            links,
            targets: vec![],
        }
    }

    #[test]
    fn export_reimport_every_convention() {
        for seed in 0..3 {
            let spec = every_convention_spec(seed);
            let back = from_urdf_str(&to_urdf(&spec).unwrap(), None).unwrap();
            assert_same_fk(&spec, &back, 10 + seed, 1e-9, 1e-12);
        }
    }

    #[test]
    fn export_reimport_dh_model_with_targets() {
        let mut spec = robots::robot("kr300").unwrap().spec;
        spec.links[0].geometry = LinkGeometry::frame6([100.0, -20.0, 645.0], [0.01, 0.02, 3.0]);
        for (name, xyz) in [
            ("smr1", [-89.58, -2.84, 327.03]),
            ("smr2", [60.0, 40.0, 300.0]),
        ] {
            spec.targets.push(LinkSpec {
                name: name.into(),
                geometry: LinkGeometry::point(xyz),
                joint: None,
            });
        }
        let xml = to_urdf(&spec).unwrap();
        // both targets hang off the tool, so the tree branches
        let err = from_urdf_str(&xml, None).unwrap_err().to_string();
        assert!(
            err.contains("choose the tip") && err.contains("smr1, smr2"),
            "{err}"
        );
        let chain = from_urdf_str(&xml, Some("tool")).unwrap();
        let mut no_targets = spec.clone();
        no_targets.targets.clear();
        assert_same_fk(&no_targets, &chain, 20, 1e-9, 1e-12);
        // to a target: the target's position of the original model
        let m = Model::from_spec(&spec).unwrap();
        let mut data = crate::model::Data::new(&m);
        let q = [0.1, -0.5, 0.3, 0.2, -0.4, 0.6];
        crate::model::forward_kinematics(&m, &mut data, &m.nominal(), &q);
        for (k, name) in ["smr1", "smr2"].iter().enumerate() {
            let t = Model::from_spec(&from_urdf_str(&xml, Some(name)).unwrap()).unwrap();
            let p = tool_pose(&t, &t.nominal(), &q);
            assert!((p.trans - data.targets[k].trans).norm() < 1e-9, "{name}");
        }
    }

    #[test]
    fn names_are_sanitised_and_unique() {
        let xml = r#"<robot name="r">
          <link name="a"/> <link name="b"/> <link name="c"/> <link name="d"/>
          <joint name="base" type="revolute"><parent link="a"/><child link="b"/>
            <limit lower="-1" upper="1" effort="0" velocity="1"/></joint>
          <joint name="x.y" type="revolute"><parent link="b"/><child link="c"/>
            <limit lower="-1" upper="1" effort="0" velocity="1"/></joint>
          <joint name="x*y" type="revolute"><parent link="c"/><child link="d"/>
            <limit lower="-1" upper="1" effort="0" velocity="1"/></joint>
        </robot>"#;
        let spec = from_urdf_str(xml, None).unwrap();
        let names: Vec<&str> = spec.links.iter().map(|l| l.name.as_str()).collect();
        assert_eq!(names, ["base", "base_2", "x_y", "x_y_2", "tool"]);
        // URDF's default axis is x
        assert_eq!(spec.links[1].geometry.axis, Some([1.0, 0.0, 0.0]));
        Model::from_spec(&spec).unwrap();
    }

    fn import_err(xml: &str, tip: Option<&str>) -> String {
        match from_urdf_str(xml, tip) {
            Ok(_) => panic!("accepted: {xml}"),
            Err(e) => e.to_string(),
        }
    }

    /// A two-link URDF with one joint described by `joint` (type attribute and body).
    fn one_joint(joint: &str) -> String {
        format!(
            r#"<robot name="r"><link name="a"/><link name="b"/>
               <joint name="j" {joint}<parent link="a"/><child link="b"/></joint></robot>"#
        )
    }

    #[test]
    fn bad_inputs_give_clear_errors() {
        let lim = r#"<limit lower="-1" upper="1" effort="0" velocity="1"/>"#;
        let cases: Vec<(String, Option<&str>, &str)> = vec![
            (
                "<robot name=\"r\"><link name=\"a\"".into(),
                None,
                "not a valid URDF",
            ),
            (
                r#"<robot name="r"><link name="a"/></robot>"#.into(),
                None,
                "no movable joint",
            ),
            (one_joint(r#"type="fixed">"#), None, "no movable joint"),
            (
                one_joint(&format!(r#"type="revolute"><axis xyz="0 0 0"/>{lim}"#)),
                None,
                "non-zero",
            ),
            (
                one_joint(&format!(r#"type="revolute"><mimic joint="k"/>{lim}"#)),
                None,
                "mimic",
            ),
            (one_joint(r#"type="floating">"#), None, "not supported"),
            (
                one_joint(
                    r#"type="revolute"><limit lower="1" upper="-1" effort="0" velocity="1"/>"#,
                ),
                None,
                "empty joint range",
            ),
            (
                one_joint(r#"type="revolute">"#),
                None,
                "is <limit> missing?",
            ),
            (
                one_joint(r#"type="revolute"><origin xyz="nan 0 0"/>"#),
                None,
                "not finite",
            ),
            (
                one_joint(&format!(r#"type="revolute">{lim}"#)),
                Some("c"),
                "unknown tip link `c`",
            ),
            (
                format!(
                    r#"<robot name="r"><link name="a"/><link name="b"/><link name="c"/>
                    <joint name="j" type="revolute"><parent link="a"/><child link="b"/>{lim}</joint>
                    <joint name="k" type="revolute"><parent link="a"/><child link="c"/>{lim}</joint>
                    </robot>"#
                ),
                None,
                "several leaf links (b, c)",
            ),
            (
                format!(
                    r#"<robot name="r"><link name="a"/><link name="b"/>
                    <joint name="j" type="revolute"><parent link="a"/><child link="z"/>{lim}</joint>
                    </robot>"#
                ),
                None,
                "unknown link `z`",
            ),
            (
                format!(
                    r#"<robot name="r"><link name="a"/><link name="b"/><link name="c"/>
                    <joint name="j" type="revolute"><parent link="a"/><child link="c"/>{lim}</joint>
                    <joint name="k" type="revolute"><parent link="b"/><child link="c"/>{lim}</joint>
                    </robot>"#
                ),
                None,
                "child of two joints",
            ),
            (
                format!(
                    r#"<robot name="r"><link name="a"/><link name="b"/>
                    <joint name="j" type="revolute"><parent link="a"/><child link="b"/>{lim}</joint>
                    <joint name="k" type="revolute"><parent link="b"/><child link="a"/>{lim}</joint>
                    </robot>"#
                ),
                None,
                "no root link",
            ),
            (
                format!(
                    r#"<robot name="r"><link name="a"/><link name="b"/><link name="c"/><link name="d"/>
                    <joint name="j" type="revolute"><parent link="a"/><child link="b"/>{lim}</joint>
                    <joint name="k" type="revolute"><parent link="c"/><child link="d"/>{lim}</joint>
                    <joint name="l" type="revolute"><parent link="d"/><child link="c"/>{lim}</joint>
                    </robot>"#
                ),
                Some("d"),
                "form a cycle",
            ),
            (
                r#"<robot name="r"><link name="a"/><link name="b"/></robot>"#.into(),
                None,
                "several root links",
            ),
        ];
        for (xml, tip, expected) in cases {
            let e = import_err(&xml, tip);
            assert!(e.contains(expected), "expected `{expected}` in: {e}");
        }
    }

    #[test]
    fn file_errors_name_the_file() {
        let e = read_urdf("/nonexistent/robot.urdf", None).unwrap_err();
        assert!(
            matches!(&e, Error::File { file, .. } if file == "/nonexistent/robot.urdf"),
            "{e}"
        );
        let dir = std::env::temp_dir().join(format!("armcal-urdf-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("bad.urdf");
        std::fs::write(&path, one_joint(r#"type="planar">"#)).unwrap();
        let e = read_urdf(&path, None).unwrap_err().to_string();
        assert!(
            e.starts_with(&path.display().to_string()) && e.contains("planar"),
            "{e}"
        );
        std::fs::write(&path, IRB120).unwrap();
        assert_eq!(read_urdf(&path, Some("tool0")).unwrap().links.len(), 9);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn export_rejects_duplicate_joint_names() {
        let mut spec = robots::robot("paper").unwrap().spec;
        spec.links[2].joint.as_mut().unwrap().name = "q1".into();
        let e = to_urdf(&spec).unwrap_err().to_string();
        assert!(e.contains("`q1` is used twice"), "{e}");
    }
}
