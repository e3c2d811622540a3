//! A campaign after a drift check (issue 16 item 2): the old calibration is the prior, the
//! group the check found moved is released, the check poses are the first step, and the
//! campaign measures until the TCP at the working pose is as precise as asked — with far
//! fewer poses than a campaign from the nominal model, and with the moved parameter found.

use armcal::cell::builtin::PAPER_CELL;
use armcal::model::random_configurations;
use armcal::{
    campaign_measure_until_stopped as measure_until_stopped, campaign_simulate as simulate,
    campaign_start_after_check as start_after_check, check, CampaignDecision as Decision,
    CampaignPrior, CampaignSettings, CheckSettings, DriftVerdict,
};
use armcal::{identify, perturbed_truth, Cell, IdentifySettings, Perturbation, Silent};

#[test]
fn a_campaign_from_the_old_calibration_needs_only_what_moved() {
    let cell = crate::common::paper_cell_with_default_margins();
    let model = &cell.model;
    let truth = perturbed_truth(model, &Perturbation::default(), 7);
    // The old calibration: 120 random poses (σ = 1 mm).
    let qs = random_configurations(model, 120, 70);
    let data = armcal::simulate(model, &truth, &qs, Some(&cell.noise()), 71).unwrap();
    let old = identify(&cell, &data, &IdentifySettings::default(), &mut Silent).unwrap();
    // Later the second joint's offset has moved by 0.5°; 10 check poses find it.
    let j2 = model.registry.index_of("j2.theta").unwrap();
    let mut moved = truth.clone();
    moved[j2] += 0.5f64.to_radians();
    let check_qs = random_configurations(model, 10, 72);
    let mut check_data =
        armcal::simulate(model, &moved, &check_qs, Some(&cell.noise()), 73).unwrap();
    check_data.config_ids = (1..=10).map(|i| format!("c{i}")).collect();
    let c = check(&cell, &old, &check_data, &CheckSettings::default()).unwrap();
    assert_eq!(c.verdict, DriftVerdict::Drifted);
    assert_eq!(c.groups[0].group, "j2", "{:?}", c.groups);

    let target = 0.45;
    let settings = CampaignSettings {
        target_sigma_mm: target,
        budget: Some(300),
        prior: Some(
            CampaignPrior::from_estimate(&cell, &old, "old.json", &["j2".to_string()]).unwrap(),
        ),
        ..CampaignSettings::default()
    };
    let first = start_after_check(&cell, "paper", &settings, &check_data, &mut Silent).unwrap();
    let (state, estimate) =
        measure_until_stopped(&cell, first.state, first.estimate, &moved, 74, &mut Silent).unwrap();
    assert_eq!(
        state.decision,
        Decision::TargetReached,
        "{}",
        state.steps.last().unwrap().reason
    );
    let after_check = state.measured();

    // The same target from the nominal model, on the moved robot's kind of cell.
    let scratch = simulate(
        &cell,
        "paper",
        &CampaignSettings {
            target_sigma_mm: target,
            budget: Some(300),
            ..CampaignSettings::default()
        },
        &Perturbation::default(),
        7,
        &mut Silent,
    )
    .unwrap();
    assert_eq!(scratch.state.decision, Decision::TargetReached);
    let from_scratch = scratch.state.measured();

    let e = estimate.unwrap();
    let p = e.params_for(model).unwrap();
    let k = e.free.iter().position(|n| n == "j2.theta").unwrap();
    let sigma = e.uncertainty.sigma[k];
    let last = state.steps.last().unwrap();
    eprintln!(
        "target σ {target} mm at the working pose: {after_check} poses after the check (10 check \
         poses included, prior from 120) against {from_scratch} from the nominal model; \
         j2.theta moved by {:.4}°, estimated {:.4}° ± {:.4}° from the old calibration; final σ \
         {:.3} mm, true TCP error {:?} mm (inside the 95 % ellipsoid: {:?})",
        0.5,
        (p[j2] - old.params_for(model).unwrap()[j2]).to_degrees(),
        sigma.to_degrees(),
        last.working[0].sigma_mm,
        last.working[0].true_error_mm,
        last.working[0].true_error_inside_95
    );
    assert!(
        after_check * 2 <= from_scratch,
        "{after_check} vs {from_scratch}"
    );
    assert!(
        (p[j2] - moved[j2]).abs() <= 4.0 * sigma,
        "j2.theta {} vs truth {} (σ {sigma})",
        p[j2],
        moved[j2]
    );
}

#[test]
fn a_damaged_estimate_is_an_error_for_the_check_and_the_prior() {
    // An estimate file whose C_p does not match its free set (edited or damaged) would be
    // indexed out of range by the check and by the campaign's prior: an error instead.
    let cell = Cell::from_toml(PAPER_CELL, "paper-cell.toml", ".".as_ref()).unwrap();
    let model = &cell.model;
    let truth = perturbed_truth(model, &Perturbation::default(), 3);
    let qs = random_configurations(model, 30, 3);
    let data = armcal::simulate(model, &truth, &qs, Some(&cell.noise()), 3).unwrap();
    let mut est = identify(&cell, &data, &IdentifySettings::default(), &mut Silent).unwrap();
    est.uncertainty.covariance = nalgebra::DMatrix::identity(2, 2);
    let e = check(&cell, &est, &data, &CheckSettings::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("damaged"), "{e}");
    let e = CampaignPrior::from_estimate(&cell, &est, "bad.json", &[])
        .unwrap_err()
        .to_string();
    assert!(e.contains("damaged"), "{e}");
}
