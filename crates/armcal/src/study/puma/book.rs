//! The book's Chapter 6 tables (embedded from `tests/data/book/`, in the book's units), the
//! PUMA 560 models built from them, and Table 6.13's accuracies.

use crate::measure::NoiseModel;
use crate::model::{LinkGeometry, LinkSpec, Model, ModelSpec, ParameterStatus};
use crate::robots::puma560::book_dh_spec;
use crate::Error;
use serde::{Deserialize, Serialize};

macro_rules! table {
    ($file:literal) => {
        include_str!(concat!("../../../tests/data/book/", $file))
    };
}

/// Table 6.1: nominal modified-DH PUMA (in, deg).
pub const TABLE_6_1: &str = table!("table_6_1_puma_nominal_modified_dh.csv");
/// Table 6.2: nominal zero-reference PUMA (in).
pub const TABLE_6_2: &str = table!("table_6_2_zrp_nominal_in.csv");
/// Eq. 6.11: T₀ of the zero-reference PUMA (in).
pub const EQ_6_11: &str = table!("eq_6_11_zrp_T0_in.csv");
/// Table 6.4: σ of the CMM pose estimate (rad, mm).
pub const TABLE_6_4: &str = table!("table_6_4_measurement_std.csv");
/// Table 6.5: modified-DH parameters identified from data file 1 (in, deg).
pub const TABLE_6_5: &str = table!("table_6_5_identified_mdh_datafile1.csv");
/// Table 6.9: converted vs identified parameters 1–3, data file 1.
pub const TABLE_6_9: &str = table!("table_6_9_converted_vs_identified_datafile1.csv");
/// Table 6.13: δθ (deg), δr (in) of nominal / modified DH / ZRP on 10 poses.
pub const TABLE_6_13: &str = table!("table_6_13_accuracy_of_models.csv");

pub(super) fn csv_rows(text: &str) -> Vec<Vec<String>> {
    text.lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split(',').map(|c| c.trim().to_string()).collect())
        .collect()
}

pub(super) fn num(s: &str) -> f64 {
    s.parse().unwrap_or(f64::NAN)
}

/// Table 6.4 as an armcal noise model: σ per position axis as printed (mm); armcal's
/// constant model has one σ for the three rotation rows, the RMS of the printed three
/// (0.000575 rad = 0.0330°). armcal adds the noise in the CMM frame, the book estimated it
/// in the end-effector frame (eq. 6.17); with σ this close to isotropic the difference does
/// not matter.
pub fn table_6_4_noise() -> NoiseModel {
    let mut rot = Vec::new();
    let mut pos = Vec::new();
    for r in csv_rows(TABLE_6_4) {
        if r[0].starts_with("delta_") {
            rot.push(num(&r[1]));
        } else {
            pos.push(num(&r[1]));
        }
    }
    let ms = rot.iter().map(|s| s * s).sum::<f64>() / rot.len() as f64;
    NoiseModel::Constant {
        sigma: [pos[0], pos[1], pos[2]],
        sigma_angle: ms.sqrt(),
    }
}

/// `spec` with the CMM measuring the end-effector frame: a fixed `frame6` target `tcp` at
/// the tool (so that `sim::simulate` makes pose measurements); `tool` and `tcp` fixed.
pub fn with_tcp(spec: &ModelSpec) -> Result<Model, Error> {
    let mut spec = spec.clone();
    spec.targets.push(LinkSpec {
        name: "tcp".into(),
        geometry: LinkGeometry::frame6([0.0; 3], [0.0; 3]),
        joint: None,
    });
    let mut m = Model::from_spec(&spec)?;
    m.set_status("tool", ParameterStatus::Fixed)?;
    m.set_status("tcp", ParameterStatus::Fixed)?;
    Ok(m)
}

/// The book's modified-DH model from a Table 6.1-format CSV, with the `tcp` target; free:
/// the book's 30 parameters.
pub fn book_model(name: &str, csv: &str) -> Result<Model, Error> {
    with_tcp(&book_dh_spec(name, csv)?)
}

/// A row of Table 6.13 (or its means).
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct BookAccuracy {
    /// δr (in) of the nominal model.
    pub nominal_dr_in: f64,
    /// δθ (deg) of the nominal model.
    pub nominal_dtheta_deg: f64,
    /// δr (in) of the calibrated modified-DH model.
    pub mdh_dr_in: f64,
    /// δθ (deg) of the calibrated modified-DH model.
    pub mdh_dtheta_deg: f64,
    /// δr (in) of the calibrated zero-reference model.
    pub zrp_dr_in: f64,
    /// δθ (deg) of the calibrated zero-reference model.
    pub zrp_dtheta_deg: f64,
}

/// Table 6.13 as transcribed.
pub fn table_6_13() -> Vec<BookAccuracy> {
    csv_rows(TABLE_6_13)
        .iter()
        .map(|r| BookAccuracy {
            nominal_dtheta_deg: num(&r[1]),
            nominal_dr_in: num(&r[2]),
            mdh_dtheta_deg: num(&r[3]),
            mdh_dr_in: num(&r[4]),
            zrp_dtheta_deg: num(&r[5]),
            zrp_dr_in: num(&r[6]),
        })
        .collect()
}

pub(super) fn mean_accuracy(rows: &[BookAccuracy]) -> BookAccuracy {
    let n = rows.len().max(1) as f64;
    let m = |f: fn(&BookAccuracy) -> f64| rows.iter().map(f).sum::<f64>() / n;
    BookAccuracy {
        nominal_dr_in: m(|r| r.nominal_dr_in),
        nominal_dtheta_deg: m(|r| r.nominal_dtheta_deg),
        mdh_dr_in: m(|r| r.mdh_dr_in),
        mdh_dtheta_deg: m(|r| r.mdh_dtheta_deg),
        zrp_dr_in: m(|r| r.zrp_dr_in),
        zrp_dtheta_deg: m(|r| r.zrp_dtheta_deg),
    }
}
