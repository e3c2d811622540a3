//! Link capsules derived from the kinematic skeleton of any chain: the collision model of a
//! robot that comes without hand-made capsules (an inline `[[robot.links]]` table, a URDF
//! without `<collision>` geometry).
//!
//! Every joint `k` has a point `J_k` where the chain reaches its axis
//! ([`Data::joint_points`]: the frame origin before a DH or MDH joint factor, a URDF joint's
//! child origin). A revolute joint's axis is fixed in the bodies on both sides of it, so the
//! segment `J_k J_{k+1}` between two successive joint points is rigid in the body that joint
//! `k` drives and moves with its chain frame (the link that holds joint `k`). The skeleton is
//! - `base`: from the base frame's origin to `J_1`, on the last frame before joint 1 (it does
//!   not move);
//! - one segment `J_k J_{k+1}` per joint, on the frame of joint `k`'s link; the last joint's
//!   segment ends at the origin of its own frame (the flange of a DH chain);
//! - the tool: from that origin to the tool frame's origin, on the tool frame, unless the
//!   cell gives `[[tool_capsules]]` (they then describe the tool);
//! - a prismatic joint's body starts where `J_k` is at the reference configuration, and the
//!   frame before it also gets the joint's travel: `J_k + u q` for `q` over the joint range,
//!   `u` the joint direction.
//!
//! Each segment is a capsule of the radius given for its frame (`[robot] link_radii_mm`),
//! else `[robot] link_radius_mm`, else [`default_link_radius`]. Segments shorter than 1 µm
//! (coincident joint points: a spherical wrist's centre) are left out, so the bodies on
//! either side become neighbours for the constraint set's exemption rules
//! ([`crate::design::cell_constraints`]). The reference configuration is `q = 0`, nominal
//! parameters; any other gives the same capsules (each segment is rigid in its frame).

use super::Capsule;
use crate::model::{forward_kinematics, Data, JointKind, Model};
use nalgebra::Vector3;

/// The share of the arm's skeleton length that [`default_link_radius`] takes.
pub const DEFAULT_RADIUS_SHARE: f64 = 0.05;

/// Segments shorter than this (mm) are left out.
const MIN_LENGTH: f64 = 1e-3;

/// One skeleton segment: the link (chain frame index) it moves with and its world ends at
/// the reference configuration.
struct Segment {
    link: usize,
    a: Vector3<f64>,
    b: Vector3<f64>,
    /// The tool's own segment (flange to tool origin).
    tool: bool,
}

/// The skeleton segments of `model` at `q = 0` (see the module documentation).
fn segments(model: &Model) -> Vec<Segment> {
    let dof = model.dof();
    let mut data = Data::<f64>::new(model);
    forward_kinematics(model, &mut data, &model.nominal(), &vec![0.0; dof]);
    let joint_links: Vec<usize> = model
        .links
        .iter()
        .enumerate()
        .filter(|(_, l)| l.joint.is_some())
        .map(|(i, _)| i)
        .collect();
    let mut out = Vec::new();
    let Some(&first) = joint_links.first() else {
        return out;
    };
    let origin = |link: usize| data.frames[link].trans;
    out.push(Segment {
        link: first - 1,
        a: origin(0),
        b: data.joint_points[0],
        tool: false,
    });
    for (k, &link) in joint_links.iter().enumerate() {
        let end = match joint_links.get(k + 1) {
            Some(_) => data.joint_points[k + 1],
            None => origin(link),
        };
        out.push(Segment {
            link,
            a: data.joint_points[k],
            b: end,
            tool: false,
        });
        let joint = &model.joints[k];
        if joint.kind == JointKind::Prismatic {
            let u = data.joint_twists[k].v;
            out.push(Segment {
                link: link - 1,
                a: data.joint_points[k] + u * joint.lower,
                b: data.joint_points[k] + u * joint.upper,
                tool: false,
            });
        }
    }
    let last = *joint_links.last().expect("one joint at least");
    out.push(Segment {
        link: model.links.len() - 1,
        a: origin(last),
        b: origin(model.links.len() - 1),
        tool: true,
    });
    out.retain(|s| (s.b - s.a).norm() >= MIN_LENGTH);
    // Express each segment in its frame.
    for s in &mut out {
        let inv = data.frames[s.link].inverse();
        s.a = inv.transform_point(&s.a);
        s.b = inv.transform_point(&s.b);
    }
    out
}

/// Length (mm) of the arm's skeleton, base to the last joint's frame (the tool left out):
/// the robot's size that [`default_link_radius`] scales with.
pub fn arm_length(model: &Model) -> f64 {
    segments(model)
        .iter()
        .filter(|s| !s.tool)
        .map(|s| (s.b - s.a).norm())
        .sum()
}

/// The link radius a skeleton gets when the cell gives none: [`DEFAULT_RADIUS_SHARE`] (5 %)
/// of [`arm_length`], rounded to the millimetre, at least 1 mm. The built-in robots'
/// hand-made capsules, sized from outline drawings, have radii of 4–9 % of that length
/// (IRB 120: 40–90 mm of 1004 mm; UR10: 50–95 mm of 1683 mm); 5 % errs toward the slender
/// side of that range so that a compact wrist does not overlap its neighbours everywhere.
pub fn default_link_radius(model: &Model) -> f64 {
    (DEFAULT_RADIUS_SHARE * arm_length(model)).round().max(1.0)
}

/// The skeleton capsules of `model` (see the module documentation), each with
/// `radius(frame name)`; `with_tool`: include the tool's own segment.
pub fn skeleton_capsules(
    model: &Model,
    radius: &dyn Fn(&str) -> f64,
    with_tool: bool,
) -> Vec<Capsule> {
    segments(model)
        .into_iter()
        .filter(|s| with_tool || !s.tool)
        .map(|s| {
            let frame = model.links[s.link].spec.name.clone();
            Capsule {
                radius: radius(&frame),
                frame,
                a: [s.a.x, s.a.y, s.a.z],
                b: [s.b.x, s.b.y, s.b.z],
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The skeleton's capsules are rigid in their frames: at random configurations their
    /// world ends are still the joint points they were built from (each joint point lies on
    /// its axis, which is fixed in the bodies on both sides), for every built-in robot's
    /// chain (DH, Hayati, MDH, ZRP forms).
    #[test]
    fn skeleton_follows_the_joint_points_at_any_configuration() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        for name in super::super::NAMES {
            let robot = super::super::robot(name).expect("builds");
            let model = Model::from_spec(&robot.spec).expect("model");
            let caps = skeleton_capsules(&model, &|_| 10.0, false);
            assert!(caps.len() >= 3, "{name}: {} capsules", caps.len());
            let mut data = Data::<f64>::new(&model);
            let (lo, hi) = model.joint_limits();
            for _ in 0..5 {
                let q: Vec<f64> = lo
                    .iter()
                    .zip(&hi)
                    .map(|(l, h)| rng.random_range(*l..=*h))
                    .collect();
                forward_kinematics(&model, &mut data, &model.nominal(), &q);
                let world: Vec<[Vector3<f64>; 2]> = caps
                    .iter()
                    .map(|c| {
                        let f = &data.frames[model.link_index(&c.frame).expect("frame")];
                        [
                            f.transform_point(&c.a.into()),
                            f.transform_point(&c.b.into()),
                        ]
                    })
                    .collect();
                // Successive capsules meet: each one starts where the one before ended.
                for w in world.windows(2) {
                    assert!(
                        (w[0][1] - w[1][0]).norm() < 1e-6,
                        "{name}: the skeleton breaks at q = {q:?}"
                    );
                }
                // Every end is a joint point or the base or last frame's origin.
                for (k, jp) in data.joint_points.iter().enumerate() {
                    assert!(
                        world
                            .iter()
                            .any(|w| (w[0] - jp).norm() < 1e-6 || (w[1] - jp).norm() < 1e-6),
                        "{name}: joint point {k} is on no capsule end"
                    );
                }
            }
        }
    }
}
