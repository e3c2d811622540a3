//! Whether the instrument stations a data set names (`crate::model::station`) can be
//! located from their own rows, and how many one fit takes: a bad `station` column must not
//! grow the identification without bound (a fuzzing finding, issue 15).

use crate::measure::{Dataset, MeasurementKind};
use crate::Error;
use std::collections::BTreeMap;

/// Most stations one fit takes. Each adds six parameters; a few hundred make the
/// identification's dense algebra slow (its cost grows with the cube of the parameters)
/// for no campaign an instrument could take.
pub const MAX_STATIONS: usize = 100;

/// What locates a station: its pose has six parameters, so it needs at least six residual
/// rows of its own that see it — 3 per measured position, 6 per pose, 1 per distance to a
/// fixed point or point on a plane; distances between two poses do not see it.
pub const MIN_STATION_ROWS: usize = 6;

/// The residual rows of a measurement that see its instrument station's pose.
fn station_rows(kind: &MeasurementKind) -> usize {
    match kind {
        MeasurementKind::Position { .. } => 3,
        MeasurementKind::Pose { .. } => 6,
        MeasurementKind::Distance { .. } => 0,
        MeasurementKind::DistanceToPoint { .. } | MeasurementKind::OnPlane { .. } => 1,
    }
}

/// Checks that every station `data` names can be located from its own rows: at most
/// [`MAX_STATIONS`], each with [`MIN_STATION_ROWS`] residual rows that see it. The error
/// names the station, what it has and the line of its first row.
pub fn check_stations(data: &Dataset) -> Result<(), Error> {
    if data.stations.len() > MAX_STATIONS {
        return Err(Error::Input(format!(
            "the data name {} instrument stations; armcal fits at most {MAX_STATIONS} in one \
             go (each adds 6 parameters): is the `station` column the one you meant?",
            data.stations.len()
        )));
    }
    for (s, name) in data.stations.iter().enumerate() {
        let own = || {
            data.measurements
                .iter()
                .filter(move |m| data.station_of(m.config) == s)
        };
        if own().map(|m| station_rows(&m.kind)).sum::<usize>() >= MIN_STATION_ROWS {
            continue;
        }
        let mut kinds: BTreeMap<&str, usize> = BTreeMap::new();
        for m in own() {
            *kinds.entry(m.kind.name()).or_default() += 1;
        }
        let has: Vec<String> = kinds.iter().map(|(k, n)| format!("{n} × {k}")).collect();
        let at = match own().map(|m| m.line).filter(|&l| l > 0).min() {
            Some(line) => format!(" (first row on line {line})"),
            None => String::new(),
        };
        return Err(Error::Input(format!(
            "station `{name}`{at} cannot be located: its instrument pose (6 parameters) needs \
             2 measured positions or 1 full pose of its own, and it has {}; measure more from \
             it, or give its rows the station they were measured from",
            if has.is_empty() {
                "none".to_string()
            } else {
                has.join(", ")
            }
        )));
    }
    Ok(())
}
