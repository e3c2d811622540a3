//! Lateral (bending) compliance over a kinematic tree (issue 32 item 3): the structure at a
//! compliant joint bends about the two axes perpendicular to the joint axis under the
//! gravity moment of every branch beyond it, and the whole structure downstream turns with
//! it. (On a humanoid with a torso and two 7-axis arms, published fits reach 10.5 mm with a
//! kinematic model, 5.6 mm with joint elasticity and 3.1 mm with lateral elasticity added.)
//!
//! # Model
//! Take compliant tree joint `k` (revolute, a variable of its own) with unit axis `z_k`
//! through its point `o_k` (where its branch reaches the axis, [`Data::joint_points`]) and a
//! lumped mass `m` at `x_m` beyond it (the point where its branch reaches the axis of joint
//! `a`, as for the joint terms, [`crate::model::tree::compliance`]). The gravity moment of
//! the mass about `o_k` is `M = m g (x_m − o_k) × ĝ`; its part along the axis,
//! `z_k · M`, is the torque of the joint term; its lateral part
//!
//! `M⊥ = M − (z_k · M) z_k`
//!
//! bends the structure at the joint by the small rotation `c⊥ M⊥` about `o_k` (isotropic
//! bending stiffness `1/c⊥`). Only the product `κ⊥ = c⊥ m g` appears, one per (joint,
//! mass): `δ_t = κ⊥_t w_t(q)` with the unit-κ rotation `w_t = r × ĝ − (z_k·(r × ĝ)) z_k`,
//! `r = x_m − o_k`, named `<joint>.bending.<elbow|wrist>_<axis joint>` (unit µrad/m, as
//! the joint terms). As for the joint terms, `o_k`, `z_k` and `x_m` are taken from the
//! nominal geometry at the commanded joints (the *lever pass*), so the deflection is a
//! known function of `q` times the κ⊥ and every Jacobian is exact.
//!
//! **How it is applied.** The bends of a branch's compliant joints are superposed to first
//! order as one rigid motion of the root frame, `D_b = (Exp(δ_b), t_b)` with
//!
//! `δ_b = Σ_t κ⊥_t w_t`, `t_b = Σ_t κ⊥_t (o_{k_t} × w_t)`,
//!
//! the sums over the terms whose joint lies on branch `b` (a torso's terms move every arm;
//! a mass on one arm bends the torso whatever arm is measured). Every target of the branch,
//! evaluated by the forward kinematics at the (joint-compliance) deflected joints, is
//! moved by it: `p' = Exp(δ_b) p + t_b`, `R' = Exp(δ_b) R`. With one term this is the
//! rotation `δ` about `o_k` to first order (the translation is `δ × (−o_k)` rather than
//! `(I − Exp(δ)) o_k`: the two differ by `O(|δ|²)|o_k|`, 1e-3 µm for a milliradian at a
//! metre); between two joints of one branch the product `δ_1 δ_2` is neglected. The map
//! `D_b` itself is exact: the rotation is the exponential (Rodrigues), and the Jacobians
//! below are of this map, to the last digit:
//! * a geometric parameter of the chain or a target with world twist `ξ = (ω, v)`:
//!   `∂p'/∂θ = Exp(δ) (ω × p + v)`, `∂ω'/∂θ = Exp(δ) ω`; of the instrument (which the bend
//!   does not move): its serial column at `p'`;
//! * a joint term's κ: its twist (`ℓ Σ_i C_b[i,k] ξ_i`) likewise mapped by `Exp(δ)`;
//! * `κ⊥_t`: `∂ω'/∂κ⊥_t = J_l(δ) w_t`, `∂p'/∂κ⊥_t = (J_l(δ) w_t) × (p' − t_b) + o_k × w_t`,
//!   with the left Jacobian of SO(3) `J_l(δ) = I + (1 − cos θ)/θ² [δ]× + (θ − sin θ)/θ³ [δ]×²`,
//!   `θ = |δ|` (`∂Exp(δ)/∂s = [J_l(δ) ∂δ/∂s]× Exp(δ)`);
//! * the commanded joints: `∂p'/∂q = Exp(δ) J̃_p + (J_l ∂δ/∂q) × (p' − t_b) + ∂t_b/∂q`,
//!   `∂ω'/∂q = Exp(δ) J̃_ω + J_l ∂δ/∂q`, `J̃` the joint Jacobian with the joint terms, and
//!   the derivatives of the lever pass by the serial rule: `∂x_m/∂q_l = ω_l × x_m + v_l`
//!   for the joints `l` before the mass's axis, `∂o_k/∂q_l = ω_l × o_k + v_l` and
//!   `∂z_k/∂q_l = ω_l × z_k` for those before joint `k`, through the coupling `C_b` to the
//!   tree's joints.
//!
//! # Masses and the identifiable combinations
//! The masses follow the joint terms' rule over the bending joints (per branch an elbow
//! after its first bending joint of its own and a wrist on the second-to-last axis). A
//! mass bends joint `k` only from beyond it on a branch through it. The serial reductions
//! run on the lateral levers sampled at random tree configurations, in the frame joint
//! `k`'s link starts from: a bend constant there (the joint's axis tilted, and the
//! structure beyond with it) or constant in the frame the joint turns (the next link's
//! frame turned) is the geometry's, so these six directions span the "constant". **No
//! moment** (a mass before the joint or on another branch; the lever under 1e-9 mm), **a
//! constant moment** (on the first joint of a tree whose gravity is across the axis, the
//! lateral moment of a mass on the torso itself is constant in the world) and **the same
//! function twice** (within the span of the constants and the joint's kept levers) drop the
//! term; a bending joint with no term left is an error. What the data
//! separate is judged, term by term, by the tree fit's gate (`armcal identify`).

use crate::model::compliance::{gravity_direction, ComplianceTerm};
use crate::model::kinematics::Data;
use crate::model::pose::Pose;
use crate::model::tree::compliance::{
    compliant_joints, independent, lumped_masses, TreeCompliance, LEVER_SAMPLES,
};
use crate::model::tree::kinematics::{branch_kinematics, TreeData};
use crate::model::tree::{Branch, Tree};
use nalgebra::{convert, Matrix3, RealField, Vector3};

/// One compiled bending term of a tree ([`TreeCompliance::bending`]).
#[derive(Clone, Debug)]
pub struct TreeBendingTerm {
    /// The compliant tree joint (index into [`Tree::joints`]).
    pub joint: usize,
    /// The branch whose joint axis carries the mass, and the branch joint index of that axis.
    pub mass: (usize, usize),
    /// The branch joint index of the compliant joint on the mass's branch (before the mass).
    pub pivot: usize,
    /// Per branch, whether the compliant joint lies on it (its targets bend).
    pub branches: Vec<bool>,
    /// Index of κ⊥ in the tree registry.
    pub param: usize,
}

impl TreeBendingTerm {
    /// The term of tree joint `joint` and the mass on axis `mass` (branch, branch joint),
    /// its registry index not yet set; the error says why the mass cannot bend the joint.
    pub(crate) fn new(
        joints: &[crate::model::link::Joint],
        branches: &[Branch],
        joint: usize,
        mass: (usize, usize),
    ) -> Result<Self, String> {
        let name = &joints[joint].name;
        let on = |b: &Branch| b.model.joints.iter().position(|j| j.name == *name);
        let pivot = on(&branches[mass.0])
            .filter(|&i| i < mass.1)
            .ok_or_else(|| {
                format!(
                    "its mass (on the axis of `{}`) is not beyond joint `{name}`, so it puts \
                     no bending moment on it",
                    branches[mass.0].model.joints[mass.1].name
                )
            })?;
        Ok(TreeBendingTerm {
            joint,
            mass,
            pivot,
            branches: branches.iter().map(|b| on(b).is_some()).collect(),
            param: 0,
        })
    }
}

/// The unit-κ gravity moment `M = r × ĝ`, `r = x − o` (mm), and its lateral part
/// `w = M − (z·M) z`.
fn moments<T: RealField + Copy>(
    x: &Vector3<T>,
    o: &Vector3<T>,
    z: &Vector3<T>,
    g: &Vector3<T>,
) -> (Vector3<T>, Vector3<T>) {
    let m = (x - o).cross(g);
    (m, m - z * z.dot(&m))
}

/// The bend of one branch at the last evaluation: `D_b = (Exp(δ), t)` and its rates.
#[derive(Clone, Debug)]
pub(crate) struct BranchBend<T: RealField + Copy> {
    /// Whether a term's joint lies on the branch (else `D_b` is the identity, unused).
    pub(crate) active: bool,
    /// `Exp(δ_b)`.
    pub(crate) rot: Matrix3<T>,
    /// `t_b` (mm).
    pub(crate) trans: Vector3<T>,
    /// `J_l(δ_b)`.
    pub(crate) left: Matrix3<T>,
    /// Per tree joint, `∂δ_b/∂q_j`.
    pub(crate) rot_rate: Vec<Vector3<T>>,
    /// Per tree joint, `∂t_b/∂q_j`.
    pub(crate) trans_rate: Vec<Vector3<T>>,
    /// The branch's target poses before the bend (world).
    pub(crate) rigid: Vec<Pose<T>>,
}

/// Per evaluation, the bending terms' rotations and the bend of each branch.
#[derive(Clone, Debug)]
pub(crate) struct BendingData<T: RealField + Copy> {
    /// Per term, `w_t(q)` (unit κ⊥, mm).
    pub(crate) w: Vec<Vector3<T>>,
    /// Per term, `o_k × w_t` (mm²).
    pub(crate) u: Vec<Vector3<T>>,
    /// Per term and tree joint (`term · dof + j`), `∂w_t/∂q_j`.
    w_rate: Vec<Vector3<T>>,
    /// Per term and tree joint, `∂(o_k × w_t)/∂q_j`.
    u_rate: Vec<Vector3<T>>,
    /// Per term, κ⊥ at the last evaluation.
    kappa: Vec<f64>,
    /// Per branch, its bend.
    pub(crate) branches: Vec<BranchBend<T>>,
}

impl<T: RealField + Copy> BendingData<T> {
    /// Buffers for `tree` with compiled compliance `c`.
    pub(crate) fn new(tree: &Tree, c: &TreeCompliance) -> Self {
        let (n, dof) = (c.bending.len(), tree.dof());
        BendingData {
            w: vec![Vector3::zeros(); n],
            u: vec![Vector3::zeros(); n],
            w_rate: vec![Vector3::zeros(); n * dof],
            u_rate: vec![Vector3::zeros(); n * dof],
            kappa: vec![0.0; n],
            branches: tree
                .branches
                .iter()
                .enumerate()
                .map(|(b, br)| BranchBend {
                    active: c.bending.iter().any(|t| t.branches[b]),
                    rot: Matrix3::identity(),
                    trans: Vector3::zeros(),
                    left: Matrix3::identity(),
                    rot_rate: vec![Vector3::zeros(); dof],
                    trans_rate: vec![Vector3::zeros(); dof],
                    rigid: vec![Pose::identity(); br.model.targets.len()],
                })
                .collect(),
        }
    }

    /// Every term's `w_t`, `o_k × w_t` and their rates from the lever passes `levers` (per
    /// branch, at the commanded joints), unit gravity `g`, κ⊥ from `params`. Allocates
    /// nothing.
    pub(crate) fn evaluate_terms(
        &mut self,
        tree: &Tree,
        c: &TreeCompliance,
        levers: &[Data<T>],
        params: &[f64],
        g: &Vector3<T>,
    ) {
        let dof = tree.dof();
        for (t, term) in c.bending.iter().enumerate() {
            let ((b, a), i) = (term.mass, term.pivot);
            let d = &levers[b];
            let tw = &d.joint_twists;
            let (x, o, z) = (d.joint_points[a], d.joint_points[i], tw[i].w);
            let (m, w) = moments(&x, &o, &z, g);
            self.w[t] = w;
            self.u[t] = o.cross(&w);
            self.kappa[t] = params[term.param];
            let w_rate = &mut self.w_rate[t * dof..(t + 1) * dof];
            let u_rate = &mut self.u_rate[t * dof..(t + 1) * dof];
            w_rate.fill(Vector3::zeros());
            u_rate.fill(Vector3::zeros());
            for (l, map) in tree.branches[b].joints.iter().enumerate().take(a) {
                let dx = tw[l].point_velocity(&x);
                let (d_o, dz) = if l < i {
                    (tw[l].point_velocity(&o), tw[l].w.cross(&z))
                } else {
                    (Vector3::zeros(), Vector3::zeros())
                };
                let dm = (dx - d_o).cross(g);
                let dw = dm - z * (dz.dot(&m) + z.dot(&dm)) - dz * z.dot(&m);
                let du = d_o.cross(&w) + o.cross(&dw);
                for &(j, cl) in &map.terms {
                    let cl: T = convert(cl);
                    w_rate[j] += dw * cl;
                    u_rate[j] += du * cl;
                }
            }
        }
    }

    /// Bends branch `b`'s targets in `data` (its forward kinematics just run) by `D_b`,
    /// keeping the rigid poses; `D_b`, `J_l` and the rates are left in
    /// [`BendingData::branches`]. Allocates nothing.
    pub(crate) fn bend(&mut self, c: &TreeCompliance, b: usize, data: &mut Data<T>) {
        let bend = &mut self.branches[b];
        if !bend.active {
            return;
        }
        let dof = bend.rot_rate.len();
        let mut delta = Vector3::zeros();
        bend.trans = Vector3::zeros();
        bend.rot_rate.fill(Vector3::zeros());
        bend.trans_rate.fill(Vector3::zeros());
        for (t, term) in c.bending.iter().enumerate() {
            if !term.branches[b] {
                continue;
            }
            let kappa: T = convert(self.kappa[t]);
            delta += self.w[t] * kappa;
            bend.trans += self.u[t] * kappa;
            for j in 0..dof {
                bend.rot_rate[j] += self.w_rate[t * dof + j] * kappa;
                bend.trans_rate[j] += self.u_rate[t * dof + j] * kappa;
            }
        }
        let (rot, left) = exp_and_left_jacobian(&delta);
        bend.rot = rot;
        bend.left = left;
        for (rigid, target) in bend.rigid.iter_mut().zip(&mut data.targets) {
            *rigid = *target;
            target.rot = rot * rigid.rot;
            target.trans = rot * rigid.trans + bend.trans;
        }
    }
}

/// `Exp(δ) = I + a K + b K²` and `J_l(δ) = I + b K + c K²`, `K = [δ]×`, `θ = |δ|`,
/// `a = sin θ/θ`, `b = (1 − cos θ)/θ²`, `c = (θ − sin θ)/θ³`; below θ = 0.01 their Taylor
/// series to θ⁶ (error below 1e-19, and exact derivatives at δ = 0 for dual numbers).
fn exp_and_left_jacobian<T: RealField + Copy>(delta: &Vector3<T>) -> (Matrix3<T>, Matrix3<T>) {
    let t2 = delta.norm_squared();
    let f = |x: f64| -> T { convert(x) };
    let one = T::one();
    let (a, b, c) = if t2 < f(1e-4) {
        (
            one - t2 / f(6.0) * (one - t2 / f(20.0) * (one - t2 / f(42.0))),
            (one - t2 / f(12.0) * (one - t2 / f(30.0) * (one - t2 / f(56.0)))) / f(2.0),
            (one - t2 / f(20.0) * (one - t2 / f(42.0) * (one - t2 / f(72.0)))) / f(6.0),
        )
    } else {
        let t = t2.sqrt();
        let (s, co) = (t.sin(), t.cos());
        (s / t, (one - co) / t2, (t - s) / (t2 * t))
    };
    let k = delta.cross_matrix();
    let k2 = k * k;
    (
        Matrix3::identity() + k * a + k2 * b,
        Matrix3::identity() + k * b + k2 * c,
    )
}

/// The lumped bending terms of the tree joints `joints` of `tree` (which has no compliance
/// yet) with gravity `gravity` (root frame, any length): the masses of the joint terms'
/// rule over these joints and, per joint, the terms the reductions keep (module notes). The
/// error names the joint and what to do.
pub fn lumped_tree_bending(
    tree: &Tree,
    joints: &[String],
    gravity: [f64; 3],
) -> Result<Vec<ComplianceTerm>, String> {
    let g = gravity_direction(gravity)?;
    let index = compliant_joints(tree, joints, "bending is")?;
    let masses = lumped_masses(tree, &index);
    let qs = crate::model::sampling::random_joint_values(&tree.joints, LEVER_SAMPLES, 15);
    let levers = tree.nominal();
    let mut data = TreeData::<f64>::new(tree);
    // per joint and mass: the pivot and link of the joint on the mass's branch
    let pivots: Vec<Vec<Option<(usize, usize)>>> = index
        .iter()
        .map(|&k| {
            masses
                .iter()
                .map(|m| {
                    let model = &tree.branches[m.branch].model;
                    let i = model
                        .joints
                        .iter()
                        .position(|j| j.name == tree.joints[k].name)
                        .filter(|&i| i < m.axis)?;
                    let link = model.links.iter().position(|l| l.joint == Some(i))?;
                    Some((i, link))
                })
                .collect()
        })
        .collect();
    // per joint and mass, in the frame joint k's link starts from, per sample: the lateral
    // lever, and the axes of the frame the joint turns (what the constants span there)
    let n = qs.len();
    let mut samples = vec![vec![Vec::with_capacity(3 * n); masses.len()]; index.len()];
    let mut turned = vec![vec![[const { Vec::new() }; 3]; masses.len()]; index.len()];
    for q in &qs {
        for b in 0..tree.branches.len() {
            branch_kinematics(tree, &mut data, b, &levers, q);
        }
        for (kk, per_mass) in pivots.iter().enumerate() {
            for (m, pivot) in per_mass.iter().enumerate() {
                let Some((i, link)) = *pivot else { continue };
                let d = &data.branches[masses[m].branch];
                let before = match link {
                    0 => Matrix3::identity(),
                    l => d.frames[l - 1].rot.transpose(),
                };
                let (_, w) = moments(
                    &d.joint_points[masses[m].axis],
                    &d.joint_points[i],
                    &d.joint_twists[i].w,
                    &g,
                );
                samples[kk][m].extend((before * w).iter());
                let after = before * d.frames[link].rot;
                for (axis, v) in turned[kk][m].iter_mut().enumerate() {
                    v.extend(after.column(axis).iter());
                }
            }
        }
    }
    let mut terms = Vec::new();
    for (kk, &k) in index.iter().enumerate() {
        let kept = terms.len();
        // a bend constant in the frame before the joint (the joint's axis tilted) or in the
        // frame it turns (the next link's frame turned): the geometry's
        let mut basis: Vec<Vec<f64>> = Vec::new();
        for axis in 0..3 {
            let constant = (0..3 * n)
                .map(|s| f64::from(u8::from(s % 3 == axis)))
                .collect();
            independent(&mut basis, constant);
        }
        for (m, turned) in turned[kk].iter_mut().enumerate() {
            if pivots[kk][m].is_none() {
                continue;
            }
            for axes in turned {
                independent(&mut basis, std::mem::take(axes));
            }
        }
        for (m, mass) in masses.iter().enumerate() {
            if pivots[kk][m].is_none() {
                continue;
            }
            if independent(&mut basis, std::mem::take(&mut samples[kk][m])) {
                terms.push(ComplianceTerm {
                    joint: tree.joints[k].name.clone(),
                    mass: mass.label.clone(),
                    at: Some(mass.joint.clone()),
                    value: 0.0,
                });
            }
        }
        if terms.len() == kept {
            return Err(format!(
                "joint `{}` carries no bending moment that the geometry does not absorb (no \
                 branch's elbow or wrist lies beyond it, or their moment is constant in the \
                 frame before the joint or in the frame it turns); remove it from `bending`",
                tree.joints[k].name
            ));
        }
    }
    Ok(terms)
}
