//! The calibrated model's error at every held-out measurement, with what the data recorded
//! with it (the instrument station, the air temperature), and those errors grouped: per
//! station, and per temperature bin. They say whether a calibration holds at every
//! set-up, and whether its error changes with the temperature.

use crate::accuracy::ErrorStats;
use crate::measure::Dataset;
use serde::{Deserialize, Serialize};

/// One held-out measurement under the calibrated model ([`super::Validation::errors`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HeldOutError {
    /// The configuration's `pose_id` (validation data).
    pub pose_id: String,
    /// The instrument station it was measured from, if the data name stations.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub station: Option<String>,
    /// The air temperature recorded with it (°C), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperature_c: Option<f64>,
    /// Position error `|model − measured|` (mm; for a distance or a plane, the scalar error).
    pub position_mm: f64,
    /// Orientation error (degrees, the angle of `R_model R_measᵀ`), for a pose measurement.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orientation_deg: Option<f64>,
}

/// The held-out errors of one group of measurements (a station, a temperature bin).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct GroupErrors {
    /// The group: a station's name, or a temperature bin `[lo, hi)` in °C.
    pub group: String,
    /// Mean temperature of the group's measurements (°C), if they recorded one.
    pub temperature_c: Option<f64>,
    /// Position error statistics (mm).
    pub position: ErrorStats,
    /// Orientation error statistics (degrees), if the group has pose measurements.
    pub orientation: Option<ErrorStats>,
}

/// The held-out errors of `test`'s measurements: `position[i]` (mm) and `orientation[i]`
/// (rad) of measurement `i`, one entry per measurement.
pub(super) fn held_out_errors(
    test: &Dataset,
    position: &[f64],
    orientation: &[Option<f64>],
) -> Vec<HeldOutError> {
    test.measurements
        .iter()
        .zip(position.iter().zip(orientation))
        .map(|(m, (&p, o))| HeldOutError {
            pose_id: test.config_ids[m.config].clone(),
            station: test.stations.get(test.station_of(m.config)).cloned(),
            temperature_c: m.covariates.temperature_c,
            position_mm: p,
            orientation_deg: o.map(f64::to_degrees),
        })
        .collect()
}

/// The statistics of `rows` as the group `group`.
fn group(group: String, rows: &[&HeldOutError]) -> GroupErrors {
    let position: Vec<f64> = rows.iter().map(|r| r.position_mm).collect();
    let orientation: Vec<f64> = rows.iter().filter_map(|r| r.orientation_deg).collect();
    let temperatures: Vec<f64> = rows.iter().filter_map(|r| r.temperature_c).collect();
    GroupErrors {
        group,
        temperature_c: (!temperatures.is_empty())
            .then(|| temperatures.iter().sum::<f64>() / temperatures.len() as f64),
        position: ErrorStats::of(&position),
        orientation: (!orientation.is_empty()).then(|| ErrorStats::of(&orientation)),
    }
}

/// The held-out errors per station, in order of first appearance; empty when the data name
/// no stations.
pub fn by_station(rows: &[HeldOutError]) -> Vec<GroupErrors> {
    let mut names: Vec<&str> = Vec::new();
    for r in rows {
        if let Some(s) = r.station.as_deref().filter(|s| !names.contains(s)) {
            names.push(s);
        }
    }
    names
        .into_iter()
        .map(|name| {
            let members: Vec<&HeldOutError> = rows
                .iter()
                .filter(|r| r.station.as_deref() == Some(name))
                .collect();
            group(name.to_string(), &members)
        })
        .collect()
}

/// The held-out errors per temperature bin `[k w, (k + 1) w)` (°C, `w = width_c`), the
/// bins that hold a measurement, coldest first; measurements without a temperature are left
/// out (empty when none has one).
pub fn by_temperature(rows: &[HeldOutError], width_c: f64) -> Vec<GroupErrors> {
    let bin = |t: f64| (t / width_c).floor() as i64;
    let mut bins: Vec<i64> = rows
        .iter()
        .filter_map(|r| r.temperature_c.map(bin))
        .collect();
    bins.sort_unstable();
    bins.dedup();
    bins.into_iter()
        .map(|b| {
            let members: Vec<&HeldOutError> = rows
                .iter()
                .filter(|r| r.temperature_c.map(bin) == Some(b))
                .collect();
            let (lo, hi) = (b as f64 * width_c, (b + 1) as f64 * width_c);
            group(format!("{lo:.2}–{hi:.2} °C"), &members)
        })
        .collect()
}

impl super::Validation {
    /// The calibrated model's validation errors per station ([`by_station`]).
    pub fn errors_by_station(&self) -> Vec<GroupErrors> {
        by_station(&self.errors)
    }

    /// The calibrated model's validation errors per temperature bin `width_c` °C wide
    /// ([`by_temperature`]).
    pub fn errors_by_temperature(&self, width_c: f64) -> Vec<GroupErrors> {
        by_temperature(&self.errors, width_c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(station: &str, t: f64, p: f64) -> HeldOutError {
        HeldOutError {
            pose_id: String::new(),
            station: Some(station.into()),
            temperature_c: Some(t),
            position_mm: p,
            orientation_deg: None,
        }
    }

    #[test]
    fn groups_by_station_and_by_temperature_bin() {
        let rows = [
            row("B", 21.6, 1.0),
            row("D", 20.8, 3.0),
            row("B", 21.9, 3.0),
        ];
        let s = by_station(&rows);
        assert_eq!(s.len(), 2);
        assert_eq!((s[0].group.as_str(), s[0].position.count), ("B", 2));
        assert!((s[0].position.mean - 2.0).abs() < 1e-12);
        assert!((s[0].temperature_c.unwrap() - 21.75).abs() < 1e-12);
        assert_eq!(s[1].group, "D");
        let t = by_temperature(&rows, 0.5);
        let groups: Vec<&str> = t.iter().map(|g| g.group.as_str()).collect();
        assert_eq!(groups, ["20.50–21.00 °C", "21.50–22.00 °C"]);
        assert_eq!(t[1].position.count, 2);
        assert!(t[0].orientation.is_none());
    }
}
