//! Instrument noise models: the σ of every residual row. Weights are the inverse
//! covariance (paper eq. 5: `f1 = Σ⁻¹(η − h)` with Σ diagonal here).

use crate::measure::{Measurement, MeasurementKind};
use crate::Error;
use serde::{Deserialize, Serialize};

/// Noise of the instrument's readings, internal units (mm, rad).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "kebab-case")]
pub enum NoiseModel {
    /// Independent N(0, σ²) per position axis (mm); `sigma_angle` (rad) for the rotation
    /// rows of pose measurements. One-row blocks (distances, planes) use σ of the x axis.
    Constant {
        /// σ of the x, y, z position rows (mm).
        sigma: [f64; 3],
        /// σ of each rotation row of a pose measurement (rad).
        sigma_angle: f64,
    },
    /// Laser-tracker style σ = a + b · range per axis: `a` in mm, `b_per_m` in mm per metre
    /// of distance from the instrument (e.g. 0.015 mm + 0.006 mm/m).
    Range {
        /// Constant part of σ (mm).
        a: f64,
        /// Growth of σ with the range (mm per m).
        b_per_m: f64,
    },
    /// σ per measurement, read from the data file; values below `floor` (mm) are raised to
    /// it (a stated uncertainty of 0 would give an infinite weight).
    PerMeasurement {
        /// Smallest σ of any row (mm; the same number in rad for rotation rows).
        floor: f64,
    },
}

impl Default for NoiseModel {
    fn default() -> Self {
        NoiseModel::Constant {
            sigma: [1.0; 3],
            sigma_angle: 1e-3,
        }
    }
}

/// σ the data file gives for a measurement, if any, one per residual row (zero-padded).
fn stated_sigma(m: &Measurement) -> Option<[f64; 6]> {
    match &m.kind {
        MeasurementKind::Position { sigma, .. } => sigma.map(|s| [s[0], s[1], s[2], 0.0, 0.0, 0.0]),
        MeasurementKind::Pose { sigma, .. } => *sigma,
        MeasurementKind::Distance { sigma, .. }
        | MeasurementKind::DistanceToPoint { sigma, .. }
        | MeasurementKind::OnPlane { sigma, .. } => sigma.map(|s| [s, 0.0, 0.0, 0.0, 0.0, 0.0]),
    }
}

/// `line N: ` for a measurement read from line N of a file, nothing for a synthetic one
/// (line 0: simulated, or the design's measurement at a planned pose).
fn at_line(line: usize) -> String {
    if line == 0 {
        String::new()
    } else {
        format!("line {line}: ")
    }
}

impl NoiseModel {
    /// A sentence for the user when `data` states σ for some rows but this noise model does
    /// not use them (constant and range models weight every row by their own σ).
    pub fn unused_sigmas(&self, data: &crate::measure::Dataset) -> Option<String> {
        if matches!(self, NoiseModel::PerMeasurement { .. }) {
            return None;
        }
        let stated = data
            .measurements
            .iter()
            .filter(|m| stated_sigma(m).is_some())
            .count();
        (stated > 0).then(|| {
            format!(
                "{} of the {} measurements of {} state their σ, but the cell's noise model is \
                 {}: the σ columns are not used (set the instrument's noise model to \
                 `per-measurement` to weight each row by its own σ)",
                stated,
                data.measurements.len(),
                data.source,
                match self {
                    NoiseModel::Constant { .. } => "constant",
                    _ => "range-dependent",
                }
            )
        })
    }

    /// σ of each residual row of `m` ([`NoiseModel::sigmas`]) at the range of its own
    /// measured point: the distance from the instrument of a position or a pose's origin,
    /// 0 for the one-row kinds. Every measurement's weights in identification
    /// ([`crate::identify::Problem`]), simulation and the pose design come from here.
    pub fn row_sigmas(&self, m: &Measurement) -> Result<[f64; 6], Error> {
        let range = match &m.kind {
            MeasurementKind::Position { value, .. } => value.norm(),
            MeasurementKind::Pose { value, .. } => value.trans.norm(),
            _ => 0.0,
        };
        self.sigmas(m, range)
    }

    /// σ of each residual row of `m` (first `m.kind.rows()` entries). `range` is the
    /// distance of the observed point from the instrument (mm), for the range model.
    pub fn sigmas(&self, m: &Measurement, range: f64) -> Result<[f64; 6], Error> {
        let rows = m.kind.rows();
        let mut out = [0.0; 6];
        let given = stated_sigma(m);
        match self {
            NoiseModel::Constant { sigma, sigma_angle } => match &m.kind {
                MeasurementKind::Position { .. } => out[..3].copy_from_slice(sigma),
                MeasurementKind::Pose { .. } => {
                    out[..3].copy_from_slice(sigma);
                    out[3..].fill(*sigma_angle);
                }
                _ => out[0] = sigma[0],
            },
            NoiseModel::Range { a, b_per_m } => {
                if matches!(m.kind, MeasurementKind::Pose { .. }) {
                    return Err(Error::Input(format!(
                        "{}the range noise model has no σ for the rotation rows of a pose measurement; give the instrument the constant model (`sigma_mm`, `sigma_angle_deg`), or σ columns in the data file with the `per-measurement` model",
                        at_line(m.line)
                    )));
                }
                let s = a + b_per_m * range / 1000.0;
                out[..rows].fill(s);
            }
            NoiseModel::PerMeasurement { floor } => {
                let g = given.ok_or_else(|| {
                    Error::Input(format!(
                        "{}the noise model is per-measurement but this {} measurement has no σ columns",
                        at_line(m.line),
                        m.kind.name()
                    ))
                })?;
                for (o, s) in out.iter_mut().zip(g).take(rows) {
                    *o = s.max(*floor);
                }
            }
        }
        if let Some(bad) = out[..rows].iter().find(|s| !(s.is_finite() && **s > 0.0)) {
            return Err(Error::Input(format!(
                "{}σ = {bad} is not a positive number",
                at_line(m.line)
            )));
        }
        Ok(out)
    }
}
