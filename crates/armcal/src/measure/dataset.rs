//! A [`Dataset`]: joint configurations and the measurements taken at them, with their ids,
//! stations and payloads.

use super::{Measurement, MeasurementKind};
use serde::{Deserialize, Serialize};

/// Joint configurations and the measurements taken at them.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Dataset {
    /// Joint values per configuration, internal units (rad, mm).
    pub configurations: Vec<Vec<f64>>,
    /// A user-facing id per configuration (the data file's `pose_id`).
    pub config_ids: Vec<String>,
    /// Every measurement, each referring to a configuration by index.
    pub measurements: Vec<Measurement>,
    /// Where the data came from.
    pub source: String,
    /// The instrument stations the data name (a `station` column, or
    /// [`Dataset::at_station`]), in order of first appearance; empty: one station, the
    /// cell's instrument pose (`crate::model::station`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub stations: Vec<String>,
    /// The station of each configuration, an index into `stations`; empty when `stations`
    /// is.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub config_stations: Vec<usize>,
    /// The payloads the data name (a `payload` column naming a cell's `[[payload]]`), in
    /// order of first appearance; empty: no configuration carried one.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub payloads: Vec<String>,
    /// The payload each configuration carried, an index into `payloads` (`None`: none);
    /// empty when no configuration carried one.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub config_payloads: Vec<Option<usize>>,
}

impl Dataset {
    /// Total number of residual rows.
    pub fn rows(&self) -> usize {
        self.measurements.iter().map(|m| m.kind.rows()).sum()
    }

    /// Adds a configuration (at the first station, if the data name stations) and returns
    /// its index.
    pub fn push_configuration(&mut self, id: String, q: Vec<f64>) -> usize {
        self.configurations.push(q);
        self.config_ids.push(id);
        if !self.stations.is_empty() {
            self.config_stations.push(0);
        }
        if !self.config_payloads.is_empty() {
            self.config_payloads.push(None);
        }
        self.configurations.len() - 1
    }

    /// The payload configuration `c` carried (a name in [`Dataset::payloads`]), if any.
    pub fn payload_of(&self, c: usize) -> Option<&str> {
        let k = self.config_payloads.get(c).copied().flatten()?;
        self.payloads.get(k).map(String::as_str)
    }

    /// Records that configuration `c` carried payload `name` (`None`: none).
    pub fn set_payload(&mut self, c: usize, name: Option<&str>) {
        let Some(name) = name else {
            if let Some(p) = self.config_payloads.get_mut(c) {
                *p = None;
            }
            return;
        };
        let k = match self.payloads.iter().position(|p| p == name) {
            Some(k) => k,
            None => {
                self.payloads.push(name.to_string());
                self.payloads.len() - 1
            }
        };
        if self.config_payloads.len() < self.configurations.len() {
            self.config_payloads.resize(self.configurations.len(), None);
        }
        self.config_payloads[c] = Some(k);
    }

    /// Whether any configuration carried a payload.
    pub fn carries_payloads(&self) -> bool {
        self.config_payloads.iter().any(Option::is_some)
    }

    /// Each configuration's payload as an index into `model`'s payloads
    /// ([`Model::payload_index`](crate::Model::payload_index)); an error names a payload the model does not have.
    pub fn model_payloads(
        &self,
        model: &crate::model::Model,
    ) -> Result<Vec<Option<usize>>, crate::Error> {
        let of_name: Vec<Option<usize>> = self
            .payloads
            .iter()
            .map(|p| model.payload_index(p))
            .collect::<Result<_, _>>()
            .map_err(|e| crate::Error::Input(format!("{}: {e}", self.source)))?;
        Ok((0..self.configurations.len())
            .map(|c| {
                self.config_payloads
                    .get(c)
                    .copied()
                    .flatten()
                    .and_then(|k| of_name[k])
            })
            .collect())
    }

    /// The station of configuration `c` (an index into [`Dataset::stations`]; 0 without
    /// stations).
    pub fn station_of(&self, c: usize) -> usize {
        self.config_stations.get(c).copied().unwrap_or(0)
    }

    /// The index of station `name`, added to [`Dataset::stations`] if new. A data set
    /// without stations so far gets `name` for every configuration it has.
    pub fn station_index(&mut self, name: &str) -> usize {
        if let Some(s) = self.stations.iter().position(|s| s == name) {
            return s;
        }
        if self.stations.is_empty() {
            self.config_stations = vec![0; self.configurations.len()];
        }
        self.stations.push(name.to_string());
        self.stations.len() - 1
    }

    /// Every configuration of this data set at station `name` (the data of one set-up,
    /// before they are appended to another's, [`Dataset::append`]). The name is checked
    /// (`crate::model::station::check_name`); data that name their own stations already
    /// are an error.
    pub fn at_station(mut self, name: &str) -> Result<Dataset, crate::Error> {
        crate::model::station::check_name(name)
            .map_err(|e| crate::Error::Input(format!("station `{name}`: {e}")))?;
        if !self.stations.is_empty() {
            return Err(crate::Error::Input(format!(
                "{}: the data name their own stations ({}); give the file without a station",
                self.source,
                self.stations.join(", ")
            )));
        }
        self.stations = vec![name.to_string()];
        self.config_stations = vec![0; self.configurations.len()];
        Ok(self)
    }

    /// Appends `other`'s configurations (with their ids and stations, merged by name) and
    /// measurements, which then refer to the appended configurations.
    pub fn append(&mut self, other: &Dataset) {
        let offset = self.configurations.len();
        if !other.stations.is_empty() {
            let stations: Vec<usize> = other
                .stations
                .iter()
                .map(|s| self.station_index(s))
                .collect();
            self.config_stations
                .extend((0..other.configurations.len()).map(|c| stations[other.station_of(c)]));
        } else if !self.stations.is_empty() {
            self.config_stations
                .extend(std::iter::repeat_n(0, other.configurations.len()));
        }
        self.configurations
            .extend(other.configurations.iter().cloned());
        self.config_ids.extend(other.config_ids.iter().cloned());
        if !self.config_payloads.is_empty() {
            self.config_payloads.resize(self.configurations.len(), None);
        }
        for c in 0..other.configurations.len() {
            if let Some(p) = other.payload_of(c) {
                self.set_payload(offset + c, Some(p));
            }
        }
        for m in &other.measurements {
            let mut m = m.clone();
            m.config += offset;
            if let MeasurementKind::Distance { other, .. } = &mut m.kind {
                *other += offset;
            }
            self.measurements.push(m);
        }
    }

    /// The dataset restricted to the given configurations (measurements that refer to a
    /// dropped configuration through `Distance::other` are dropped too).
    pub fn subset(&self, configs: &[usize]) -> Dataset {
        let mut map = vec![usize::MAX; self.configurations.len()];
        let mut out = Dataset {
            source: self.source.clone(),
            stations: self.stations.clone(),
            ..Default::default()
        };
        for &c in configs {
            map[c] =
                out.push_configuration(self.config_ids[c].clone(), self.configurations[c].clone());
            if let Some(s) = out.config_stations.last_mut() {
                *s = self.station_of(c);
            }
            if let Some(p) = self.payload_of(c) {
                out.set_payload(map[c], Some(p));
            }
        }
        for m in &self.measurements {
            if map[m.config] == usize::MAX {
                continue;
            }
            let mut m2 = m.clone();
            m2.config = map[m.config];
            if let MeasurementKind::Distance { other, .. } = &mut m2.kind {
                if map[*other] == usize::MAX {
                    continue;
                }
                *other = map[*other];
            }
            out.measurements.push(m2);
        }
        out
    }
}
