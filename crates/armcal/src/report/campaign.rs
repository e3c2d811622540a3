//! The report section of an adaptive campaign (`campaign.json` of `armcal campaign`): the
//! TCP σ at every working pose against the poses measured, with the target line and the
//! stopping decision, and a table of the steps.

use super::figures::{series_figure, Reference};
use super::html::{escape, fixed, table, tagged, Section};
use crate::campaign::{CampaignState, Decision};
use crate::Error;

/// The section for the campaign state `state`, labelled `label`.
pub fn campaign_section(id: &str, label: &str, state: &CampaignState) -> Result<Section, Error> {
    let mut s = Section::new(id, &format!("Campaign: {label}"));
    let target = state.settings.target_sigma_mm;
    let decision = state.decision.words();
    s.html(format!(
        "<p>Adaptive campaign on cell <em>{}</em>{}: target TCP σ ≤ {} mm at every working pose; {} poses measured in {} steps (first batch {}, then {} per batch{}). Decision: <strong>{}</strong>.</p>\n<p class=\"note\">{} {}</p>\n",
        escape(&state.cell),
        state
            .simulation_seed
            .map(|k| format!(" (simulated robot, seed {k})"))
            .unwrap_or_default(),
        fixed(target, 3),
        state.measured(),
        state.steps.len(),
        state.first_batch,
        state.settings.batch,
        state
            .settings
            .budget
            .map(|b| format!(", budget {b}"))
            .unwrap_or_default(),
        escape(decision),
        escape(&state.sigma_definition),
        escape(&state.variance_rule),
    ));
    let series: Vec<(String, Vec<(f64, f64)>)> = state
        .working
        .iter()
        .enumerate()
        .map(|(w, name)| {
            let pts = state
                .steps
                .iter()
                .filter_map(|st| {
                    st.working
                        .get(w)
                        .map(|ws| (st.measured as f64, ws.sigma_mm))
                })
                .collect();
            (format!("σ at `{name}` (fit)"), pts)
        })
        .filter(|(_, pts): &(String, Vec<(f64, f64)>)| !pts.is_empty())
        .collect();
    if !series.is_empty() {
        let mut references = vec![Reference {
            label: format!("target {} mm", fixed(target, 3)),
            value: target,
        }];
        if let (Some(last), true) = (state.steps.last(), state.decision != Decision::Measure) {
            if let Some(w) = last.working.iter().map(|w| w.sigma_mm).reduce(f64::max) {
                references.push(Reference {
                    label: format!(
                        "{} at {} poses: σ {} mm",
                        decision,
                        last.measured,
                        fixed(w, 3)
                    ),
                    value: w,
                });
            }
        }
        let svg = series_figure(
            "TCP σ against the poses measured",
            "poses measured",
            "TCP σ (mm)",
            &series,
            &references,
        )?;
        s.figure(
            tagged(svg, "campaign-sigma"),
            format!(
                "The TCP σ = √((1/3) tr C_s) at each working pose from the fit after each step (C_s scaled by max(1, σ̂₀²)); dashed: the target and, once stopped, the decision. {}",
                escape(
                    &state
                        .steps
                        .last()
                        .map(|l| l.reason.clone())
                        .unwrap_or_default()
                )
            ),
        );
    }
    let rows: Vec<Vec<String>> = state
        .steps
        .iter()
        .enumerate()
        .map(|(k, st)| {
            vec![
                (k + 1).to_string(),
                st.measured.to_string(),
                match &st.fit {
                    Some(f) if f.status.is_converged() => "converged".into(),
                    Some(f) => escape(&f.status.to_string()),
                    None => "no fit".into(),
                },
                st.fit
                    .as_ref()
                    .and_then(|f| f.variance_factor)
                    .map_or("–".into(), |v| fixed(v, 3)),
                st.working
                    .iter()
                    .map(|w| fixed(w.sigma_mm, 4))
                    .collect::<Vec<_>>()
                    .join(", "),
                escape(st.decision.words()),
            ]
        })
        .collect();
    s.html(table(
        &["step", "poses", "fit", "σ̂₀²", "TCP σ (mm)", "decision"],
        &rows,
        &[0, 1, 3],
    ));
    Ok(s)
}
