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
                    model.registry.set_status(*i, ParameterStatus::Fixed);
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
        if let (false, Some(term)) = (grew, inseparable) {
            at =
                term.conditional_start(&solution.params, declared.registry.get(term.index).nominal);
            dropped.push((term.index, term.reason));
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

/// A non-geometric term the fit drops ([`least_separable`]).
struct DroppedTerm {
    /// Its registry index.
    index: usize,
    /// Why it is dropped (the gate's words).
    reason: String,
    /// `(registry index, C_oi / C_ii)` of every other free parameter `o` of the fit: how
    /// far `o` moves per unit the term moves with the others re-fitted to first order.
    absorb: Vec<(usize, f64)>,
}

impl DroppedTerm {
    /// The start of the refit without the term: the fit `params` with the term at
    /// `nominal` and every other free parameter moved by what re-fitting absorbs of the
    /// change, `x_o + C_oi / C_ii (nominal − x_i)`. This is the minimum of the linearised
    /// cost `½‖r + J δ‖²` under the constraint `δ_i = nominal − x_i` at a minimum of the
    /// fit (where `Jᵀr = 0`; Lagrange: `δ = C e_i (nominal − x_i) / C_ii` with
    /// `C = (JᵀJ)⁻¹`), the conditional mean of the other parameters given the term in the
    /// Gaussian of the estimate (book §4.3's covariance). A term the gate drops is nearly a
    /// combination of the others, so the others take over most of its effect and the refit
    /// starts near its minimum. Setting the term to nominal alone threw the Motoman left
    /// non-geometric fit (seed 9) from ½χ² 114 to 2.7·10⁹, and its refit walked a
    /// degenerate valley for 182 iterations into another robot; from this start the refit
    /// takes 6 (`real_data::solver_convergence`).
    fn conditional_start(&self, params: &[f64], nominal: f64) -> Vec<f64> {
        let mut at = params.to_vec();
        let gap = nominal - at[self.index];
        for &(o, ratio) in &self.absorb {
            at[o] += ratio * gap;
        }
        at[self.index] = nominal;
        at
    }
}

/// The free non-geometric term of a fit that the gate finds least separable
/// ([`nongeometric_gate`]: smallest unabsorbed share; of equal ones the last in the
/// registry, a periodic term before a compliance), with the reason it is dropped and how
/// the others absorb it; `None` when every term is separable (or the covariance cannot be
/// formed).
fn least_separable(
    model: &Model,
    problem: &Problem,
    solution: &SolverResult,
) -> Option<DroppedTerm> {
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
    let index = model.registry.index_of(&worst.name)?;
    let k = problem.free.iter().position(|&f| f == index)?;
    let c = &unc.covariance;
    let absorb = problem
        .free
        .iter()
        .enumerate()
        .filter(|&(o, _)| o != k)
        .map(|(o, &f)| (f, c[(o, k)] / c[(k, k)]))
        .collect();
    Some(DroppedTerm {
        index,
        reason: worst.reason(),
        absorb,
    })
}

/// Whether `params` of `model` put an angle of the robot 90°+ from its drawing with no
/// exactly equivalent set nearer ([`super::fit_checks::robot_far_angles`]).
fn leaves_drawing(model: &Model, params: &[f64]) -> bool {
    let far = crate::model::branch::nearest_branch(model, params).far;
    !super::fit_checks::robot_far_angles(model, &far).is_empty()
}

#[cfg(test)]
mod tests {
    use super::DroppedTerm;
    use nalgebra::{DMatrix, DVector};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// On a linear least-squares problem the conditional start is the exact fit with the
    /// term held at its new value: the least-squares solution of the other columns.
    #[test]
    fn the_conditional_start_is_the_fit_with_the_term_held() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let (m, n, i) = (12, 4, 2);
        let mut j = DMatrix::from_fn(m, n, |_, _| rng.random_range(-1.0..1.0));
        // nearly inseparable: column i is almost a combination of columns 0 and 1
        let mix = j.column(0) * 0.7 - j.column(1) * 0.4;
        j.set_column(
            i,
            &(mix + DMatrix::from_fn(m, 1, |_, _| rng.random_range(-0.05..0.05))),
        );
        let y = DVector::from_fn(m, |_, _| rng.random_range(-1.0..1.0));
        let c = (j.transpose() * &j).try_inverse().unwrap();
        let fit = &c * j.transpose() * &y;
        let term = DroppedTerm {
            index: i,
            reason: String::new(),
            absorb: (0..n)
                .filter(|&o| o != i)
                .map(|o| (o, c[(o, i)] / c[(i, i)]))
                .collect(),
        };
        let held = 0.3;
        let start = term.conditional_start(fit.as_slice(), held);
        let others: Vec<usize> = (0..n).filter(|&o| o != i).collect();
        let jo = j.select_columns(&others);
        let rest = (jo.transpose() * &jo).try_inverse().unwrap()
            * jo.transpose()
            * (&y - j.column(i) * held);
        assert_eq!(start[i], held);
        for (k, &o) in others.iter().enumerate() {
            assert!(
                (start[o] - rest[k]).abs() < 1e-9,
                "{o}: {} {}",
                start[o],
                rest[k]
            );
        }
        // the term alone at its new value (the others kept) fits far worse
        let cost = |x: &[f64]| (&j * DVector::from_column_slice(x) - &y).norm_squared();
        let mut alone = fit.as_slice().to_vec();
        alone[i] = held;
        assert!(cost(&start) < 0.5 * cost(&alone));
    }
}
