//! Forward kinematics and exact Jacobians of a [`Tree`]: a measurement of a target is its
//! branch's serial measurement ([`crate::model::kinematics`]) at the branch's joints
//! `q_b = offset + C_b q` ([`crate::model::tree::JointMap`]) and parameters gathered from
//! the tree's vector. Hence, exactly:
//! * identification Jacobian: the branch's columns scattered into the tree's
//!   (`∂m/∂p_tree[t] = ∂m/∂p_b[i]` where branch parameter `i` is tree parameter `t`, zero
//!   for a tree parameter not on the branch);
//! * joint Jacobian w.r.t. the tree's joints: `J_b C_b` (chain rule through the coupling).

use crate::model::jacobian::{identification_jacobian, joint_jacobian, Observed, Rows};
use crate::model::kinematics::{forward_kinematics, Data};
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
        }
    }

    /// The joints of branch `b` at the last [`branch_kinematics`].
    pub fn branch_q(&self, b: usize) -> &[T] {
        &self.q[b]
    }
}

/// Evaluates branch `b` of `tree` at tree parameters `params` and tree joints `q` into
/// `data.branches[b]`. Allocates nothing.
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
    for (x, map) in data.q[b].iter_mut().zip(&branch.joints) {
        let mut v: T = nalgebra::convert(map.offset);
        for &(k, c) in &map.terms {
            v += q[k] * nalgebra::convert::<f64, T>(c);
        }
        *x = v;
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
        for r in 0..rows.count() {
            out[(row + r, c)] = match data.local[b][t] {
                Some(i) => scratch[(r, i)],
                None => T::zero(),
            };
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
