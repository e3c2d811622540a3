//! Joint compliance over a kinematic tree (issue 32 item 3): a compliant joint deflects
//! under the gravity torque of *every* branch beyond it, so a torso joint is loaded by both
//! arms at both arms' current configurations.
//!
//! # Model
//! The serial model ([`crate::model::compliance`]) carried to the tree's joint space. Let
//! `q` be the tree's joints (a data row's values; a coupled joint follows its map
//! `q_b = offset + C_b q`, [`crate::model::tree::JointMap`]) and let a point mass `m` sit at
//! `x(q)`, the point where its branch reaches the axis of a joint. By virtual work in the
//! tree's coordinates, the generalised gravity force on tree joint `k` is
//!
//! `τ_k = m g ĝ · ∂x/∂q_k`, `∂x/∂q_k = Σ_{i < a} C_b[i, k] (ω_i × x + v_i)`,
//!
//! the sum over the joints `i` of the mass's branch before its point (the joint `a` on whose
//! axis it sits), `ξ_i = (ω_i, v_i)` their world twists: the serial lever
//! `ℓ_i = ĝ · ∂x/∂q_i` through the coupling (a coupled joint's share goes to the joints it
//! follows). A mass on one arm loads the torso joints whatever arm is measured: its lever
//! about the torso is evaluated at the whole tree's `q`. The deflection is
//! `Δq_k = Σ_m κ_{k,m} ℓ_k(x_m, q)` with `κ_{k,m} = c_k m g` (only products appear), and
//! every branch's forward kinematics runs at `q_b = offset + C_b (q + Δq)`: a torso
//! deflection moves both arms, a coupled joint follows its deflected drivers.
//!
//! `ĝ` is the unit gravity direction in the tree's root frame (the frame the first link
//! starts from; a cell's `[robot] gravity`, default `[0, 0, −1]`). As in the serial model
//! the levers are taken from the nominal geometry (kept with the spec), so `Δq` is a known
//! function of `q` times the unknown `κ` and the Jacobians stay exact:
//! * the column of `κ_t` (joint `k`) for a target of branch `b` is `ℓ_t Σ_i C_b[i, k] ξ_i`
//!   (tree joint `k`'s column of the branch's joint Jacobian at the deflected joints);
//! * the joint Jacobian w.r.t. the commanded tree joints is `J_b C_b (I + Σ_t κ_t e_k ∇ℓ_tᵀ)`,
//!   with `∂ℓ_t/∂q_j = Σ_i Σ_l C_b[i, k] C_b[l, j] ∂(ĝ · ξ_i(x))/∂q_{b,l}` and the serial
//!   rule for the inner derivative: `ĝ · (ω_l × (ω_i × x + v_i))` for `l ≤ i` (joint `l`
//!   turns axis `i` and the point), `ĝ · (ω_i × (ω_l × x + v_l))` for `i < l < a` (the point
//!   moves), 0 after the point.
//!
//! # Masses and the identifiable combinations
//! Per branch, the serial rule: an **elbow** on the axis of the joint after the branch's
//! first compliant joint of its own (past the fork; the first it shares with other
//! branches, the torso's, if it has none) and a **wrist** on the axis of the
//! second-to-last joint; a mass on a shared link (the torso) is one mass, however many
//! branches reach it. The term of joint `k` and the mass on the axis of joint `r3` is named
//! `k.compliance.elbow_r3` (`wrist_…` alike; the joint names the mass, so two arms' wrists
//! are two terms). The serial reductions run over the tree's joint space, on the levers
//! sampled at random tree configurations within the joint limits: **no torque** (a mass on
//! another branch than the joint, before it, on its axis, or an axis along gravity), **a
//! constant torque** (the joint offset's column) and **the same function twice** (a lever in
//! the span of the constant and the joint's kept levers) drop the term; a compliant joint
//! with no term left is an error. Compliance is for revolute joints with a variable of
//! their own: a coupled joint deflects with the joints it follows.

use crate::model::compliance::{gravity_direction, ComplianceSpec, ComplianceTerm};
use crate::model::kinematics::{forward_kinematics, Data};
use crate::model::registry::{Registry, Segment};
use crate::model::tree::bending::BendingData;
use crate::model::tree::kinematics::{branch_kinematics, TreeData};
use crate::model::tree::{Branch, Tree};
use crate::model::JointKind;
use crate::Error;
use nalgebra::{convert, RealField, Vector3};

/// Random tree configurations the lever tests of [`lumped_tree_compliance`] sample.
pub(crate) const LEVER_SAMPLES: usize = 200;

/// A lever whose part outside the span of the constant and the kept levers is below this
/// share of its norm is dropped (the serial test's threshold).
const LEVER_DEPENDENCE: f64 = 1e-6;

/// One compiled term of a tree's compliance.
#[derive(Clone, Debug)]
pub struct TreeComplianceTerm {
    /// The compliant tree joint (index into [`Tree::joints`]).
    pub joint: usize,
    /// The branch whose joint axis carries the mass, and the branch joint index of that axis.
    pub mass: (usize, usize),
    /// Index of κ in the tree registry.
    pub param: usize,
}

/// A tree's joint compliance compiled against it ([`Tree::compliance`]).
#[derive(Clone, Debug)]
pub struct TreeCompliance {
    /// Unit gravity in the tree's root frame.
    pub gravity: Vector3<f64>,
    /// The lever parameters: the tree's nominal link, instrument and target values (κ
    /// entries unused).
    pub levers: Vec<f64>,
    /// The terms, in registry order.
    pub terms: Vec<TreeComplianceTerm>,
    /// The lateral (bending) terms ([`crate::model::tree::bending`]), in registry order
    /// after the joint terms.
    pub bending: Vec<crate::model::tree::bending::TreeBendingTerm>,
}

/// Checks a tree's [`ComplianceSpec`] against its joints and branches and adds its κ to the
/// tree registry (unit µrad/m, segment chain); the error names the term and why.
pub(crate) fn compile(
    spec: &ComplianceSpec,
    joints: &[crate::model::link::Joint],
    branches: &[Branch],
    registry: &mut Registry,
) -> Result<TreeCompliance, Error> {
    let err = |m: String| Error::Model(format!("compliance: {m}"));
    let gravity = gravity_direction(spec.gravity).map_err(err)?;
    let link_params = registry.len();
    if spec.levers.len() != link_params || !spec.levers.iter().all(|x| x.is_finite()) {
        return Err(err(format!(
            "the lever geometry has {} values, the tree {link_params}",
            spec.levers.len()
        )));
    }
    let mut terms = Vec::new();
    for t in &spec.terms {
        let (joint, mass) =
            resolve(t, &ComplianceSpec::parameter_name(t), joints, branches).map_err(err)?;
        let param = add_term(t, ComplianceSpec::parameter_name(t), registry)?;
        terms.push(TreeComplianceTerm { joint, mass, param });
    }
    let mut bending = Vec::new();
    for t in &spec.bending {
        let name = ComplianceSpec::bending_name(t);
        let (joint, mass) = resolve(t, &name, joints, branches).map_err(err)?;
        let term = crate::model::tree::bending::TreeBendingTerm::new(joints, branches, joint, mass)
            .map_err(|m| err(format!("term `{name}`: {m}")))?;
        let param = add_term(t, name, registry)?;
        bending.push(crate::model::tree::bending::TreeBendingTerm { param, ..term });
    }
    let mut levers = spec.levers.clone();
    levers.resize(registry.len(), 0.0);
    Ok(TreeCompliance {
        gravity,
        levers,
        terms,
        bending,
    })
}

/// The tree joint of term `t` (named `name`) and its mass (branch, branch joint); the
/// error names the term and why.
fn resolve(
    t: &ComplianceTerm,
    name: &str,
    joints: &[crate::model::link::Joint],
    branches: &[Branch],
) -> Result<(usize, (usize, usize)), String> {
    let joint = joints
        .iter()
        .position(|j| j.name == t.joint && j.kind == JointKind::Revolute)
        .ok_or_else(|| {
            format!(
                "term `{name}`: `{}` is not a revolute joint of the tree with a variable of its \
                 own (a coupled joint deflects with the joints it follows)",
                t.joint
            )
        })?;
    let mass =
        t.at.as_deref()
            .and_then(|at| {
                branches.iter().enumerate().find_map(|(b, br)| {
                    br.model
                        .joints
                        .iter()
                        .position(|j| j.name == at)
                        .map(|a| (b, a))
                })
            })
            .ok_or_else(|| {
                format!(
                "term `{name}`: its mass names no joint of the tree (`at` = {:?}; a tree takes \
                 no payload terms)",
                t.at
            )
            })?;
    Ok((joint, mass))
}

/// Adds term `t`'s κ, named `name`, to the tree registry (segment chain), its value checked.
fn add_term(t: &ComplianceTerm, name: String, registry: &mut Registry) -> Result<usize, Error> {
    let unit = t.unit();
    if !unit.holds(t.value) {
        return Err(Error::Model(format!(
            "compliance: term `{name}` = {:e} {} is outside {}",
            t.value * unit.display_factor(),
            unit.display_name(),
            unit.range_text()
        )));
    }
    registry.add(name, unit, t.value, Segment::Chain)
}

/// Per evaluation, the deflection of a tree's compliant joints ([`TreeData`]).
#[derive(Clone, Debug)]
pub(crate) struct DeflectionData<T: RealField + Copy> {
    /// Per branch, the lever pass (the branch at the lever parameters and commanded joints).
    levers: Vec<Data<T>>,
    /// Per branch, its commanded joints.
    q: Vec<Vec<T>>,
    /// Per branch, its parameters at the lever geometry.
    lever_params: Vec<Vec<f64>>,
    /// Per branch, whether a term's mass sits on it (its lever pass is needed).
    needed: Vec<bool>,
    /// Per term, `ℓ_t(q)` (mm).
    pub(crate) lever: Vec<T>,
    /// Per term and tree joint (row-major, `term · dof + j`), `∂ℓ_t/∂q_j`.
    pub(crate) lever_rate: Vec<T>,
    /// The deflected tree joints `q + Δq`.
    pub(crate) deflected: Vec<T>,
    /// Per term, κ at the last evaluation.
    pub(crate) kappa: Vec<f64>,
    /// The bending terms' rotations and each branch's bend.
    pub(crate) bending: BendingData<T>,
}

impl<T: RealField + Copy> DeflectionData<T> {
    /// Buffers for `tree`; `None` without compliance.
    pub(crate) fn new(tree: &Tree) -> Option<Self> {
        let c = tree.compliance.as_ref()?;
        let mut needed = vec![false; tree.branches.len()];
        for mass in c
            .terms
            .iter()
            .map(|t| t.mass)
            .chain(c.bending.iter().map(|t| t.mass))
        {
            needed[mass.0] = true;
        }
        Some(DeflectionData {
            levers: tree
                .branches
                .iter()
                .map(|b| Data::without_corrections(&b.model))
                .collect(),
            q: tree
                .branches
                .iter()
                .map(|b| vec![T::zero(); b.model.dof()])
                .collect(),
            lever_params: tree
                .branches
                .iter()
                .map(|b| b.params.iter().map(|&t| c.levers[t]).collect())
                .collect(),
            needed,
            lever: vec![T::zero(); c.terms.len()],
            lever_rate: vec![T::zero(); c.terms.len() * tree.dof()],
            deflected: vec![T::zero(); tree.dof()],
            kappa: vec![0.0; c.terms.len()],
            bending: BendingData::new(tree, c),
        })
    }

    /// The levers, their rates and the deflected joints at the commanded tree joints `q`
    /// and parameters `params` (only the κ are read from them). Allocates nothing.
    pub(crate) fn evaluate(&mut self, tree: &Tree, params: &[f64], q: &[T]) {
        let c = tree
            .compliance
            .as_ref()
            .expect("DeflectionData::new checked");
        for (b, branch) in tree.branches.iter().enumerate() {
            if !self.needed[b] {
                continue;
            }
            let qb = &mut self.q[b];
            map_joints(branch, q, qb);
            forward_kinematics(
                &branch.model,
                &mut self.levers[b],
                &self.lever_params[b],
                qb,
            );
        }
        let g: Vector3<T> = c.gravity.map(convert::<f64, T>);
        let dof = tree.dof();
        self.deflected.copy_from_slice(q);
        for (t, term) in c.terms.iter().enumerate() {
            let (b, a) = term.mass;
            let branch = &tree.branches[b];
            let data = &self.levers[b];
            let x = data.joint_points[a];
            let tw = &data.joint_twists;
            let rates = &mut self.lever_rate[t * dof..(t + 1) * dof];
            rates.fill(T::zero());
            let mut lever = T::zero();
            for i in 0..a {
                let ci = coefficient(branch, i, term.joint);
                if ci == 0.0 {
                    continue;
                }
                let ci: T = convert(ci);
                let vi = tw[i].point_velocity(&x);
                lever += ci * g.dot(&vi);
                for (l, map) in branch.joints.iter().enumerate().take(a) {
                    let d = if l <= i {
                        g.dot(&tw[l].w.cross(&vi))
                    } else {
                        g.dot(&tw[i].w.cross(&tw[l].point_velocity(&x)))
                    };
                    for &(j, cl) in &map.terms {
                        rates[j] += ci * convert::<f64, T>(cl) * d;
                    }
                }
            }
            self.lever[t] = lever;
            self.kappa[t] = params[term.param];
            self.deflected[term.joint] += convert::<f64, T>(self.kappa[t]) * lever;
        }
        self.bending
            .evaluate_terms(tree, c, &self.levers, params, &g);
    }
}

/// `∂q_b[i]/∂q[k]`: the coefficient of tree joint `k` in branch joint `i`'s map.
pub(crate) fn coefficient(branch: &Branch, i: usize, k: usize) -> f64 {
    branch.joints[i]
        .terms
        .iter()
        .filter(|&&(j, _)| j == k)
        .map(|&(_, c)| c)
        .sum()
}

/// The branch's joints `q_b = offset + C_b q` from the tree's joints `q`, into `qb`.
pub(crate) fn map_joints<T: RealField + Copy>(branch: &Branch, q: &[T], qb: &mut [T]) {
    for (x, map) in qb.iter_mut().zip(&branch.joints) {
        let mut v: T = convert(map.offset);
        for &(k, c) in &map.terms {
            v += q[k] * convert::<f64, T>(c);
        }
        *x = v;
    }
}

/// A lumped point mass of a tree: its label in a term's name (`elbow_r3`), its branch, the
/// branch joint on whose axis it sits and that joint's name.
pub(crate) struct LumpedMass {
    pub(crate) label: String,
    pub(crate) branch: usize,
    pub(crate) axis: usize,
    pub(crate) joint: String,
}

/// The tree joints named `joints` (revolute, each with a variable of its own), sorted; the
/// error names the joint (`what`: "compliance is", "bending is").
pub(crate) fn compliant_joints(
    tree: &Tree,
    joints: &[String],
    what: &str,
) -> Result<Vec<usize>, String> {
    let index = crate::model::joint_correction::revolute_joints(&tree.joints, joints, what)
        .map_err(|e| {
            if tree
                .coupled
                .iter()
                .any(|c| e.contains(&format!("`{}`", c.joint)))
            {
                format!("{e}; a coupled joint deflects with the joints it follows: name those")
            } else {
                e
            }
        })?;
    if index.is_empty() {
        return Err("give at least one joint, e.g. [\"t1\", \"r2\"]".into());
    }
    Ok(index)
}

/// The lumped masses of the tree joints `index` (module notes): per branch an elbow on the
/// axis after its first such joint of its own (past the fork; else the first it shares)
/// and a wrist on the second-to-last axis; one mass per joint axis.
pub(crate) fn lumped_masses(tree: &Tree, index: &[usize]) -> Vec<LumpedMass> {
    let mut masses: Vec<LumpedMass> = Vec::new();
    for (b, branch) in tree.branches.iter().enumerate() {
        let on: Vec<usize> = (0..branch.model.dof())
            .filter(|&i| index.iter().any(|&k| coefficient(branch, i, k) != 0.0))
            .collect();
        let shared = |i: usize| {
            let name = &branch.model.joints[i].name;
            tree.branches
                .iter()
                .enumerate()
                .any(|(o, other)| o != b && other.model.joints.iter().any(|j| j.name == *name))
        };
        let Some(&first) = on.iter().find(|&&i| !shared(i)).or(on.first()) else {
            continue;
        };
        let dof = branch.model.dof();
        let mut add = |role: &str, a: usize| {
            let name = &branch.model.joints[a].name;
            if !masses.iter().any(|m| m.joint == *name) {
                masses.push(LumpedMass {
                    label: format!("{role}_{name}"),
                    branch: b,
                    axis: a,
                    joint: name.clone(),
                });
            }
        };
        if first + 1 < dof {
            add("elbow", first + 1);
        }
        if dof >= 2 {
            add("wrist", dof - 2);
        }
    }
    masses
}

/// The samples of a lever `l` (over random configurations) that are a function of their own:
/// `l` less its projection on the orthonormal `basis` (a constant and the kept levers) is
/// appended, normalised, and `true` returned; `false` for no lever at all (below 1e-9 mm
/// per sample) or one within [`LEVER_DEPENDENCE`] of the span.
pub(crate) fn independent(basis: &mut Vec<Vec<f64>>, mut l: Vec<f64>) -> bool {
    let norm = l.iter().map(|x| x * x).sum::<f64>().sqrt();
    for v in basis.iter() {
        let d: f64 = v.iter().zip(&l).map(|(x, y)| x * y).sum();
        l.iter_mut().zip(v).for_each(|(y, x)| *y -= d * x);
    }
    let rest = l.iter().map(|x| x * x).sum::<f64>().sqrt();
    if norm < 1e-9 * l.len() as f64 || rest < LEVER_DEPENDENCE * norm {
        return false;
    }
    l.iter_mut().for_each(|x| *x /= rest);
    basis.push(l);
    true
}

/// The lumped compliance of the tree joints `joints` of `tree` (which has no compliance
/// yet) with gravity `gravity` (root frame, any length): per branch the elbow and wrist
/// masses, and for each joint the terms the tests over the tree's joint space keep (module
/// notes). The error names the joint and what to do.
pub fn lumped_tree_compliance(
    tree: &Tree,
    joints: &[String],
    gravity: [f64; 3],
) -> Result<ComplianceSpec, String> {
    let g = gravity_direction(gravity)?;
    let index = compliant_joints(tree, joints, "compliance is")?;
    let masses = lumped_masses(tree, &index);
    let qs = crate::model::sampling::random_joint_values(&tree.joints, LEVER_SAMPLES, 14);
    let levers = tree.nominal();
    let mut data = TreeData::<f64>::new(tree);
    // samples[s][m][k]: lever of mass m about tree joint k at configuration s
    let mut samples = Vec::with_capacity(qs.len());
    for q in &qs {
        for b in 0..tree.branches.len() {
            branch_kinematics(tree, &mut data, b, &levers, q);
        }
        let per_mass: Vec<Vec<f64>> = masses
            .iter()
            .map(|m| {
                let d = &data.branches[m.branch];
                let x = d.joint_points[m.axis];
                (0..tree.dof())
                    .map(|k| {
                        (0..m.axis)
                            .map(|i| {
                                coefficient(&tree.branches[m.branch], i, k)
                                    * g.dot(&d.joint_twists[i].point_velocity(&x))
                            })
                            .sum()
                    })
                    .collect()
            })
            .collect();
        samples.push(per_mass);
    }
    let mut terms = Vec::new();
    for &k in &index {
        let n = samples.len() as f64;
        let mut basis: Vec<Vec<f64>> = vec![vec![1.0 / n.sqrt(); samples.len()]];
        for (m, mass) in masses.iter().enumerate() {
            let l: Vec<f64> = samples.iter().map(|s| s[m][k]).collect();
            if independent(&mut basis, l) {
                terms.push(ComplianceTerm {
                    joint: tree.joints[k].name.clone(),
                    mass: mass.label.clone(),
                    at: Some(mass.joint.clone()),
                    value: 0.0,
                });
            }
        }
        if basis.len() == 1 {
            return Err(format!(
                "joint `{}` carries no gravity torque that a joint offset does not absorb \
                 (its axis is along gravity, or every branch's elbow and wrist lie on it or \
                 before it); remove it from the list",
                tree.joints[k].name
            ));
        }
    }
    Ok(ComplianceSpec {
        gravity: [g.x, g.y, g.z],
        levers,
        terms,
        bending: Vec::new(),
    })
}
