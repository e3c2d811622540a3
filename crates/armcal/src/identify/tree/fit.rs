//! A tree fitted with its non-geometric model ([`fit_tree_free_set`]: the identifiable set,
//! the solver, the compliance gate) and the cross-validated choice of that model
//! ([`choose_tree`], `--nongeometric auto`).

use super::{check_determined, identifiable_at, TreeProblem};
use crate::cell::tree::TreeCell;
use crate::identify::lm::minimise;
use crate::identify::nongeometric_choice::{cross_validate, deal_folds};
use crate::identify::nongeometric_gate::{gate, TermVerdict};
use crate::identify::robust::{robust_minimise, Outlier};
use crate::identify::solver::SolverResult;
use crate::identify::uncertainty::parameter_uncertainty;
use crate::identify::{Candidate, IdentifySettings, Method, NonGeometricChoice};
use crate::measure::Dataset;
use crate::model::identifiability::{Identifiability, Measurement};
use crate::progress::{Observer, Silent};
use crate::Error;

/// A tree fitted with its identifiable set and gated compliance ([`fit_tree_free_set`]).
pub(super) struct TreeFit<'a> {
    /// The problem at the free set.
    pub(super) problem: TreeProblem<'a>,
    /// The solver's result.
    pub(super) solution: SolverResult,
    /// A robust fit's outliers.
    pub(super) outliers: Vec<Outlier>,
    /// The identifiability analysis that decided the free set.
    pub(super) report: Identifiability,
    /// The gate's verdict on each compliance term fitted.
    pub(super) verdicts: Vec<TermVerdict>,
    /// The compliance terms the gate dropped, with their reasons.
    pub(super) dropped: Vec<(usize, String)>,
}

/// Fits `cell`'s tree to `train` from `start` (the frames-first fit): its identifiable set
/// at the data's rows (without the compliance terms when `rigid`), by the settings' solver,
/// the set decided again at the fit and the tree refitted from there when the fit's
/// covariance is singular (the fit left the geometry the set was decided at; a serial fit
/// decides its set at the fit alike, [`crate::identify::free_set`]); while a compliance term is not separable
/// ([`gate`]) the least separable is dropped, its reason kept, and the tree fitted again.
pub(super) fn fit_tree_free_set<'a>(
    cell: &'a TreeCell,
    train: &'a Dataset,
    start: &[f64],
    measurement: Measurement,
    rigid: bool,
    opts: &IdentifySettings,
    observer: &mut dyn Observer,
) -> Result<TreeFit<'a>, Error> {
    let tree = &cell.tree;
    let lm = &opts.lm;
    let is_kappa = |i: usize| {
        tree.compliance.as_ref().is_some_and(|c| {
            c.terms.iter().any(|t| t.param == i) || c.bending.iter().any(|t| t.param == i)
        })
    };
    let mut dropped: Vec<(usize, String)> = Vec::new();
    // where the free set is decided and the fit starts: the frames-first fit, then, once
    // per gate step, the fit itself when its identifiable set differs from the start's
    let mut at = start.to_vec();
    let mut rechecked = false;
    loop {
        let candidates = |i: usize| {
            tree.registry.get(i).status.is_free()
                && !(is_kappa(i) && (rigid || dropped.iter().any(|d| d.0 == i)))
        };
        let (free, report) = identifiable_at(tree, &at, train, measurement, candidates)?;
        let mut problem = TreeProblem::new(tree, train, &cell.noise, free)?;
        check_determined(&problem)?;
        let (sol, outliers) = match opts.robust {
            Some(loss) => {
                let r = robust_minimise(&mut problem, &at, loss, lm, observer)?;
                (r.solution, r.outliers)
            }
            None => {
                let s = match opts.method {
                    Method::GaussNewton => crate::identify::gauss_newton::minimise(
                        &problem,
                        &at,
                        &lm.tolerances,
                        observer,
                    )?,
                    _ => minimise(&problem, &at, lm, observer)?,
                };
                (s, Vec::new())
            }
        };
        // the fit may leave the geometry the set was decided at, so that two of its
        // parameters move the measurements alike there (a compliant tree's κ move it): then
        // the set is decided again at the fit and the tree refitted from there
        let unc = match parameter_uncertainty(&sol.jacobian, &sol.residual, &problem.free_names()) {
            Ok(unc) => unc,
            Err(e) if !rechecked => {
                rechecked = true;
                let (at_fit, _) =
                    identifiable_at(tree, &sol.params, train, measurement, candidates)?;
                if at_fit == problem.free {
                    return Err(e);
                }
                at = sol.params.clone();
                continue;
            }
            Err(e) => return Err(e),
        };
        let verdicts = gate(
            &tree.registry,
            is_kappa,
            &problem.free,
            &sol.jacobian,
            &unc.covariance,
            &sol.params,
        );
        let worst = verdicts
            .iter()
            .filter(|v| !v.separable)
            .rev()
            .min_by(|a, b| a.unabsorbed.total_cmp(&b.unabsorbed));
        match worst {
            Some(v) => {
                dropped.push((tree.registry.require(&v.name)?, v.reason()));
                at = start.to_vec();
                rechecked = false;
            }
            None => {
                return Ok(TreeFit {
                    problem,
                    solution: sol,
                    outliers,
                    report,
                    verdicts,
                    dropped,
                })
            }
        }
    }
}

/// `--nongeometric auto` on a tree: the kinematic tree and, when the cell declares joint
/// compliance or bending, the compliant one (every term of both kinds), cross-validated on `train` with `folds` folds as a serial
/// fit's candidates are ([`super::nongeometric_choice`]: each candidate's free set decided
/// once on all of `train`, its folds fitted from that fit, the one-standard-error rule).
pub(super) fn choose_tree(
    cell: &TreeCell,
    train: &Dataset,
    start: &[f64],
    measurement: Measurement,
    opts: &IdentifySettings,
    folds: usize,
    observer: &mut dyn Observer,
) -> Result<NonGeometricChoice, Error> {
    let tree = &cell.tree;
    let terms = tree
        .compliance
        .as_ref()
        .map_or(0, |c| c.terms.len() + c.bending.len());
    let mut offered = vec![Candidate::Kinematic];
    offered.extend((terms > 0).then_some(Candidate::Compliance));
    let inner = IdentifySettings {
        holdout: 0.0,
        test: None,
        ..opts.clone()
    };
    cross_validate(
        &offered,
        &deal_folds(train, folds, opts.seed)?,
        train.configurations.len(),
        |candidate| {
            let rigid = candidate == Candidate::Kinematic;
            let whole =
                fit_tree_free_set(cell, train, start, measurement, rigid, &inner, &mut Silent)?;
            Ok((if rigid { 0 } else { terms }, whole))
        },
        |whole, fit_data, held| {
            let free = whole.problem.free.clone();
            let problem = TreeProblem::new(tree, fit_data, &cell.noise, free)?;
            let fit = minimise(&problem, &whole.solution.params, &inner.lm, &mut Silent)?;
            let eval = TreeProblem::new(tree, held, &cell.noise, Vec::new())?;
            Ok(eval.position_errors(&fit.params))
        },
        observer,
    )
}
