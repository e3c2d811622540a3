//! The adaptive campaign (issue 16 item 1): a small simulated run on the paper cell
//! (σ = 1 mm, target 0.7 mm) stops with every working pose's σ at or below the target from
//! a converged fit, its state resumes, and a batch that is not the planned one is refused
//! without changing the state.

use armcal::campaign::{self, CampaignSettings, CampaignState, Decision};
use armcal::cell::builtin::PAPER_CELL;
use armcal::progress::Silent;
use armcal::sim::Perturbation;
use armcal::Cell;

fn paper_cell() -> Cell {
    Cell::from_toml(PAPER_CELL, "paper-cell.toml", ".".as_ref()).unwrap()
}

#[test]
fn a_simulated_campaign_stops_at_the_target_and_resumes() {
    let cell = paper_cell();
    let target = 0.7;
    let settings = CampaignSettings {
        target_sigma_mm: target,
        batch: 5,
        ..CampaignSettings::default()
    };
    let t0 = std::time::Instant::now();
    let run = campaign::simulate(
        &cell,
        "paper",
        &settings,
        &Perturbation::default(),
        3,
        &mut Silent,
    )
    .unwrap();
    let s = &run.state;
    eprintln!(
        "stopped after {} poses in {} steps ({:.1} s): {}",
        s.measured(),
        s.steps.len(),
        t0.elapsed().as_secs_f64(),
        s.steps.last().unwrap().reason
    );
    assert_eq!(s.decision, Decision::TargetReached);
    let last = s.steps.last().unwrap();
    assert!(last.fit.as_ref().unwrap().status.is_converged());
    assert!(!last.working.is_empty());
    for w in &last.working {
        assert!(w.sigma_mm <= target, "{}: {}", w.name, w.sigma_mm);
        assert!(w.true_error_inside_95.is_some());
    }
    // It did not stop before it had to: the step before was above the target (or unfit).
    if s.steps.len() > 1 {
        let before = &s.steps[s.steps.len() - 2];
        assert_eq!(before.decision, Decision::Measure);
        let worst = campaign::largest_sigma(&before.working);
        assert!(
            worst > target || worst.is_nan() || !before.fit.as_ref().unwrap().status.is_converged()
        );
    }
    // The first batch is the fewest poses that identify the free set; later batches 5.
    assert_eq!(
        s.steps[0].poses.len(),
        campaign::fewest_poses(&cell).unwrap()
    );
    assert!(s.steps[1..].iter().all(|st| st.poses.len() == 5));
    // The σ's shrink as poses are added (more information never loses precision; the
    // variance-factor scale may move them a little).
    let first = campaign::largest_sigma(&s.steps[1].working);
    assert!(campaign::largest_sigma(&last.working) < first);

    // Resume: the state written as JSON and read back, its second step replayed from the
    // state after the first one gives the same decision and σ's.
    let json = s.to_json().unwrap();
    let back = CampaignState::from_json(&json, "campaign.json").unwrap();
    assert_eq!(back.steps.len(), s.steps.len());
    let mut after_first = back.clone();
    after_first.steps.truncate(1);
    after_first.decision = Decision::Measure;
    after_first.next = back.steps[1]
        .poses
        .iter()
        .map(|p| campaign::CampaignPose {
            id: p.id.clone(),
            joints: p.joints.clone(),
        })
        .collect();
    let again = campaign::step(&cell, &after_first, &back.steps[1].data, &mut Silent).unwrap();
    let replayed = &again.state.steps[1];
    assert_eq!(replayed.decision, s.steps[1].decision);
    for (a, b) in replayed.working.iter().zip(&s.steps[1].working) {
        assert!((a.sigma_mm - b.sigma_mm).abs() < 1e-6 * b.sigma_mm);
    }
    assert!(replayed.fit.as_ref().unwrap().warm_start);

    // A batch that is not next.csv's is refused, naming the missing and extra poses, and
    // the state passed in is unchanged.
    let mut wrong = back.steps[1].data.clone();
    wrong.config_ids[0] = "999".into();
    let before = after_first.to_json().unwrap();
    let e = campaign::step(&cell, &after_first, &wrong, &mut Silent)
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing poses") && e.contains("999"), "{e}");
    assert_eq!(after_first.to_json().unwrap(), before);
    // A stopped campaign takes no more batches.
    let e = campaign::step(&cell, &back, &back.steps[1].data, &mut Silent)
        .unwrap_err()
        .to_string();
    assert!(e.contains("stopped"), "{e}");
}
