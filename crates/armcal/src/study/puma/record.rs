//! The files of `armcal study puma`: the JSON record of a run ([`PumaRecord`],
//! `puma.json`) and the study's two tables as CSV (`puma-conversion.csv` for Tables
//! 6.9/6.10, `puma-accuracy.csv` for Table 6.13).

use super::{run, PumaSettings, PumaStudy};
use crate::progress::Observer;
use crate::table::Table;
use crate::Error;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// `puma.json`: the study's result and how long it took.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PumaRecord {
    /// "puma".
    pub study: String,
    /// Wall-clock time of the study (s).
    pub seconds: f64,
    /// The study's result.
    pub result: PumaStudy,
}

impl PumaRecord {
    /// The record as JSON (keys in alphabetical order, see `crate::json`).
    pub fn to_json(&self) -> Result<String, Error> {
        crate::json::sorted_pretty(self)
    }
}

/// Runs the study ([`run`]), timed; `observer` sees its fits.
pub fn run_record(s: &PumaSettings, observer: &mut dyn Observer) -> Result<PumaRecord, Error> {
    let t0 = Instant::now();
    let result = run(s, observer)?;
    Ok(PumaRecord {
        study: "puma".into(),
        seconds: t0.elapsed().as_secs_f64(),
        result,
    })
}

impl PumaStudy {
    /// Tables 6.9/6.10 as CSV: per transform its fields and the three parameters of each
    /// column (converted, identified, σ, truth, book converted, book identified).
    pub fn conversion_csv(&self) -> String {
        let three = |c: &'static str| (1..=3).map(move |i| format!("{c}_p{i}"));
        let mut conv = Table::new(
            ["transform", "link", "field1", "field2", "field3"]
                .map(String::from)
                .into_iter()
                .chain(
                    ["conv", "ident", "sigma", "truth", "book_conv", "book_ident"]
                        .into_iter()
                        .flat_map(three),
                ),
        );
        for r in &self.conversion {
            let values = [
                r.converted,
                r.identified,
                r.identified_sigma,
                r.truth,
                r.book_converted,
                r.book_identified,
            ];
            conv.row(
                [r.transform.clone(), r.link.clone()]
                    .into_iter()
                    .chain(r.fields.iter().cloned())
                    .chain(values.iter().flatten().map(|x| format!("{x:.6}"))),
            );
        }
        conv.into_string()
    }

    /// Table 6.13 as CSV: per held-out pose δr (in) and δθ (deg) of each model, armcal's
    /// and the book's (empty where the book has no pose of that number).
    pub fn accuracy_csv(&self) -> String {
        let columns = ["nominal", "mdh", "zrp"]
            .into_iter()
            .flat_map(|m| [format!("{m}_dr_in"), format!("{m}_dtheta_deg")]);
        let mut acc = Table::new(
            std::iter::once("pose".to_string())
                .chain(columns.clone())
                .chain(columns.map(|c| format!("book_{c}"))),
        );
        for r in &self.held_out {
            let book = match r.book {
                Some(b) => [
                    b.nominal_dr_in,
                    b.nominal_dtheta_deg,
                    b.mdh_dr_in,
                    b.mdh_dtheta_deg,
                    b.zrp_dr_in,
                    b.zrp_dtheta_deg,
                ]
                .map(|x| x.to_string()),
                None => Default::default(),
            };
            let ours = [
                r.nominal_dr_in,
                r.nominal_dtheta_deg,
                r.mdh_dr_in,
                r.mdh_dtheta_deg,
                r.zrp_dr_in,
                r.zrp_dtheta_deg,
            ]
            .map(|x| format!("{x:.6}"));
            acc.row(std::iter::once(r.pose.to_string()).chain(ours).chain(book));
        }
        acc.into_string()
    }
}
