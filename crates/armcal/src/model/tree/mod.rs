//! Kinematic trees (a torso with several arms, a humanoid) and coupled joints (a joint that
//! is a linear function of others: a parallelogram, a URDF `<mimic>`), issue 32.
//!
//! (Over 600 lines: the tree, its construction with every structural check, and the maps
//! between the tree and its branches — registry, joints, the spec at an estimate — read the
//! same index tables; split, they would be passed between files.)
//!
//! # Design: a tree is a set of serial branches with index maps
//!
//! A [`Tree`] holds one ordinary serial [`Model`] per *branch*: the path from the root link
//! to a link that targets hang from, with those targets. Around the branches it keeps
//! * one tree [`Registry`]: every parameter once, by name (`t1.theta`, `r3.d`,
//!   `tracker.x`): a link shared by several branches (the torso) and the instrument frame
//!   appear once;
//! * per branch, the map from its registry indices to the tree's ([`Branch::params`]): a
//!   branch's identification Jacobian columns scatter into the tree's columns (a tree
//!   parameter that is not on the branch has a zero column: it does not move that target);
//! * the tree's joint vector: every joint that is not coupled, in link order (what a data row
//!   carries), and per branch joint an affine map from it ([`JointMap`]):
//!   `q_b = offset + Σ c_k q_k`, the identity for an ordinary joint and the coupling for a
//!   coupled one. The joint Jacobian w.r.t. the tree's joints is the branch's, times the map.
//!
//! The alternative, one chain with a parent index per link (pinocchio's `parents`), is the
//! leaner representation (no link is evaluated twice) but every serial algorithm — the
//! chain's step list, forward kinematics, the twists, `ChainOrder` of the mixed derivative,
//! compliance's levers, the completeness form, calibrated IK, the design gradients — walks
//! `links` in order as one chain; each would need a tree walk and a second round of checks
//! for the 271 serial tests. The branch representation leaves every serial path untouched and
//! exactly as fast (a serial robot is not a [`Tree`] at all), reuses every serial algorithm
//! on each branch as it is (its Jacobians are the ones already checked against finite
//! differences and dual numbers), and costs, per measurement, one evaluation of the branch
//! it measures: the shared links are evaluated once per branch *measured*, which is what a
//! measurement row needs anyway (a row sees one target). What it costs is memory (the shared
//! links' steps are stored once per branch) and a scatter of Jacobian columns. So: branches.
//!
//! # Coupled joints
//!
//! A coupled joint has no variable of its own: its value is `offset + Σ c_k q_k` over
//! joints that are not coupled themselves (a coupling names no coupled joint, so the map
//! is one level deep), so data files need not carry it. Its link's parameters stay in the
//! registry; what the coupling makes redundant, the identifiability analysis finds over the
//! tree's own joints and names with the coupling as its reason.

use crate::model::chain::{LinkSpec, Model, ModelSpec};
use crate::model::link::{Joint, JointKind};
use crate::model::registry::{ParameterStatus, Registry, Segment};
use crate::Error;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

pub mod bending;
pub mod compliance;
pub mod identifiability;
pub mod kinematics;

/// A joint driven by others: `q = offset + Σ coefficient · q_joint` (rad or mm).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Coupling {
    /// The joints it follows (by joint name; none of them coupled) with their coefficients.
    pub terms: Vec<(String, f64)>,
    /// Constant term, in the coupled joint's unit (rad or mm).
    pub offset: f64,
}

/// A link of a tree as described: the link, the link it hangs from, and, for a coupled
/// joint, its coupling.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TreeLinkSpec {
    /// The link (name, geometry, joint), as in a serial chain.
    pub link: LinkSpec,
    /// The link it hangs from; `None`: the previous link in the list (the first link is the
    /// root).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub parent: Option<String>,
    /// Its joint is a linear function of others (`None`: its own variable).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coupling: Option<Coupling>,
}

/// A target (reflector, SMR, frame) and the link it hangs from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TreeTargetSpec {
    /// The target, as in a serial model.
    pub target: LinkSpec,
    /// Name of the link it hangs from.
    pub parent: String,
}

/// Everything needed to build a [`Tree`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TreeSpec {
    /// Robot name.
    pub name: String,
    /// Frame of the instrument in the world, shared by every branch (paper eq. 3).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub instrument: Option<LinkSpec>,
    /// The links, root first; a link's parent comes anywhere in the list.
    pub links: Vec<TreeLinkSpec>,
    /// The targets, each naming its link.
    pub targets: Vec<TreeTargetSpec>,
    /// Joint and lateral compliance over the tree ([`compliance`], [`bending`]): gravity,
    /// the lever geometry (the tree's nominal parameters) and the lumped joint and bending
    /// terms, each naming its tree joint and the joint on whose axis its mass sits.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compliance: Option<crate::model::compliance::ComplianceSpec>,
}

/// A coupled joint of a tree: its name, its link, its kind and what drives it.
#[derive(Clone, Debug, PartialEq)]
pub struct CoupledJoint {
    /// Joint name.
    pub joint: String,
    /// Name of the link it drives.
    pub link: String,
    /// Revolute or prismatic (the unit of its offset).
    pub kind: JointKind,
    /// What drives it.
    pub coupling: Coupling,
}

/// One joint of a branch as a function of the tree's joints: `offset + Σ c_k q[k]`.
#[derive(Clone, Debug, PartialEq)]
pub struct JointMap {
    /// Constant term (rad or mm).
    pub offset: f64,
    /// (index into the tree's joints, coefficient).
    pub terms: Vec<(usize, f64)>,
}

/// A serial path of the tree, root to the link its targets hang from.
#[derive(Clone, Debug)]
pub struct Branch {
    /// The path as an ordinary serial model (instrument, links, the targets of its last link).
    pub model: Model,
    /// Tree registry index of each of the branch model's parameters.
    pub params: Vec<usize>,
    /// Each branch joint as a function of the tree's joints.
    pub joints: Vec<JointMap>,
    /// Tree target index of each of the branch's targets.
    pub targets: Vec<usize>,
}

/// An immutable kinematic tree with one parameter registry.
#[derive(Clone, Debug)]
pub struct Tree {
    /// Robot name.
    pub name: String,
    /// Every parameter once: instrument, links in spec order, targets.
    pub registry: Registry,
    /// The joints a data row carries: every joint that is not coupled, in link order.
    pub joints: Vec<Joint>,
    /// The coupled joints, in link order.
    pub coupled: Vec<CoupledJoint>,
    /// The branches, in the order of their last link in the spec.
    pub branches: Vec<Branch>,
    /// Per tree target (spec order): its name, branch and index within the branch.
    pub targets: Vec<(String, usize, usize)>,
    /// Names of the links where several branches part (the last link they share).
    pub forks: Vec<String>,
    /// Joint compliance over the tree (its κ follow the targets in the registry); `None`:
    /// a rigid tree.
    pub compliance: Option<compliance::TreeCompliance>,
    /// The links that hang from a fork with a joint whose axis the fork's frame places (a
    /// DH, Hayati or MDH link), after the first such link of that fork: their axes are tied
    /// to the first's (DH: on the fork frame's z; MDH: meeting its x at a right angle), so
    /// the tree is not complete there ([`Tree::incomplete_forks`]).
    incomplete: Vec<String>,
    /// The spec it was built from.
    spec: TreeSpec,
}

impl Tree {
    /// Builds a tree and checks it: link and joint names unique, every parent exists, no
    /// cycle, every link leads to a target, every target's link exists, couplings name
    /// joints that exist and are not coupled themselves, with finite coefficients.
    pub fn from_spec(spec: &TreeSpec) -> Result<Tree, Error> {
        let n = spec.links.len();
        if n == 0 {
            return Err(Error::Model(format!("tree `{}` has no links", spec.name)));
        }
        let index: HashMap<&str, usize> = {
            let mut index = HashMap::new();
            for (i, l) in spec.links.iter().enumerate() {
                if index.insert(l.link.name.as_str(), i).is_some() {
                    return Err(Error::Model(format!(
                        "link name `{}` is used twice",
                        l.link.name
                    )));
                }
            }
            index
        };
        let parent = parents(spec, &index)?;
        // every joint named once; the tree's own joints in link order
        let mut joint_link: HashMap<&str, usize> = HashMap::new();
        for (i, l) in spec.links.iter().enumerate() {
            if let Some(j) = &l.link.joint {
                if let Some(first) = joint_link.insert(j.name.as_str(), i) {
                    return Err(Error::Model(format!(
                        "joint `{}` is named twice (links `{}` and `{}`)",
                        j.name, spec.links[first].link.name, l.link.name
                    )));
                }
            }
        }
        let mut joints = Vec::new();
        let mut tree_joint = HashMap::new();
        for l in &spec.links {
            match (&l.link.joint, &l.coupling) {
                (Some(j), None) => {
                    tree_joint.insert(j.name.clone(), joints.len());
                    joints.push(j.clone());
                }
                (None, Some(_)) => {
                    return Err(Error::Model(format!(
                        "link `{}` is coupled but has no joint",
                        l.link.name
                    )))
                }
                _ => {}
            }
        }
        let mut coupled = Vec::new();
        let mut maps: Vec<Option<JointMap>> = vec![None; n];
        for (i, l) in spec.links.iter().enumerate() {
            let Some(j) = &l.link.joint else { continue };
            maps[i] = Some(match &l.coupling {
                None => JointMap {
                    offset: 0.0,
                    terms: vec![(tree_joint[&j.name], 1.0)],
                },
                Some(c) => {
                    let map =
                        coupling_map(&j.name, c, &tree_joint, &joint_link).map_err(
                            |e| match e {
                                Error::Model(m) => {
                                    Error::Model(format!("link `{}`: {m}", l.link.name))
                                }
                                other => other,
                            },
                        )?;
                    coupled.push(CoupledJoint {
                        joint: j.name.clone(),
                        link: l.link.name.clone(),
                        kind: j.kind,
                        coupling: c.clone(),
                    });
                    map
                }
            });
        }
        // branches: one per link that targets hang from, in link order
        let mut hung: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (k, t) in spec.targets.iter().enumerate() {
            let Some(&i) = index.get(t.parent.as_str()) else {
                return Err(Error::Model(format!(
                    "target `{}` hangs from `{}`, which is no link of the robot",
                    t.target.name, t.parent
                )));
            };
            hung[i].push(k);
        }
        let mut on_path = vec![0usize; n];
        let mut paths = Vec::new();
        for (i, targets) in hung.iter().enumerate() {
            if targets.is_empty() {
                continue;
            }
            let mut path = vec![i];
            while let Some(p) = parent[*path.last().expect("non-empty")] {
                path.push(p);
            }
            path.reverse();
            for &l in &path {
                on_path[l] += 1;
            }
            paths.push((path, targets.clone()));
        }
        if let Some(i) = on_path.iter().position(|&c| c == 0) {
            return Err(Error::Model(format!(
                "link `{}` leads to no target: name a target that hangs from it or from a \
                 link beyond it, or remove it",
                spec.links[i].link.name
            )));
        }
        let forks = (0..n)
            .filter(|&i| {
                (0..n).filter(|&c| parent[c] == Some(i)).count() > 1
                    || (!hung[i].is_empty() && on_path[i] > 1)
            })
            .map(|i| spec.links[i].link.name.clone())
            .collect();
        let mut incomplete = Vec::new();
        for (f, fork) in spec.links.iter().enumerate() {
            let tied: Vec<&TreeLinkSpec> = spec
                .links
                .iter()
                .enumerate()
                .filter(|&(c, l)| parent[c] == Some(f) && places_axis_on_parent(l))
                .map(|(_, l)| l)
                .collect();
            for l in tied.iter().skip(1) {
                incomplete.push(format!(
                    "link `{}` hangs from `{}` with a {} joint, as `{}` does: both joint axes \
                     are set by the frame of `{}`, so the tree cannot place them apart; start \
                     the branch with a frame of its own (a `frame6` link) or give the link a \
                     convention that places its own axis (zrp, urdf)",
                    l.link.name,
                    fork.link.name,
                    l.link.geometry.convention,
                    tied[0].link.name,
                    fork.link.name
                ));
            }
        }
        let mut branches = Vec::new();
        let mut targets = vec![(String::new(), 0, 0); spec.targets.len()];
        for (path, ks) in &paths {
            let model = Model::from_spec(&ModelSpec {
                name: spec.name.clone(),
                instrument: spec.instrument.clone(),
                links: path.iter().map(|&i| spec.links[i].link.clone()).collect(),
                targets: ks.iter().map(|&k| spec.targets[k].target.clone()).collect(),
                compliance: None,
                periodic: None,
                payloads: Vec::new(),
            })?;
            let joints = path
                .iter()
                .filter_map(|&i| maps[i].clone())
                .collect::<Vec<_>>();
            for (local, &k) in ks.iter().enumerate() {
                targets[k] = (spec.targets[k].target.name.clone(), branches.len(), local);
            }
            branches.push(Branch {
                model,
                params: Vec::new(),
                joints,
                targets: ks.clone(),
            });
        }
        let mut registry = tree_registry(spec, &branches, &targets)?;
        for b in &mut branches {
            b.params = (0..b.model.param_count())
                .map(|i| registry.require(&b.model.registry.get(i).name))
                .collect::<Result<_, _>>()?;
        }
        let compliance = spec
            .compliance
            .as_ref()
            .map(|c| compliance::compile(c, &joints, &branches, &mut registry))
            .transpose()?;
        Ok(Tree {
            name: spec.name.clone(),
            registry,
            joints,
            coupled,
            branches,
            targets,
            forks,
            compliance,
            incomplete,
            spec: spec.clone(),
        })
    }

    /// The spec the tree was built from (nominal values).
    pub fn spec(&self) -> &TreeSpec {
        &self.spec
    }

    /// The spec of this tree with every geometric value taken from the tree parameter
    /// vector `params` (an estimate): each link, the instrument and each target at its
    /// branch's values (a shared link is one parameter set, so every branch gives it alike).
    pub fn spec_at(&self, params: &[f64]) -> TreeSpec {
        let mut spec = self.spec.clone();
        for b in &self.branches {
            let local: Vec<f64> = b.params.iter().map(|&t| params[t]).collect();
            let at = b.model.spec_at(&local);
            if let (Some(i), Some(given)) = (at.instrument, spec.instrument.as_mut()) {
                *given = i;
            }
            for l in at.links {
                if let Some(t) = spec.links.iter_mut().find(|t| t.link.name == l.name) {
                    t.link = l;
                }
            }
            for (k, t) in at.targets.into_iter().enumerate() {
                spec.targets[b.targets[k]].target = t;
            }
        }
        if let (Some(c), Some(given)) = (&self.compliance, spec.compliance.as_mut()) {
            for (term, t) in c.terms.iter().zip(&mut given.terms) {
                t.value = params[term.param];
            }
            for (term, t) in c.bending.iter().zip(&mut given.bending) {
                t.value = params[term.param];
            }
        }
        spec
    }

    /// The same tree with every coupled joint moving on its own (a data row then carries
    /// it): what the coupling costs is the difference between their identifiable sets.
    pub fn uncoupled(&self) -> Result<Tree, Error> {
        let mut spec = self.spec.clone();
        for l in &mut spec.links {
            l.coupling = None;
        }
        let mut tree = Tree::from_spec(&spec)?;
        for i in 0..tree.param_count() {
            tree.registry.set_status(i, self.registry.get(i).status);
        }
        Ok(tree)
    }

    /// Links after a fork whose joint axes the tree cannot place apart (each sentence names
    /// the link, its fork and the fix); empty for a complete tree, the condition of the
    /// generic count ([`identifiability::expected_tree_count`]).
    pub fn incomplete_forks(&self) -> &[String] {
        &self.incomplete
    }

    /// Number of the tree's joints (a data row's joint values).
    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    /// Number of parameters (length of a tree parameter vector).
    pub fn param_count(&self) -> usize {
        self.registry.len()
    }

    /// Nominal parameter vector in registry order (mm, rad).
    pub fn nominal(&self) -> Vec<f64> {
        self.registry.nominal()
    }

    /// Branch and index within it of the target named `name`.
    pub fn target(&self, name: &str) -> Option<(usize, usize)> {
        self.targets
            .iter()
            .find(|t| t.0 == name)
            .map(|&(_, b, k)| (b, k))
    }

    /// Sets the status of every parameter matching `pattern` ([`Registry::matching`]).
    pub fn set_status(&mut self, pattern: &str, status: ParameterStatus) -> Result<(), Error> {
        for i in self.registry.matching(pattern)? {
            self.registry.set_status(i, status);
        }
        Ok(())
    }

    /// The coupling that drives the link named `link`, if its joint is coupled, in words:
    /// ``joint `q4` = -1 × `q2` - 1 × `q3` + 90°``.
    pub fn coupling_of(&self, link: &str) -> Option<String> {
        let c = self.coupled.iter().find(|c| c.link == link)?;
        let mut s = format!("joint `{}` =", c.joint);
        for (k, (name, a)) in c.coupling.terms.iter().enumerate() {
            let sign = match (k, *a < 0.0) {
                (0, true) => " -".to_string(),
                (0, false) => " ".to_string(),
                (_, true) => " - ".to_string(),
                (_, false) => " + ".to_string(),
            };
            s += &format!("{sign}{} × `{name}`", a.abs());
        }
        if c.coupling.offset != 0.0 {
            let unit = c.kind.unit();
            s += &format!(
                " + {}{}",
                c.coupling.offset * unit.display_factor(),
                if c.kind == JointKind::Revolute {
                    "°"
                } else {
                    " mm"
                }
            );
        }
        Some(s)
    }
}

/// Whether a link's joint axis is set by its parent's frame: a jointed DH, Hayati or MDH
/// link (the axis is the parent frame's z, or meets its x at a right angle); a ZRP, URDF or
/// S-model link places its own axis, a fixed link has none.
fn places_axis_on_parent(l: &TreeLinkSpec) -> bool {
    use crate::model::link::Convention;
    l.link.joint.is_some()
        && !matches!(
            l.link.geometry.convention,
            Convention::Zrp | Convention::Urdf | Convention::SModel
        )
}

/// Each link's parent index (`None` for the root), checking that parents exist and that
/// every link leads back to the root.
fn parents(spec: &TreeSpec, index: &HashMap<&str, usize>) -> Result<Vec<Option<usize>>, Error> {
    let n = spec.links.len();
    let mut parent = vec![None; n];
    for (i, l) in spec.links.iter().enumerate() {
        parent[i] = match &l.parent {
            Some(p) => Some(*index.get(p.as_str()).ok_or_else(|| {
                Error::Model(format!(
                    "link `{}` names parent `{p}`, which is no link of the robot",
                    l.link.name
                ))
            })?),
            None => i.checked_sub(1),
        };
    }
    if spec.links[0].parent.is_some() {
        return Err(Error::Model(format!(
            "the first link `{}` is the root: it cannot name a parent",
            spec.links[0].link.name
        )));
    }
    for start in 0..n {
        let (mut at, mut seen) = (start, vec![start]);
        while let Some(p) = parent[at] {
            if seen.contains(&p) {
                let names: Vec<&str> = seen
                    .iter()
                    .map(|&i| spec.links[i].link.name.as_str())
                    .collect();
                return Err(Error::Model(format!(
                    "links {} form a cycle through their parents: every link's parent must \
                     lead back to the first link",
                    names
                        .iter()
                        .map(|s| format!("`{s}`"))
                        .collect::<Vec<_>>()
                        .join(" → ")
                )));
            }
            seen.push(p);
            at = p;
        }
    }
    Ok(parent)
}

/// The map of a coupled joint, checked.
fn coupling_map(
    joint: &str,
    c: &Coupling,
    tree_joint: &HashMap<String, usize>,
    joint_link: &HashMap<&str, usize>,
) -> Result<JointMap, Error> {
    if c.terms.is_empty() {
        return Err(Error::Model(format!(
            "coupled joint `{joint}` names no joint it follows"
        )));
    }
    if !c.offset.is_finite() {
        return Err(Error::Model(format!(
            "coupled joint `{joint}`: the offset is not finite"
        )));
    }
    let mut terms = Vec::new();
    for (name, a) in &c.terms {
        if !a.is_finite() {
            return Err(Error::Model(format!(
                "coupled joint `{joint}`: the coefficient of `{name}` is not finite"
            )));
        }
        let k = match tree_joint.get(name) {
            Some(&k) => k,
            None if joint_link.contains_key(name.as_str()) => {
                return Err(Error::Model(format!(
                    "coupled joint `{joint}` follows `{name}`, which is coupled itself: \
                     write the coupling in the joints `{name}` follows"
                )))
            }
            None => {
                return Err(Error::Model(format!(
                    "coupled joint `{joint}` follows `{name}`, which is no joint of the robot"
                )))
            }
        };
        if terms.iter().any(|&(o, _)| o == k) {
            return Err(Error::Model(format!(
                "coupled joint `{joint}` names `{name}` twice"
            )));
        }
        terms.push((k, *a));
    }
    Ok(JointMap {
        offset: c.offset,
        terms,
    })
}

/// The tree's registry: instrument, links in spec order, targets, each parameter once, with
/// the nominal values and units of the branch that holds it; a target's segment is its tree
/// target index.
fn tree_registry(
    spec: &TreeSpec,
    branches: &[Branch],
    targets: &[(String, usize, usize)],
) -> Result<Registry, Error> {
    let mut registry = Registry::new();
    let mut add_frame = |model: &Model, first: usize, count: usize, segment: Segment| {
        for i in first..first + count {
            let p = model.registry.get(i);
            registry.add(p.name.clone(), p.unit, p.nominal, segment)?;
        }
        Ok::<(), Error>(())
    };
    let first = &branches[0].model;
    if let Some(l) = &first.instrument {
        add_frame(first, l.first_param, l.param_count(), Segment::Instrument)?;
    }
    for l in &spec.links {
        let (model, link) = branches
            .iter()
            .find_map(|b| {
                b.model
                    .link_index(&l.link.name)
                    .map(|i| (&b.model, &b.model.links[i]))
            })
            .expect("every link is on a branch (checked)");
        add_frame(model, link.first_param, link.param_count(), Segment::Chain)?;
    }
    for (k, &(_, b, local)) in targets.iter().enumerate() {
        let model = &branches[b].model;
        let t = &model.targets[local];
        add_frame(model, t.first_param, t.param_count(), Segment::Target(k))?;
    }
    Ok(registry)
}
