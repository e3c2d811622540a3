//! The whole identification in one call ([`identify`]): the fit, its uncertainty, checks
//! and held-out validation.

use super::split::Split;
use super::{
    estimate_of_fit, fit_checks, fit_free_set, nongeometric_choice, payload_terms, phase, refit,
    Estimate, IdentifySettings, ModelFingerprint, NonGeometric,
};
use crate::cell::Cell;
use crate::measure::Dataset;
use crate::progress::Observer;
use crate::Error;

/// Identifies the cell's free parameters from a dataset: fit (optionally on a training
/// split), covariance, TCP covariance at the working configurations, diagnostics, and
/// held-out validation against the nominal and frames-only models.
///
/// The fit is Levenberg–Marquardt (book §5.3) on the σ-weighted residuals; its covariance
/// `C_p = σ̂² (JᵀJ)⁻¹` (book eq. 5.23) and `C_s = G C_p Gᵀ` at each working pose (paper
/// eq. 19) say how well the robot is known. A fit that did not converge says so in its
/// status and is not a calibration.
///
/// ```
/// use armcal::{identify, simulate, Cell, IdentifySettings};
/// use armcal::model::random_configurations;
/// use armcal::Silent;
/// use armcal::{perturbed_truth, Perturbation};
///
/// # fn main() -> armcal::Result<()> {
/// let cell = armcal::cell::builtin::paper_cell()?;
/// let model = &cell.model;
/// let truth = perturbed_truth(model, &Perturbation::default(), 5);
/// let data = simulate(model, &truth, &random_configurations(model, 50, 2), Some(&cell.noise()), 3)?;
/// let estimate = identify(&cell, &data, &IdentifySettings::default(), &mut Silent)?;
/// assert!(estimate.solver.status.is_converged());
/// // Every free parameter lies within 4 stated σ of the truth.
/// let fitted = estimate.params_for(model)?;
/// for p in estimate.parameters.iter().filter(|p| p.free) {
///     let k = model.registry.index_of(&p.name).expect("a parameter of the model");
///     assert!((fitted[k] - truth[k]).abs() < 4.0 * p.sigma.unwrap(), "{}", p.name);
/// }
/// # Ok(())
/// # }
/// ```
pub fn identify(
    cell: &Cell,
    data: &Dataset,
    opts: &IdentifySettings,
    observer: &mut dyn Observer,
) -> Result<Estimate, Error> {
    let noise = cell.noise();
    let split = Split::of(data, opts)?;
    let train: &Dataset = &split.train;
    crate::measure::stations::check_stations(data)?;
    let stationed = cell.with_stations(&data.stations)?;
    let (mut left_out, choice) = match opts.nongeometric {
        NonGeometric::AsCell => (Vec::new(), None),
        NonGeometric::Only(c) => (c.left_out(&stationed.model)?, None),
        NonGeometric::Auto { folds } => {
            let choice =
                nongeometric_choice::choose(&stationed, train, &noise, opts, folds, observer)?;
            (choice.chosen.left_out(&stationed.model)?, Some(choice))
        }
    };
    if !train.carries_payloads() {
        let new: Vec<(usize, String)> = payload_terms(&stationed.model)
            .filter(|(i, _)| !left_out.iter().any(|(j, _)| j == i))
            .collect();
        left_out.extend(new);
    }
    let fit = match &opts.refit {
        Some(refit) => refit::fit_frames(&stationed, cell, train, &noise, opts, refit, observer)?,
        None => fit_free_set(&stationed, train, &noise, opts, &left_out, observer)?,
    };
    observer.start("uncertainty, observability and residuals", None);
    let estimate = estimate_of_fit(&stationed, data, opts, &split, fit, &noise, observer);
    observer.finish();
    let mut estimate = estimate?;
    let checks = phase(observer, "units, misfit, joint signs and zeros", || {
        fit_checks::check(
            &stationed.model,
            train,
            &noise,
            &estimate,
            opts.diagnose_signs,
            opts.accept_misfit.as_deref(),
        )
    })?;
    if let Some(v) = estimate.verdicts.as_mut() {
        v.chi2.name_worst_rows(&checks.worst_rows);
        v.fit = checks;
    }
    // an estimate belongs to the cell as its file describes it, whatever stations its data name
    Ok(Estimate {
        fingerprint: Some(ModelFingerprint::of(&cell.model)),
        nongeometric_choice: choice,
        ..estimate
    })
}
