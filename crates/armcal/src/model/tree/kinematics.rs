//! Forward kinematics and exact Jacobians of a [`Tree`]: a measurement of a target is its
//! branch's serial measurement (`crate::model::kinematics`) at the branch's joints
//! `q_b = offset + C_b q` ([`crate::model::tree::JointMap`]) and parameters gathered from
//! the tree's vector. Hence, exactly:
//! * identification Jacobian: the branch's columns scattered into the tree's
//!   (`∂m/∂p_tree[t] = ∂m/∂p_b[i]` where branch parameter `i` is tree parameter `t`, zero
//!   for a tree parameter not on the branch);
//! * joint Jacobian w.r.t. the tree's joints: `J_b C_b` (chain rule through the coupling).
//!
//! With joint compliance ([`crate::model::tree::compliance`]) the branch runs at the
//! deflected tree joints `q + Δq(q)`: the compliance's κ columns and the chain rule through
//! `Δq` are added here. With bending ([`crate::model::tree::bending`]) the branch's targets
//! are then moved by its bend `D_b = (Exp(δ_b), t_b)`: the chain's columns are mapped by
//! `Exp(δ_b)` at the rigid target, the instrument's taken at the bent one, and the κ⊥
//! columns and the chain rule through `δ_b(q)`, `t_b(q)` added (equations in that module).

use crate::model::jacobian::{identification_jacobian, influence, Observed, Rows};
use crate::model::kinematics::{forward_kinematics, Data};
use crate::model::pose::Twist;
use crate::model::tree::bending::BranchBend;
use crate::model::tree::compliance::{coefficient, map_joints, DeflectionData};
use crate::model::tree::Tree;
use nalgebra::{DMatrix, RealField, Vector3};

/// Reusable buffers for evaluating a [`Tree`]: one serial [`Data`] per branch, the branch's
/// joints and parameters, and a scratch Jacobian of the branch's columns.
#[derive(Clone, Debug)]
pub struct TreeData<T: RealField + Copy> {
    /// Per branch, the serial model's evaluation (frames, targets, twists); with bending,
    /// its targets are bent by the branch's bend (the frames and twists stay rigid).
    pub branches: Vec<Data<T>>,
    q: Vec<Vec<T>>,
    params: Vec<Vec<f64>>,
    scratch: Vec<DMatrix<T>>,
    all_columns: Vec<Vec<usize>>,
    /// Per branch: the branch parameter index of each tree parameter, if on the branch.
    local: Vec<Vec<Option<usize>>>,
    /// The compliance's term of each tree parameter that is a κ.
    kappa: Vec<Option<usize>>,
    /// The bending term of each tree parameter that is a κ⊥.
    bending: Vec<Option<usize>>,
    /// The joint compliance's levers and deflected joints; `None` without compliance.
    pub(crate) deflection: Option<Box<DeflectionData<T>>>,
}

impl<T: RealField + Copy> TreeData<T> {
    /// Buffers sized for `tree`.
    pub fn new(tree: &Tree) -> Self {
        let mut local = Vec::new();
        for b in &tree.branches {
            let mut l = vec![None; tree.param_count()];
            for (i, &t) in b.params.iter().enumerate() {
                l[t] = Some(i);
            }
            local.push(l);
        }
        TreeData {
            branches: tree.branches.iter().map(|b| Data::new(&b.model)).collect(),
            q: tree
                .branches
                .iter()
                .map(|b| vec![T::zero(); b.model.dof()])
                .collect(),
            params: tree
                .branches
                .iter()
                .map(|b| vec![0.0; b.model.param_count()])
                .collect(),
            scratch: tree
                .branches
                .iter()
                .map(|b| DMatrix::zeros(6, b.model.param_count()))
                .collect(),
            all_columns: tree
                .branches
                .iter()
                .map(|b| (0..b.model.param_count()).collect())
                .collect(),
            local,
            kappa: (0..tree.param_count())
                .map(|i| {
                    tree.compliance
                        .as_ref()
                        .and_then(|c| c.terms.iter().position(|t| t.param == i))
                })
                .collect(),
            bending: (0..tree.param_count())
                .map(|i| {
                    tree.compliance
                        .as_ref()
                        .and_then(|c| c.bending.iter().position(|t| t.param == i))
                })
                .collect(),
            deflection: DeflectionData::new(tree).map(Box::new),
        }
    }

    /// The joints of branch `b` at the last [`branch_kinematics`].
    pub fn branch_q(&self, b: usize) -> &[T] {
        &self.q[b]
    }
}

/// Evaluates branch `b` of `tree` at tree parameters `params` and tree joints `q` into
/// `data.branches[b]` (with compliance, at the deflected joints `q + Δq(q)`; with bending,
/// its targets then bent by `D_b`, the frames and twists left rigid). Allocates nothing.
pub fn branch_kinematics<T: RealField + Copy>(
    tree: &Tree,
    data: &mut TreeData<T>,
    b: usize,
    params: &[f64],
    q: &[T],
) {
    let branch = &tree.branches[b];
    for (x, &t) in data.params[b].iter_mut().zip(&branch.params) {
        *x = params[t];
    }
    match data.deflection.as_mut() {
        Some(d) => {
            d.evaluate(tree, params, q);
            map_joints(branch, &d.deflected, &mut data.q[b]);
        }
        None => map_joints(branch, q, &mut data.q[b]),
    }
    forward_kinematics(
        &branch.model,
        &mut data.branches[b],
        &data.params[b],
        &data.q[b],
    );
    if let (Some(d), Some(c)) = (data.deflection.as_mut(), &tree.compliance) {
        d.bending.bend(c, b, &mut data.branches[b]);
    }
}

/// The bend of branch `b` in `data`, if its targets bend.
fn bend_of<T: RealField + Copy>(data: &TreeData<T>, b: usize) -> Option<&BranchBend<T>> {
    data.deflection
        .as_ref()
        .map(|d| &d.bending.branches[b])
        .filter(|bend| bend.active)
}

/// The world motion (velocity of the point, angular velocity) of target `local` of a branch
/// evaluated in `data` under a world twist `tw` of the structure before the bend `bend`:
/// `(Exp(δ) (ω × p + v), Exp(δ) ω)` at the rigid target `p`; without a bend, `tw` at the
/// target.
fn downstream<T: RealField + Copy>(
    data: &Data<T>,
    bend: Option<&BranchBend<T>>,
    local: usize,
    tw: &Twist<T>,
) -> (Vector3<T>, Vector3<T>) {
    match bend {
        Some(bend) => (
            bend.rot * tw.point_velocity(&bend.rigid[local].trans),
            bend.rot * tw.w,
        ),
        None => (tw.point_velocity(&data.targets[local].trans), tw.w),
    }
}

/// The identification Jacobian of tree target `target` (its branch evaluated by
/// [`branch_kinematics`]) for the tree parameters `columns`, into `out` at rows
/// `row..row + rows.count()`: the branch's columns scattered, zero for a parameter not on
/// the branch; a κ's and a κ⊥'s column from the deflection, the chain's mapped by the bend
/// (module notes).
#[allow(clippy::too_many_arguments)]
pub fn tree_identification_jacobian<T: RealField + Copy>(
    tree: &Tree,
    data: &mut TreeData<T>,
    target: usize,
    rows: Rows,
    columns: &[usize],
    out: &mut DMatrix<T>,
    row: usize,
) {
    let (_, b, k) = tree.targets[target];
    let model = &tree.branches[b].model;
    // the serial columns at the (bent) target: the instrument's as they are
    identification_jacobian(
        model,
        &data.branches[b],
        Observed::Target(k),
        rows,
        &data.all_columns[b],
        &mut data.scratch[b],
        0,
    );
    let bend = bend_of(data, b);
    let branch = &data.branches[b];
    let rt = branch.instrument.rot.transpose();
    for (c, &t) in columns.iter().enumerate() {
        let motion = match (
            data.local[b][t],
            data.kappa[t],
            data.bending[t],
            &data.deflection,
        ) {
            (Some(i), _, _, _) => {
                let bent_chain = bend.is_some()
                    && influence(model.registry.get(i).segment, Observed::Target(k)) > 0.0;
                if !bent_chain {
                    for r in 0..rows.count() {
                        out[(row + r, c)] = data.scratch[b][(r, i)];
                    }
                    continue;
                }
                downstream(branch, bend, k, &branch.param_twists[i])
            }
            (None, Some(term), _, Some(d)) => {
                let joint = tree.compliance.as_ref().expect("a κ").terms[term].joint;
                let tw = kappa_twist(tree, branch, b, joint, d.lever[term]);
                downstream(branch, bend, k, &tw)
            }
            (None, None, Some(term), Some(d)) => match bend {
                Some(bend) if tree.compliance.as_ref().expect("a κ⊥").bending[term].branches[b] =>
                {
                    let dw = bend.left * d.bending.w[term];
                    let p = branch.targets[k].trans - bend.trans;
                    (dw.cross(&p) + d.bending.u[term], dw)
                }
                _ => (Vector3::zeros(), Vector3::zeros()),
            },
            _ => (Vector3::zeros(), Vector3::zeros()),
        };
        let (dp, dw) = (rt * motion.0, rt * motion.1);
        for r in 0..3 {
            out[(row + r, c)] = dp[r];
            if rows == Rows::Pose {
                out[(row + 3 + r, c)] = dw[r];
            }
        }
    }
}

/// The world twist a unit κ of tree joint `k` with lever `lever` gives branch `b`
/// (evaluated in `data`): `ℓ Σ_i C_b[i, k] ξ_i`.
fn kappa_twist<T: RealField + Copy>(
    tree: &Tree,
    data: &Data<T>,
    b: usize,
    k: usize,
    lever: T,
) -> Twist<T> {
    let mut tw = Twist::zero();
    for (i, joint) in data.joint_twists.iter().enumerate() {
        let ci = coefficient(&tree.branches[b], i, k);
        if ci != 0.0 {
            let s: T = nalgebra::convert::<f64, T>(ci) * lever;
            tw.w += joint.w * s;
            tw.v += joint.v * s;
        }
    }
    tw
}

/// Geometric joint Jacobian (world frame, 6 × tree joints) of tree target `target`, its
/// branch evaluated by [`branch_kinematics`]: the branch's `J_b` times `∂q_b/∂q = C_b`,
/// with compliance through `q + Δq(q)`, with bending mapped by the bend and through
/// `δ_b(q)`, `t_b(q)` ([`crate::model::tree::bending`]).
pub fn tree_joint_jacobian<T: RealField + Copy>(
    tree: &Tree,
    data: &TreeData<T>,
    target: usize,
) -> DMatrix<T> {
    let (_, b, k) = tree.targets[target];
    let (branch, bend) = (&data.branches[b], bend_of(data, b));
    let mut j = DMatrix::zeros(6, tree.dof());
    for (i, map) in tree.branches[b].joints.iter().enumerate() {
        let (dp, dw) = downstream(branch, bend, k, &branch.joint_twists[i]);
        for &(t, c) in &map.terms {
            let c: T = nalgebra::convert(c);
            for r in 0..3 {
                j[(r, t)] += dp[r] * c;
                j[(r + 3, t)] += dw[r] * c;
            }
        }
    }
    if let (Some(c), Some(d)) = (&tree.compliance, &data.deflection) {
        // w.r.t. the commanded joints: J̃ (I + Σ_t κ_t e_k ∇ℓ_tᵀ)
        let deflected = j.clone_owned();
        let dof = tree.dof();
        for (t, term) in c.terms.iter().enumerate() {
            let kappa: T = nalgebra::convert(d.kappa[t]);
            for m in 0..dof {
                let a = kappa * d.lever_rate[t * dof + m];
                for r in 0..6 {
                    j[(r, m)] += deflected[(r, term.joint)] * a;
                }
            }
        }
    }
    if let Some(bend) = bend {
        // the bend's own motion: (J_l ∂δ/∂q) × (p' − t) + ∂t/∂q, J_l ∂δ/∂q
        let p = branch.targets[k].trans - bend.trans;
        for m in 0..tree.dof() {
            let dw = bend.left * bend.rot_rate[m];
            let dp = dw.cross(&p) + bend.trans_rate[m];
            for r in 0..3 {
                j[(r, m)] += dp[r];
                j[(r + 3, m)] += dw[r];
            }
        }
    }
    j
}

/// Pose of tree target `target` in the instrument frame (what the instrument reports), its
/// branch evaluated by [`branch_kinematics`].
pub fn tree_observed_pose<T: RealField + Copy>(
    tree: &Tree,
    data: &TreeData<T>,
    target: usize,
) -> crate::model::Pose<T> {
    let (_, b, k) = tree.targets[target];
    crate::model::jacobian::observed_pose(&data.branches[b], Observed::Target(k))
}
