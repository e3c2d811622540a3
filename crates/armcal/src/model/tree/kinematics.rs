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
//! `Δq` are added here.

use crate::model::jacobian::{
    identification_jacobian, joint_jacobian, observed_world, Observed, Rows,
};
use crate::model::kinematics::{forward_kinematics, Data};
use crate::model::pose::Twist;
use crate::model::tree::compliance::{coefficient, map_joints, DeflectionData};
use crate::model::tree::Tree;
use nalgebra::{DMatrix, RealField};

/// Reusable buffers for evaluating a [`Tree`]: one serial [`Data`] per branch, the branch's
/// joints and parameters, and a scratch Jacobian of the branch's columns.
#[derive(Clone, Debug)]
pub struct TreeData<T: RealField + Copy> {
    /// Per branch, the serial model's evaluation (frames, targets, twists).
    pub branches: Vec<Data<T>>,
    q: Vec<Vec<T>>,
    params: Vec<Vec<f64>>,
    scratch: Vec<DMatrix<T>>,
    all_columns: Vec<Vec<usize>>,
    /// Per branch: the branch parameter index of each tree parameter, if on the branch.
    local: Vec<Vec<Option<usize>>>,
    /// The compliance's term of each tree parameter that is a κ.
    kappa: Vec<Option<usize>>,
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
            deflection: DeflectionData::new(tree).map(Box::new),
        }
    }

    /// The joints of branch `b` at the last [`branch_kinematics`].
    pub fn branch_q(&self, b: usize) -> &[T] {
        &self.q[b]
    }
}

/// Evaluates branch `b` of `tree` at tree parameters `params` and tree joints `q` into
/// `data.branches[b]` (with compliance, at the deflected joints `q + Δq(q)`). Allocates
/// nothing.
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
}

/// The identification Jacobian of tree target `target` (its branch evaluated by
/// [`branch_kinematics`]) for the tree parameters `columns`, into `out` at rows
/// `row..row + rows.count()`: the branch's columns scattered, zero for a parameter not on
/// the branch.
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
    let scratch = &mut data.scratch[b];
    identification_jacobian(
        model,
        &data.branches[b],
        Observed::Target(k),
        rows,
        &data.all_columns[b],
        scratch,
        0,
    );
    for (c, &t) in columns.iter().enumerate() {
        match (data.local[b][t], data.kappa[t], &data.deflection) {
            (Some(i), _, _) => {
                for r in 0..rows.count() {
                    out[(row + r, c)] = scratch[(r, i)];
                }
            }
            (None, Some(term), Some(d)) => {
                let k = tree.compliance.as_ref().expect("a κ").terms[term].joint;
                kappa_column(
                    tree,
                    &data.branches[b],
                    b,
                    k,
                    d.lever[term],
                    target,
                    rows,
                    out,
                    (row, c),
                );
            }
            _ => {
                for r in 0..rows.count() {
                    out[(row + r, c)] = T::zero();
                }
            }
        }
    }
}

/// The column of a compliance κ of tree joint `k` with lever `lever` for tree target
/// `target` of branch `b` (evaluated in `data`) at `out[at]`: the observed frame's motion
/// under the twist `ℓ Σ_i C_b[i, k] ξ_i`, in the instrument frame (as
/// [`identification_jacobian`] writes a chain parameter's).
#[allow(clippy::too_many_arguments)]
fn kappa_column<T: RealField + Copy>(
    tree: &Tree,
    data: &Data<T>,
    b: usize,
    k: usize,
    lever: T,
    target: usize,
    rows: Rows,
    out: &mut DMatrix<T>,
    (row, c): (usize, usize),
) {
    let mut tw = Twist::zero();
    for (i, joint) in data.joint_twists.iter().enumerate() {
        let ci = coefficient(&tree.branches[b], i, k);
        if ci != 0.0 {
            let s: T = nalgebra::convert::<f64, T>(ci) * lever;
            tw.w += joint.w * s;
            tw.v += joint.v * s;
        }
    }
    let (_, _, local) = tree.targets[target];
    let p = observed_world(data, Observed::Target(local)).trans;
    let rt = data.instrument.rot.transpose();
    let dp = rt * tw.point_velocity(&p);
    let dw = rt * tw.w;
    for r in 0..3 {
        out[(row + r, c)] = dp[r];
        if rows == Rows::Pose {
            out[(row + 3 + r, c)] = dw[r];
        }
    }
}

/// Geometric joint Jacobian (world frame, 6 × tree joints) of tree target `target`, its
/// branch evaluated by [`branch_kinematics`]: the branch's `J_b` times `∂q_b/∂q = C_b`.
pub fn tree_joint_jacobian<T: RealField + Copy>(
    tree: &Tree,
    data: &TreeData<T>,
    target: usize,
) -> DMatrix<T> {
    let (_, b, k) = tree.targets[target];
    let jb = joint_jacobian(&data.branches[b], Observed::Target(k));
    let mut j = DMatrix::zeros(6, tree.dof());
    for (i, map) in tree.branches[b].joints.iter().enumerate() {
        for &(t, c) in &map.terms {
            let c: T = nalgebra::convert(c);
            for r in 0..6 {
                j[(r, t)] += jb[(r, i)] * c;
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
