//! The frames-first start of every fit: the instrument, target, base and tool frames fitted
//! at the nominal robot before the full calibration (a two-stage fit), and the frames-only
//! model it uses.

use super::{
    data_measurement, solve, uncertainty, IdentifySettings, Method, Problem, SolverResult,
};
use crate::measure::Dataset;
use crate::model::identifiability::IdentifiabilitySettings;
use crate::model::{Model, ParameterStatus, Segment};
use crate::progress::Silent;
use crate::Error;

/// Starting point of the full fit, the same for every method: the nominal robot with the
/// instrument, target, base and tool frames fitted first ([`frames_only_fit`], a two-stage
/// fit; robust if `opts.robust`), except the flange offsets that fit does not determine,
/// which keep their nominal. A tracker placed only roughly in the cell, or not at all, and
/// a target whose offset is unknown are then no obstacle for the full calibration. With no
/// free frame parameter the start is the nominal.
///
/// **Which offsets are carried.** A flange offset (a target's offset, or the tool link:
/// the frames the robot carries) is carried from the frames-only fit only if that fit
/// determines it on its own: its variance inflation `σᵢ ‖Jᵢ‖ = 1 / sin θᵢ` ≤
/// [`DETERMINED_VIF`], from the fit's own covariance `C = (JᵀJ)⁻¹` of the whitened
/// Jacobian, where θᵢ is the angle between its column and the span of the other frames'
/// columns (`(JᵀJ)⁻¹ᵢᵢ = 1/‖P⊥Jᵢ‖²`; Belsley, Kuh & Welsch 1980, *Regression
/// Diagnostics*, §3.1). An offset above it is seen by the data almost only in a
/// combination with the placement (a target offset along a tool axis that hardly turns
/// is a translation of the instrument), so the frames-only fit's value is that
/// combination's share plus whatever part of the nominal robot's errors the combination
/// absorbs: on the Motoman grid the reflector offset lands 650 mm from nominal where the
/// full fit ends 100 mm from it, and the full fit then walks back along a curved valley
/// for hundreds of iterations. Such offsets keep their nominal and the other frames are
/// fitted again with them held, so the placement takes the combination (it may be metres
/// off; an offset is a part on the flange whose nominal the cell states). The full fit
/// frees the offsets again. Measured (`real_data::solver_convergence`): determined
/// offsets have VIF ≤ 10 (UR10 series B's tool), undetermined ones 1500–7000 (the
/// Motoman reflector) and 3000 (UR10 series D's tool along its axis).
pub fn frames_first_start(
    model: &Model,
    data: &Dataset,
    noise: &crate::measure::NoiseModel,
    opts: &IdentifySettings,
) -> Result<Vec<f64>, Error> {
    let Some(fit) = fit_frames(model, data, noise, opts)? else {
        return Ok(model.nominal());
    };
    let held = undetermined_offsets(&fit.model, &fit.free, &fit.solution);
    if held.is_empty() {
        return Ok(fit.solution.params);
    }
    let nominal = model.nominal();
    let mut start = fit.solution.params;
    let mut rest = fit.model;
    for &i in &held {
        start[i] = nominal[i];
        rest.registry.set_status(i, ParameterStatus::Fixed);
    }
    let mut problem = Problem::new(&rest, data, noise)?;
    if problem.free.is_empty() {
        return Ok(start);
    }
    let (sol, _, _) = solve(&mut problem, &start, &stage(opts), &mut Silent)?;
    Ok(sol.params)
}

/// A flange offset is determined by the frames-only fit when its variance inflation
/// `σᵢ ‖Jᵢ‖` is at most this: its whitened column lies more than 0.57° (1/100 rad) from
/// the span of the other frames' columns ([`frames_first_start`]).
pub const DETERMINED_VIF: f64 = 100.0;

/// The free flange offsets of a frames-only fit whose variance inflation exceeds
/// [`DETERMINED_VIF`] ([`frames_first_start`]); none if the fit's covariance cannot be
/// formed.
fn undetermined_offsets(model: &Model, free: &[usize], sol: &SolverResult) -> Vec<usize> {
    let names: Vec<String> = free
        .iter()
        .map(|&i| model.registry.get(i).name.clone())
        .collect();
    let Ok(unc) = uncertainty::parameter_uncertainty(&sol.jacobian, &sol.residual, &names) else {
        return Vec::new();
    };
    free.iter()
        .enumerate()
        .filter(|&(c, &i)| {
            is_flange_offset(model, i)
                && unc.sigma[c] * sol.jacobian.column(c).norm() > DETERMINED_VIF
        })
        .map(|(_, &i)| i)
        .collect()
}

/// The frames-only fit: the nominal robot with the frames of `model`'s free set that these
/// data identify at the nominal (base and instrument, tool and target overlap) fitted by
/// Levenberg–Marquardt (robust if `opts.robust`); the nominal with no free frame
/// parameter. The reference a calibration is validated against (the held-out "frames
/// only" errors, ISO 9283 before calibration). When the free parameters are only frames
/// this is the whole fit, and the chosen method refines it.
pub fn frames_only_fit(
    model: &Model,
    data: &Dataset,
    noise: &crate::measure::NoiseModel,
    opts: &IdentifySettings,
) -> Result<Vec<f64>, Error> {
    Ok(match fit_frames(model, data, noise, opts)? {
        Some(fit) => fit.solution.params,
        None => model.nominal(),
    })
}

/// A frames-only fit: the model with its free set, the free parameters, the solution.
struct FramesFit {
    model: Model,
    free: Vec<usize>,
    solution: SolverResult,
}

/// The frames-only fit of [`frames_only_fit`]; `None` with no free frame parameter.
fn fit_frames(
    model: &Model,
    data: &Dataset,
    noise: &crate::measure::NoiseModel,
    opts: &IdentifySettings,
) -> Result<Option<FramesFit>, Error> {
    let frames = frames_only(model);
    if frames.registry.free().is_empty() {
        return Ok(None);
    }
    let (frames, _) = frames_model(&frames, data, &frames.nominal())?;
    let mut problem = Problem::new(&frames, data, noise)?;
    if problem.free.is_empty() {
        return Ok(None);
    }
    let (solution, _, _) = solve(&mut problem, &model.nominal(), &stage(opts), &mut Silent)?;
    let free = problem.free.clone();
    Ok(Some(FramesFit {
        model: frames,
        free,
        solution,
    }))
}

/// The settings of the frames-only stage: Levenberg–Marquardt, robust if `opts.robust`.
fn stage(opts: &IdentifySettings) -> IdentifySettings {
    IdentifySettings {
        method: Method::Lm,
        robust: opts.robust,
        lm: opts.lm.clone(),
        ..Default::default()
    }
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

/// Whether a parameter is a flange offset: a target's offset or the tool (last chain link,
/// when the chain has more than one) — a frame the robot carries, not its placement.
fn is_flange_offset(model: &Model, i: usize) -> bool {
    match model.registry.get(i).segment {
        Segment::Target(_) => true,
        Segment::Instrument => false,
        Segment::Chain => {
            let last = &model.links[model.links.len() - 1];
            model.links.len() > 1
                && i >= last.first_param
                && i < last.first_param + last.param_count()
        }
    }
}

/// A copy of the model whose free set is restricted to the frame parameters.
pub fn frames_only(model: &Model) -> Model {
    let mut m = model.clone();
    for i in 0..m.param_count() {
        if m.registry.get(i).status.is_free() && !is_frame_parameter(&m, i) {
            m.registry.set_status(i, ParameterStatus::Fixed);
        }
    }
    m
}
