//! Whether the data and the model speak the same units (issue 30 item 4a): a length written
//! in metres or inches where millimetres are meant, an angle in radians where degrees are
//! meant, converges to a rescaled robot that fits well, so only a comparison of scales finds
//! it.
//!
//! **Data extent against the model** ([`data_scale`]). The distance between two measured
//! points of one target at one instrument station does not depend on where the instrument
//! stands, so it can be compared with the distance the nominal model predicts between the
//! same two configurations before any frame is fitted. The median of the ratios
//! `s = d_measured / d_model` over all such pairs is 1 within the nominal model's error (a
//! few mm over distances of hundreds of mm: `|s − 1|` below a few %); a unit mistake makes
//! it 1/1000 (metres), 1/25.4 (inches), 1/10 (centimetres), 1/304.8 (feet) or the inverse.
//! `s` outside [2/3, 3/2] is a finding, named by the unit whose factor is within 15 % of
//! `s` (nothing in between is a unit). Which side holds the wrong unit follows from the
//! model's arm length ([`arm_length`]): no serial robot armcal calibrates is shorter than
//! [`PLAUSIBLE_ARM_MM`]`.0` or longer than `.1`, so a model outside that range holds the
//! wrong unit, else the data do. Before the lengths, the joint angles are tried read the
//! other way (radians as degrees and back): if that brings `s` within 10 % of 1, the
//! finding names the joint columns.
//!
//! **Fitted against nominal lengths** ([`fitted_lengths`]): a single length written in the
//! wrong unit (`d_m = 400` for 400 mm) moves the model's scale little, but the fit brings
//! that parameter to its true value, a unit factor away from its nominal.
//!
//! **Blunders** ([`DataScale::blunders`]): with the scale right, a measurement whose
//! distances to the others disagree with the model's by more than any plausible model error
//! (the median over its pairs, [`super::fit_checks::plausible_model_error`]) is a blunder
//! (one coordinate of 10¹² mm).

use super::ParameterEstimate;
use crate::measure::{Dataset, MeasurementKind};
use crate::model::Segment;
use crate::model::{forward_kinematics, observed_position, Data, JointKind, Model, Observed};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// The lengths of unit mistakes: millimetres per unit, the unit's name, and how a data
/// column in it is named (empty: armcal reads no such column; convert the values).
const LENGTH_UNITS: [(f64, &str, &str); 4] = [
    (1000.0, "metres", "`x_m`, `y_m`, `z_m`"),
    (25.4, "inches", "`x_in`, `y_in`, `z_in`"),
    (10.0, "centimetres", ""),
    (304.8, "feet", ""),
];

/// The arm lengths (mm, [`arm_length`]) of every serial robot armcal calibrates lie within
/// this range: a table-top arm is longer than 100 mm, the largest industrial arms and
/// gantries shorter than 20 m.
pub const PLAUSIBLE_ARM_MM: (f64, f64) = (100.0, 20_000.0);

/// A scale ratio `s` is a finding when `|ln s| > ln 1.5`.
const SCALE_BAND: f64 = 1.5;
/// A ratio is named by a unit whose factor is within 15 % of it.
const UNIT_MATCH: f64 = 1.15;
/// Joint angles read the other way explain the data when they bring `s` within 10 % of 1.
const ANGLE_MATCH: f64 = 1.1;
/// At most this many measurements per target and station enter the pairs.
const SAMPLE: usize = 300;

/// One unit the data or the model likely holds where another is meant.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct UnitFinding {
    /// What holds the wrong unit: `data lengths`, `joint angles`, `model lengths` or a
    /// parameter's name.
    pub subject: String,
    /// The ratio found: measured over model distances, or fitted over nominal value.
    pub ratio: f64,
    /// The unit likely written (`metres`, `inches`, `radians`, …); empty when no unit
    /// explains the ratio.
    pub likely_unit: String,
    /// One sentence: what was compared, what it suggests, what to check.
    pub message: String,
}

/// The data's scale against the nominal model's ([`data_scale`]).
#[derive(Clone, Debug, Default)]
pub struct DataScale {
    /// The unit mistakes found (at most one).
    pub findings: Vec<UnitFinding>,
    /// With the scale right: the measurements (indices into the data's measurements) whose
    /// median distance discrepancy exceeds the plausible model error, with it (mm); empty
    /// when more than 5 % of the measurements would be (then the model, not a row, is
    /// wrong).
    pub blunders: Vec<(usize, f64)>,
}

/// The length of the arm at `params` (mm): the sum of the distances between consecutive
/// chain frame origins from the base to the tool, and on to the farthest target, at q = 0.
/// An upper bound of the reach that does not depend on the configuration.
pub fn arm_length(model: &Model, params: &[f64]) -> f64 {
    let mut data = Data::new(model);
    let q = vec![0.0; model.dof()];
    forward_kinematics(model, &mut data, params, &q);
    let chain: f64 = data
        .frames
        .windows(2)
        .map(|w| (w[1].trans - w[0].trans).norm())
        .sum();
    let tool = data.tool().trans;
    let target = data
        .targets
        .iter()
        .map(|t| (t.trans - tool).norm())
        .fold(0.0, f64::max);
    chain + target
}

/// The position-bearing measurements grouped by (target, station), at most [`SAMPLE`] per
/// group (evenly spread), as measurement indices.
fn pair_groups(data: &Dataset) -> Vec<Vec<usize>> {
    let mut groups: Vec<((Observed, usize), Vec<usize>)> = Vec::new();
    for (i, m) in data.measurements.iter().enumerate() {
        if measured_position(&m.kind).is_none() {
            continue;
        }
        let key = (
            m.observed,
            data.config_stations.get(m.config).copied().unwrap_or(0),
        );
        match groups.iter_mut().find(|(k, _)| *k == key) {
            Some((_, v)) => v.push(i),
            None => groups.push((key, vec![i])),
        }
    }
    groups
        .into_iter()
        .map(|(_, v)| {
            let step = v.len().div_ceil(SAMPLE).max(1);
            v.into_iter().step_by(step).collect()
        })
        .filter(|v: &Vec<usize>| v.len() >= 2)
        .collect()
}

/// The measured position of a position or pose measurement (instrument frame, mm).
fn measured_position(kind: &MeasurementKind) -> Option<Vector3<f64>> {
    match kind {
        MeasurementKind::Position { value, .. } => Some(*value),
        MeasurementKind::Pose { value, .. } => Some(value.trans),
        _ => None,
    }
}

/// The model's position of every measurement's observed point (instrument frame of its
/// station, mm) at `params`, the revolute joints of the data multiplied by `angle_factor`;
/// `None` for measurements without a position.
fn predicted(
    model: &Model,
    params: &[f64],
    data: &Dataset,
    angle_factor: f64,
) -> Vec<Option<Vector3<f64>>> {
    let mut ws = Data::new(model);
    let payloads = data
        .model_payloads(model)
        .unwrap_or_else(|_| vec![None; data.configurations.len()]);
    data.measurements
        .iter()
        .map(|m| {
            measured_position(&m.kind)?;
            let q: Vec<f64> = data.configurations[m.config]
                .iter()
                .zip(&model.joints)
                .map(|(v, j)| match j.kind {
                    JointKind::Revolute => v * angle_factor,
                    JointKind::Prismatic => *v,
                })
                .collect();
            ws.station = data.config_stations.get(m.config).copied().unwrap_or(0);
            ws.payload = payloads.get(m.config).copied().flatten();
            forward_kinematics(model, &mut ws, params, &q);
            Some(observed_position(&ws, m.observed))
        })
        .collect()
}

/// The pairs `(i, j, d_measured, d_model)` of every group, with `d_model` at least 5 % of
/// the group's largest (the ratio of shorter ones is dominated by the model's error).
fn pairs(
    data: &Dataset,
    groups: &[Vec<usize>],
    model_points: &[Option<Vector3<f64>>],
) -> Vec<(usize, usize, f64, f64)> {
    let mut out = Vec::new();
    for g in groups {
        let start = out.len();
        for (a, &i) in g.iter().enumerate() {
            for &j in &g[a + 1..] {
                let (Some(mi), Some(mj)) = (
                    measured_position(&data.measurements[i].kind),
                    measured_position(&data.measurements[j].kind),
                ) else {
                    continue;
                };
                let (Some(pi), Some(pj)) = (model_points[i], model_points[j]) else {
                    continue;
                };
                out.push((i, j, (mi - mj).norm(), (pi - pj).norm()));
            }
        }
        let longest = out[start..].iter().map(|p| p.3).fold(0.0, f64::max);
        let mut k = start;
        while k < out.len() {
            if out[k].3 < 0.05 * longest || !out[k].2.is_finite() {
                out.swap_remove(k);
            } else {
                k += 1;
            }
        }
    }
    out
}

/// The median of `v` (`None` when empty); reorders `v`.
pub(crate) fn median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let mid = v.len() / 2;
    let (_, m, _) = v.select_nth_unstable_by(mid, f64::total_cmp);
    Some(*m)
}

/// The median ratio `d_measured / d_model` of the pairs at joint-angle factor
/// `angle_factor`.
fn scale_at(
    model: &Model,
    params: &[f64],
    data: &Dataset,
    groups: &[Vec<usize>],
    f: f64,
) -> Option<f64> {
    let points = predicted(model, params, data, f);
    let mut ratios: Vec<f64> = pairs(data, groups, &points)
        .iter()
        .map(|p| p.2 / p.3)
        .collect();
    median(&mut ratios)
}

/// The unit a ratio `s` of data over model lengths names: `Some((columns, unit,
/// data_small))` with the unit's data columns ([`LENGTH_UNITS`]) and `data_small` when the
/// data's lengths are the smaller (s ≈ 1/factor).
fn length_unit(s: f64) -> Option<(&'static str, &'static str, bool)> {
    LENGTH_UNITS.iter().find_map(|&(f, name, columns)| {
        if (s * f).ln().abs() < UNIT_MATCH.ln() {
            Some((columns, name, true))
        } else if (s / f).ln().abs() < UNIT_MATCH.ln() {
            Some((columns, name, false))
        } else {
            None
        }
    })
}

/// The data's scale against the nominal model at `params` (see the module doc): the unit
/// mistake it names, if any, and with the scale right the blunder measurements whose
/// median distance discrepancy exceeds `tolerance_mm` (the plausible model error).
pub fn data_scale(model: &Model, params: &[f64], data: &Dataset, tolerance_mm: f64) -> DataScale {
    let groups = pair_groups(data);
    let points = predicted(model, params, data, 1.0);
    let all = pairs(data, &groups, &points);
    let mut ratios: Vec<f64> = all.iter().map(|p| p.2 / p.3).collect();
    let Some(s) = median(&mut ratios) else {
        return DataScale::default();
    };
    let in_band = s.ln().abs() <= SCALE_BAND.ln();
    if in_band {
        return DataScale {
            findings: Vec::new(),
            blunders: blunders(data, &all, s, tolerance_mm),
        };
    }
    let degrees = 180.0 / std::f64::consts::PI;
    let angles = [
        (degrees, "radians", "degrees"),
        (1.0 / degrees, "degrees", "radians"),
    ];
    let revolute = model.joints.iter().any(|j| j.kind == JointKind::Revolute);
    for (f, written, read) in angles.into_iter().filter(|_| revolute) {
        let Some(t) = scale_at(model, params, data, &groups, f) else {
            continue;
        };
        if t.ln().abs() < ANGLE_MATCH.ln() {
            let message = format!(
                "the measured points lie {s:.3}× as far apart as the model predicts at the data's joint values, and {t:.3}× read as {written}: the revolute joint columns, read as {read}, likely hold {written} (rename them, e.g. `q1_{}`, or convert the values)",
                if written == "radians" { "rad" } else { "deg" }
            );
            return finding(s, "joint angles", written, message);
        }
    }
    let arm = arm_length(model, params);
    let model_wrong = arm < PLAUSIBLE_ARM_MM.0 || arm > PLAUSIBLE_ARM_MM.1;
    let plausible = format!(
        "the model's arm is {arm:.0} mm long ({} {:.0}–{:.0} mm)",
        if model_wrong { "outside" } else { "within" },
        PLAUSIBLE_ARM_MM.0,
        PLAUSIBLE_ARM_MM.1
    );
    let compared = format!("the measured points lie {s:.4}× as far apart as the model predicts");
    let (subject, unit, message) = match length_unit(s) {
        Some((_, unit, true)) if model_wrong => (
            "model lengths",
            unit,
            format!("{compared}, and {plausible}: the model's lengths are likely millimetres written where {unit} are meant (a URDF is in metres; a cell field `_m` in metres), so the model is too large"),
        ),
        Some((columns, unit, true)) => (
            "data lengths",
            unit,
            format!(
                "{compared}, and {plausible}: the data's length columns, read as millimetres, likely hold {unit} ({})",
                if columns.is_empty() {
                    "convert the values to millimetres".to_string()
                } else {
                    format!("name them {columns}, or convert the values to millimetres")
                }
            ),
        ),
        Some((_, unit, false)) if model_wrong => (
            "model lengths",
            unit,
            format!("{compared}, and {plausible}: the model's lengths are likely {unit} written where millimetres are meant (a cell field `_mm`), so the model is too small"),
        ),
        Some((_, unit, false)) => (
            "data lengths",
            unit,
            format!("{compared}, and {plausible}: the data's length columns likely hold millimetres where {unit} are read (a column `_m` or `_in` holding mm)"),
        ),
        None => (
            if model_wrong { "model lengths" } else { "data lengths" },
            "",
            format!("{compared}, and {plausible}; no common unit explains the factor: check the model's lengths and the data's length and joint columns"),
        ),
    };
    finding(s, subject, unit, message)
}

/// A data scale with one finding.
fn finding(s: f64, subject: &str, unit: &str, message: String) -> DataScale {
    DataScale {
        findings: vec![UnitFinding {
            subject: subject.to_string(),
            ratio: s,
            likely_unit: unit.to_string(),
            message,
        }],
        blunders: Vec::new(),
    }
}

/// The measurements whose median discrepancy `|d_measured − s d_model|` over their pairs
/// exceeds `tolerance_mm`, worst first; empty when more than 5 % of the measurements
/// (at least one) would be.
fn blunders(
    data: &Dataset,
    pairs: &[(usize, usize, f64, f64)],
    s: f64,
    tolerance_mm: f64,
) -> Vec<(usize, f64)> {
    let mut by_row: Vec<Vec<f64>> = vec![Vec::new(); data.measurements.len()];
    for &(i, j, dm, dp) in pairs {
        let e = (dm - s * dp).abs();
        by_row[i].push(e);
        by_row[j].push(e);
    }
    let mut out: Vec<(usize, f64)> = by_row
        .iter_mut()
        .enumerate()
        .filter_map(|(i, v)| median(v).map(|m| (i, m)))
        .filter(|&(_, m)| m > tolerance_mm)
        .collect();
    out.sort_by(|a, b| b.1.total_cmp(&a.1));
    let allowed = (data.measurements.len() / 20).max(1);
    if out.len() > allowed {
        return Vec::new();
    }
    out
}

/// The free chain lengths whose fitted value lies a unit factor from the nominal (a length
/// written in metres where mm are meant: nominal 400 000 mm, fitted 400 mm): `parameters`
/// are an estimate's of `model` (display units), nominal at least 20 mm.
pub fn fitted_lengths(model: &Model, parameters: &[ParameterEstimate]) -> Vec<UnitFinding> {
    parameters
        .iter()
        .filter(|p| p.free && p.unit == "mm" && p.nominal.abs() >= 20.0 && p.estimate != 0.0)
        .filter(|p| {
            model
                .registry
                .index_of(&p.name)
                .is_some_and(|i| model.registry.get(i).segment == Segment::Chain)
        })
        .filter_map(|p| {
            let r = p.estimate / p.nominal;
            let (_, unit, smaller) = length_unit(r.abs())?;
            let (name, fitted, nominal) = (&p.name, p.estimate, p.nominal);
            let message = if smaller {
                format!(
                    "`{name}` was fitted to {fitted:.1} mm from its nominal {nominal:.1} mm ({r:.4}× the nominal): the nominal is likely millimetres written where {unit} are meant (a field `_m` holding mm: `d_m = 400` for 400 mm)"
                )
            } else {
                format!(
                    "`{name}` was fitted to {fitted:.1} mm from its nominal {nominal:.1} mm ({r:.1}× the nominal): the nominal is likely {unit} written where millimetres are meant (a field `_mm` holding {unit})"
                )
            };
            Some(UnitFinding {
                subject: name.clone(),
                ratio: r,
                likely_unit: unit.to_string(),
                message,
            })
        })
        .collect()
}
