//! An adaptive measurement campaign (paper §6): measure a small batch, fit, and plan the
//! next batch until the TCP is as precise as required at every working pose.
//!
//! `measure` stands in for the laser tracker: here it measures a virtual robot that differs
//! from its drawing; on a real cell it drives the robot to each planned pose and records
//! the reflector's position. Everything else is what a real campaign does: `campaign_start`
//! plans the fewest poses that identify the free parameters, `campaign_step` fits what has
//! been measured, states every working pose's TCP σ, and decides whether to stop.
//!
//! Run: `cargo run --release -p armcal --example adaptive_campaign`
//! (the same as `armcal campaign start` / `campaign step`; guide: "Campaigns and drift checks").

use armcal::{
    campaign_largest_sigma, campaign_start, campaign_step, CampaignDecision as Decision,
    CampaignSettings, CampaignState,
};
use armcal::{perturbed_truth, simulate, Dataset, Perturbation, Silent};

fn main() -> armcal::Result<()> {
    let cell = armcal::cell::builtin::paper_cell()?;
    let model = &cell.model;
    let truth = perturbed_truth(model, &Perturbation::default(), 3);
    let settings = CampaignSettings {
        target_sigma_mm: 0.6,
        batch: 5,
        budget: Some(80),
        ..CampaignSettings::default()
    };
    let mut state = campaign_start(&cell, "paper-cell (built in)", &settings, &mut Silent)?;
    println!(
        "first batch: {} poses (the fewest that identify the free parameters)",
        state.next.len()
    );

    // The instrument: measures the planned poses, keeping their ids.
    let measure = |state: &CampaignState, batch: u64| -> armcal::Result<Dataset> {
        let qs: Vec<Vec<f64>> = state.next.iter().map(|p| p.q(model)).collect();
        let mut data = simulate(model, &truth, &qs, Some(&cell.noise()), 100 + batch)?;
        data.config_ids = state.next.iter().map(|p| p.id.clone()).collect();
        Ok(data)
    };

    while state.decision == Decision::Measure {
        let batch = measure(&state, state.steps.len() as u64)?;
        state = campaign_step(&cell, &state, &batch, &mut Silent)?.state;
        let last = state.steps.last().expect("a step was just taken");
        let worst = campaign_largest_sigma(&last.working);
        println!(
            "{:3} poses measured: largest working-pose σ {worst:.3} mm → {}",
            last.measured,
            state.decision.words()
        );
    }
    Ok(())
}
