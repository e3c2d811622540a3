//! The residuals of a fit in millimetres: every measurement's position residual with the
//! whitening and robust weights undone, and the residual record of an estimate (statistics
//! per axis and of the norm, per measurement).

use super::estimate::{AxisErrors, MeasurementResidual, ResidualReport};
use super::problem::{Problem, Workspace};
use crate::accuracy::ErrorStats;
use crate::measure::MeasurementKind;
use nalgebra::DVector;

/// The position residual `model − measured` of every measurement at `params` (mm, the
/// whitening and robust weights undone); `None` for distance and plane measurements.
pub fn position_components(
    problem: &Problem,
    ws: &mut Workspace,
    params: &[f64],
) -> Vec<Option<[f64; 3]>> {
    let mut r = DVector::zeros(problem.rows());
    problem.evaluate(ws, params, &mut r, None);
    problem
        .data
        .measurements
        .iter()
        .enumerate()
        .map(|(i, m)| match m.kind {
            MeasurementKind::Position { .. } | MeasurementKind::Pose { .. } => {
                let row = problem.row_of[i];
                let un = |k: usize| {
                    let w = problem.row_weights[row + k].sqrt() / problem.sigmas[row + k];
                    r[row + k] / w
                };
                Some([un(0), un(1), un(2)])
            }
            _ => None,
        })
        .collect()
}

/// Residuals of the fit; `file_configs[c]` is the data-file index of the fitted data's
/// configuration `c` (pose numbers are reported in the file's numbering).
pub fn residual_report(
    problem: &Problem,
    params: &[f64],
    file_configs: &[usize],
) -> ResidualReport {
    let mut ws = problem.workspace();
    let components = position_components(problem, &mut ws, params);
    let norms = problem.errors(&mut ws, params);
    let xyz: Vec<[f64; 3]> = components.iter().flatten().copied().collect();
    let axes = AxisErrors::of(&xyz);
    let mut per_measurement = Vec::with_capacity(norms.len());
    for (i, (m, xyz)) in problem.data.measurements.iter().zip(components).enumerate() {
        per_measurement.push(MeasurementResidual {
            pose: file_configs[m.config] + 1,
            pose_id: problem
                .data
                .config_ids
                .get(m.config)
                .cloned()
                .unwrap_or_default(),
            xyz,
            norm: norms[i],
        });
    }
    ResidualReport {
        orientation: orientation_stats(problem, &mut ws, params),
        x: axes.x,
        y: axes.y,
        z: axes.z,
        norm: ErrorStats::of(&norms),
        per_measurement,
    }
}

/// Statistics of the orientation errors (degrees) of the pose measurements at `params`
/// ([`Problem::orientation_errors`]); `None` when no measurement has an orientation.
pub fn orientation_stats(
    problem: &Problem,
    ws: &mut Workspace,
    params: &[f64],
) -> Option<ErrorStats> {
    let degrees: Vec<f64> = problem
        .orientation_errors(ws, params)
        .into_iter()
        .flatten()
        .map(f64::to_degrees)
        .collect();
    (!degrees.is_empty()).then(|| ErrorStats::of(&degrees))
}
