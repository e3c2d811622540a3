//! Real data: `identify --nongeometric auto` on the Motoman arms (issue 14): the candidate
//! chosen by cross-validation on the training two thirds never makes the held-out third
//! worse than the kinematic fit by more than the noise of the held-out RMS itself.

use super::motoman_calibration::motoman;
use armcal::identify::Validation;
use armcal::{
    identify, Candidate, Cell, Dataset, ErrorStats, IdentifySettings, NonGeometric, Silent,
};

/// The held-out validation of a fit of `cell` to `data` with `nongeometric`, and the
/// candidate `auto` chose (every candidate's cross-validated RMS printed as `label: …`).
fn held_out(
    label: &str,
    cell: &Cell,
    data: &Dataset,
    opts: &IdentifySettings,
    nongeometric: NonGeometric,
) -> (Validation, Option<Candidate>) {
    let opts = IdentifySettings {
        nongeometric,
        ..opts.clone()
    };
    let est = identify(cell, data, &opts, &mut Silent).unwrap();
    assert!(est.solver.status.is_converged(), "{:?}", est.solver.status);
    let chosen = est.nongeometric_choice.as_ref().map(|c| {
        for s in &c.candidates {
            eprintln!(
                "{label}: {:<24} CV RMS {:.4} ± {:.4} mm",
                s.candidate.words(),
                s.held_out.rms,
                s.standard_error
            );
        }
        c.chosen
    });
    (est.validation.unwrap(), chosen)
}

/// `auto`'s held-out RMS is at most the kinematic fit's plus the noise of that RMS: an RMS of
/// n errors has a relative standard error of about 1/√(2n).
fn no_worse(label: &str, what: &str, kinematic: &ErrorStats, auto: &ErrorStats) {
    let (k, a) = (kinematic, auto);
    let noise = k.rms / (2.0 * k.count as f64).sqrt();
    eprintln!(
        "{label}: {what}: kinematic {:.4} / {:.4} / {:.4}, auto {:.4} / {:.4} / {:.4} (mean / RMS / max), noise of the RMS {noise:.4}",
        k.mean, k.rms, k.max, a.mean, a.rms, a.max
    );
    assert!(
        a.rms <= k.rms + noise,
        "{label}: {what}: auto {a:?} vs kinematic {k:?}"
    );
}

/// Fits `cell` to `data` (held out as `opts` says) kinematic and with `--nongeometric auto`,
/// and checks that `auto` is no worse held out, in position and, for pose data, orientation.
pub(super) fn auto_is_no_worse_than_kinematic(
    label: &str,
    cell: &Cell,
    data: &Dataset,
    opts: &IdentifySettings,
) {
    let (kinematic, _) = held_out(
        label,
        cell,
        data,
        opts,
        NonGeometric::Only(Candidate::Kinematic),
    );
    let (auto, chosen) = held_out(label, cell, data, opts, NonGeometric::Auto { folds: 5 });
    eprintln!("{label}: auto chose {chosen:?}");
    assert!(chosen.is_some());
    no_worse(
        label,
        "position (mm)",
        &kinematic.calibrated,
        &auto.calibrated,
    );
    if let (Some(k), Some(a)) = (&kinematic.orientation, &auto.orientation) {
        no_worse(label, "orientation (deg)", &k.calibrated, &a.calibrated);
    }
}

fn motoman_auto_is_no_worse_than_kinematic(arm: &str) {
    let (cell, data) = motoman(&format!("{arm}-nongeometric-cell"), arm);
    let mut opts = IdentifySettings {
        holdout: 1.0 / 3.0,
        seed: 1,
        ..Default::default()
    };
    opts.lm.tolerances.max_iterations = 2000;
    auto_is_no_worse_than_kinematic(arm, &cell, &data, &opts);
}

#[test]
fn motoman_right_arm_auto_is_no_worse_than_kinematic() {
    motoman_auto_is_no_worse_than_kinematic("right");
}

#[test]
fn motoman_left_arm_auto_is_no_worse_than_kinematic() {
    motoman_auto_is_no_worse_than_kinematic("left");
}
