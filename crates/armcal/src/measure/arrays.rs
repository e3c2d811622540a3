//! A [`Dataset`] from plain arrays (a program's or a Python caller's numpy rows), checked as
//! strictly as a data file ([`crate::measure::csv`]); and the data of several instrument
//! stations merged into one set ([`Dataset::merge_stations`]).

use super::{Dataset, Measurement, MeasurementKind};
use crate::model::{Model, Observed, Pose};
use crate::Error;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// What each measured row of [`DataArrays`] holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RowKind {
    /// `x, y, z`: the observed point's position in the instrument frame (mm).
    #[default]
    Position,
    /// `x, y, z, roll, pitch, yaw`: the observed frame's pose in the instrument frame (mm;
    /// rad, fixed-axis `Rz(yaw) Ry(pitch) Rx(roll)`, [`Pose::from_xyz_rpy`]).
    Pose,
}

impl RowKind {
    /// The values of one measured row.
    pub fn width(self) -> usize {
        match self {
            RowKind::Position => 3,
            RowKind::Pose => 6,
        }
    }
}

/// Measurements as arrays: row `i` is the robot at `joints[i]` measured as `measured[i]`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct DataArrays {
    /// Joint values per row, one per joint, internal units (rad; mm for a prismatic joint)
    /// as everywhere in the library (files use deg).
    pub joints: Vec<Vec<f64>>,
    /// Measured values per row, [`RowKind::width`] each.
    pub measured: Vec<Vec<f64>>,
    /// What the measured rows hold.
    pub kind: RowKind,
    /// The cell's target each row measured; empty: the cell's only target, or the tool
    /// (TCP) for a cell without targets (as a data file without a `target` column).
    #[serde(default)]
    pub targets: Vec<String>,
    /// The instrument station each row was measured from; empty: one station.
    #[serde(default)]
    pub stations: Vec<String>,
    /// A pose id per row; empty: `1`, `2`, …
    #[serde(default)]
    pub ids: Vec<String>,
}

impl Dataset {
    /// The data set of `arrays` for `model`. Every shape, joint count, non-finite value,
    /// joint past its limits (by more than [`crate::model::MEASURED_LIMIT_TOLERANCE`], what a
    /// unit mistake gives), unknown target and bad station is an [`Error::Input`] naming the
    /// row (1-based) and field.
    ///
    /// ```
    /// use armcal::{DataArrays, Dataset, RowKind};
    /// let cell = armcal::cell::builtin::paper_cell()?;
    /// let arrays = DataArrays {
    ///     joints: vec![vec![0.0, 0.0, 0.0, 0.0, 0.0, 0.0]],
    ///     measured: vec![vec![1000.0, 200.0, 300.0]],
    ///     kind: RowKind::Position,
    ///     ..Default::default()
    /// };
    /// let data = Dataset::from_arrays(&cell.model, &arrays)?;
    /// assert_eq!(data.rows(), 3);
    /// let mut bad = arrays.clone();
    /// bad.measured[0][1] = f64::NAN;
    /// let e = Dataset::from_arrays(&cell.model, &bad).unwrap_err();
    /// assert!(e.to_string().contains("row 1, measured[1]"), "{e}");
    /// # Ok::<(), armcal::Error>(())
    /// ```
    pub fn from_arrays(model: &Model, arrays: &DataArrays) -> Result<Dataset, Error> {
        let n = arrays.joints.len();
        let fail = |row: usize, field: &str, why: String| {
            Error::Input(format!("data arrays: row {}, {field}: {why}", row + 1))
        };
        let count = |name: &str, len: usize| {
            if len != n && !(len == 0 && name != "measured") {
                return Err(Error::Input(format!(
                    "data arrays: {n} rows of joints but {len} of {name}"
                )));
            }
            Ok(())
        };
        count("measured", arrays.measured.len())?;
        count("targets", arrays.targets.len())?;
        count("stations", arrays.stations.len())?;
        count("ids", arrays.ids.len())?;
        if !arrays.stations.is_empty() && model.instrument.is_none() {
            return Err(Error::Input(format!(
                "data arrays: stations given, but model `{}` has no instrument whose pose a \
                 station sets",
                model.name
            )));
        }
        let width = arrays.kind.width();
        let mut data = Dataset {
            source: "data arrays".into(),
            ..Default::default()
        };
        for (i, (shown, values)) in arrays.joints.iter().zip(&arrays.measured).enumerate() {
            if shown.len() != model.dof() {
                let why = format!("{} values for the {} joints", shown.len(), model.dof());
                return Err(fail(i, "joints", why));
            }
            for (j, (v, joint)) in shown.iter().zip(&model.joints).enumerate() {
                if !v.is_finite() {
                    let why = format!("joint `{}` is not a finite number", joint.name);
                    return Err(fail(i, &format!("joints[{j}]"), why));
                }
            }
            let q = shown.clone();
            model.check_measured_joints(&q).map_err(|e| {
                let why = format!(
                    "{e} (joints are in rad, mm for a prismatic joint; a value in deg or a \
                     wrong joint order reads as one past its limits)"
                );
                fail(i, "joints", why.replace("invalid input: ", ""))
            })?;
            if values.len() != width {
                let why = format!(
                    "{} values, a {:?} row has {width}",
                    values.len(),
                    arrays.kind
                );
                return Err(fail(i, "measured", why));
            }
            if let Some(k) = values.iter().position(|v| !v.is_finite()) {
                let why = "not a finite number".to_string();
                return Err(fail(i, &format!("measured[{k}]"), why));
            }
            let observed = match arrays.targets.get(i).map(String::as_str) {
                Some("") | None => match model.targets.len() {
                    0 => Observed::Tool,
                    1 => Observed::Target(0),
                    _ => {
                        let why = "the cell has several targets: name the one measured".into();
                        return Err(fail(i, "targets", why));
                    }
                },
                Some(name) => Observed::Target(model.target_index(name).ok_or_else(|| {
                    let names: Vec<&str> =
                        model.targets.iter().map(|t| t.spec.name.as_str()).collect();
                    let why = format!("no target `{name}` (the cell has: {})", names.join(", "));
                    fail(i, "targets", why)
                })?),
            };
            let xyz = Vector3::new(values[0], values[1], values[2]);
            let kind = match arrays.kind {
                RowKind::Position => MeasurementKind::Position {
                    value: xyz,
                    sigma: None,
                },
                RowKind::Pose => MeasurementKind::Pose {
                    value: Pose::from_xyz_rpy(xyz.into(), [values[3], values[4], values[5]]),
                    sigma: None,
                },
            };
            let id = arrays.ids.get(i).cloned().unwrap_or((i + 1).to_string());
            let c = data.push_configuration(id, q);
            if let Some(name) = arrays.stations.get(i) {
                crate::model::station::check_name(name)
                    .map_err(|e| fail(i, "stations", format!("`{name}`: {e}")))?;
                let s = data.station_index(name);
                data.config_stations[c] = s;
            }
            data.measurements.push(Measurement {
                config: c,
                observed,
                kind,
                line: 0,
                covariates: Default::default(),
            });
        }
        if n == 0 {
            return Err(Error::Input("data arrays: no rows".into()));
        }
        Ok(data)
    }

    /// The data of several set-ups merged into one set, in order: each part at the station
    /// it names (`Some`, [`Dataset::at_station`]) or with its own `station` column. With
    /// more than one part, a part that names no station is an error (its rows would be
    /// taken from the first station's instrument pose).
    pub fn merge_stations(parts: Vec<(Option<String>, Dataset)>) -> Result<Dataset, Error> {
        let several = parts.len() > 1;
        let mut all = Dataset::default();
        let mut sources = Vec::new();
        for (station, data) in parts {
            let data = match station {
                Some(s) => data.at_station(&s)?,
                None => data,
            };
            if several && data.stations.is_empty() {
                return Err(Error::Input(format!(
                    "{}: with several data files, give each its station \
                     (`--data STATION=FILE`) or a `station` column",
                    data.source
                )));
            }
            sources.push(data.source.clone());
            all.append(&data);
        }
        all.source = sources.join(" + ");
        Ok(all)
    }
}

#[cfg(test)]
mod tests {
    use super::{DataArrays, RowKind};
    use crate::{Cell, Dataset};

    fn arrays() -> (Cell, DataArrays) {
        let cell = crate::cell::builtin::paper_cell().unwrap();
        let arrays = DataArrays {
            joints: vec![vec![0.0, 0.0, 0.0, 0.0, 0.2, 0.0]; 2],
            measured: vec![vec![1000.0, 200.0, 300.0]; 2],
            kind: RowKind::Position,
            ..Default::default()
        };
        (cell, arrays)
    }

    fn error(cell: &Cell, arrays: &DataArrays) -> String {
        Dataset::from_arrays(&cell.model, arrays)
            .unwrap_err()
            .to_string()
    }

    /// The joints are stored as given (rad); the measurement is the cell's only target's
    /// position.
    #[test]
    fn reads_internal_units() {
        let (cell, a) = arrays();
        let data = Dataset::from_arrays(&cell.model, &a).unwrap();
        assert_eq!(data.configurations.len(), 2);
        assert_eq!(data.configurations[0][4], 0.2);
        assert_eq!(
            data.measurements[1].observed,
            crate::model::Observed::Target(0)
        );
        assert_eq!(data.config_ids, ["1", "2"]);
        assert!(data.stations.is_empty());
    }

    /// Every check names its row and field.
    #[test]
    fn every_check_names_row_and_field() {
        let (cell, a) = arrays();
        type Mutation = Box<dyn Fn(&mut DataArrays)>;
        let cases: Vec<(Mutation, &str)> = vec![
            (
                Box::new(|a| a.measured.pop().map(drop).unwrap()),
                "2 rows of joints but 1 of measured",
            ),
            (
                Box::new(|a| a.joints[1].pop().map(drop).unwrap()),
                "row 2, joints: 5 values for the 6 joints",
            ),
            (
                Box::new(|a| a.joints[0][2] = f64::INFINITY),
                "row 1, joints[2]: joint",
            ),
            (Box::new(|a| a.joints[1][1] = 400.0), "row 2, joints: joint"),
            (
                Box::new(|a| a.measured[1] = vec![1.0; 6]),
                "row 2, measured: 6 values, a Position row has 3",
            ),
            (
                Box::new(|a| a.measured[0][2] = f64::NAN),
                "row 1, measured[2]: not a finite number",
            ),
            (
                Box::new(|a| a.targets = vec!["smr1".into(), "nowhere".into()]),
                "row 2, targets: no target `nowhere`",
            ),
            (
                Box::new(|a| a.stations = vec!["A".into(), "bad name".into()]),
                "row 2, stations: `bad name`",
            ),
            (
                Box::new(|a| a.ids = vec!["p".into()]),
                "2 rows of joints but 1 of ids",
            ),
            (
                Box::new(|a| {
                    a.joints.clear();
                    a.measured.clear()
                }),
                "no rows",
            ),
        ];
        for (mutate, expected) in cases {
            let mut bad = a.clone();
            mutate(&mut bad);
            let e = error(&cell, &bad);
            assert!(e.contains(expected), "expected `{expected}` in: {e}");
        }
    }

    /// A joint in deg where rad are expected reads as past its limits: the message says
    /// the unit.
    #[test]
    fn degrees_for_radians_is_an_error() {
        let (cell, mut a) = arrays();
        a.joints[0][1] = -90.0;
        assert!(error(&cell, &a).contains("joints are in rad"));
    }

    /// Stations: each row's, merged by name; two parts without one are refused.
    #[test]
    fn stations_by_row_and_merged() {
        let (cell, mut a) = arrays();
        a.stations = vec!["A".into(), "B".into()];
        let data = Dataset::from_arrays(&cell.model, &a).unwrap();
        assert_eq!(data.stations, ["A", "B"]);
        assert_eq!(data.config_stations, [0, 1]);
        let (_, plain) = arrays();
        let one = Dataset::from_arrays(&cell.model, &plain).unwrap();
        let merged =
            Dataset::merge_stations(vec![(None, data), (Some("C".into()), one.clone())]).unwrap();
        assert_eq!(merged.stations, ["A", "B", "C"]);
        assert_eq!(merged.config_stations, [0, 1, 2, 2]);
        assert_eq!(merged.measurements[3].config, 3);
        let e = Dataset::merge_stations(vec![(None, one.clone()), (None, one.clone())])
            .unwrap_err()
            .to_string();
        assert!(e.contains("give each its station"), "{e}");
        // One part needs no station.
        assert!(Dataset::merge_stations(vec![(None, one)])
            .unwrap()
            .stations
            .is_empty());
    }
}
