//! armcal → URDF: any chain, in any convention, as a URDF serial chain (see the [module
//! documentation](super) for how link transforms become joint origins).

use crate::model::chain::{Model, ModelSpec};
use crate::model::link::{JointKind, LinkGeometry, Motion};
use crate::model::pose::{rot_axis, rot_x, rot_y, rot_z, Pose};
use crate::Error;
use nalgebra::{Matrix3, Vector3};
use std::collections::HashSet;

use super::{unique, M_PER_MM};

/// Writes the chain (base … tool) and its targets as a URDF document. See the module
/// documentation for how link transforms become joint origins.
pub fn to_urdf(spec: &ModelSpec) -> Result<String, Error> {
    write(&urdf_robot(spec, &[])?, &spec.name)
}

/// The URDF document of `robot`.
pub(crate) fn write(robot: &urdf_rs::Robot, name: &str) -> Result<String, Error> {
    urdf_rs::write_to_string(robot)
        .map_err(|e| Error::Model(format!("URDF export of `{name}`: {e}")))
}

/// The chain of `spec` as a URDF robot; joint `i` of the chain with `offsets[i] ≠ 0`
/// (`offsets` empty: none) carries it as `<calibration rising="offsets[i]"/>` and its origin
/// is taken with the joint's own factor at its value minus the offset, so that
/// `origin · Rot(axis, q + rising)` is the link's motion (the joint offsets ROS calibration
/// tools write; see [`super::calibration`]).
pub(crate) fn urdf_robot(spec: &ModelSpec, offsets: &[f64]) -> Result<urdf_rs::Robot, Error> {
    let model = Model::from_spec(spec)?;
    if !offsets.is_empty() && offsets.len() != model.dof() {
        return Err(Error::Model(format!(
            "URDF export of `{}`: {} joint offsets for {} joints",
            spec.name,
            offsets.len(),
            model.dof()
        )));
    }
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
                let k = link.joint.expect("a link with a joint has its index");
                let offset = offsets.get(k).copied().unwrap_or(0.0);
                let mut geometry = ls.geometry.clone();
                let field = geometry
                    .convention
                    .joint_field(joint.kind)
                    .expect("Model::from_spec accepted the joint");
                geometry.values[field] -= offset;
                let (a, axis, b) = split_at_joint(&geometry, joint.kind);
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
                if offset != 0.0 {
                    let j = urdf_joints.last_mut().expect("just pushed");
                    j.calibration = Some(urdf_rs::Calibration {
                        rising: Some(offset * scale),
                        falling: None,
                    });
                }
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
    Ok(urdf_rs::Robot {
        name: spec.name.clone(),
        version: None,
        links: urdf_links,
        joints: urdf_joints,
        materials: Vec::new(),
    })
}

pub(super) fn empty_link(name: &str) -> urdf_rs::Link {
    urdf_rs::Link {
        name: name.into(),
        inertial: Default::default(),
        visual: Vec::new(),
        collision: Vec::new(),
    }
}

/// A URDF joint with origin `pose` (mm → m), `axis` and optional limits (m or rad).
pub(super) fn urdf_joint(
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
pub(crate) fn fixed_pose(g: &LinkGeometry) -> Pose<f64> {
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
pub(crate) fn split_at_joint(
    g: &LinkGeometry,
    kind: JointKind,
) -> (Pose<f64>, Vector3<f64>, Pose<f64>) {
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
