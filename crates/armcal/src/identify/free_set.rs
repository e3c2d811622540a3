//! The fit with its free set decided where the fit is (frames first, the identifiable set
//! at the estimate, grown when the fit leaves a special geometry), and the non-geometric
//! terms the gate finds not separable dropped one by one ([`super::nongeometric_gate`]).

use super::*;

/// A fit with its free set, as [`fit_free_set`] decided it.
pub(super) struct FreeSetFit {
    pub(super) model: Model,
    pub(super) reasons: Vec<(String, String)>,
    /// The parameters held at their nominal as only weakly identifiable at the fit
    /// ([`super::weak_gain`]).
    pub(super) weak: Vec<String>,
    /// The problem's final row weights (a robust fit's IRLS weights).
    pub(super) row_weights: Vec<f64>,
    pub(super) solution: SolverResult,
    pub(super) outliers: Vec<Outlier>,
    pub(super) robust_scale: Option<f64>,
}

/// The fit with the free set decided where the fit is, never at the nominal: frames first
/// ([`frames_first_start`] on every parameter the cell declared free), the identifiable set
/// at that estimate ([`identifiable_model`]), the fit, and the identifiable set again at
/// the fit. When it grew there (the start sat at a special geometry the fit left), the fit
/// is repeated from there with the larger set; the set grows every time, so this ends. With
/// `free = "auto"`, a non-geometric term the gate finds not separable
/// ([`nongeometric_gate`]) is then dropped like every parameter the data cannot identify —
/// the least separable first, named with its reason — and the fit repeated without it.
/// `left_out` are terms left out from the start (a non-geometric candidate,
/// [`super::nongeometric_choice`]), with their reasons.
pub(super) fn fit_free_set(
    cell: &Cell,
    train: &Dataset,
    noise: &crate::measure::NoiseModel,
    opts: &IdentifySettings,
    left_out: &[(usize, String)],
    observer: &mut dyn Observer,
) -> Result<FreeSetFit, Error> {
    let declared = if cell.auto_free {
        cell.declared_model()
    } else {
        cell.model.clone()
    };
    let generic = if cell.auto_free {
        Some(cell.identifiability(&cell.identifiability_settings())?)
    } else {
        None
    };
    let mut dropped: Vec<(usize, String)> = left_out.to_vec();
    let decide = |at: &[f64], dropped: &[(usize, String)]| match &generic {
        Some(g) => identifiable_model_given(cell, train, at, g, dropped),
        None => {
            let mut model = cell.model.clone();
            let reasons = dropped
                .iter()
                .map(|(i, why)| {
                    model.registry.set_status(*i, ParamStatus::Fixed);
                    (model.registry.get(*i).name.clone(), why.clone())
                })
                .collect();
            Ok((model, reasons, Vec::new()))
        }
    };
    let mut at = match &opts.start {
        Some(start) if start.len() == declared.param_count() => start.clone(),
        Some(start) => {
            return Err(Error::Input(format!(
                "the warm start has {} parameters; the model of cell `{}` has {}",
                start.len(),
                cell.name,
                declared.param_count()
            )))
        }
        None => phase(observer, "fitting the frames first", || {
            frames_first_start(&declared, train, noise, opts)
        })?,
    };
    for &(i, _) in left_out {
        at[i] = declared.registry.get(i).nominal;
    }
    let start = at.clone();
    let mut decided = phase(observer, "choosing the identifiable parameters", || {
        decide(&at, &dropped)
    })?;
    loop {
        let (model, reasons, weak) = decided;
        let mut problem = Problem::new(&model, train, noise)?;
        let (mut solution, mut outliers, mut robust_scale) =
            solve(&mut problem, &at, opts, observer)?;
        // A refit from the previous fit (a term dropped at its nominal, or the free set
        // grown) can walk a nearly degenerate valley into another robot: an angle of the
        // robot 90°+ from its drawing (fit_checks::FarFromDrawing). It is fitted again from
        // the frames-first start with the dropped terms at nominal; the lower cost wins.
        // (Motoman left non-geometric cell, seed 9: the refit after the first dropped term
        // ended with b2.theta 149.6° from nominal, smr1.z −878 mm, ½χ² 150.47.)
        if at != start && leaves_drawing(&model, &solution.params) {
            let mut again = start.clone();
            for &(i, _) in &dropped {
                again[i] = declared.registry.get(i).nominal;
            }
            let mut retry = Problem::new(&model, train, noise)?;
            let fit = solve(&mut retry, &again, opts, observer)?;
            if fit.0.cost() < solution.cost() {
                (solution, outliers, robust_scale) = fit;
                problem = retry;
            }
        }
        let row_weights = problem.row_weights.clone();
        let inseparable = generic
            .as_ref()
            .and_then(|_| least_separable(&model, &problem, &solution));
        drop(problem);
        let recheck = phase(
            observer,
            "checking the identifiable parameters at the fit",
            || decide(&solution.params, &dropped),
        )?;
        let grew = recheck.0.registry.free().len() > model.registry.free().len();
        if let (false, Some((i, why))) = (grew, inseparable) {
            at = solution.params;
            at[i] = declared.registry.get(i).nominal;
            dropped.push((i, why));
            decided = phase(observer, "dropping a term that is not separable", || {
                decide(&at, &dropped)
            })?;
            continue;
        }
        if !grew {
            return Ok(FreeSetFit {
                model,
                reasons,
                weak,
                row_weights,
                solution,
                outliers,
                robust_scale,
            });
        }
        at = solution.params;
        decided = recheck;
    }
}

/// The free non-geometric term of a fit that the gate finds least separable
/// ([`nongeometric_gate`]: smallest unabsorbed share; of equal ones the last in the
/// registry, a periodic term before a compliance), with the reason it is dropped; `None`
/// when every term is separable (or the covariance cannot be formed).
fn least_separable(
    model: &Model,
    problem: &Problem,
    solution: &SolverResult,
) -> Option<(usize, String)> {
    if !problem.free.iter().any(|&i| model.is_joint_correction(i)) {
        return None;
    }
    let names = problem.free_names();
    let unc =
        uncertainty::parameter_uncertainty(&solution.jacobian, &solution.residual, &names).ok()?;
    let data_rows = solution.jacobian.nrows() - problem.prior_rows.nrows();
    let gate = nongeometric_gate::nongeometric_gate(
        model,
        &problem.free,
        &solution.jacobian.rows(0, data_rows).into_owned(),
        &unc.covariance,
        &solution.params,
    );
    let worst = gate
        .iter()
        .filter(|v| !v.separable)
        .rev()
        .min_by(|a, b| a.unabsorbed.total_cmp(&b.unabsorbed))?;
    let i = model.registry.index_of(&worst.name)?;
    Some((i, worst.reason()))
}

/// Whether `params` of `model` put an angle of the robot 90°+ from its drawing with no
/// exactly equivalent set nearer ([`super::fit_checks::robot_far_angles`]).
fn leaves_drawing(model: &Model, params: &[f64]) -> bool {
    let far = crate::model::branch::nearest_branch(model, params).far;
    !super::fit_checks::robot_far_angles(model, &far).is_empty()
}
