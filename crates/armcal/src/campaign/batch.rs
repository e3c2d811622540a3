//! What a campaign step takes as its batch ([`StepSettings`]) and the check that the
//! measured batch is the planned one ([`check_batch`]).

use super::{CampaignPose, CampaignState};
use crate::cell::Cell;
use crate::measure::Dataset;
use crate::Error;

/// Joint values of a measured pose may differ from the planned ones by this much by default
/// (deg, mm for a prismatic joint): `next.csv` holds them to 1e-6, a controller reports its
/// own ([`step_with`](super::step_with) takes another tolerance).
pub const JOINT_TOLERANCE: f64 = 0.01;

/// How [`step_with`](super::step_with) takes a batch.
#[derive(Clone, Debug, PartialEq)]
pub struct StepSettings {
    /// The measured joint values may differ from the planned ones by this (deg, mm for a
    /// prismatic joint; a finite number ≥ 0): a controller that reports its joints to 0.05°
    /// needs 0.05. Default [`JOINT_TOLERANCE`].
    pub joint_tolerance: f64,
    /// Ids of `next.csv` poses the instrument could not measure (the beam blocked, the
    /// reflector turned past its acceptance angle on the real cell): the batch lacks them,
    /// the step records them ([`CampaignStep::unmeasurable`](super::CampaignStep::unmeasurable)) and the campaign goes on
    /// without them. At least one pose of the batch must be measured.
    pub unmeasurable: Vec<String>,
}

impl Default for StepSettings {
    fn default() -> Self {
        StepSettings {
            joint_tolerance: JOINT_TOLERANCE,
            unmeasurable: Vec::new(),
        }
    }
}

/// Checks that `batch` measured exactly the poses of `state.next` but those `settings`
/// declares unmeasurable: the same ids, joint values within the joint tolerance (deg, mm for
/// a prismatic joint). The error lists what is missing, extra, declared wrongly or moved.
pub(super) fn check_batch(
    cell: &Cell,
    state: &CampaignState,
    batch: &Dataset,
    settings: &StepSettings,
) -> Result<(), Error> {
    let tolerance = settings.joint_tolerance;
    let declared = |id: &str| settings.unmeasurable.iter().any(|u| u == id);
    let mut problems = Vec::new();
    let mut name = |ids: Vec<&str>, what: &str, then: &str| {
        if !ids.is_empty() {
            problems.push(format!("{what}{}{then}", ids.join(", ")));
        }
    };
    let in_next = |id: &str| state.next.iter().any(|p| p.id == id);
    name(
        state
            .next
            .iter()
            .map(|p| p.id.as_str())
            .filter(|id| !batch.config_ids.iter().any(|b| b == id) && !declared(id))
            .collect(),
        "missing poses ",
        " (measure them, or declare the ones the instrument cannot measure with `campaign \
         step --unmeasurable`)",
    );
    let unmeasurable = || settings.unmeasurable.iter().map(String::as_str);
    name(
        unmeasurable().filter(|id| !in_next(id)).collect(),
        "poses declared unmeasurable but not in next.csv: ",
        "",
    );
    name(
        unmeasurable()
            .filter(|id| batch.config_ids.iter().any(|b| b == id))
            .collect(),
        "poses both measured and declared unmeasurable: ",
        "",
    );
    name(
        batch
            .config_ids
            .iter()
            .map(String::as_str)
            .filter(|id| !in_next(id))
            .collect(),
        "poses not in next.csv: ",
        "",
    );
    for (id, q) in batch.config_ids.iter().zip(&batch.configurations) {
        let Some(planned) = state.next.iter().find(|p| &p.id == id) else {
            continue;
        };
        let measured = CampaignPose::of(&cell.model, id.clone(), q);
        let worst = measured
            .joints
            .iter()
            .zip(&planned.joints)
            .zip(&cell.model.joints)
            .map(|((a, b), j)| ((a - b).abs(), j.name.as_str()))
            .max_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((d, joint)) = worst.filter(|w| w.0 > tolerance) {
            problems.push(format!(
                "pose {id}: joint `{joint}` is {d:.4} from the planned value (more than the joint tolerance {tolerance}; `campaign step --joint-tolerance-deg` sets it)"
            ));
        }
    }
    if batch.measurements.is_empty() {
        problems.push("no measurements".into());
    }
    if problems.is_empty() {
        return Ok(());
    }
    Err(Error::Input(format!(
        "{}: not the batch of next.csv ({} poses, ids {}): {}; measure exactly the poses of next.csv but those declared unmeasurable",
        batch.source,
        state.next.len(),
        state
            .next
            .iter()
            .map(|p| p.id.as_str())
            .collect::<Vec<_>>()
            .join(", "),
        problems.join("; ")
    )))
}
