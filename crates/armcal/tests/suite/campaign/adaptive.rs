//! The adaptive campaign (issue 16 item 1): a small simulated run on the paper cell (with the
//! default `[design]` margins)
//! (σ = 1 mm, target 0.7 mm) stops with every working pose's σ at or below the target from
//! a converged fit, its state resumes, and a batch that is not the planned one is refused
//! without changing the state.

use armcal::{
    campaign_fewest_poses, campaign_largest_sigma, campaign_simulate, campaign_start,
    campaign_step, CampaignDecision as Decision, CampaignPose, CampaignSettings, CampaignState,
    CampaignStep,
};
use armcal::{Cell, Perturbation, Silent};

/// The paper cell with the default `[design]` margins: with the paper's zero margins, the
/// poses a campaign plans sit on the 30° limit and the virtual instrument cannot measure some
/// of them.
fn paper_cell() -> Cell {
    crate::common::paper_cell_with_default_margins()
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
    let run = campaign_simulate(
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
        let worst = campaign_largest_sigma(&before.working);
        assert!(
            worst > target || worst.is_nan() || !before.fit.as_ref().unwrap().status.is_converged()
        );
    }
    // The first batch is the fewest poses that identify the free set; later batches 5.
    assert_eq!(
        s.steps[0].poses.len(),
        campaign_fewest_poses(&cell).unwrap()
    );
    assert!(s.steps[1..].iter().all(|st| st.poses.len() == 5));
    // The σ's shrink as poses are added (more information never loses precision; the
    // variance-factor scale may move them a little).
    let first = campaign_largest_sigma(&s.steps[1].working);
    assert!(campaign_largest_sigma(&last.working) < first);

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
        .map(|p| CampaignPose {
            id: p.id.clone(),
            joints: p.joints.clone(),
        })
        .collect();
    let again = campaign_step(&cell, &after_first, &back.steps[1].data, &mut Silent).unwrap();
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
    let e = campaign_step(&cell, &after_first, &wrong, &mut Silent)
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing poses") && e.contains("999"), "{e}");
    assert_eq!(after_first.to_json().unwrap(), before);
    // A stopped campaign takes no more batches.
    let e = campaign_step(&cell, &back, &back.steps[1].data, &mut Silent)
        .unwrap_err()
        .to_string();
    assert!(e.contains("stopped"), "{e}");
}

#[test]
fn the_next_batch_is_planned_at_the_estimate_not_the_nominal() {
    // The paper cell, whose true tracker stands 300 mm (x and y) from where the cell puts
    // it: the first batch is planned at the nominal; after its fit, the next batch is
    // planned with the tracker (and reflector) where the fit puts them — feasible there
    // (incidence, line of sight, collisions, joint limits) — not where the cell puts them.
    let cell = paper_cell();
    let model = &cell.model;
    let mut truth = armcal::perturbed_truth(model, &Perturbation::default(), 5);
    for name in ["tracker.x", "tracker.y"] {
        truth[model.registry.require(name).unwrap()] += 300.0;
    }
    let settings = CampaignSettings {
        target_sigma_mm: 0.01,
        batch: 5,
        ..CampaignSettings::default()
    };
    let state = campaign_start(&cell, "unplaced", &settings, &mut Silent).unwrap();
    let qs: Vec<Vec<f64>> = state.next.iter().map(|p| p.q(model)).collect();
    // Many more poses than the fewest, so that the first fit converges from afar.
    let mut qs2 = qs.clone();
    qs2.extend(armcal::model::random_configurations(model, 31, 60));
    let mut state = state;
    state.next = qs2
        .iter()
        .enumerate()
        .map(|(i, q)| CampaignPose::of(model, (i + 1).to_string(), q))
        .collect();
    let noise = cell.noise();
    let mut batch = armcal::simulate(model, &truth, &qs2, Some(&noise), 7).unwrap();
    batch.config_ids = state.next.iter().map(|p| p.id.clone()).collect();
    let r = campaign_step(&cell, &state, &batch, &mut Silent).unwrap();
    let step = r.state.steps.last().unwrap();
    let fit = step.fit.as_ref().unwrap();
    assert!(fit.status.is_converged(), "{:?}", fit.status);
    assert_eq!(r.state.decision, Decision::Measure);
    let set = armcal::design::constraint_set(&cell, true).unwrap();
    let nominal = model.nominal();
    // The fit's frames on the nominal links.
    let frames_at_fit: Vec<f64> = model
        .registry
        .iter()
        .zip(nominal.iter().zip(&fit.params))
        .map(|(p, (&n, &f))| match p.segment {
            armcal::model::Segment::Chain => n,
            _ => f,
        })
        .collect();
    let at_fit = armcal::design::CellConstraints::new(&set, &frames_at_fit);
    let at_nominal = armcal::design::CellConstraints::new(&set, &nominal);
    let next: Vec<Vec<f64>> = r.state.next.iter().map(|p| p.q(model)).collect();
    assert_eq!(next.len(), 5);
    assert!(next.iter().all(|q| at_fit.feasible(q)));
    let infeasible_at_nominal = next.iter().filter(|q| !at_nominal.feasible(q)).count();
    assert!(
        infeasible_at_nominal > 0,
        "every pose of the next batch is also feasible at the nominal"
    );
}

/// The first batch is the fewest poses that identify the free set (27 rows for 27
/// parameters), and identify must be able to fit it at the robot measured, not only at the
/// nominal it was planned at. With planning seed 3 both starts' refined 9-pose designs
/// ended nearly rank deficient in the tracker frame (column-normalised singular-value ratio
/// 1.3e-6 and 2.5e-7 at the nominal; identify refuses about 1e-7 and found the first rank
/// deficient at the virtual robot); the planner keeps such a batch's exchange design.
#[test]
fn the_fewest_poses_batch_is_fittable_at_the_robot_measured() {
    let cell = paper_cell();
    let first = campaign_fewest_poses(&cell).unwrap();
    for seed in [1, 3] {
        let settings = CampaignSettings {
            target_sigma_mm: 0.7,
            batch: 5,
            budget: Some(first),
            seed,
            ..CampaignSettings::default()
        };
        let run = campaign_simulate(
            &cell,
            "paper",
            &settings,
            &Perturbation::default(),
            seed,
            &mut Silent,
        )
        .unwrap();
        let step = &run.state.steps[0];
        assert_eq!(step.poses.len(), first);
        let fit = step.fit.as_ref();
        assert!(
            fit.is_some_and(|f| f.status.is_converged()),
            "seed {seed}: the first batch was not fitted: {}",
            step.reason
        );
    }
}

/// A pose the virtual instrument cannot measure for its incidence or line of sight is left
/// out, declared unmeasurable, and the campaign goes on (it stopped the whole run before;
/// robot 166 of the paper cell, the tracker placed with σ 20 mm, stopped at batch 3). With the
/// virtual tracker placed 150 mm off per axis (σ), the first batch, planned where the cell
/// puts the tracker, meets the reflector beyond 30° at some poses: each step records them,
/// fits the rest, and numbers the next batch on after every id it issued.
#[test]
fn a_pose_the_instrument_cannot_measure_is_left_out_and_recorded() {
    let cell = paper_cell();
    let perturbation = Perturbation {
        instrument_length: Some(150.0),
        ..Perturbation::default()
    };
    let mut skipped_runs = 0;
    for seed in 1..=4u64 {
        let settings = CampaignSettings {
            target_sigma_mm: 0.6,
            batch: 5,
            budget: Some(19),
            seed,
            ..CampaignSettings::default()
        };
        // a batch with no measurable pose, or one in collision, stops a run: not this test's
        let Ok(run) =
            campaign_simulate(&cell, "paper", &settings, &perturbation, seed, &mut Silent)
        else {
            continue;
        };
        let s = &run.state;
        let mut issued = 0;
        for st in &s.steps {
            let ids: Vec<usize> = st
                .poses
                .iter()
                .chain(&st.unmeasurable)
                .map(|p| p.id.parse().unwrap())
                .collect();
            // numbered on after every id issued before, the unmeasurable ones included
            assert_eq!(
                ids.iter().min(),
                Some(&(issued + 1)),
                "seed {seed}: {ids:?}"
            );
            issued += ids.len();
            for u in &st.unmeasurable {
                assert!(
                    !st.data.config_ids.contains(&u.id),
                    "seed {seed}: pose {} measured",
                    u.id
                );
            }
        }
        assert_eq!(
            s.measured()
                + s.steps
                    .iter()
                    .map(|st| st.unmeasurable.len())
                    .sum::<usize>(),
            issued
        );
        if s.steps.iter().any(|st| !st.unmeasurable.is_empty()) {
            skipped_runs += 1;
            let back = CampaignState::from_json(&s.to_json().unwrap(), "state").unwrap();
            let ids = |st: &CampaignStep| {
                st.unmeasurable
                    .iter()
                    .map(|p| p.id.clone())
                    .collect::<Vec<_>>()
            };
            assert!(back
                .steps
                .iter()
                .zip(&s.steps)
                .all(|(a, b)| ids(a) == ids(b)));
        }
    }
    assert!(
        skipped_runs > 0,
        "no run left a pose out: the test does not test"
    );
}
