//! A campaign against a virtual robot and instrument ([`crate::sim`]): the same
//! [`start`](super::start) and [`step`](super::step) loop, each batch measured on a robot
//! perturbed from the nominal with the instrument's noise, for planning a campaign before
//! the robot is free. The true robot is known, so every step also records the true TCP
//! error and whether it lies in the stated 95 % ellipsoid.

use super::precision::tcp_position;
use super::{start, step_with, CampaignSettings, CampaignState, Decision, StepSettings};
use crate::cell::Cell;
use crate::design::cell_constraints::{unmeasurable_poses_at, ConstraintKind, Unmeasurable};
use crate::identify::Estimate;
use crate::progress::Observer;
use crate::sim::{perturbed_truth, Perturbation, TruthRecord};
use crate::Error;

/// What a simulated campaign made.
#[derive(Clone, Debug)]
pub struct SimulatedCampaign {
    /// The final state (stopped: target reached or budget exhausted).
    pub state: CampaignState,
    /// The last fit's estimate.
    pub estimate: Option<Estimate>,
    /// The virtual robot.
    pub truth: TruthRecord,
}

/// Runs a campaign on `cell` against a robot perturbed by `perturbation` (seed `seed`)
/// measured with the cell's instrument noise (batch `k` with noise seed
/// `seed · 1000 + k`); `observer` follows each step. Without a budget in `settings` the
/// run stops at the target or at 2 000 poses.
pub fn simulate(
    cell: &Cell,
    cell_source: &str,
    settings: &CampaignSettings,
    perturbation: &Perturbation,
    seed: u64,
    observer: &mut dyn Observer,
) -> Result<SimulatedCampaign, Error> {
    let model = &cell.model;
    let mut settings = settings.clone();
    settings.budget = Some(settings.budget.unwrap_or(2_000));
    let truth = perturbed_truth(model, perturbation, seed);
    let mut state = start(cell, cell_source, &settings, observer)?;
    state.simulation_seed = Some(seed);
    let (state, estimate) = measure_until_stopped(cell, state, None, &truth, seed, observer)?;
    Ok(SimulatedCampaign {
        truth: TruthRecord::new(&cell.name, model, &truth, seed),
        state,
        estimate,
    })
}

/// Measures the poses `state` asks for on the robot `truth` with the cell's instrument
/// noise (batch `k` with noise seed `seed · 1000 + k`) and steps until the campaign stops.
/// A pose the virtual instrument cannot measure there (`unmeasurable_poses_at` at the true
/// robot and instrument) only for its incidence or line of sight is left out and declared
/// unmeasurable ([`StepSettings::unmeasurable`]), as an operator whose tracker loses the
/// beam goes on without it; a pose in collision at the true robot, or a batch with no
/// measurable pose, is an error naming the poses, as it would stop a real campaign.
/// Every step records the true TCP error at the working poses. `estimate`: the estimate of
/// the state's last step, if any. Returns the final state and the last fit's estimate.
pub fn measure_until_stopped(
    cell: &Cell,
    mut state: CampaignState,
    mut estimate: Option<Estimate>,
    truth: &[f64],
    seed: u64,
    observer: &mut dyn Observer,
) -> Result<(CampaignState, Option<Estimate>), Error> {
    let model = &cell.model;
    let noise = cell.noise();
    while state.decision == Decision::Measure {
        let k = state.steps.len() as u64 + 1;
        let qs: Vec<Vec<f64>> = state.next.iter().map(|p| p.q(model)).collect();
        let poses: Vec<(String, Vec<f64>)> = state
            .next
            .iter()
            .map(|p| p.id.clone())
            .zip(qs.iter().cloned())
            .collect();
        let blocked = unmeasurable_poses_at(cell, truth, &poses)?;
        let beam_only = |u: &Unmeasurable| {
            u.violations.iter().all(|v| {
                matches!(
                    v.kind,
                    ConstraintKind::Incidence | ConstraintKind::LineOfSight
                )
            })
        };
        if blocked.len() == poses.len() || !blocked.iter().all(beam_only) {
            let list: Vec<String> = blocked.iter().map(|u| format!("  {u}")).collect();
            return Err(Error::Input(format!(
                "batch {k}: {} of {} poses cannot be measured on the virtual robot (its true geometry, the instrument where the simulation placed it){}:\n{}\nthe poses were planned too close to the limits: raise the cell's [design] incidence_margin_deg, line_of_sight_margin_mm or clearance_mm",
                blocked.len(),
                poses.len(),
                if blocked.len() == poses.len() { ", none of the batch" } else { ", some in collision" },
                list.join("\n")
            )));
        }
        let settings = StepSettings {
            unmeasurable: blocked.into_iter().map(|u| u.id).collect(),
            ..StepSettings::default()
        };
        let (qs, ids): (Vec<Vec<f64>>, Vec<String>) = qs
            .into_iter()
            .zip(state.next.iter().map(|p| p.id.clone()))
            .filter(|(_, id)| !settings.unmeasurable.contains(id))
            .unzip();
        let mut batch = crate::sim::simulate_measuring(
            model,
            truth,
            &qs,
            &[],
            cell.measurement,
            Some(&noise),
            seed.wrapping_mul(1000).wrapping_add(k),
        )?;
        batch.config_ids = ids;
        batch.source = format!("simulation (seed {seed}, batch {k})");
        let r = step_with(cell, &state, &batch, &settings, observer)?;
        state = r.state;
        if let (Some(e), Some(last)) = (&r.estimate, state.steps.last_mut()) {
            let params = e.params_for(model)?;
            for (w, working) in last.working.iter_mut().zip(&cell.working) {
                let err = tcp_position(model, &params, &working.q)
                    - tcp_position(model, truth, &working.q);
                *w = w.clone().with_true_error(err);
            }
        }
        estimate = r.estimate.or(estimate);
    }
    Ok((state, estimate))
}
