//! The report section of a drift check (`check.json` of `armcal check`): the χ² test of the
//! check poses against the calibration's prediction, its verdict, and the score test of
//! every parameter group, the likeliest movers first.

use super::html::{escape, fixed, number, table, Section};
use crate::campaign::drift::{DriftCheck, DriftVerdict};

/// The section for the drift check `c`, labelled `label`.
pub fn check_section(id: &str, label: &str, c: &DriftCheck) -> Section {
    let mut s = Section::new(id, &format!("Drift check: {label}"));
    s.html(format!(
        "<p>{} check poses of cell <em>{}</em> ({}) against the calibration on {}: χ² = {} with {} degrees of freedom, p = {} at α = {}; position residual RMS {} mm. Verdict: <strong>{}</strong>.</p>\n",
        c.poses,
        escape(&c.cell),
        escape(&c.data),
        escape(&c.calibrated_on),
        number(c.chi2),
        c.dof,
        number(c.p_value),
        number(c.alpha),
        fixed(c.rms_position_mm, 4),
        if c.verdict == DriftVerdict::Drifted {
            "drifted: the robot or the cell changed since the calibration"
        } else {
            "consistent with the calibration"
        }
    ));
    s.html(format!(
        "<p class=\"note\">χ² = rᵀ S⁻¹ r of the check residuals r, S the instrument's covariance plus the calibration's prediction covariance ({}); without the prediction covariance χ² would be {}. The groups' score tests say which parameters most likely moved; a group marked ! rejects \"did not move\" by Holm's step-down procedure over the groups at α (so an unmoved robot has a group marked with probability at most α).</p>\n",
        escape(&c.covariance_rule),
        number(c.chi2_without_prediction)
    ));
    let moved = c.moved_groups();
    let rows: Vec<Vec<String>> = c
        .groups
        .iter()
        .map(|g| {
            let name = escape(&g.group);
            vec![
                if moved.contains(&g.group) {
                    format!("!{name}")
                } else {
                    name
                },
                g.parameters.len().to_string(),
                g.rank.to_string(),
                number(g.statistic),
                number(g.p_value),
            ]
        })
        .collect();
    s.html(table(
        &["group", "parameters", "rank", "score statistic", "p"],
        &rows,
        &[1, 2, 3, 4],
    ));
    s
}
