//! Robust estimation by iteratively reweighted least squares (IRLS): each measurement
//! block gets a weight from its standardised residual `e = ‖r_i‖ / (s √rows)` with a robust
//! scale `s = 1.4826 · median(e)` (MAD), Huber `w = min(1, k/e)` (k = 1.345) or Cauchy
//! `w = 1/(1 + (e/c)²)` (c = 2.385); Levenberg–Marquardt with fixed weights; repeat until
//! the weights settle. Blocks whose `‖r_i‖²/s²` exceeds the χ²(rows) 99.9 % quantile are
//! reported as outliers. The solution's residual and Jacobian are then those of the kept
//! measurements, unweighted (outlier rows removed): the variance factor and χ² test of a
//! robust fit are computed on the data it kept, with m − n = kept rows − free parameters.

use super::lm::{minimise, LmSettings};
use super::problem::Problem;
use super::solver::{LeastSquares, SolverResult};
use crate::progress::Observer;
use crate::Error;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// Robust loss.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Loss {
    /// Huber: `w = min(1, k/e)`, k = 1.345.
    Huber,
    /// Cauchy: `w = 1/(1 + (e/c)²)`, c = 2.385.
    Cauchy,
}

impl Loss {
    /// The loss in words, for output: `Huber`, `Cauchy`.
    pub fn words(self) -> &'static str {
        match self {
            Loss::Huber => "Huber",
            Loss::Cauchy => "Cauchy",
        }
    }

    /// The loss named `huber` or `cauchy`; `None` for another name.
    pub fn from_name(s: &str) -> Option<Loss> {
        match s {
            "huber" => Some(Loss::Huber),
            "cauchy" => Some(Loss::Cauchy),
            _ => None,
        }
    }

    fn weight(self, e: f64) -> f64 {
        match self {
            Loss::Huber => {
                let k = 1.345;
                if e <= k {
                    1.0
                } else {
                    k / e
                }
            }
            Loss::Cauchy => {
                let c = 2.385;
                1.0 / (1.0 + (e / c).powi(2))
            }
        }
    }
}

/// A measurement judged an outlier.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Outlier {
    /// Index of the measurement in the dataset.
    pub measurement: usize,
    /// Data-file line (0 for synthetic data).
    pub line: usize,
    /// `pose_id` of the measurement's configuration.
    pub configuration: String,
    /// ‖r_i‖ / s: the whitened residual norm in robust-scale units.
    pub standardized: f64,
    /// Final IRLS weight.
    pub weight: f64,
}

/// Result of [`robust_fit`].
pub struct RobustResult {
    /// The final fit; its residual and Jacobian are those of the kept measurements with
    /// weight 1 (the rows of the outliers removed, prior rows kept).
    pub solution: SolverResult,
    /// Measurements whose `‖r_i‖²/s²` exceeds the χ²(rows) 99.9 % quantile.
    pub outliers: Vec<Outlier>,
    /// Robust scale of the whitened residuals at the end (≈ 1 if σ is right).
    pub scale: f64,
    /// Number of reweightings done (at most 30).
    pub reweightings: usize,
}

/// IRLS around Levenberg–Marquardt. `problem.row_weights` is overwritten.
pub fn robust_fit(
    problem: &mut Problem,
    start: &[f64],
    loss: Loss,
    settings: &LmSettings,
    observer: &mut dyn Observer,
) -> Result<RobustResult, Error> {
    robust_minimise(problem, start, loss, settings, observer)
}

/// [`robust_fit`] of any least-squares problem (a serial chain's or a tree's).
pub(crate) fn robust_minimise<P: LeastSquares>(
    problem: &mut P,
    start: &[f64],
    loss: Loss,
    settings: &LmSettings,
    observer: &mut dyn Observer,
) -> Result<RobustResult, Error> {
    let blocks = problem.blocks();
    problem.row_weights_mut().fill(1.0);
    observer.start("robust reweighting", None);
    let mut sol = minimise(problem, start, settings, observer)?;
    let mut scale = 1.0;
    let mut reweightings = 0;
    let norms = |sol: &SolverResult, problem: &mut P| -> Vec<f64> {
        // Undo the weights to get the plain whitened residual of each block.
        blocks
            .iter()
            .map(|&(row, k)| {
                (0..k)
                    .map(|i| {
                        let w = problem.row_weights_mut()[row + i];
                        if w > 0.0 {
                            (sol.residual[row + i] / w.sqrt()).powi(2)
                        } else {
                            0.0
                        }
                    })
                    .sum::<f64>()
                    .sqrt()
            })
            .collect()
    };
    for _ in 0..30 {
        let e = norms(&sol, problem);
        let mut per_row: Vec<f64> = e
            .iter()
            .zip(&blocks)
            .map(|(n, &(_, k))| n / (k as f64).sqrt())
            .collect();
        per_row.sort_by(f64::total_cmp);
        scale = (1.4826 * per_row[per_row.len() / 2]).max(1e-12);
        let mut change: f64 = 0.0;
        for (b, &(row, k)) in blocks.iter().enumerate() {
            let w = loss.weight(e[b] / (k as f64).sqrt() / scale);
            for i in 0..k {
                let weights = problem.row_weights_mut();
                change = change.max((weights[row + i] - w).abs());
                weights[row + i] = w;
            }
        }
        reweightings += 1;
        sol = minimise(problem, &sol.params, settings, observer)?;
        if change < 1e-4 {
            break;
        }
    }
    let e = norms(&sol, problem);
    let mut outliers = Vec::new();
    for (b, &(row, k)) in blocks.iter().enumerate() {
        let limit = ChiSquared::new(k as f64)
            .map(|d| d.inverse_cdf(0.999))
            .unwrap_or(f64::INFINITY);
        let z = e[b] / scale;
        if z * z > limit {
            let weight = problem.row_weights_mut()[row];
            let data = problem.dataset();
            let m = &data.measurements[b];
            outliers.push(Outlier {
                measurement: b,
                line: m.line,
                configuration: data.config_ids[m.config].clone(),
                standardized: z,
                weight,
            });
        }
    }
    (sol.residual, sol.jacobian) = kept_rows(problem, &sol.params, &outliers);
    observer.finish();
    Ok(RobustResult {
        solution: sol,
        outliers,
        scale,
        reweightings,
    })
}

/// Unweighted whitened residual and Jacobian at `params` without the rows of `outliers`.
pub(crate) fn kept_rows<P: LeastSquares>(
    problem: &mut P,
    params: &[f64],
    outliers: &[Outlier],
) -> (DVector<f64>, DMatrix<f64>) {
    let ones = vec![1.0; problem.data_rows()];
    let weights = std::mem::replace(problem.row_weights_mut(), ones);
    let (r, j) = problem.residual_and_jacobian_at(params);
    *problem.row_weights_mut() = weights;
    let blocks = problem.blocks();
    let mut dropped = vec![false; problem.rows()];
    for o in outliers {
        let (row, k) = blocks[o.measurement];
        dropped[row..row + k].fill(true);
    }
    let keep: Vec<usize> = (0..problem.rows()).filter(|&i| !dropped[i]).collect();
    (r.select_rows(&keep), j.select_rows(&keep))
}
