//! Instrument stations: one fit over data an instrument took from several places (a tracker
//! moved between stations in one session, or set up again for each of several series).
//! The robot is the same at every station; the instrument's pose in the world is not.
//!
//! A data file names each row's station in a `station` column (or the caller gives a whole
//! file one station, [`crate::measure::Dataset::at_station`]); the stations are those the
//! data name, in order of first appearance. [`Model::with_stations`] repeats the
//! instrument's frame once per station: frame `<instrument>@<station>` with parameters
//! `<instrument>@<station>.<field>` (e.g. `tracker@B.x`, `tracker@B.rz`), each station's
//! starting from the cell's instrument and with its status (a cell's `tracker.rz` pattern
//! applies to every station's `rz`). A measurement at station s is `T_{I,s}⁻¹ T_target`
//! (paper eq. 3 with the instrument frame of its station): its Jacobian columns are those
//! of its own station's parameters, and zero for every other station's.
//!
//! Each extra station adds 6 identifiable parameters to the generic count (its pose relative
//! to the others, seen through the shared robot) for position and pose measurements, none
//! for distances, which do not see the instrument.

use crate::model::chain::{Model, ModelSpec};
use crate::model::registry::Segment;
use crate::Error;

/// The separator of an instrument's name and a station's in a station's frame name.
pub const SEPARATOR: char = '@';

/// The frame name of `instrument` at `station`: `tracker@B`.
pub fn frame_name(instrument: &str, station: &str) -> String {
    format!("{instrument}{SEPARATOR}{station}")
}

/// Whether `station` can name a station: not empty, and none of `.`, `*`, `@`, `,` or white
/// space (it becomes part of parameter names and patterns). The error says why.
pub fn check_name(station: &str) -> Result<(), String> {
    if station.is_empty() {
        return Err("a station name cannot be empty".into());
    }
    match station
        .chars()
        .find(|c| c.is_whitespace() || matches!(c, '.' | '*' | '@' | ','))
    {
        Some(c) => Err(format!(
            "a station name cannot contain `{c}` (it becomes part of parameter names such as `tracker@{}.x`)",
            station.replace(c, "_")
        )),
        None => Ok(()),
    }
}

impl Model {
    /// This model (one instrument pose) with the instrument's frame repeated once per
    /// station in `stations` (see the module documentation): every parameter keeps its
    /// nominal value and status, each station's instrument parameters those of the
    /// instrument. An empty list gives the model as it is; a model without an instrument,
    /// or already with stations, and a repeated or malformed station name are errors.
    pub fn with_stations(&self, stations: &[String]) -> Result<Model, Error> {
        if stations.is_empty() {
            return Ok(self.clone());
        }
        if !self.stations.is_empty() {
            return Err(Error::Model(format!(
                "model `{}` already has stations",
                self.name
            )));
        }
        for (k, s) in stations.iter().enumerate() {
            check_name(s).map_err(|e| Error::Input(format!("station `{s}`: {e}")))?;
            if stations[..k].contains(s) {
                return Err(Error::Input(format!("station `{s}` is named twice")));
            }
        }
        let mut spec: ModelSpec = self.spec();
        let instrument_params = self.instrument.as_ref().map_or(0, |l| l.param_count());
        if let Some(c) = &mut spec.compliance {
            // the levers are a parameter vector: the instrument's once per station
            let mut levers = Vec::with_capacity(c.levers.len() + instrument_params);
            for _ in stations {
                levers.extend_from_slice(&c.levers[..instrument_params]);
            }
            levers.extend_from_slice(&c.levers[instrument_params..]);
            c.levers = levers;
        }
        let mut model = Model::compile(&spec, stations)?;
        for i in 0..model.param_count() {
            let source = self.station_source(&model, i);
            let status = self.registry.get(source).status;
            model.registry.set_status(i, status);
        }
        // a correlated prior keeps the parameters it names; an instrument's own, which the
        // stations rename, leave it (marginalised, `crate::model::prior`)
        model
            .registry
            .set_correlated_prior(self.registry.correlated_prior().cloned())?;
        Ok(model)
    }

    /// The parameter of this model (without stations) that parameter `i` of `stationed`
    /// (this model [`Model::with_stations`]) comes from: the instrument's same field for a
    /// station's parameter, the parameter of the same name otherwise.
    pub fn station_source(&self, stationed: &Model, i: usize) -> usize {
        let p = stationed.registry.get(i);
        let name = match (p.segment, &self.instrument) {
            (Segment::Instrument, Some(instrument)) => {
                let field = p.name.rsplit_once('.').map_or("", |(_, f)| f);
                format!("{}.{field}", instrument.spec.name)
            }
            _ => p.name.clone(),
        };
        self.registry
            .index_of(&name)
            .expect("a stationed model has its source's parameters")
    }

    /// The name of station `s` (`None` without stations): the frame name after the
    /// separator.
    pub fn station_name(&self, s: usize) -> Option<&str> {
        self.stations
            .get(s)
            .and_then(|l| l.spec.name.split_once(SEPARATOR))
            .map(|(_, station)| station)
    }
}
