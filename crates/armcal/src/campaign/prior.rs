//! A campaign that starts from an earlier calibration (issue 16 item 2): after a drift check
//! ([`super::drift`]) said "drifted", the robot is re-identified with the old estimate as a
//! prior, so that only what moved needs new poses.
//!
//! The campaign fits the old calibration's free set. Every parameter starts at the old
//! estimate; the groups the check released (those that most likely moved, or the user's
//! choice) are free without a prior; every other free parameter carries the old estimate's
//! joint Gaussian `N(p̂_old, s · C_p,old)` ([`crate::model::prior`]), `s` the old fit's
//! covariance scale (max(1, σ̂₀²), [`super::precision::scale`]), so the correlations of the
//! old fit are kept (a parameter is known only as well as its combinations are). The
//! campaign's fits, its TCP covariances, its stopping decision and the design of every batch
//! ([`crate::design::DesignModel::prior_rows`]) all include that information.

use crate::campaign::drift::group_of;
use crate::campaign::precision;
use crate::cell::Cell;
use crate::identify::Estimate;
use crate::model::prior::CorrelatedPrior;
use crate::model::ParameterStatus;
use crate::Error;
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// The old calibration a campaign starts from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CampaignPrior {
    /// Every parameter of the cell's model at the old estimate (internal units), registry
    /// order: where every fit starts and what the fixed parameters are held at.
    pub params: Vec<f64>,
    /// The old calibration's free parameters: the campaign's free set.
    pub free: Vec<String>,
    /// The groups released from the prior (parameter name before the first `.`): free and
    /// without prior information.
    pub released: Vec<String>,
    /// The prior on every other free parameter.
    pub prior: CorrelatedPrior,
}

impl CampaignPrior {
    /// The prior of `estimate` (read from `source`) of `cell`, with the groups `released`
    /// free of it. A released group the estimate has no free parameter of is an error that
    /// lists the groups it has.
    pub fn from_estimate(
        cell: &Cell,
        estimate: &Estimate,
        source: &str,
        released: &[String],
    ) -> Result<CampaignPrior, Error> {
        estimate.check_consistent()?;
        let params = estimate.params_for(&cell.model)?;
        let groups: Vec<&str> = {
            let mut g: Vec<&str> = estimate.free.iter().map(|n| group_of(n)).collect();
            g.dedup();
            g
        };
        if let Some(r) = released.iter().find(|r| !groups.contains(&r.as_str())) {
            return Err(Error::Input(format!(
                "group `{r}` has no free parameter in {source}; its groups: {}",
                groups.join(", ")
            )));
        }
        let kept: Vec<usize> = (0..estimate.free.len())
            .filter(|&k| !released.iter().any(|r| r == group_of(&estimate.free[k])))
            .collect();
        let s = precision::scale(estimate);
        let c = &estimate.uncertainty.covariance;

        let prior = CorrelatedPrior {
            source: source.to_string(),
            parameters: kept.iter().map(|&k| estimate.free[k].clone()).collect(),
            mean: kept
                .iter()
                .map(|&k| {
                    let i = cell.model.registry.require(&estimate.free[k])?;
                    Ok(params[i])
                })
                .collect::<Result<_, Error>>()?,
            covariance: DMatrix::from_fn(kept.len(), kept.len(), |a, b| s * c[(kept[a], kept[b])]),
        };
        prior.check()?;
        Ok(CampaignPrior {
            params,
            free: estimate.free.clone(),
            released: released.to_vec(),
            prior,
        })
    }

    /// `cell` as the campaign fits it: every parameter at the old estimate, the old free set
    /// free (the rest fixed) with the prior on it, and no automatic reduction of the free
    /// set (the prior identifies what the new poses alone cannot).
    pub fn apply(&self, cell: &Cell) -> Result<Cell, Error> {
        let mut at = cell.clone();
        let registry = &mut at.model.registry;
        if self.params.len() != registry.len() {
            return Err(Error::Input(format!(
                "the campaign's prior has {} parameters, cell `{}` {}",
                self.params.len(),
                cell.name,
                registry.len()
            )));
        }
        for (i, &v) in self.params.iter().enumerate() {
            registry.set_nominal(i, v);
            registry.set_status(i, ParameterStatus::Fixed);
        }
        for name in &self.free {
            let i = registry.require(name)?;
            registry.set_status(i, ParameterStatus::Free);
        }
        registry.set_correlated_prior(Some(self.prior.clone()))?;
        at.auto_free = false;
        Ok(at)
    }
}
