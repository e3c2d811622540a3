//! Prior information on a model's parameters, as whitened rows: the per-parameter Gaussian
//! priors of the cell (`ParameterStatus::Prior`) and a correlated Gaussian prior over named
//! parameters — an earlier calibration's estimate and covariance carried into a new fit
//! (issue 16 item 2: the campaign after a drift check starts from what the robot was).
//!
//! A Gaussian prior `p ~ N(μ, C)` adds `½ (p − μ)ᵀ C⁻¹ (p − μ) = ½ ‖L⁻¹ (p − μ)‖²` to the
//! least-squares cost (`C = L Lᵀ`, Cholesky), i.e. whitened residual rows `W p − W μ` with
//! `W = L⁻¹` (maximum a-posteriori estimation, Tarantola, *Inverse Problem Theory* 2005,
//! §3.2.2; the book's eq. 4.60 weighting with a-priori information). Over the free
//! parameters only: a parameter of the prior that a fit holds fixed is marginalised out
//! (its rows and columns of `C` dropped), and a name the model does not have is ignored.

use crate::model::registry::{Parameter, ParameterStatus, Registry, Unit};
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

/// Default σ of a fixed length (mm): a link length or frame offset known from a drawing or
/// CAD. The same as the simulation's default truth perturbation
/// ([`crate::sim::Perturbation`]), so a simulated robot lies within what its cell states.
pub const FIXED_LENGTH_SIGMA_MM: f64 = 0.5;
/// Default σ of a fixed angle (deg), as [`FIXED_LENGTH_SIGMA_MM`].
pub const FIXED_ANGLE_SIGMA_DEG: f64 = 0.1;
/// Default σ of a fixed dimensionless parameter (a zero-reference axis component), as
/// [`FIXED_LENGTH_SIGMA_MM`].
pub const FIXED_UNITLESS_SIGMA: f64 = 1e-3;

/// The stated prior uncertainty of the parameters a fit holds fixed (cell `[parameters]
/// fixed_prior` per kind, `fixed_priors` per parameter): a fixed parameter `p` is taken as
/// `p_true ~ N(p_nominal, σ²)`, independently. Only the parameters a fit holds fixed use it;
/// an estimated parameter's uncertainty is in C_p. A non-geometric term (compliance,
/// periodic error) left out of a fit is exact unless `parameters` names it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FixedPrior {
    /// σ of a fixed length (mm).
    pub length_mm: f64,
    /// σ of a fixed angle (rad).
    pub angle_rad: f64,
    /// σ of a fixed dimensionless parameter.
    pub unitless: f64,
    /// Per-parameter σ (internal units) by name; takes precedence over the kind's. A frame
    /// the cell does not give (`[base]`, `[tool]` absent: the world is the robot base, the
    /// TCP the flange) is a definition and has σ = 0 here.
    pub parameters: Vec<(String, f64)>,
}

impl Default for FixedPrior {
    fn default() -> Self {
        FixedPrior {
            length_mm: FIXED_LENGTH_SIGMA_MM,
            angle_rad: FIXED_ANGLE_SIGMA_DEG.to_radians(),
            unitless: FIXED_UNITLESS_SIGMA,
            parameters: Vec::new(),
        }
    }
}

impl FixedPrior {
    /// The σ of `p` held fixed (internal units): its own if named, else its kind's (0 for a
    /// non-geometric term).
    pub fn sigma(&self, p: &Parameter) -> f64 {
        if let Some((_, s)) = self.parameters.iter().find(|(n, _)| *n == p.name) {
            return *s;
        }
        match p.unit {
            Unit::Mm => self.length_mm,
            Unit::Rad => self.angle_rad,
            Unit::Unitless => self.unitless,
            Unit::RadPerMm | Unit::RadPerNmm | Unit::Arcsec => 0.0,
        }
    }

    /// Sets the σ of the parameter `name` (replacing an earlier one).
    pub fn set(&mut self, name: &str, sigma: f64) {
        self.parameters.retain(|(n, _)| n != name);
        self.parameters.push((name.to_string(), sigma));
    }
}

/// The prior information of `registry` over the columns `free` (registry indices, the
/// order of the rows' columns): whitened rows `W` and offsets `W μ` such that the prior adds
/// `½ ‖W p_free − W μ‖²` to the cost (module notes). First one row `1/σ` per free parameter
/// with [`ParameterStatus::Prior`] (not in the correlated prior), then `L⁻¹` of the correlated
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
        if let ParameterStatus::Prior { sigma } = p.status {
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
