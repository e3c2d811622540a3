//! How far the tool centre point moves between two models of one robot: the largest
//! distance `max_q ‖p_a(q) − p_b(q)‖` between their tool positions over seeded random
//! configurations within the joint limits. It is what a model file that cannot hold part of a
//! calibration costs (the part left out: a non-geometric term, a tool frame), and what the
//! corrections a conservative export drops cost. A tree's alike, over every target.

use crate::model::chain::{Model, ModelSpec};
use crate::model::kinematics::tool_pose;
use crate::model::sampling::{random_configurations, random_joint_values};
use crate::model::tree::kinematics::{branch_kinematics, tree_observed_pose, TreeData};
use crate::model::tree::{Tree, TreeSpec};
use crate::Error;
use serde::{Deserialize, Serialize};

/// Configurations the shift is the largest over.
pub const SHIFT_CONFIGURATIONS: usize = 1000;
/// Their seed.
pub const SHIFT_SEED: u64 = 33;

/// A calibrated quantity a model file does not hold, and how far the tool centre point moves
/// without it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NotHeld {
    /// What is left out, in words (parameter names where it has them).
    pub what: String,
    /// Largest tool-position change without it over [`SHIFT_CONFIGURATIONS`] random
    /// configurations (seed [`SHIFT_SEED`]), mm.
    pub tcp_shift_mm: f64,
}

impl NotHeld {
    /// One line: what, and the shift.
    pub fn sentence(&self) -> String {
        format!(
            "not held: {}; the TCP moves up to {:.4} mm without it (max over {} random \
             configurations, seed {})",
            self.what, self.tcp_shift_mm, SHIFT_CONFIGURATIONS, SHIFT_SEED
        )
    }
}

/// `max_q ‖p_a(q) − p_b(q)‖` (mm) of the tool positions of `a` at `pa` and `b` at `pb` (the
/// same joints) over [`SHIFT_CONFIGURATIONS`] random configurations of `a`.
pub(crate) fn max_tcp_shift(a: &Model, pa: &[f64], b: &Model, pb: &[f64]) -> Result<f64, Error> {
    if a.dof() != b.dof() {
        return Err(Error::Model(format!(
            "comparing models with {} and {} joints",
            a.dof(),
            b.dof()
        )));
    }
    Ok(random_configurations(a, SHIFT_CONFIGURATIONS, SHIFT_SEED)
        .iter()
        .map(|q| (tool_pose(a, pa, q).trans - tool_pose(b, pb, q).trans).norm())
        .fold(0.0, f64::max))
}

/// [`max_tcp_shift`] of two specs at their own values.
pub(crate) fn spec_shift(a: &ModelSpec, b: &ModelSpec) -> Result<f64, Error> {
    let (ma, mb) = (Model::from_spec(a)?, Model::from_spec(b)?);
    max_tcp_shift(&ma, &ma.nominal(), &mb, &mb.nominal())
}

/// `spec` without its non-geometric terms (compliance, periodic errors, payloads), and what
/// leaving them out costs; `None` when it has none.
pub(crate) fn without_nongeometric(
    spec: &ModelSpec,
) -> Result<(ModelSpec, Option<NotHeld>), Error> {
    let model = Model::from_spec(spec)?;
    let terms: Vec<&str> = model
        .joint_corrections()
        .map(|(p, _)| model.registry.get(p).name.as_str())
        .collect();
    let mut rigid = spec.clone();
    rigid.compliance = None;
    rigid.periodic = None;
    rigid.payloads.clear();
    if terms.is_empty() {
        return Ok((rigid, None));
    }
    let shift = spec_shift(spec, &rigid)?;
    Ok((
        rigid,
        Some(NotHeld {
            what: format!("the non-geometric terms ({})", terms.join(", ")),
            tcp_shift_mm: shift,
        }),
    ))
}

/// The tree `spec` without its joint and lateral (bending) compliance, and what leaving it
/// out costs (the warning names every κ and κ⊥): the
/// largest distance between a target's positions in the two trees over
/// [`SHIFT_CONFIGURATIONS`] random configurations of the tree's joints (seed
/// [`SHIFT_SEED`]), every target; `None` when it has no compliance.
pub(crate) fn tree_without_compliance(
    spec: &TreeSpec,
) -> Result<(TreeSpec, Option<NotHeld>), Error> {
    let mut rigid = spec.clone();
    rigid.compliance = None;
    let compliant = Tree::from_spec(spec)?;
    let Some(compliance) = &compliant.compliance else {
        return Ok((rigid, None));
    };
    let terms: Vec<&str> = compliance
        .terms
        .iter()
        .map(|t| t.param)
        .chain(compliance.bending.iter().map(|t| t.param))
        .map(|i| compliant.registry.get(i).name.as_str())
        .collect();
    let what = if compliance.bending.is_empty() {
        "the joint compliance"
    } else {
        "the joint and lateral (bending) compliance"
    };
    let stiff = Tree::from_spec(&rigid)?;
    let (pc, ps) = (compliant.nominal(), stiff.nominal());
    let (mut dc, mut ds) = (TreeData::new(&compliant), TreeData::new(&stiff));
    let mut shift = 0.0f64;
    for q in random_joint_values(&compliant.joints, SHIFT_CONFIGURATIONS, SHIFT_SEED) {
        for (t, &(_, b, _)) in compliant.targets.iter().enumerate() {
            branch_kinematics(&compliant, &mut dc, b, &pc, &q);
            branch_kinematics(&stiff, &mut ds, b, &ps, &q);
            let (a, r) = (
                tree_observed_pose(&compliant, &dc, t),
                tree_observed_pose(&stiff, &ds, t),
            );
            shift = shift.max((a.trans - r.trans).norm());
        }
    }
    Ok((
        rigid,
        Some(NotHeld {
            what: format!("{what} ({})", terms.join(", ")),
            tcp_shift_mm: shift,
        }),
    ))
}
