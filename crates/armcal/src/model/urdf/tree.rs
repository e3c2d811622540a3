//! URDF ↔ kinematic tree ([`crate::model::tree`], issue 32): a URDF whose link graph branches
//! (a torso with two arms, a humanoid) as one [`TreeSpec`], `<mimic>` joints as coupled
//! joints, and a tree back to one URDF file.
//!
//! **Import** ([`read_urdf_tree`], [`tree_from_urdf_str`]). The tree's root is an identity
//! frame `base` at the URDF root link; every URDF joint becomes one link of the tree, named
//! after the joint (as in the serial import, [`super`]), hanging from the link of the joint
//! whose child its URDF parent link is (`base` for the root link): revolute, continuous and
//! prismatic joints as [`Convention::Urdf`](crate::model::Convention::Urdf) links, fixed
//! joints as `frame6` links, with the serial import's origins, limits and unit checks. The
//! measured points name the URDF link they hang from (`targets`; a target may also name a
//! tree link, the joint's name, or `base`); without targets, every leaf link of the URDF is a
//! frame target named after that link (a pose at each hand). Links beyond which no target
//! hangs are left out (as the serial import leaves out the links off its chain).
//!
//! `<mimic joint="j" multiplier="m" offset="o"/>` (URDF: `q = m · q_j + o`, defaults m = 1,
//! o = 0) becomes a coupled joint `q = m' · q_j + o'` in armcal's internal units (rad, mm):
//! `o' = o` for a revolute joint and `o / 1 m/1000 mm` for a prismatic one, `m' = m` between
//! joints of one kind, `m · 1000` for a prismatic joint following a revolute one (m/rad →
//! mm/rad) and `m / 1000` for the converse. A mimic of a mimic joint, of an unknown or fixed
//! joint, of itself, or of a joint that no target needs, is refused naming both joints.
//!
//! **Export** ([`tree_to_urdf`]): every link transform is split at its joint motion as in the
//! serial export (`T_i(q) = A_i · J(q) · B_i`); a joint's `<origin>` is the fixed transform
//! from the URDF frame of the nearest jointed link above it (`B` of that link, then the fixed
//! links between) to its `A_i`, so fixed links fold into the next joint's origin (their
//! names are not kept; the joints, their parents and couplings are). A coupled joint following
//! one joint is written as `<mimic>` (the inverse unit conversion); a coupling of several
//! joints (`q4 = −q2 − q3`) has no URDF form and is refused by name. Every target hangs off its
//! link's URDF frame with a fixed joint. The instrument belongs to the cell and is not
//! exported.

use crate::model::chain::LinkSpec;
use crate::model::link::{JointKind, LinkGeometry};
use crate::model::pose::Pose;
use crate::model::tree::{Coupling, Tree, TreeLinkSpec, TreeSpec, TreeTargetSpec};
use crate::Error;
use std::collections::{HashMap, HashSet};
use std::path::Path;

use super::export::{empty_link, fixed_pose, split_at_joint, urdf_joint, write};
use super::import::{identity_frame, import_joint, parse_robot, sanitise, structure};
use super::{unique, M_PER_MM};

/// Reads a URDF file as a kinematic tree whose `targets` each name the URDF link (or tree
/// link) they hang from; `None`: a frame target at every leaf link. Errors name the file.
pub fn read_urdf_tree(
    path: impl AsRef<Path>,
    targets: Option<&[TreeTargetSpec]>,
) -> Result<TreeSpec, Error> {
    super::parse_file(path.as_ref(), "the URDF file", |text| {
        tree_from_urdf_str(text, targets)
    })
}

/// Parses URDF text as a kinematic tree (see [`read_urdf_tree`]).
pub fn tree_from_urdf_str(
    xml: &str,
    targets: Option<&[TreeTargetSpec]>,
) -> Result<TreeSpec, Error> {
    import_tree(&parse_robot(xml)?, targets)
}

/// The tree of a parsed URDF robot.
fn import_tree(
    robot: &urdf_rs::Robot,
    targets: Option<&[TreeTargetSpec]>,
) -> Result<TreeSpec, Error> {
    let err = |m: String| Error::Input(format!("URDF robot `{}`: {m}", robot.name));
    let s = structure(robot)?;
    // the URDF links depth first from the root, children in file order
    let mut children: HashMap<&str, Vec<&urdf_rs::Joint>> = HashMap::new();
    for j in &robot.joints {
        children.entry(j.parent.link.as_str()).or_default().push(j);
    }
    let mut order: Vec<&urdf_rs::Joint> = Vec::new();
    let mut stack: Vec<&urdf_rs::Joint> = children
        .get(s.root)
        .map(|c| c.iter().rev().copied().collect())
        .unwrap_or_default();
    while let Some(j) = stack.pop() {
        order.push(j);
        if let Some(c) = children.get(j.child.link.as_str()) {
            stack.extend(c.iter().rev().copied());
        }
    }
    if order.len() != robot.joints.len() {
        let mut lost: Vec<&str> = robot
            .joints
            .iter()
            .filter(|j| !order.iter().any(|o| o.name == j.name))
            .map(|j| j.name.as_str())
            .collect();
        lost.sort_unstable();
        return Err(err(format!(
            "joints {} form a cycle: they do not hang from the root link `{}`; a URDF is a tree",
            lost.iter()
                .map(|j| format!("`{j}`"))
                .collect::<Vec<_>>()
                .join(", "),
            s.root
        )));
    }
    // tree link names: `base` for the root, the joint's name (made unique) for the others
    let mut taken: HashSet<String> = ["base".to_string()].into();
    let mut frame_of: HashMap<&str, String> = HashMap::new();
    frame_of.insert(s.root, "base".into());
    let mut links = vec![TreeLinkSpec {
        link: identity_frame("base"),
        parent: None,
        coupling: None,
    }];
    for j in &order {
        let name = unique(&sanitise(&j.name), &mut taken);
        let link =
            import_joint(j, name.clone()).map_err(|m| err(format!("joint `{}`: {m}", j.name)))?;
        links.push(TreeLinkSpec {
            link,
            parent: Some(frame_of[j.parent.link.as_str()].clone()),
            coupling: None,
        });
        frame_of.insert(j.child.link.as_str(), name);
    }
    // targets: on the links they name, or a frame at every leaf
    let targets: Vec<TreeTargetSpec> = match targets {
        Some(given) => given
            .iter()
            .map(|t| {
                let parent = match frame_of.get(t.parent.as_str()) {
                    Some(f) => f.clone(),
                    None if links.iter().any(|l| l.link.name == t.parent) => t.parent.clone(),
                    None => {
                        let mut known: Vec<&str> = s.links.iter().copied().collect();
                        known.sort_unstable();
                        return Err(err(format!(
                            "target `{}` hangs from `{}`, which is no link of the URDF (links: \
                             {})",
                            t.target.name,
                            t.parent,
                            known.join(", ")
                        )));
                    }
                };
                Ok(TreeTargetSpec {
                    target: t.target.clone(),
                    parent,
                })
            })
            .collect::<Result<_, Error>>()?,
        None => robot
            .links
            .iter()
            .filter(|l| !s.has_children.contains(l.name.as_str()))
            .map(|l| TreeTargetSpec {
                target: LinkSpec {
                    name: unique(&sanitise(&l.name), &mut taken),
                    geometry: LinkGeometry::frame6([0.0; 3], [0.0; 3]),
                    joint: None,
                },
                parent: frame_of[l.name.as_str()].clone(),
            })
            .collect(),
    };
    // keep the links on a path from the root to a target
    let parent_of: HashMap<&str, &str> = links
        .iter()
        .filter_map(|l| Some((l.link.name.as_str(), l.parent.as_deref()?)))
        .collect();
    let mut needed: HashSet<&str> = HashSet::new();
    for t in &targets {
        let mut at = Some(t.parent.as_str());
        while let Some(l) = at {
            if !needed.insert(l) {
                break;
            }
            at = parent_of.get(l).copied();
        }
    }
    let needed: HashSet<String> = needed.into_iter().map(str::to_string).collect();
    let mut links: Vec<TreeLinkSpec> = links
        .into_iter()
        .filter(|l| needed.contains(&l.link.name))
        .collect();
    // <mimic> joints: couplings to joints that stay in the tree
    let tree_name: HashMap<&str, &str> = order
        .iter()
        .map(|j| (j.name.as_str(), frame_of[j.child.link.as_str()].as_str()))
        .collect();
    for j in &order {
        let Some(m) = &j.mimic else { continue };
        let name = tree_name[j.name.as_str()];
        let Some(link) = links.iter().position(|l| l.link.name == name) else {
            continue;
        };
        let mimic_err = |what: String| {
            err(format!(
                "joint `{}`, <mimic joint=\"{}\">: {what}",
                j.name, m.joint
            ))
        };
        let kind = |j: &urdf_rs::Joint| match j.joint_type {
            urdf_rs::JointType::Revolute | urdf_rs::JointType::Continuous => {
                Some(JointKind::Revolute)
            }
            urdf_rs::JointType::Prismatic => Some(JointKind::Prismatic),
            _ => None,
        };
        let follower = kind(j).ok_or_else(|| mimic_err("a fixed joint cannot mimic".into()))?;
        if m.joint == j.name {
            return Err(mimic_err("a joint cannot mimic itself".into()));
        }
        let leader = robot
            .joints
            .iter()
            .find(|o| o.name == m.joint)
            .ok_or_else(|| mimic_err(format!("the URDF has no joint `{}`", m.joint)))?;
        if let Some(mm) = &leader.mimic {
            return Err(mimic_err(format!(
                "`{}` mimics `{}` itself; write this joint's <mimic> on `{}` (multiplier and \
                 offset composed): a coupled joint follows joints that move on their own",
                m.joint, mm.joint, mm.joint
            )));
        }
        let leader_kind = kind(leader).ok_or_else(|| {
            mimic_err(format!(
                "`{}` is a fixed joint; mimic a moving one",
                m.joint
            ))
        })?;
        let leader_name = tree_name[leader.name.as_str()];
        if !needed.contains(leader_name) {
            return Err(mimic_err(format!(
                "`{}` is on no path from the root to a target, so the tree does not hold it; \
                 hang a target beyond `{}`",
                m.joint, leader.child.link
            )));
        }
        let (multiplier, offset) = (m.multiplier.unwrap_or(1.0), m.offset.unwrap_or(0.0));
        if !(multiplier.is_finite() && offset.is_finite()) {
            return Err(mimic_err(format!(
                "multiplier {multiplier} and offset {offset} must be finite numbers"
            )));
        }
        links[link].coupling = Some(Coupling {
            terms: vec![(
                leader_name.to_string(),
                multiplier * coefficient_scale(follower, leader_kind),
            )],
            offset: offset / length_scale(follower),
        });
    }
    if links.iter().all(|l| l.link.joint.is_none()) {
        return Err(err(
            "no movable joint on a path from the root to a target".into()
        ));
    }
    let spec = TreeSpec {
        name: robot.name.clone(),
        instrument: None,
        links,
        targets,
        compliance: None,
    };
    Tree::from_spec(&spec).map_err(|e| err(e.to_string()))?;
    Ok(spec)
}

/// URDF units (m or rad) per internal unit (mm or rad) of a joint of `kind`.
fn length_scale(kind: JointKind) -> f64 {
    match kind {
        JointKind::Revolute => 1.0,
        JointKind::Prismatic => M_PER_MM,
    }
}

/// Internal coupling coefficient per URDF mimic multiplier of a `follower` joint following a
/// `leader`: (URDF unit of the leader / internal unit) ÷ (URDF unit of the follower /
/// internal unit).
fn coefficient_scale(follower: JointKind, leader: JointKind) -> f64 {
    length_scale(leader) / length_scale(follower)
}

/// Writes the tree `spec` as one URDF document: every joint with its parent, `<mimic>` for a
/// coupled joint following one joint, every target on a fixed joint (see the module
/// documentation). The instrument is not written.
pub fn tree_to_urdf(spec: &TreeSpec) -> Result<String, Error> {
    Tree::from_spec(spec)?;
    let err = |m: String| Error::Model(format!("URDF export of tree `{}`: {m}", spec.name));
    let mut link_names: HashSet<String> = spec
        .links
        .iter()
        .map(|l| l.link.name.clone())
        .chain(spec.targets.iter().map(|t| t.target.name.clone()))
        .collect();
    let mut joint_names: HashSet<String> = spec
        .links
        .iter()
        .filter_map(|l| l.link.joint.as_ref().map(|j| j.name.clone()))
        .collect();
    let root = unique(&format!("{}_root", spec.name), &mut link_names);
    let mut urdf_links = vec![empty_link(&root)];
    let mut urdf_joints = Vec::new();
    // per tree link: the URDF link it moves with, and the pose of its end frame in that link
    let mut at: HashMap<&str, (String, Pose<f64>)> = HashMap::new();
    let kind_of: HashMap<&str, JointKind> = spec
        .links
        .iter()
        .filter_map(|l| l.link.joint.as_ref().map(|j| (j.name.as_str(), j.kind)))
        .collect();
    for (i, l) in spec.links.iter().enumerate() {
        let parent = match &l.parent {
            Some(p) => p.as_str(),
            None if i == 0 => "",
            None => spec.links[i - 1].link.name.as_str(),
        };
        let (frame, pending) = at
            .get(parent)
            .cloned()
            .unwrap_or_else(|| (root.clone(), Pose::identity()));
        let ls = &l.link;
        let Some(joint) = &ls.joint else {
            let pose = pending.compose(&fixed_pose(&ls.geometry));
            at.insert(ls.name.as_str(), (frame, pose));
            continue;
        };
        let (a, axis, b) = split_at_joint(&ls.geometry, joint.kind);
        let child = ls.name.clone();
        let scale = length_scale(joint.kind);
        let mut uj = urdf_joint(
            &joint.name,
            match joint.kind {
                JointKind::Revolute => urdf_rs::JointType::Revolute,
                JointKind::Prismatic => urdf_rs::JointType::Prismatic,
            },
            &frame,
            &child,
            &pending.compose(&a),
            axis,
            Some((joint.lower * scale, joint.upper * scale)),
        );
        if let Some(c) = &l.coupling {
            let [(leader, coefficient)] = c.terms.as_slice() else {
                return Err(err(format!(
                    "coupled joint `{}` follows {} joints; a URDF <mimic> follows one (write \
                     the tree as a cell instead)",
                    joint.name,
                    c.terms.len()
                )));
            };
            let leader_kind = kind_of.get(leader.as_str()).copied().ok_or_else(|| {
                err(format!(
                    "coupled joint `{}`: no joint `{leader}`",
                    joint.name
                ))
            })?;
            uj.mimic = Some(urdf_rs::Mimic {
                joint: leader.clone(),
                multiplier: Some(coefficient / coefficient_scale(joint.kind, leader_kind)),
                offset: Some(c.offset * scale),
            });
        }
        urdf_joints.push(uj);
        urdf_links.push(empty_link(&child));
        at.insert(ls.name.as_str(), (child, b));
    }
    for t in &spec.targets {
        let (frame, pending) = at
            .get(t.parent.as_str())
            .cloned()
            .expect("Tree::from_spec checked every target's link");
        let name = unique(&format!("{}_fixed", t.target.name), &mut joint_names);
        urdf_joints.push(urdf_joint(
            &name,
            urdf_rs::JointType::Fixed,
            &frame,
            &t.target.name,
            &pending.compose(&fixed_pose(&t.target.geometry)),
            nalgebra::Vector3::x(),
            None,
        ));
        urdf_links.push(empty_link(&t.target.name));
    }
    write(
        &urdf_rs::Robot {
            name: spec.name.clone(),
            version: None,
            links: urdf_links,
            joints: urdf_joints,
            materials: Vec::new(),
        },
        &spec.name,
    )
}
