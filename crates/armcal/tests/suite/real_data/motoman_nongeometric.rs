//! Real data: `identify --nongeometric auto` on the Motoman arms (issue 14): the candidate
//! chosen by cross-validation on the training two thirds never makes the held-out third
//! worse than the kinematic fit by more than the noise of the held-out RMS itself.

use super::motoman_calibration::motoman;
use armcal::identify::{identify, Candidate, IdentifySettings, NonGeometric, Validation};
use armcal::progress::Silent;

fn held_out(arm: &str, nongeometric: NonGeometric) -> (Validation, Option<Candidate>) {
    let (cell, data) = motoman(&format!("{arm}-nongeometric-cell"), arm);
    let mut opts = IdentifySettings {
        holdout: 1.0 / 3.0,
        seed: 1,
        nongeometric,
        ..Default::default()
    };
    opts.lm.tolerances.max_iterations = 2000;
    let est = identify(&cell, &data, &opts, &mut Silent).unwrap();
    assert!(est.solver.status.is_converged(), "{:?}", est.solver.status);
    let chosen = est.nongeometric_choice.as_ref().map(|c| {
        for s in &c.candidates {
            eprintln!(
                "{arm}: {:<24} CV RMS {:.4} ± {:.4} mm",
                s.candidate.words(),
                s.held_out.rms,
                s.standard_error
            );
        }
        c.chosen
    });
    (est.validation.unwrap(), chosen)
}

fn auto_is_no_worse_than_kinematic(arm: &str) {
    let (kinematic, _) = held_out(arm, NonGeometric::Only(Candidate::Kinematic));
    let (auto, chosen) = held_out(arm, NonGeometric::Auto { folds: 5 });
    let (k, a) = (&kinematic.calibrated, &auto.calibrated);
    // the RMS of n errors has a relative standard error of about 1/√(2n)
    let noise = k.rms / (2.0 * k.count as f64).sqrt();
    eprintln!(
        "{arm}: kinematic RMS {:.4} mm, auto ({:?}) RMS {:.4} mm, noise of the RMS {noise:.4} mm",
        k.rms, chosen, a.rms
    );
    assert!(chosen.is_some());
    assert!(a.rms <= k.rms + noise, "auto {a:?} vs kinematic {k:?}");
}

#[test]
fn motoman_right_arm_auto_is_no_worse_than_kinematic() {
    auto_is_no_worse_than_kinematic("right");
}

#[test]
fn motoman_left_arm_auto_is_no_worse_than_kinematic() {
    auto_is_no_worse_than_kinematic("left");
}
