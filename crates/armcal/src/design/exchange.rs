//! Candidate-pool exchange (Fedorov 1972; Mitchell's DETMAX style): start from N pool
//! configurations (a seeded random set, or one given, e.g. a greedy D-optimal selection), then repeatedly remove one design point and put back the pool
//! configuration that improves the criterion most, until no exchange helps.
//!
//! The removal is a rank-r downdate of the covariance and every candidate is scored with a
//! rank-r update (r = rows per configuration, Woodbury): for A-type criteria
//! `tr(L C' Lᵀ) = tr(L C Lᵀ) − tr((I + J C Jᵀ)⁻¹ J C LᵀL C Jᵀ)`, for D
//! `log det M' = log det M + log det(I + J C Jᵀ)`. Criteria without such an update (E, O1–O5)
//! take the best D-scored candidates and evaluate them exactly.

use crate::design::criteria::{evaluate, kpi_matrix, Criterion};
use crate::design::information::{DesignModel, InformationWorkspace};
use crate::design::objective::information_factor;
use crate::progress::Observer;
use crate::solve::Status;
use crate::Error;
use nalgebra::DMatrix;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rank_updates::SweepState;
use std::time::{Duration, Instant};

mod rank_updates;

/// Settings of [`exchange`].
#[derive(Clone, Debug)]
pub struct ExchangeSettings {
    /// Most sweeps (each removes and re-inserts every design point once) before stopping with
    /// [`Status::IterationLimit`].
    pub max_sweeps: usize,
    /// Seed of the random start: the first N pool configurations of a seeded shuffle that
    /// identify every parameter.
    pub seed: u64,
    /// Relative improvement below which a sweep counts as no progress.
    pub tolerance: f64,
    /// Candidates scored exactly per removal for criteria without a rank update.
    pub exact_shortlist: usize,
    /// The start: N distinct pool indices (`None`: the seeded random start).
    pub start: Option<Vec<usize>>,
}

impl Default for ExchangeSettings {
    fn default() -> Self {
        ExchangeSettings {
            max_sweeps: 20,
            seed: 1,
            tolerance: 1e-9,
            exact_shortlist: 12,
            start: None,
        }
    }
}

/// Result of an exchange run: indices into the pool.
#[derive(Clone, Debug)]
pub struct ExchangeResult {
    /// The design: N indices into the pool.
    pub chosen: Vec<usize>,
    /// Criterion value of the chosen design (with the prior information of measured poses).
    pub value: f64,
    /// Converged when a sweep improved the criterion by less than the tolerance, else
    /// the sweep limit ([`Status::IterationLimit`]).
    pub status: Status,
    /// Sweeps run.
    pub sweeps: usize,
    /// Design points replaced, over all sweeps.
    pub exchanges: usize,
    /// Criterion value at the start and after each sweep.
    pub history: Vec<f64>,
    /// Wall-clock time of the run.
    pub time: Duration,
}

/// Whitened Jacobians of every pool configuration, stacked (rows per configuration each).
pub fn pool_jacobians(d: &DesignModel, pool: &[Vec<f64>]) -> DMatrix<f64> {
    let rows = d.rows();
    let mut ws = InformationWorkspace::new(d);
    let mut out = DMatrix::zeros(rows * pool.len(), d.n());
    for (i, q) in pool.iter().enumerate() {
        d.jacobian(&mut ws, q);
        out.rows_mut(i * rows, rows).copy_from(&ws.jac);
    }
    out
}

/// The criterion of a set of pool points (rows of `jp`, [`pool_jacobians`]) plus prior rows.
pub(crate) fn value_of(
    d: &DesignModel,
    c: Criterion,
    jp: &DMatrix<f64>,
    prior: &DMatrix<f64>,
    set: &[usize],
) -> Result<f64, Error> {
    let rows = d.rows();
    let mut a = DMatrix::zeros(prior.nrows() + rows * set.len(), d.n());
    a.rows_mut(0, prior.nrows()).copy_from(prior);
    for (k, &i) in set.iter().enumerate() {
        a.rows_mut(prior.nrows() + k * rows, rows)
            .copy_from(&jp.rows(i * rows, rows));
    }
    Ok(evaluate(c, &information_factor(c, &a), d)?.value)
}

/// The fewest poses that can identify the `n` free parameters of `d`: each gives `d.rows()`
/// rows, and the `prior` rows of measured poses count.
pub fn minimum_poses(d: &DesignModel, prior: &DMatrix<f64>) -> usize {
    d.n().saturating_sub(prior.nrows()).div_ceil(d.rows())
}

/// Runs the exchange for `n_points` configurations from `pool` (with `prior` whitened rows of
/// already-measured configurations).
pub fn exchange(
    d: &DesignModel,
    criterion: Criterion,
    pool: &[Vec<f64>],
    prior: &DMatrix<f64>,
    n_points: usize,
    settings: &ExchangeSettings,
    observer: &mut dyn Observer,
) -> Result<ExchangeResult, Error> {
    let t0 = Instant::now();
    if pool.len() < n_points {
        return Err(Error::Input(format!(
            "the candidate pool has {} feasible configurations, fewer than the {n_points} poses asked for",
            pool.len()
        )));
    }
    let rows = d.rows();
    let n = d.n();
    // L for A-type criteria: φ = tr(L C Lᵀ). First, so that a criterion the cell cannot
    // serve (KPI without a working pose) says so rather than failing every start below.
    let l: Option<DMatrix<f64>> = match criterion {
        Criterion::A => Some(DMatrix::identity(n, n) / (n as f64).sqrt()),
        Criterion::Kpi => Some(kpi_matrix(d)?),
        _ => None,
    };
    let needed = minimum_poses(d, prior);
    if n_points < needed {
        return Err(Error::Input(format!(
            "{n_points} poses cannot identify the {n} free parameters: each pose gives {rows} \
             measurement rows{}, so at least {needed} poses are needed",
            if prior.nrows() > 0 {
                format!(" and the measured poses give {}", prior.nrows())
            } else {
                String::new()
            }
        )));
    }
    let jp = pool_jacobians(d, pool);
    // Start: the given set, or a random subset that identifies every parameter (retry a
    // few times).
    let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
    let mut idx: Vec<usize> = (0..pool.len()).collect();
    let mut chosen = Vec::new();
    let mut value = f64::INFINITY;
    let mut last_failure = None;
    if let Some(start) = &settings.start {
        let mut seen = vec![false; pool.len()];
        for &i in start {
            if i >= pool.len() || std::mem::replace(&mut seen[i], true) {
                return Err(Error::Input(format!(
                    "the exchange's start names pool configuration {i} twice or past the pool's {}",
                    pool.len()
                )));
            }
        }
        if start.len() != n_points {
            return Err(Error::Input(format!(
                "the exchange's start has {} configurations, not the {n_points} asked for",
                start.len()
            )));
        }
        chosen = start.clone();
        value = value_of(d, criterion, &jp, prior, &chosen)?;
    }
    let random_tries = if settings.start.is_some() { 0 } else { 20 };
    for _ in 0..random_tries {
        idx.shuffle(&mut rng);
        let trial: Vec<usize> = idx[..n_points].to_vec();
        match value_of(d, criterion, &jp, prior, &trial) {
            Ok(v) => {
                chosen = trial;
                value = v;
                break;
            }
            Err(e) => last_failure = Some(e),
        }
    }
    if chosen.is_empty() {
        return Err(Error::Input(format!(
            "no random set of {n_points} of the {} feasible pool configurations identifies every \
             free parameter ({}); use more poses, a larger pool, or check which parameters the \
             cell's measurements cannot identify (`armcal model`)",
            pool.len(),
            last_failure.map_or_else(|| "no start was tried".to_string(), |e| e.to_string())
        )));
    }
    let mut history = vec![value];
    let mut sweeps = 0;
    let mut exchanges = 0;
    let mut state = SweepState::new(&jp, rows, l.as_ref().map_or(0, |l| l.nrows()));
    let mut in_design = vec![false; pool.len()];
    let mut scores: Vec<(f64, usize)> = Vec::with_capacity(pool.len());
    observer.start("exchange", Some(settings.max_sweeps));
    let mut status = Status::IterationLimit;
    while sweeps < settings.max_sweeps {
        sweeps += 1;
        let start_value = value;
        // C, U, V and the Q blocks anew from the design (the rank updates below drift).
        if !state.refresh(prior, l.as_ref(), &chosen) {
            break;
        }
        for slot in 0..n_points {
            let removed = chosen[slot];
            in_design.fill(false);
            for &i in &chosen {
                in_design[i] = true;
            }
            in_design[removed] = false;
            // Covariance without the point in `slot`, by the rank-`rows` downdate.
            if !state.remove(removed) {
                continue; // this point is essential; keep it
            }
            scores.clear();
            for x in (0..pool.len()).filter(|&x| !in_design[x]) {
                if let Some(score) = state.score(x, l.is_some()) {
                    scores.push((score, x));
                }
            }
            let best = if l.is_some() || criterion == Criterion::D {
                scores
                    .iter()
                    .min_by(|p, q| p.0.total_cmp(&q.0))
                    .map(|s| s.1)
            } else {
                scores.sort_by(|p, q| p.0.total_cmp(&q.0));
                // Exact evaluation of a short list.
                let mut best = None;
                let mut best_v = f64::INFINITY;
                for &(_, x) in scores.iter().take(settings.exact_shortlist) {
                    let mut trial = chosen.clone();
                    trial[slot] = x;
                    if let Ok(v) = value_of(d, criterion, &jp, prior, &trial) {
                        if v < best_v {
                            best_v = v;
                            best = Some(x);
                        }
                    }
                }
                best
            };
            let Some(x) = best.filter(|&x| x != removed) else {
                continue;
            };
            let mut trial = chosen.clone();
            trial[slot] = x;
            if let Ok(v) = value_of(d, criterion, &jp, prior, &trial) {
                if v < value - 1e-15 * value.abs() && state.replace(x) {
                    chosen = trial;
                    value = v;
                    exchanges += 1;
                }
            }
        }
        history.push(value);
        observer.iteration(sweeps, value, 0.0);
        if start_value - value <= settings.tolerance * value.abs() {
            status = Status::Converged {
                criterion: format!(
                    "a sweep improved the criterion by less than {:e}",
                    settings.tolerance
                ),
            };
            break;
        }
    }
    observer.finish();
    Ok(ExchangeResult {
        chosen,
        value,
        status,
        sweeps,
        exchanges,
        history,
        time: t0.elapsed(),
    })
}
