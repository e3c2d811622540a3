//! The held-out error of an estimate against the air temperature its data recorded
//! ([`crate::identify::held_out`]): per station (or for the whole validation set) the RMS
//! position and orientation error in bins of [`BIN_C`], as a table and two figures. Whether
//! a calibration's error changes with the temperature shows here; nothing without
//! temperatures.

use super::figures::{series_figure, Reference};
use super::html::{escape, fixed, table, tagged, Section};
use crate::identify::held_out::{by_temperature, GroupErrors, HeldOutError};
use crate::identify::Estimate;
use crate::Error;

/// Width of a temperature bin (°C).
pub const BIN_C: f64 = 0.25;

/// The held-out errors `rows` per station (one group, `held out`, without stations), each
/// binned by temperature.
fn binned(rows: &[HeldOutError]) -> Vec<(String, Vec<GroupErrors>)> {
    let mut stations: Vec<Option<&str>> = Vec::new();
    for r in rows {
        if !stations.contains(&r.station.as_deref()) {
            stations.push(r.station.as_deref());
        }
    }
    stations
        .into_iter()
        .map(|s| {
            let members: Vec<HeldOutError> = rows
                .iter()
                .filter(|r| r.station.as_deref() == s)
                .cloned()
                .collect();
            let name = s.map_or("held out".to_string(), |s| format!("station {s}"));
            (name, by_temperature(&members, BIN_C))
        })
        .filter(|(_, bins)| !bins.is_empty())
        .collect()
}

/// Appends the held-out error against temperature of `e` (labelled `label`) to `s`; nothing
/// when its validation recorded no temperature.
pub fn temperature_block(s: &mut Section, label: &str, e: &Estimate) -> Result<(), Error> {
    let Some(v) = &e.validation else {
        return Ok(());
    };
    let groups = binned(&v.errors);
    if groups.is_empty() {
        return Ok(());
    }
    s.html("<h3>Held-out error against temperature</h3>\n");
    let rows: Vec<Vec<String>> = groups
        .iter()
        .flat_map(|(name, bins)| {
            bins.iter().map(move |b| {
                vec![
                    name.clone(),
                    b.group.clone(),
                    b.position.count.to_string(),
                    b.temperature_c.map_or(String::new(), |t| fixed(t, 2)),
                    fixed(b.position.rms, 4),
                    fixed(b.position.p95, 4),
                    b.orientation
                        .as_ref()
                        .map_or(String::new(), |o| fixed(o.rms, 4)),
                ]
            })
        })
        .collect();
    s.html(table(
        &[
            "",
            "temperature bin",
            "measurements",
            "mean (°C)",
            "RMS position error (mm)",
            "p95 position error (mm)",
            "RMS orientation error (deg)",
        ],
        &rows,
        &[2, 3, 4, 5, 6],
    ));
    let points = |f: &dyn Fn(&GroupErrors) -> Option<f64>| -> Vec<(String, Vec<(f64, f64)>)> {
        groups
            .iter()
            .map(|(name, bins)| {
                let pts = bins
                    .iter()
                    .filter_map(|b| Some((b.temperature_c?, f(b)?)))
                    .collect();
                (name.clone(), pts)
            })
            .collect()
    };
    let figures = [
        (
            "position",
            "RMS position error (mm)",
            points(&|b| Some(b.position.rms)),
            v.calibrated.rms,
        ),
        (
            "orientation",
            "RMS orientation error (deg)",
            points(&|b| b.orientation.as_ref().map(|o| o.rms)),
            v.orientation
                .as_ref()
                .map_or(f64::NAN, |o| o.calibrated.rms),
        ),
    ];
    for (what, axis, series, overall) in figures {
        if series.iter().all(|(_, p)| p.is_empty()) {
            continue;
        }
        let references: Vec<Reference> = [overall]
            .into_iter()
            .filter(|x| x.is_finite())
            .map(|value| Reference {
                label: format!("all held-out measurements: {}", fixed(value, 4)),
                value,
            })
            .collect();
        s.figure(
            tagged(
                series_figure(
                    &format!("Held-out {what} error against temperature — {label}"),
                    "air temperature (°C)",
                    axis,
                    &series,
                    &references,
                )?,
                &format!("held-out-temperature-{what}"),
            ),
            format!(
                "RMS {what} error of <em>{}</em> on the held-out measurements, in bins of {BIN_C} °C of the air temperature recorded with them (each point at its bin's mean temperature; the bins' counts are in the table above). A calibration whose error grows away from the temperature it was fitted at rises to the sides.",
                escape(label)
            ),
        );
    }
    Ok(())
}
