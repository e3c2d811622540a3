//! A frames refit: the robot of an existing estimate carried over to a new set-up. Every
//! robot (link) parameter keeps the estimate's value; only what changes when the instrument
//! is set up again or the tool is re-mounted — the instrument, base, tool and target frames
//! ([`is_frame_parameter`]) — is fitted to the new data. The free frames are those these
//! data identify with the robot held at the estimate ([`frames_model`]).

use super::{
    frames_model, frames_only, is_frame_parameter, solve, Acceptance, Estimate, FreeSetFit,
    IdentifySettings, Method, Problem,
};
use crate::cell::Cell;
use crate::measure::{Dataset, NoiseModel};
use crate::model::rank_deficit::RankDeficit;
use crate::progress::{Observer, Silent};
use crate::Error;
use serde::{Deserialize, Serialize};

/// What a frames refit starts from ([`IdentifySettings::refit`]).
#[derive(Clone, Debug)]
pub struct FramesRefit {
    /// The estimate whose robot parameters are kept (of the same cell and robot).
    pub estimate: Estimate,
    /// Where the estimate came from (its file), for messages and the record.
    pub origin: String,
    /// Whether an estimate whose fit did not converge is accepted, in the caller's words.
    pub acceptance: Acceptance<'static>,
}

/// What an estimate made by a frames refit records of it ([`Estimate::refit`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RefitRecord {
    /// The estimate whose robot was kept (its file, as the caller named it).
    pub estimate: String,
    /// That estimate's cell.
    pub cell: String,
    /// The data that estimate was fitted on.
    pub data: String,
    /// Number of robot parameters held at that estimate's values.
    pub kept: usize,
}

/// The fit of a frames refit: the estimate checked (converged, or accepted; the same cell
/// model, [`Estimate::params_for`]), the robot parameters held at its values, the frames
/// these data identify fitted by Levenberg–Marquardt from the cell's nominal frames, then
/// refined by the chosen method. `cell` is `source` (the cell the estimate is of) with the
/// data's stations ([`Cell::with_stations`]).
pub(super) fn fit_frames(
    cell: &Cell,
    source: &Cell,
    train: &Dataset,
    noise: &NoiseModel,
    opts: &IdentifySettings,
    refit: &FramesRefit,
    observer: &mut dyn Observer,
) -> Result<FreeSetFit, Error> {
    let of_estimate = |e: Error| Error::Input(format!("{}: {e}", refit.origin));
    refit
        .estimate
        .check_usable(&refit.acceptance)
        .map_err(of_estimate)?;
    let robot = refit
        .estimate
        .params_for(&source.model)
        .map_err(of_estimate)?;
    let declared = if cell.auto_free {
        cell.declared_model()
    } else {
        cell.model.clone()
    };
    let mut start = declared.nominal();
    for (i, value) in start.iter_mut().enumerate() {
        if !is_frame_parameter(&declared, i) {
            *value = robot[source.model.station_source(&declared, i)];
        }
    }
    let (model, excluded) = frames_model(&frames_only(&declared), train, &start)?;
    let reasons = excluded.into_iter().map(|e| (e.name, e.reason)).collect();
    let mut problem = Problem::new(&model, train, noise)?;
    let stage = IdentifySettings {
        method: Method::Lm,
        robust: opts.robust,
        lm: opts.lm.clone(),
        ..Default::default()
    };
    let (first, _, _) = solve(&mut problem, &start, &stage, &mut Silent)?;
    let (solution, outliers, robust_scale) = solve(&mut problem, &first.params, opts, observer)?;
    Ok(FreeSetFit {
        row_weights: problem.row_weights.clone(),
        model,
        reasons,
        weak: Vec::new(),
        solution,
        outliers,
        robust_scale,
    })
}

/// The record of a refit of `refit` that held `kept` robot parameters.
pub(super) fn record(refit: &FramesRefit, kept: usize) -> RefitRecord {
    RefitRecord {
        estimate: refit.origin.clone(),
        cell: refit.estimate.cell.clone(),
        data: refit.estimate.data.clone(),
        kept,
    }
}

/// Why a refit estimates fewer parameters than the generic count: the robot's are kept.
pub(super) fn deficit(
    cell: &Cell,
    refit: &FramesRefit,
    identified: usize,
    kept: usize,
) -> Option<RankDeficit> {
    let expected = crate::model::identifiability::expected_count(&cell.model, cell.measurement)?;
    (identified < expected).then(|| RankDeficit {
        measurement: cell.measurement,
        expected,
        identifiable: identified,
        causes: vec![format!(
            "a frames refit of {} keeps its {kept} robot parameters and fits only the frames",
            refit.origin
        )],
    })
}
