//! Identifiability of a [`Tree`]: the identification Jacobians of every target over the same
//! random configurations of the tree's joints, stacked (one registry, so a shared link is one
//! column fed by every branch), analysed as a serial model's
//! (`crate::model::identifiability`: rank, greedy minimal set, reasons, variance inflation).
//!
//! # The generic count of a tree ([`expected_tree_count`])
//!
//! A complete, minimal model of a serial chain has `4R + 2P + 6` parameters (book §2.3,
//! eq. 2.49): written in the instrument frame at the joints' zero, every revolute axis is a
//! line (4 numbers), every prismatic axis a direction (2; its position is absorbed by the
//! next axis), and the measured frame a pose (6). The instrument and base frames, joint
//! offsets and the rest are absorbed by these; measuring a point instead of a frame leaves 3
//! for the point (book §4.7): `4R + 2P + 3`.
//!
//! A tree measured at a target per branch is, per branch `b`, a serial chain with its own
//! count `N_b = 4R_b + 2P_b + e_b` (`e_b` = 6 for a frame, 3 for a point). Every branch sees
//! the same instrument frame and the same shared links, so a shared axis is one line in
//! the instrument frame, however many branches carry it: summing the branch counts counts
//! a joint `j` carried by `m_j` branches `m_j` times, and
//!
//! `N = Σ_b N_b − Σ_j (m_j − 1)(4 or 2) = 4R + 2P + Σ_b e_b`,
//!
//! with `R`, `P` the tree's revolute and prismatic joints (each once). Nothing is lost by the
//! sharing (each branch alone identifies its axes and its end) and nothing is gained (every
//! parameter of the union is in some branch). Several frame targets on one link add 6
//! each; several points on one link have a count that depends on their layout, and a
//! coupled joint's count depends on the coupling: for those the count is `None` and the
//! numerical rank is the answer. Tested against the numerical rank on random trees
//! (`tests/suite/model/tree.rs`).

use crate::linalg::RowCompressor;
use crate::model::identifiability::{
    select, Completeness, Identifiability, IdentifiabilitySettings, Measurement,
};
use crate::model::jacobian::Rows;
use crate::model::link::JointKind;
use crate::model::registry::{ParameterStatus, Segment};
use crate::model::sampling::random_joint_values;
use crate::model::tree::kinematics::{branch_kinematics, tree_identification_jacobian, TreeData};
use crate::model::tree::Tree;
use crate::Error;
use nalgebra::DMatrix;

/// The number of parameters a measurement type identifies on `tree` in generic geometry
/// (module doc): `4R + 2P + 6F` for the pose of `F` frame targets, `4R + 2P + 3B` for the
/// position of one point on each of `B` links. `None` with a coupled joint, several points
/// on one link, a pose measurement of point targets, distances, a tree that is not
/// complete at a fork ([`Tree::incomplete_forks`]: two branches whose first axes the fork's
/// frame sets alike), or joint compliance (whether a κ is told apart from the geometry
/// depends on the arm: the numerical rank and the gate say).
pub fn expected_tree_count(tree: &Tree, m: Measurement) -> Option<usize> {
    if !tree.coupled.is_empty() || !tree.incomplete_forks().is_empty() || tree.compliance.is_some()
    {
        return None;
    }
    let r = tree
        .joints
        .iter()
        .filter(|j| j.kind == JointKind::Revolute)
        .count();
    let axes = 4 * r + 2 * (tree.dof() - r);
    let frames = |b: &crate::model::tree::Branch| {
        (0..b.targets.len())
            .filter(|&k| b.model.target_is_frame(k))
            .count()
    };
    match m {
        Measurement::Pose => {
            let all_frames = tree.branches.iter().all(|b| frames(b) == b.targets.len());
            all_frames.then(|| axes + 6 * tree.targets.len())
        }
        Measurement::Position => tree
            .branches
            .iter()
            .all(|b| b.targets.len() == 1)
            .then(|| axes + 3 * tree.branches.len()),
        Measurement::Distance => None,
    }
}

/// Rows of every target per configuration: the pose of every frame target (an error if
/// there is none), or the position of every target.
fn observations(tree: &Tree, m: Measurement) -> Result<Vec<(usize, Rows)>, Error> {
    let is_frame = |t: usize| {
        let (_, b, k) = tree.targets[t];
        tree.branches[b].model.target_is_frame(k)
    };
    match m {
        Measurement::Pose => {
            let frames: Vec<(usize, Rows)> = (0..tree.targets.len())
                .filter(|&t| is_frame(t))
                .map(|t| (t, Rows::Pose))
                .collect();
            if frames.is_empty() {
                return Err(Error::Input(format!(
                    "tree `{}`: a pose measurement needs a frame target; every target is a point",
                    tree.name
                )));
            }
            Ok(frames)
        }
        Measurement::Position => Ok((0..tree.targets.len())
            .map(|t| (t, Rows::Position))
            .collect()),
        Measurement::Distance => Err(Error::Input(format!(
            "tree `{}`: the identifiability of a tree measured by distances is not analysed",
            tree.name
        ))),
    }
}

/// Preference of a tree parameter for the minimal set (lower kept first): instrument,
/// targets, the root link, the links targets hang from, the other links; then registry order.
fn preference(tree: &Tree, i: usize) -> (usize, usize) {
    let p = tree.registry.get(i);
    let group = match p.segment {
        Segment::Instrument => 0,
        Segment::Target(_) => 1,
        Segment::Chain => {
            let frame = p.frame();
            let root = tree.branches[0].model.links[0].spec.name == frame;
            let end = tree
                .branches
                .iter()
                .any(|b| b.model.links.last().is_some_and(|l| l.spec.name == frame));
            match (root, end) {
                (true, _) => 2,
                (false, true) => 3,
                _ => 4,
            }
        }
    };
    (group, i)
}

/// The identifiability of the free parameters of `tree` at `params` from every target's
/// measurement at configurations `qs` of the tree's joints (`None`: `opts.poses` random ones
/// within the joint limits, seeded by `opts.seed`). A parameter left out because of a coupled
/// joint says so in its reason.
pub fn analyze_tree(
    tree: &Tree,
    params: &[f64],
    qs: Option<&[Vec<f64>]>,
    opts: &IdentifiabilitySettings,
) -> Result<Identifiability, Error> {
    let random;
    let qs = match qs {
        Some(qs) => qs,
        None => {
            random = random_joint_values(&tree.joints, opts.poses.max(2), opts.seed);
            &random
        }
    };
    analyze_tree_measured(tree, params, qs, None, opts)
}

/// As [`analyze_tree`] at the configurations `qs`, configuration `c` measuring only the tree
/// targets `measured[c]` (`None`: every target at every configuration): the analysis of a
/// data set that measures one arm at a time, where the other arm's joints stand still and
/// its parameters have no effect on those rows.
pub(crate) fn analyze_tree_measured(
    tree: &Tree,
    params: &[f64],
    qs: &[Vec<f64>],
    measured: Option<&[Vec<usize>]>,
    opts: &IdentifiabilitySettings,
) -> Result<Identifiability, Error> {
    for q in qs {
        if q.len() != tree.dof() || q.iter().any(|x| !x.is_finite()) {
            return Err(Error::Input(format!(
                "tree `{}` has {} joints; a configuration has {} values or a non-finite one",
                tree.name,
                tree.dof(),
                q.len()
            )));
        }
    }
    let obs = observations(tree, opts.measurement)?;
    let mut candidates = tree.registry.free();
    candidates.sort_by_key(|&i| preference(tree, i));
    let mut data = TreeData::new(tree);
    let mut factor = RowCompressor::new(candidates.len());
    for (c, q) in qs.iter().enumerate() {
        let seen: Vec<(usize, Rows)> = obs
            .iter()
            .filter(|(t, _)| measured.is_none_or(|m| m[c].contains(t)))
            .copied()
            .collect();
        let per_pose: usize = seen.iter().map(|(_, r)| r.count()).sum();
        let mut block = DMatrix::zeros(per_pose, candidates.len());
        for b in 0..tree.branches.len() {
            branch_kinematics(tree, &mut data, b, params, q);
        }
        let mut row = 0;
        for &(t, rows) in &seen {
            tree_identification_jacobian(tree, &mut data, t, rows, &candidates, &mut block, row);
            row += rows.count();
        }
        factor.add_rows(block.as_view());
    }
    let m = factor.rows();
    let name = |i: usize| tree.registry.get(i).name.clone();
    let names: Vec<String> = candidates.iter().map(|&i| name(i)).collect();
    let mut s = select(factor.finish(), m, &names, opts.measurement, opts.tolerance);
    if !tree.coupled.is_empty() {
        // what the same tree identifies with its coupled joints moving on their own: a
        // parameter left out only under the coupling is left out because of it
        let free = tree.uncoupled()?;
        let free_opts = IdentifiabilitySettings {
            poses: opts.poses.max(qs.len()),
            ..opts.clone()
        };
        let without = analyze_tree(&free, params, None, &free_opts)?;
        let couplings: Vec<String> = tree
            .coupled
            .iter()
            .filter_map(|c| tree.coupling_of(&c.link))
            .collect();
        for e in &mut s.excluded {
            if without.identifiable.contains(&e.name) {
                e.reason += &format!(
                    "; it is identifiable when the coupled joints move on their own, so the \
                     coupling ({}) makes it redundant",
                    couplings.join("; ")
                );
            }
        }
    }
    let r = tree
        .joints
        .iter()
        .filter(|j| j.kind == JointKind::Revolute)
        .count();
    let p = tree.dof() - r;
    let fixed = (0..tree.param_count())
        .filter(|&i| tree.registry.get(i).status == ParameterStatus::Fixed)
        .map(name)
        .collect();
    Ok(s.into_report(
        &candidates,
        &name,
        fixed,
        opts.measurement,
        qs.len(),
        Completeness {
            revolute: r,
            prismatic: p,
            complete_pose_model: 4 * r + 2 * p + 6 * tree.targets.len(),
            expected_for_measurement: expected_tree_count(tree, opts.measurement),
        },
    ))
}
