//! The files of `armcal study puma`: the JSON record of a run ([`PumaRecord`],
//! `puma.json`) and the study's two tables as CSV (`puma-conversion.csv` for Tables
//! 6.9/6.10, `puma-accuracy.csv` for Table 6.13).

use super::{run, PumaSettings, PumaStudy};
use crate::progress::Observer;
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
    /// The record as JSON (keys in alphabetical order, see [`crate::json`]).
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
        let mut conv = String::from(
            "transform,link,field1,field2,field3,conv_p1,conv_p2,conv_p3,ident_p1,ident_p2,ident_p3,\
             sigma_p1,sigma_p2,sigma_p3,truth_p1,truth_p2,truth_p3,book_conv_p1,book_conv_p2,book_conv_p3,book_ident_p1,\
             book_ident_p2,book_ident_p3\n",
        );
        for r in &self.conversion {
            let v: Vec<String> = [
                r.converted,
                r.identified,
                r.identified_sigma,
                r.truth,
                r.book_converted,
                r.book_identified,
            ]
            .iter()
            .flatten()
            .map(|x| format!("{x:.6}"))
            .collect();
            conv.push_str(&format!(
                "{},{},{},{}\n",
                r.transform,
                r.link,
                r.fields.join(","),
                v.join(",")
            ));
        }
        conv
    }

    /// Table 6.13 as CSV: per held-out pose δr (in) and δθ (deg) of each model, armcal's
    /// and the book's (empty where the book has no pose of that number).
    pub fn accuracy_csv(&self) -> String {
        let mut acc = String::from(
            "pose,nominal_dr_in,nominal_dtheta_deg,mdh_dr_in,mdh_dtheta_deg,zrp_dr_in,zrp_dtheta_deg,\
             book_nominal_dr_in,book_nominal_dtheta_deg,book_mdh_dr_in,book_mdh_dtheta_deg,\
             book_zrp_dr_in,book_zrp_dtheta_deg\n",
        );
        for r in &self.held_out {
            let b = r
                .book
                .map(|b| {
                    format!(
                        "{},{},{},{},{},{}",
                        b.nominal_dr_in,
                        b.nominal_dtheta_deg,
                        b.mdh_dr_in,
                        b.mdh_dtheta_deg,
                        b.zrp_dr_in,
                        b.zrp_dtheta_deg
                    )
                })
                .unwrap_or_else(|| ",,,,,".into());
            acc.push_str(&format!(
                "{},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{b}\n",
                r.pose,
                r.nominal_dr_in,
                r.nominal_dtheta_deg,
                r.mdh_dr_in,
                r.mdh_dtheta_deg,
                r.zrp_dr_in,
                r.zrp_dtheta_deg
            ));
        }
        acc
    }
}
