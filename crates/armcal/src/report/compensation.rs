//! The compensation section: the joint corrections of a compensated joint program
//! ([`ProgramRecord`], e.g. the demo's `program.csv` → `program-corrected.csv`), per row and
//! joint, as a table and grouped bars.

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

/// The section for the compensated program `p`; `summary` (HTML) says what it is.
pub fn compensation_section(id: &str, p: &ProgramRecord, summary: &str) -> Result<Section, Error> {
    let mut s = Section::new(id, "Compensation: the corrected working program");
    s.html(format!("<p>{summary}</p>\n"));
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
