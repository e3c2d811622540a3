//! Which non-geometric terms a fit keeps (issue 14 item 3, `identify --nongeometric`): the
//! kinematic model alone, with the cell's compliance, with its periodic joint errors, or with
//! both — chosen by the user, or by k-fold cross-validation on the training data.
//!
//! # Cross-validation
//! The training configurations are shuffled (seeded) and dealt into `k` folds. Each
//! candidate is first fitted on all the training configurations exactly as the final fit
//! (frames first, the identifiable set, the gate's drops): that decides its free set once.
//! It is then fitted `k` times with that free set, on all folds but one, each fit started
//! from the all-training fit (the folds run in parallel), and predicts the held-out fold; its
//! score is the RMS of the position errors of every held-out measurement over all folds,
//! with the standard error of the per-fold RMS values.
//!
//! Deciding the free set once, rather than in every fold, is what makes the choice cheap
//! enough to run on every fit (one analysis and one sequence of gate refits per candidate
//! instead of `k`; Motoman right arm, 141 training configurations, 5 folds: 3.2 s → see
//! the benchmark table). The fold does see its held-out rows in that decision, but the
//! decision is about which parameters the configurations separate — a property of the
//! poses that a fold of 4/5 of them shares with the whole — not about how well they fit. The choice is the candidate with the smallest
//! score — unless a candidate with fewer terms scores within one standard error of it (the
//! one-standard-error rule of Hastie, Tibshirani & Friedman, *The Elements of Statistical
//! Learning*, §7.10): a term has to buy more than the noise of its own score to be kept, so
//! nothing overfits silently. The test split is never seen.

use super::free_set::fit_free_set;
use super::{solve, IdentifySettings, Problem};
use crate::accuracy::ErrorStats;
use crate::cell::Cell;
use crate::measure::{Dataset, NoiseModel};
use crate::model::{Model, Unit};
use crate::progress::{Observer, Silent};
use crate::Error;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// A set of non-geometric terms a fit keeps.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Candidate {
    /// No non-geometric term: the kinematic model.
    Kinematic,
    /// The cell's compliance terms.
    Compliance,
    /// The cell's periodic joint errors.
    Periodic,
    /// Both.
    Both,
}

/// What [`super::identify`] does with the cell's non-geometric terms.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NonGeometric {
    /// Keep every term the cell declares (the gate still drops what is not separable).
    #[default]
    AsCell,
    /// Keep only this candidate's terms.
    Only(Candidate),
    /// Choose the candidate by cross-validation with this many folds (≥ 2).
    Auto {
        /// Number of folds.
        folds: usize,
    },
}

impl Candidate {
    /// `none`/`kinematic`, `compliance`, `periodic` or `both`; `None` for another name.
    pub fn from_name(s: &str) -> Option<Candidate> {
        match s {
            "none" | "kinematic" => Some(Candidate::Kinematic),
            "compliance" => Some(Candidate::Compliance),
            "periodic" => Some(Candidate::Periodic),
            "both" => Some(Candidate::Both),
            _ => None,
        }
    }

    /// The candidate in words, for a table.
    pub fn words(self) -> &'static str {
        match self {
            Candidate::Kinematic => "kinematic",
            Candidate::Compliance => "+ compliance",
            Candidate::Periodic => "+ periodic",
            Candidate::Both => "+ compliance + periodic",
        }
    }

    /// The candidates `model` offers, simplest first: kinematic, then each kind of term it
    /// has, then both when it has both.
    pub fn offered(model: &Model) -> Vec<Candidate> {
        let (c, p) = kinds(model);
        let mut out = vec![Candidate::Kinematic];
        out.extend(c.then_some(Candidate::Compliance));
        out.extend(p.then_some(Candidate::Periodic));
        out.extend((c && p).then_some(Candidate::Both));
        out
    }

    /// The terms of `model` this candidate leaves out, each with its reason; an error if the
    /// candidate keeps a kind of term the cell does not declare.
    pub fn left_out(self, model: &Model) -> Result<Vec<(usize, String)>, Error> {
        if !Candidate::offered(model).contains(&self) {
            return Err(Error::Input(format!(
                "`{}`: the cell declares no such terms ([parameters] compliance / periodic)",
                self.words()
            )));
        }
        let (keep_c, keep_p) = match self {
            Candidate::Kinematic => (false, false),
            Candidate::Compliance => (true, false),
            Candidate::Periodic => (false, true),
            Candidate::Both => (true, true),
        };
        Ok(model
            .joint_corrections()
            .map(|(i, _)| i)
            .filter(|&i| match model.registry.get(i).unit {
                Unit::RadPerMm | Unit::RadPerNmm => !keep_c,
                _ => !keep_p,
            })
            .map(|i| {
                let name = &model.registry.get(i).name;
                (
                    i,
                    format!(
                        "`{name}` left out: the non-geometric model is `{}`",
                        self.words()
                    ),
                )
            })
            .collect())
    }
}

/// Whether `model` has compliance terms and periodic terms.
fn kinds(model: &Model) -> (bool, bool) {
    (model.compliance.is_some(), !model.periodic.is_empty())
}

/// One candidate's cross-validated score.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CandidateScore {
    /// The candidate.
    pub candidate: Candidate,
    /// Non-geometric terms the candidate declares (a fold's fit may drop some: the
    /// identifiable set, the gate).
    pub terms: usize,
    /// Position errors (mm) of every held-out measurement over all folds.
    pub held_out: ErrorStats,
    /// RMS (mm) of each fold.
    pub fold_rms: Vec<f64>,
    /// Standard error of the mean of the per-fold RMS (mm).
    pub standard_error: f64,
}

/// The cross-validation of [`NonGeometric::Auto`], recorded in the estimate.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct NonGeometricChoice {
    /// Number of folds.
    pub folds: usize,
    /// Training configurations dealt into the folds.
    pub configurations: usize,
    /// Every candidate's score, simplest first.
    pub candidates: Vec<CandidateScore>,
    /// The candidate chosen.
    pub chosen: Candidate,
    /// The rule, in words.
    pub rule: String,
}

/// Cross-validates every candidate the cell offers on `train` with `folds` folds (seeded by
/// `opts.seed`) and chooses one (see the module notes).
pub(super) fn choose(
    cell: &Cell,
    train: &Dataset,
    noise: &NoiseModel,
    opts: &IdentifySettings,
    folds: usize,
    observer: &mut dyn Observer,
) -> Result<NonGeometricChoice, Error> {
    let inner = IdentifySettings {
        holdout: 0.0,
        test: None,
        start: None,
        ..opts.clone()
    };
    let offered = Candidate::offered(&cell.model);
    let folds_of = deal_folds(train, folds, opts.seed)?;
    cross_validate(
        &offered,
        &folds_of,
        train.configurations.len(),
        |candidate| {
            let left_out = candidate.left_out(&cell.model)?;
            let whole = fit_free_set(cell, train, noise, &inner, &left_out, &mut Silent)?;
            Ok((
                cell.model.joint_corrections().count() - left_out.len(),
                whole,
            ))
        },
        |whole, fit_data, held| {
            let mut problem = Problem::new(&whole.model, fit_data, noise)?;
            let start = &whole.solution.params;
            let (fit, _, _) = solve(&mut problem, start, &inner, &mut Silent)?;
            let eval = Problem::new(&whole.model, held, noise)?;
            Ok(eval.errors(&mut eval.workspace(), &fit.params))
        },
        observer,
    )
}

/// Cross-validates the candidates `offered` over the folds `folds_of` of `configurations`
/// training configurations and chooses one ([`scored`]): each candidate is fitted once on
/// all of them by `whole` (its term count and fit), then each fold by `fold` (the fit on
/// the fold's data, started from the whole fit; the position errors (mm) of its held-out
/// data); the candidates and their folds run in parallel.
pub(super) fn cross_validate<W: Send + Sync>(
    offered: &[Candidate],
    folds_of: &[(Dataset, Dataset)],
    configurations: usize,
    whole: impl Fn(Candidate) -> Result<(usize, W), Error> + Sync,
    fold: impl Fn(&W, &Dataset, &Dataset) -> Result<Vec<f64>, Error> + Sync,
    observer: &mut dyn Observer,
) -> Result<NonGeometricChoice, Error> {
    observer.start(
        "cross-validating the non-geometric terms",
        Some(offered.len() * folds_of.len()),
    );
    let fitted: Vec<(usize, Vec<Vec<f64>>)> = offered
        .par_iter()
        .map(|&candidate| {
            let (terms, fit) = whole(candidate)?;
            let errors = folds_of
                .par_iter()
                .map(|(fit_data, held)| fold(&fit, fit_data, held))
                .collect::<Result<_, Error>>()?;
            Ok((terms, errors))
        })
        .collect::<Result<_, Error>>()?;
    Ok(scored(offered, fitted, configurations, observer))
}

/// The `folds` folds of `train`'s configurations, each (the data fitted, the data held out):
/// the configurations shuffled (seed `seed`) and dealt in turn.
pub(super) fn deal_folds(
    train: &Dataset,
    folds: usize,
    seed: u64,
) -> Result<Vec<(Dataset, Dataset)>, Error> {
    let n = train.configurations.len();
    if folds < 2 || folds > n {
        return Err(Error::Input(format!(
            "{folds} cross-validation folds of {n} training configurations: give 2 to {n}"
        )));
    }
    let mut order: Vec<usize> = (0..n).collect();
    order.shuffle(&mut ChaCha8Rng::seed_from_u64(seed));
    Ok((0..folds)
        .map(|f| {
            let (mut fit, mut held): (Vec<usize>, Vec<usize>) = (Vec::new(), Vec::new());
            for (k, &c) in order.iter().enumerate() {
                if k % folds == f {
                    held.push(c)
                } else {
                    fit.push(c)
                }
            }
            fit.sort_unstable();
            held.sort_unstable();
            (train.subset(&fit), train.subset(&held))
        })
        .collect())
}

/// Scores each candidate of `offered` from its (term count, held-out position errors of
/// each fold) in `fitted`, and chooses one by the one-standard-error rule (module notes);
/// `configurations` were dealt into the folds. Steps `observer` once per fold (its `start`
/// is the caller's).
fn scored(
    offered: &[Candidate],
    fitted: Vec<(usize, Vec<Vec<f64>>)>,
    configurations: usize,
    observer: &mut dyn Observer,
) -> NonGeometricChoice {
    let folds = fitted.first().map_or(0, |(_, f)| f.len());
    let mut candidates = Vec::new();
    for (&candidate, (terms, fold_errors)) in offered.iter().zip(fitted) {
        let mut errors = Vec::new();
        let mut fold_rms = Vec::new();
        for e in fold_errors {
            fold_rms.push(ErrorStats::of(&e).rms);
            errors.extend(e);
            observer.step();
        }
        let mean = fold_rms.iter().sum::<f64>() / folds as f64;
        let var = fold_rms.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / (folds - 1) as f64;
        candidates.push(CandidateScore {
            candidate,
            terms,
            held_out: ErrorStats::of(&errors),
            standard_error: (var / folds as f64).sqrt(),
            fold_rms,
        });
    }
    observer.finish();
    let best = candidates
        .iter()
        .min_by(|a, b| a.held_out.rms.total_cmp(&b.held_out.rms))
        .expect("the kinematic candidate is always offered");
    let bound = best.held_out.rms + best.standard_error;
    let chosen = candidates
        .iter()
        .filter(|c| c.held_out.rms <= bound)
        .min_by_key(|c| c.terms)
        .expect("the best is within its own bound")
        .candidate;
    NonGeometricChoice {
        folds,
        configurations,
        rule: format!(
            "the candidate with the fewest terms whose cross-validated RMS is within one \
             standard error of the best ({:.4} + {:.4} mm)",
            best.held_out.rms, best.standard_error
        ),
        candidates,
        chosen,
    }
}
