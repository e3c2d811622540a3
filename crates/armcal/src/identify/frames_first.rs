//! The frames-first start of every fit: the instrument, target, base and tool frames fitted
//! at the nominal robot before the full calibration (a two-stage fit), and the frames-only
//! model it uses.

use super::{data_measurement, solve, IdentifySettings, Method, Problem};
use crate::measure::Dataset;
use crate::model::identifiability::IdentifiabilitySettings;
use crate::model::{Model, Segment, Status as ParamStatus};
use crate::progress::Silent;
use crate::Error;

/// Starting point of the full fit, the same for every method: the nominal robot with the
/// instrument, target, base and tool frames fitted first by Levenberg–Marquardt (a
/// two-stage fit; robust if `opts.robust`). A tracker placed only roughly in the cell, or
/// not at all, and a target whose offset is unknown are then no obstacle for the full
/// calibration. The frames fitted are those of `model`'s free set that these data identify
/// at the nominal (base and instrument, tool and target overlap); with no free frame
/// parameter the start is the nominal. When the free parameters are only frames this stage
/// is the whole fit, and the chosen method refines it.
pub fn frames_first_start(
    model: &Model,
    data: &Dataset,
    noise: &crate::measure::NoiseModel,
    opts: &IdentifySettings,
) -> Result<Vec<f64>, Error> {
    let frames = frames_only(model);
    if frames.registry.free().is_empty() {
        return Ok(model.nominal());
    }
    let (frames, _) = frames_model(&frames, data, &frames.nominal())?;
    let mut problem = Problem::new(&frames, data, noise)?;
    if problem.free.is_empty() {
        return Ok(model.nominal());
    }
    let stage = IdentifySettings {
        method: Method::Lm,
        robust: opts.robust,
        lm: opts.lm.clone(),
        ..Default::default()
    };
    let (sol, _, _) = solve(&mut problem, &model.nominal(), &stage, &mut Silent)?;
    Ok(sol.params)
}

/// `frames` (a frames-only model, [`frames_only`]) with its free set reduced to what
/// `data` identify at the parameters `at`, and the parameters left out with their reasons.
pub(super) fn frames_model(
    frames: &Model,
    data: &Dataset,
    at: &[f64],
) -> Result<(Model, Vec<crate::model::identifiability::Exclusion>), Error> {
    let mut frames = frames.clone();
    let report = crate::model::identifiability::analyze_at(
        &frames,
        at,
        &data.configurations,
        &IdentifiabilitySettings {
            measurement: data_measurement(data),
            stations: data.config_stations.clone(),
            payloads: Some(data.model_payloads(&frames)?),
            ..Default::default()
        },
    )?;
    report.apply(&mut frames)?;
    Ok((frames, report.excluded))
}

/// Whether a parameter belongs to the frames a "frames only" fit adjusts: instrument,
/// targets, the base (first chain link) and the tool (last chain link).
pub fn is_frame_parameter(model: &Model, i: usize) -> bool {
    match model.registry.get(i).segment {
        Segment::Instrument | Segment::Target(_) => true,
        Segment::Chain => {
            let first = &model.links[0];
            let last = &model.links[model.links.len() - 1];
            let within =
                |l: &crate::model::Link| i >= l.first_param && i < l.first_param + l.param_count();
            within(first) || within(last)
        }
    }
}

/// A copy of the model whose free set is restricted to the frame parameters.
pub fn frames_only(model: &Model) -> Model {
    let mut m = model.clone();
    for i in 0..m.param_count() {
        if m.registry.get(i).status.is_free() && !is_frame_parameter(&m, i) {
            m.registry.set_status(i, ParamStatus::Fixed);
        }
    }
    m
}
