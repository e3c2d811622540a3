//! The summary section of `armcal demo`: KPI vs heuristic design, predicted vs achieved TCP
//! precision, held-out accuracy before and after calibration, the compensated program.

use super::figures::{cdf_figure_coloured, NOMINAL};
use super::html::{facts, fixed, table, Section};
use crate::study::demo::DemoSummary;
use crate::Error;

/// The section for the demo's numbers; `colour_of` gives the palette index of a design by
/// its name (`heuristic`, `kpi`), the colour it has in every figure.
pub fn demo_section(
    id: &str,
    s: &DemoSummary,
    colour_of: &dyn Fn(&str) -> usize,
) -> Result<Section, Error> {
    let mut sec = Section::new(id, "Summary: KPI design vs heuristic design");
    sec.html(format!(
        "<p>A simulated calibration of the paper's cell (KUKA-like robot with λ = 650 mm, μ = 600 mm, laser tracker with σ = 1 mm, car body and wall as obstacles). Two designs of {} poses each — a KPI-optimal design planned with collision avoidance and a random feasible (heuristic) design — were measured on the same perturbed \"true\" robot, the model identified from each, and both checked on 100 feasible poses that neither design used (seed {}).</p>\n",
        s.poses, s.seed
    ));
    let row = |name: &str, h: f64, k: f64| vec![name.to_string(), fixed(h, 3), fixed(k, 3)];
    sec.html(table(
        &["", "heuristic design", "KPI design"],
        &[
            row(
                "TCP σ at the working pose, predicted (mm)",
                s.heuristic.tcp_sigma_predicted,
                s.kpi.tcp_sigma_predicted,
            ),
            row(
                "TCP error at the working pose, achieved (mm)",
                s.heuristic.tcp_error_achieved,
                s.kpi.tcp_error_achieved,
            ),
            row(
                "held-out position error, RMS (mm)",
                s.heuristic.held_out.rms,
                s.kpi.held_out.rms,
            ),
            row(
                "held-out position error, max (mm)",
                s.heuristic.held_out.max,
                s.kpi.held_out.max,
            ),
        ],
        &[1, 2],
    ));
    let mut rows = vec![
        (
            "nominal model",
            format!(
                "held-out position error RMS {} mm, max {} mm",
                fixed(s.nominal_held_out.rms, 3),
                fixed(s.nominal_held_out.max, 3)
            ),
        ),
        (
            "working program",
            format!(
                "largest miss on the true robot {} mm with the nominal joints → {} mm with the compensated joints",
                fixed(s.program_miss_nominal, 3),
                fixed(s.program_miss_compensated, 3)
            ),
        ),
    ];
    if let Some(e) = s.kpi_bound_efficiency {
        rows.push((
            "KPI design efficiency",
            format!(
                "{} of the optimality bound (1 = no design of {} poses can do better)",
                fixed(e, 3),
                s.poses
            ),
        ));
    }
    sec.html(facts(&rows));
    sec.html("<p class=\"note\">“Predicted” is √((1/3) tr C_s) from the identification's covariance; “achieved” is the distance between the identified and the true TCP at the working pose in this one simulated campaign, a single draw from that distribution.</p>\n");
    sec.figure(
        cdf_figure_coloured(
            "Held-out position error before and after calibration",
            "position error of the TCP reflector on held-out poses (mm)",
            &[
                ("nominal model".into(), s.nominal_held_out_errors.clone()),
                (
                    "calibrated from the heuristic design".into(),
                    s.heuristic.held_out_errors.clone(),
                ),
                (
                    "calibrated from the KPI design".into(),
                    s.kpi.held_out_errors.clone(),
                ),
            ],
            &[
                NOMINAL,
                colour_of(&s.heuristic.design),
                colour_of(&s.kpi.design),
            ],
        )?,
        format!(
            "Cumulative distribution of the position error on {} held-out poses against the true robot (mm): the share of poses whose error is at most x. Further left is better.",
            s.nominal_held_out_errors.len()
        ),
    );
    Ok(sec)
}
