//! Prior information on a model's parameters, as whitened rows: the per-parameter Gaussian
//! priors of the cell (`Status::Prior`) and a correlated Gaussian prior over named
//! parameters — an earlier calibration's estimate and covariance carried into a new fit
//! (issue 16 item 2: the campaign after a drift check starts from what the robot was).
//!
//! A Gaussian prior `p ~ N(μ, C)` adds `½ (p − μ)ᵀ C⁻¹ (p − μ) = ½ ‖L⁻¹ (p − μ)‖²` to the
//! least-squares cost (`C = L Lᵀ`, Cholesky), i.e. whitened residual rows `W p − W μ` with
//! `W = L⁻¹` (maximum a-posteriori estimation, Tarantola, *Inverse Problem Theory* 2005,
//! §3.2.2; the book's eq. 4.60 weighting with a-priori information). Over the free
//! parameters only: a parameter of the prior that a fit holds fixed is marginalised out
//! (its rows and columns of `C` dropped), and a name the model does not have is ignored.

use crate::model::registry::{Registry, Status};
use crate::Error;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// A correlated Gaussian prior over named parameters (internal units: mm, rad, …).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CorrelatedPrior {
    /// Where it comes from, in words (an estimate file).
    pub source: String,
    /// The parameters, by registry name.
    pub parameters: Vec<String>,
    /// The mean, in `parameters` order.
    pub mean: Vec<f64>,
    /// The covariance, symmetric positive definite, in `parameters` order.
    pub covariance: DMatrix<f64>,
}

impl CorrelatedPrior {
    /// Checks the shapes, finiteness and that the covariance is symmetric positive definite;
    /// the error says what is wrong.
    pub fn check(&self) -> Result<(), Error> {
        let n = self.parameters.len();
        let bad = |why: String| {
            Err(Error::Input(format!(
                "the prior from {}: {why}",
                self.source
            )))
        };
        if self.mean.len() != n || self.covariance.shape() != (n, n) {
            return bad(format!(
                "{n} parameters, {} means and a {}×{} covariance",
                self.mean.len(),
                self.covariance.nrows(),
                self.covariance.ncols()
            ));
        }
        if !self
            .mean
            .iter()
            .chain(self.covariance.iter())
            .all(|x| x.is_finite())
        {
            return bad("a mean or covariance entry is not a finite number".into());
        }
        let asymmetry = (&self.covariance - self.covariance.transpose()).abs().max();
        if asymmetry > 1e-9 * self.covariance.abs().max() {
            return bad("the covariance is not symmetric".into());
        }
        if n > 0 && self.covariance.clone().cholesky().is_none() {
            return bad("the covariance is not positive definite".into());
        }
        Ok(())
    }
}

/// The prior information of `registry` over the columns `free` (registry indices, the
/// order of the rows' columns): whitened rows `W` and offsets `W μ` such that the prior adds
/// `½ ‖W p_free − W μ‖²` to the cost (module notes). First one row `1/σ` per free parameter
/// with [`Status::Prior`] (not in the correlated prior), then `L⁻¹` of the correlated
/// prior's marginal covariance over its free parameters.
pub fn prior_rows(
    registry: &Registry,
    free: &[usize],
) -> Result<(DMatrix<f64>, DVector<f64>), Error> {
    let correlated = registry.correlated_prior();
    let in_correlated =
        |name: &str| correlated.is_some_and(|c| c.parameters.iter().any(|p| p == name));
    let mut rows: Vec<(Vec<(usize, f64)>, f64)> = Vec::new();
    for (column, &i) in free.iter().enumerate() {
        let p = registry.get(i);
        if let Status::Prior { sigma } = p.status {
            if !in_correlated(&p.name) {
                rows.push((vec![(column, 1.0 / sigma)], p.nominal / sigma));
            }
        }
    }
    if let Some(c) = correlated {
        // (index in the prior, column) of every free parameter it holds
        let kept: Vec<(usize, usize)> = c
            .parameters
            .iter()
            .enumerate()
            .filter_map(|(k, name)| {
                let i = registry.index_of(name)?;
                free.iter().position(|&f| f == i).map(|column| (k, column))
            })
            .collect();
        let m = kept.len();
        let marginal = DMatrix::from_fn(m, m, |a, b| c.covariance[(kept[a].0, kept[b].0)]);
        let mean = DVector::from_fn(m, |a, _| c.mean[kept[a].0]);
        let chol = marginal.cholesky().ok_or_else(|| {
            Error::Input(format!(
                "the prior from {}: its covariance over the free parameters is not positive definite",
                c.source
            ))
        })?;
        // W = L⁻¹: solve L W = I
        let w = chol
            .l()
            .solve_lower_triangular(&DMatrix::identity(m, m))
            .expect("a Cholesky factor has a non-zero diagonal");
        let offset = &w * mean;
        for a in 0..m {
            let terms = (0..=a).map(|b| (kept[b].1, w[(a, b)])).collect();
            rows.push((terms, offset[a]));
        }
    }
    let mut w = DMatrix::zeros(rows.len(), free.len());
    let mut offset = DVector::zeros(rows.len());
    for (r, (terms, o)) in rows.into_iter().enumerate() {
        for (column, x) in terms {
            w[(r, column)] = x;
        }
        offset[r] = o;
    }
    Ok((w, offset))
}
