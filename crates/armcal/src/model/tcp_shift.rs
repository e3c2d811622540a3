//! How far the tool centre point moves between two models of one robot: the largest
//! distance `max_q ‖p_a(q) − p_b(q)‖` between their tool positions over seeded random
//! configurations within the joint limits. It is what a model file that cannot hold part of a
//! calibration costs (the part left out: a non-geometric term, a tool frame), and what the
//! corrections a conservative export drops cost.

use crate::model::chain::{Model, ModelSpec};
use crate::model::kinematics::tool_pose;
use crate::model::sampling::random_configurations;
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
