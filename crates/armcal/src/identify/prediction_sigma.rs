//! The 1-σ of what a calibrated model predicts (`armcal predict`): at every predicted
//! measurement, the covariance of the predicted point (and, for a pose, its orientation)
//! from the estimate's C_p, and the model floor beside it.
//!
//! The predicted point x(p, q) (a target's or the tool's position in the instrument frame)
//! moves with the free parameters as `J = ∂x/∂p` (the identification Jacobian of that point,
//! the rows [`crate::identify::uncertainty::tcp_jacobian`] takes for the TCP), so
//!
//! ```text
//! C_x = J C_p Jᵀ                   (paper appendix, C_s = G C_p Gᵀ at any point)
//! C_floor = K Σ_f Kᵀ,  K = J_f − J A   (identify::model_floor, A = C_p Fᵀ F_f)
//! ```
//!
//! Each is stated as one σ: `√((1/3) tr C)`, the RMS of the three axis σ's — the square
//! root of the paper's KPI φ_A, the σ `estimate.json`'s `tcp[].kpi` and the campaign give
//! ([`crate::identify::model_floor::TcpFloor::kpi`]); at a working configuration the
//! predicted tool σ is exactly √kpi. C_x is not scaled by σ̂₀² (as `estimate.json`'s C_s);
//! the combination is `√(σ² + σ_floor²)`, the σ of C_x + C_floor.

use crate::identify::model_floor::Absorbed;
use crate::identify::Estimate;
use crate::measure::{csv, Dataset};
use crate::model::{forward_kinematics, identification_jacobian, Data, Model, Observed, Rows};
use crate::Error;
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// The σ's of one predicted point.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PredictionSigma {
    /// √((1/3) tr J C_p Jᵀ) of the position (mm).
    pub position_mm: f64,
    /// The same of the model floor (mm); `None`: the estimate states no floor.
    pub floor_mm: Option<f64>,
    /// The orientation's (rad), for a pose measurement.
    pub orientation_rad: Option<f64>,
    /// The orientation's floor (rad), for a pose measurement of an estimate with a floor.
    pub floor_orientation_rad: Option<f64>,
}

impl PredictionSigma {
    /// √(σ² + σ_floor²) of the position (mm); `None` without a floor.
    pub fn total_mm(&self) -> Option<f64> {
        self.floor_mm.map(|f| self.position_mm.hypot(f))
    }

    /// √(σ² + σ_floor²) of the orientation (rad).
    pub fn total_orientation_rad(&self) -> Option<f64> {
        Some(self.orientation_rad?.hypot(self.floor_orientation_rad?))
    }
}

/// The σ's of one predicted measurement: of the point it measures and, when that is a
/// target, of the TCP (the tool origin, the KPI's point) at the same configuration — a
/// target's floor can vanish (its offset absorbs a fixed flange parameter) where the TCP's
/// does not.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RowSigma {
    /// The measured point (the row's `x_mm, y_mm, z_mm`).
    pub point: PredictionSigma,
    /// The TCP's, position only; `None` when the row is the tool's.
    pub tcp: Option<PredictionSigma>,
}

/// Registry indices in `model` of the names `names`; `None` if one is not a parameter of
/// `model` (an estimate fitted over instrument stations names each station's pose).
fn columns(model: &Model, names: &[String]) -> Option<Vec<usize>> {
    names.iter().map(|n| model.registry.index_of(n)).collect()
}

/// √((1/3) tr) of the 3×3 block at `at` of `c`.
fn rms_sigma(c: &DMatrix<f64>, at: usize) -> f64 {
    (c.view((at, at), (3, 3)).trace() / 3.0).max(0.0).sqrt()
}

/// The σ's of every measurement of `data` (the model's prediction at `params`, as
/// [`crate::sim::predict`] writes it) from `estimate`'s C_p and model floor (module notes).
/// `None` when the estimate's free parameters are not all `model`'s (a fit over stations:
/// the prediction is at the cell's one instrument pose, which no column of C_p is) or for a
/// measurement that is neither a position nor a pose.
pub fn prediction_sigmas(
    model: &Model,
    params: &[f64],
    estimate: &Estimate,
    data: &Dataset,
) -> Result<Option<Vec<RowSigma>>, Error> {
    estimate.check_consistent()?;
    let Some(free) = columns(model, &estimate.free) else {
        return Ok(None);
    };
    let floor = estimate
        .model_floor
        .as_ref()
        .and_then(|f| f.absorbed.as_ref())
        .and_then(|a: &Absorbed| Some((a, columns(model, &a.fixed)?)));
    let cp = &estimate.uncertainty.covariance;
    let mut fk = Data::new(model);
    let mut out = Vec::with_capacity(data.measurements.len());
    for m in &data.measurements {
        let Some(rows) = m.kind.jacobian_rows() else {
            return Ok(None);
        };
        fk.payload = data.config_payloads.get(m.config).copied().flatten();
        forward_kinematics(model, &mut fk, params, &data.configurations[m.config]);
        let sigma = |obs: Observed, rows: Rows| {
            let jacobian = |cols: &[usize]| point_jacobian(model, &fk, obs, rows, cols);
            let j = jacobian(&free);
            let c = &j * cp * j.transpose();
            let cf = floor.as_ref().map(|(a, fixed)| {
                let k = jacobian(fixed) - &j * &a.map;
                let ks = DMatrix::from_fn(k.nrows(), k.ncols(), |r, c| k[(r, c)] * a.sigma[c]);
                &ks * ks.transpose()
            });
            let pose = rows == Rows::Pose;
            PredictionSigma {
                position_mm: rms_sigma(&c, 0),
                floor_mm: cf.as_ref().map(|cf| rms_sigma(cf, 0)),
                orientation_rad: pose.then(|| rms_sigma(&c, 3)),
                floor_orientation_rad: cf.as_ref().filter(|_| pose).map(|cf| rms_sigma(cf, 3)),
            }
        };
        out.push(RowSigma {
            point: sigma(m.observed, rows),
            tcp: (m.observed != Observed::Tool).then(|| sigma(Observed::Tool, Rows::Position)),
        });
    }
    Ok(Some(out))
}

/// The identification Jacobian of the observed point `obs` (`rows`) over `columns` at the
/// configuration `fk` holds.
fn point_jacobian(
    model: &Model,
    fk: &Data<f64>,
    obs: Observed,
    rows: Rows,
    columns: &[usize],
) -> DMatrix<f64> {
    let mut j = DMatrix::zeros(rows.count(), columns.len());
    identification_jacobian(model, fk, obs, rows, columns, &mut j, 0);
    j
}

/// The prediction `data` as a data file ([`csv::write_string`]) with the σ columns
/// `sigma_mm`, `floor_sigma_mm`, `total_sigma_mm` (the floor's two only if the estimate states
/// a floor), the same in `_deg` if a row is a pose, and the same with `tcp_` if a row is a
/// target's; a data file's reader ignores them.
///
/// sigma_mm = √((1/3) tr J C_p Jᵀ), the RMS of the three axis σ's of the row's predicted point
/// from the estimate's C_p (not scaled by σ̂₀²); floor_sigma_mm the same of the model floor
/// K Σ_f Kᵀ (the fixed parameters' stated prior); total_sigma_mm = √(sigma² + floor²); the
/// `_deg` columns the same of a pose row's orientation (rotation vector); the `tcp_` columns the
/// same of the TCP (tool origin) at the row's configuration when the row is a target's.
pub fn csv_with_sigmas(
    data: &Dataset,
    model: &Model,
    sigmas: &[RowSigma],
) -> Result<String, Error> {
    let floor = sigmas.iter().any(|s| s.point.floor_mm.is_some());
    let pose = sigmas.iter().any(|s| s.point.orientation_rad.is_some());
    let tcp = sigmas.iter().any(|s| s.tcp.is_some());
    let group = |prefix: &str, unit: &str| {
        let mut names = vec![format!("{prefix}sigma_{unit}")];
        if floor {
            names.extend([
                format!("{prefix}floor_sigma_{unit}"),
                format!("{prefix}total_sigma_{unit}"),
            ]);
        }
        names
    };
    let mut header = group("", "mm");
    if pose {
        header.extend(group("", "deg"));
    }
    if tcp {
        header.extend(group("tcp_", "mm"));
    }
    let f = |x: Option<f64>| x.map(|x| format!("{x:.9}")).unwrap_or_default();
    let values = |sigma: Option<f64>, floor_sigma: Option<f64>, total: Option<f64>| {
        let mut v = vec![f(sigma)];
        if floor {
            v.extend([f(floor_sigma), f(total)]);
        }
        v
    };
    let deg = |x: Option<f64>| x.map(f64::to_degrees);
    let rows = sigmas
        .iter()
        .map(|s| {
            let p = &s.point;
            let mut row = values(Some(p.position_mm), p.floor_mm, p.total_mm());
            if pose {
                row.extend(values(
                    deg(p.orientation_rad),
                    deg(p.floor_orientation_rad),
                    deg(p.total_orientation_rad()),
                ));
            }
            if tcp {
                let t = s.tcp.as_ref();
                row.extend(values(
                    t.map(|t| t.position_mm),
                    t.and_then(|t| t.floor_mm),
                    t.and_then(PredictionSigma::total_mm),
                ));
            }
            row
        })
        .collect::<Vec<_>>();
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    csv::write_string_with(data, model, &header, &rows)
}
