//! Baseline designs: uniform random feasible configurations (the paper's heuristic, §3.3)
//! and the book's observation strategies 1–4 (book §4.5.2, Table 4.6): 1 moves every joint
//! by constant increments simultaneously; 2 moves one joint at a time with the others at
//! mid-range; 3 holds one joint at mid-range and moves the others simultaneously; 4 is
//! uniform random (Monte Carlo). And the reference for choosing N poses of a candidate
//! pool: the greedy D-optimal selection followed by the Fedorov exchange.

use crate::design::exchange::{exchange, pool_jacobians, ExchangeResult, ExchangeSettings};
use crate::design::information::DesignModel;
use crate::design::selection::{greedy_d, SelectionSettings};
use crate::design::Criterion;
use crate::model::Model;
use crate::progress::Observer;
use crate::Error;
use nalgebra::DMatrix;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The book's observation strategies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Strategy {
    /// Strategy 1: every joint swept from its lower to its upper limit in equal increments, all
    /// simultaneously.
    S1,
    /// Strategy 2: one joint swept at a time, the others at mid-range.
    S2,
    /// Strategy 3: one joint held at mid-range at a time, the others swept simultaneously.
    S3,
    /// Strategy 4: uniform random configurations within the joint limits (Monte Carlo, seeded).
    S4,
}

/// `n` configurations by a book strategy (no feasibility filter; S4 is seeded).
pub fn strategy(model: &Model, s: Strategy, n: usize, seed: u64) -> Vec<Vec<f64>> {
    let (lo, hi) = model.joint_limits();
    let k = lo.len();
    let mid: Vec<f64> = lo.iter().zip(&hi).map(|(a, b)| 0.5 * (a + b)).collect();
    let sweep = |j: usize, t: f64| lo[j] + t * (hi[j] - lo[j]);
    let frac = |i: usize, m: usize| {
        if m <= 1 {
            0.5
        } else {
            i as f64 / (m - 1) as f64
        }
    };
    match s {
        Strategy::S1 => (0..n)
            .map(|i| (0..k).map(|j| sweep(j, frac(i, n))).collect())
            .collect(),
        Strategy::S2 | Strategy::S3 => {
            let per = n.div_ceil(k);
            let mut out = Vec::with_capacity(n);
            for j in 0..k {
                for i in 0..per {
                    if out.len() == n {
                        break;
                    }
                    let t = frac(i, per);
                    let q: Vec<f64> = (0..k)
                        .map(|l| match (s, l == j) {
                            (Strategy::S2, true) | (Strategy::S3, false) => sweep(l, t),
                            _ => mid[l],
                        })
                        .collect();
                    out.push(q);
                }
            }
            out
        }
        Strategy::S4 => crate::model::random_configurations(model, n, seed),
    }
}

/// `n` uniform random configurations within the joint limits that pass `feasible` (the
/// paper's heuristic: unmeasurable draws do not count). Returns the configurations and the
/// number of draws; an error if fewer than `n` are found in `max_draws`.
pub fn random_feasible(
    model: &Model,
    n: usize,
    seed: u64,
    max_draws: usize,
    mut feasible: impl FnMut(&[f64]) -> bool,
) -> Result<(Vec<Vec<f64>>, usize), Error> {
    let (lo, hi) = model.joint_limits();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = Vec::with_capacity(n);
    let mut draws = 0;
    while out.len() < n && draws < max_draws {
        draws += 1;
        let q: Vec<f64> = lo
            .iter()
            .zip(&hi)
            .map(|(a, b)| if b > a { rng.random_range(*a..*b) } else { *a })
            .collect();
        if feasible(&q) {
            out.push(q);
        }
    }
    if out.len() < n {
        return Err(Error::Input(format!(
            "only {} of {draws} random configurations are feasible; {n} were asked for (the constraints may be too tight: check the tracker position, obstacles and incidence limit)",
            out.len()
        )));
    }
    Ok((out, draws))
}

/// The textbook way to choose `n_points` of `pool` for `criterion` (with `prior` whitened
/// rows of measured poses): the greedy D-optimal selection ([`greedy_d`]), then the Fedorov
/// exchange on `criterion` from it ([`exchange`], which recomputes the covariance for every
/// design point it removes). The benchmark's reference for
/// [`select_d`](crate::design::selection::select_d).
pub fn greedy_then_exchange(
    d: &DesignModel,
    criterion: Criterion,
    pool: &[Vec<f64>],
    prior: &DMatrix<f64>,
    n_points: usize,
    observer: &mut dyn Observer,
) -> Result<ExchangeResult, Error> {
    let start = greedy_d(
        &pool_jacobians(d, pool),
        d.rows(),
        prior,
        n_points,
        SelectionSettings::default().regularisation,
    )?;
    exchange(
        d,
        criterion,
        pool,
        prior,
        n_points,
        &ExchangeSettings {
            start: Some(start),
            ..ExchangeSettings::default()
        },
        observer,
    )
}
