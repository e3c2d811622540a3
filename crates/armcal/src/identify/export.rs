//! An estimate's model as a file ([`export_estimate`]): every format of
//! [`ExportFormat`], the ones that write corrections against the nominal model with the
//! estimate's nominal values and σ.

use super::Estimate;
use crate::cell::export::{export_against_nominal, ExportFormat, Exported, NominalReference};
use crate::cell::Cell;
use crate::model::Model;
use crate::Error;
use std::collections::HashMap;

/// Exports `est`'s calibrated model in `format` (with the `cell` it was identified in, a cell
/// export carries the cell's other sections): the nominal model the corrections of
/// `urdf-calibration`, `urdf-conservative` and `ros-params` are taken against is the
/// estimate's model at its parameters' nominal values, and their σ are the estimate's.
pub fn export_estimate(
    est: &Estimate,
    cell: Option<&Cell>,
    format: ExportFormat,
) -> Result<Exported, Error> {
    let model = Model::from_spec(&est.model)?;
    let mut nominal = model.nominal();
    let mut sigmas = HashMap::new();
    for p in &est.parameters {
        let Some(i) = model.registry.index_of(&p.name) else {
            continue;
        };
        let factor = model.registry.get(i).unit.display_factor();
        nominal[i] = p.nominal / factor;
        if let Some(s) = p.sigma {
            sigmas.insert(p.name.clone(), s / factor);
        }
    }
    let nominal = model.spec_at(&nominal);
    let sigma = |name: &str| sigmas.get(name).copied();
    let source = format!("the estimate of `{}` on `{}`", est.cell, est.data);
    let reference = NominalReference {
        nominal: &nominal,
        sigma: &sigma,
        source: &source,
    };
    export_against_nominal(&est.model, Some(&reference), cell, format)
}
