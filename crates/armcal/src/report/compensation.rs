//! The compensation section: the joint corrections of a compensated joint program
//! ([`ProgramRecord`], e.g. the demo's `program.csv` → `program-corrected.csv`), per row and
//! joint, as a table and grouped bars, with how many rows converged, how many were solved
//! with position priority within the joint-change limit and how many of those miss the
//! tolerance ([`status_counts`]).

use super::figures::bar_figure;
use super::html::{escape, fixed, table, tagged, Section};
use crate::compensate::program::ProgramRecord;
use crate::Error;

/// The correction `compensated − nominal` of every row and joint (display units), in the
/// record's order.
pub fn joint_corrections(p: &ProgramRecord) -> Vec<Vec<f64>> {
    p.rows
        .iter()
        .map(|r| {
            r.compensated
                .iter()
                .zip(&r.nominal)
                .map(|(c, n)| c - n)
                .collect()
        })
        .collect()
}

/// One sentence on the rows' statuses: converged, solved with position priority within the
/// joint-change limit, beyond it (with the largest remaining miss), otherwise not converged.
pub fn status_counts(p: &ProgramRecord) -> String {
    let count = |f: &dyn Fn(&crate::compensate::program::ProgramRecordRow) -> bool| {
        p.rows.iter().filter(|r| f(r)).count()
    };
    let converged = count(&|r| r.converged);
    let priority = count(&|r| r.position_priority);
    let beyond: Vec<_> = p.rows.iter().filter(|r| r.beyond_change_limit).collect();
    let other = p.rows.len() - converged - beyond.len();
    let mut text = format!(
        "{converged} of {} rows converged ({priority} of all rows solved with position \
         priority within the joint-change limit)",
        p.rows.len()
    );
    if !beyond.is_empty() {
        let worst = |f: fn(&crate::compensate::program::ProgramRecordRow) -> f64| {
            beyond.iter().map(|r| f(r)).fold(0.0, f64::max)
        };
        text += &format!(
            "; {} rows need a larger joint change than the limit (status joint-change-limit) \
             and miss by up to {} mm, {} deg within it",
            beyond.len(),
            fixed(worst(|r| r.position_error_mm), 6),
            fixed(worst(|r| r.orientation_error_deg), 4)
        );
    }
    if other > 0 {
        text += &format!("; {other} rows not converged otherwise (see their status)");
    }
    text + "."
}

/// The section for the compensated program `p`; `summary` (HTML) says what it is.
pub fn compensation_section(id: &str, p: &ProgramRecord, summary: &str) -> Result<Section, Error> {
    let mut s = Section::new(id, "Compensation: the corrected working program");
    s.html(format!("<p>{summary} {}</p>\n", escape(&status_counts(p))));
    let corrections = joint_corrections(p);
    let heads: Vec<String> = p
        .joints
        .iter()
        .zip(&p.units)
        .map(|(j, u)| format!("Δ{} ({})", escape(j), escape(u)))
        .collect();
    let mut head: Vec<&str> = vec!["pose"];
    head.extend(heads.iter().map(String::as_str));
    head.extend(["status", "remaining error (mm)"]);
    let rows: Vec<Vec<String>> = p
        .rows
        .iter()
        .zip(&corrections)
        .map(|(r, d)| {
            let mut row = vec![format!(
                "{}{}",
                if r.converged { "" } else { "!" },
                escape(&r.id)
            )];
            row.extend(d.iter().map(|x| fixed(*x, 4)));
            row.push(escape(&r.status));
            row.push(fixed(r.position_error_mm, 6));
            row
        })
        .collect();
    let numeric: Vec<usize> = (1..=p.joints.len()).chain([p.joints.len() + 2]).collect();
    s.html(table(&head, &rows, &numeric));
    let series: Vec<(String, Vec<f64>)> = p
        .rows
        .iter()
        .zip(&corrections)
        .map(|(r, d)| (format!("pose {}", r.id), d.clone()))
        .collect();
    let unit = if p.units.iter().all(|u| u == "deg") {
        "deg"
    } else {
        "deg or mm"
    };
    s.figure(
        tagged(
            bar_figure(
                "Joint corrections of the compensated program",
                &format!("compensated − nominal joint value ({unit})"),
                &p.joints,
                &series,
                None,
                false,
            )?,
            "joint-corrections",
        ),
        format!(
            "How much each joint of the {} program poses changes so that the calibrated robot reaches what the nominal model meant ({unit}). Corrections of a few hundredths of a degree are typical of a robot whose geometry is off by a millimetre or so.",
            p.rows.len()
        ),
    );
    Ok(s)
}
