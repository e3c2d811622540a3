//! The held-out error of an estimate per axis of the instrument frame, before and after
//! calibration ([`crate::identify::Validation::per_axis`]), as a table and grouped bars.

use super::figures::{bar_figure_coloured, FRAMES_ONLY, NOMINAL};
use super::html::{escape, fixed, table, tagged, Section};
use crate::identify::{AxisErrors, Estimate};
use crate::Error;

/// `(x, y, z)` RMS of `a` (mm).
pub fn axis_rms(a: &AxisErrors) -> [f64; 3] {
    [a.x.rms, a.y.rms, a.z.rms]
}

/// Appends the per-axis held-out table and figure of `e` (labelled `label`) to `s`, the
/// calibrated bars in palette colour `fill` (the design's); nothing without a per-axis
/// validation.
pub fn held_out_axes_block(
    s: &mut Section,
    label: &str,
    e: &Estimate,
    fill: usize,
) -> Result<(), Error> {
    let Some(v) = &e.validation else {
        return Ok(());
    };
    let Some(a) = &v.per_axis else {
        s.html("<p class=\"note\">This estimate's validation holds no per-axis errors (written by an older armcal).</p>\n");
        return Ok(());
    };
    s.html("<h3>Held-out error per axis</h3>\n");
    let models = [
        ("nominal model", &a.nominal, NOMINAL),
        ("frames only", &a.frames_only, FRAMES_ONLY),
        ("calibrated", &a.calibrated, fill),
    ];
    let rows: Vec<Vec<String>> = models
        .iter()
        .map(|(name, ax, _)| {
            let mut row = vec![(*name).to_string()];
            for st in [&ax.x, &ax.y, &ax.z] {
                row.push(fixed(st.rms, 4));
                row.push(fixed(st.max, 4));
            }
            row
        })
        .collect();
    s.html(table(
        &[
            "",
            "x RMS (mm)",
            "x max (mm)",
            "y RMS (mm)",
            "y max (mm)",
            "z RMS (mm)",
            "z max (mm)",
        ],
        &rows,
        &[1, 2, 3, 4, 5, 6],
    ));
    let cats: Vec<String> = ["x", "y", "z"].map(String::from).to_vec();
    let series: Vec<(String, Vec<f64>)> = models
        .iter()
        .map(|(name, ax, _)| ((*name).to_string(), axis_rms(ax).to_vec()))
        .collect();
    let colours: Vec<usize> = models.iter().map(|m| m.2).collect();
    s.figure(
        tagged(
            bar_figure_coloured(
                &format!("Held-out RMS error per axis before and after calibration — {label}"),
                "RMS position error component (mm)",
                &cats,
                &series,
                &colours,
                None,
                false,
            )?,
            "held-out-axes",
        ),
        format!(
            "RMS of the x, y and z components (instrument frame) of the position error of <em>{}</em> on {} configurations the fit did not see (mm): nominal model, frames-only fit and full calibration. An axis that stays large after calibration points at an error the model does not describe (or at the instrument's noise along that axis).",
            escape(label),
            v.test_configurations
        ),
    );
    Ok(())
}
