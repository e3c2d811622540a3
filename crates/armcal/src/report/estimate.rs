//! The report section of one estimate: solver and statistical tests, the parameter table
//! with σ and flagged correlations, observability, residuals (histograms, per pose) and the
//! held-out validation.

use super::decimate::{envelope, MAX_POINTS};
use super::figures::{bar_figure, histogram_figure, series_figure, Reference};
use super::html::{escape, facts, fixed, number, table, Section};
use crate::accuracy::ErrorStats;
use crate::identify::{Estimate, Observability};
use crate::Error;

fn stats_row(name: &str, s: &ErrorStats) -> Vec<String> {
    vec![
        name.to_string(),
        s.count.to_string(),
        fixed(s.mean, 4),
        fixed(s.rms, 4),
        fixed(s.p95, 4),
        fixed(s.max, 4),
    ]
}

/// The observability indices O1–O5 and the condition number as a one-row table (also used
/// by the design section).
pub(super) fn observability_table(o: &Observability) -> String {
    table(
        &["O1", "O2", "O3", "O4", "O5", "condition number"],
        &[vec![
            number(o.o1),
            number(o.o2),
            number(o.o3),
            number(o.o4),
            number(o.o5),
            number(o.condition_number),
        ]],
        &[0, 1, 2, 3, 4, 5],
    )
}

/// A parameter value to the resolution that matters: 0.001 mm, 0.0001°.
fn value(x: f64, unit: &str) -> String {
    fixed(x, if unit == "deg" { 4 } else { 3 })
}

/// Text between backticks (parameter names in the identifiability reasons) as code.
pub(super) fn code_spans(escaped: &str) -> String {
    let mut out = String::with_capacity(escaped.len() + 16);
    for (i, part) in escaped.split('`').enumerate() {
        if i % 2 == 1 {
            out.push_str(&format!("<code>{part}</code>"));
        } else {
            out.push_str(part);
        }
    }
    out
}

const STATS_HEAD: [&str; 6] = [
    "",
    "count",
    "mean |·| (mm)",
    "RMS (mm)",
    "95 % (mm)",
    "max (mm)",
];

/// [`STATS_HEAD`] for angles.
const STATS_HEAD_DEG: [&str; 6] = [
    "",
    "count",
    "mean (deg)",
    "RMS (deg)",
    "95 % (deg)",
    "max (deg)",
];

/// σ̂₀², χ² with its degrees of freedom, the p-value and the verdict (book eq. 5.23), as a
/// report states them.
pub(super) fn variance_factor(u: &crate::identify::uncertainty::ParameterUncertainty) -> String {
    format!(
        "{} (χ² = {} with {} degrees of freedom, p = {}): {}",
        number(u.variance_factor),
        number(u.chi2),
        u.dof,
        fixed(u.p_value, 3),
        escape(&u.verdict)
    )
}

/// The section for `e`, labelled `label` (plain text), anchored at `id`.
pub fn estimate_section(id: &str, label: &str, e: &Estimate) -> Result<Section, Error> {
    let mut s = Section::new(id, &format!("Estimate: {label}"));
    let u = &e.uncertainty;
    let sol = &e.solver;
    let mut rows = vec![
        ("cell", escape(&e.cell)),
        ("data", escape(&e.data)),
        (
            "fitted",
            format!(
                "{} measurements at {} configurations; {} free parameters",
                e.measurements,
                e.configurations,
                e.free.len()
            ),
        ),
        (
            "solver",
            format!(
                "{}{}, {} — {} iterations",
                sol.method.words(),
                sol.robust
                    .map(|l| format!(" with robust {l:?} loss"))
                    .unwrap_or_default(),
                escape(&sol.status.to_string()),
                sol.iterations
            ),
        ),
        (
            "cost ½‖r‖² (whitened)",
            format!(
                "{} → {}",
                number(sol.history.first().copied().unwrap_or(f64::NAN)),
                number(sol.history.last().copied().unwrap_or(f64::NAN))
            ),
        ),
        ("variance factor σ̂₀²", variance_factor(u)),
    ];
    match &e.verdicts {
        Some(v) => {
            rows.push((
                "fit verdict",
                if v.solver.is_converged() {
                    escape(&v.solver.to_string())
                } else {
                    format!(
                        "<span class=\"flag\">did not converge ({}): the parameters are not a least-squares solution</span>",
                        escape(&v.solver.to_string())
                    )
                },
            ));
            rows.push(("χ² verdict", escape(&v.chi2.meaning)));
            rows.push(("identifiability", escape(&v.identifiability.meaning)));
        }
        None => rows.push((
            "fit verdict",
            "<span class=\"flag\">none recorded (written by an older armcal): unverified</span>"
                .into(),
        )),
    }
    if sol.time_ms > 0.0 {
        rows.push(("solver time", format!("{} ms", fixed(sol.time_ms, 1))));
    }
    if let Some(scale) = e.robust_scale {
        rows.push((
            "robust scale",
            format!(
                "{} ({} outliers flagged, left out of χ² and C_p)",
                number(scale),
                e.outliers.len()
            ),
        ));
    }
    if !e.far_from_nominal.is_empty() {
        let list: Vec<String> = e
            .far_from_nominal
            .iter()
            .map(|f| {
                format!(
                    "{} = {}° (nominal {}°): {}",
                    f.name,
                    fixed(f.estimate_deg, 3),
                    fixed(f.nominal_deg, 3),
                    f.reason
                )
            })
            .collect();
        rows.push(("angles far from nominal", escape(&list.join("; "))));
    }
    s.html(facts(&rows));

    // Parameters.
    s.html("<h3>Parameters</h3>\n<p class=\"note\">Nominal and identified values in display units (mm, deg); σ is the standard deviation implied by the stated measurement noise (C_p = (F₁ᵀF₁)⁻¹, paper §1.1). Pairs of free parameters with |ρ| &gt; 0.95 are flagged: their values are poorly separated by these data.</p>\n");
    let partners = |name: &str| -> Vec<String> {
        e.strong_correlations
            .iter()
            .filter_map(|(a, b, rho)| {
                if a == name {
                    Some(format!("{} (ρ = {})", escape(b), fixed(*rho, 3)))
                } else if b == name {
                    Some(format!("{} (ρ = {})", escape(a), fixed(*rho, 3)))
                } else {
                    None
                }
            })
            .collect()
    };
    let prows: Vec<Vec<String>> = e
        .parameters
        .iter()
        .map(|p| {
            let status = if p.free {
                "free".to_string()
            } else {
                match e.fixed_reasons.iter().find(|r| r.0 == p.name) {
                    Some((_, why)) => format!("fixed: {}", code_spans(&escape(why))),
                    None => "fixed".into(),
                }
            };
            let corr = partners(&p.name);
            vec![
                format!(
                    "{}{}",
                    if corr.is_empty() { "" } else { "!" },
                    escape(&p.name)
                ),
                escape(&p.unit),
                value(p.nominal, &p.unit),
                value(p.estimate, &p.unit),
                value(p.estimate - p.nominal, &p.unit),
                p.sigma.map(number).unwrap_or_else(|| "–".into()),
                status,
                if corr.is_empty() {
                    String::new()
                } else {
                    format!("<span class=\"flag\">{}</span>", corr.join(", "))
                },
            ]
        })
        .collect();
    s.html(table(
        &[
            "parameter",
            "unit",
            "nominal",
            "estimate",
            "change",
            "± σ",
            "status",
            "strongly correlated with",
        ],
        &prows,
        &[2, 3, 4, 5],
    ));

    // Observability.
    s.html("<h3>Observability</h3>\n<p class=\"note\">Indices of the whitened identification Jacobian (book §4.5.3, paper eqs. 8–10): larger is better; the condition number is that of the column-normalised Jacobian.</p>\n");
    s.html(observability_table(&e.observability));

    // Residuals.
    let r = &e.residuals;
    s.html("<h3>Residuals</h3>\n<p class=\"note\">Residuals are model − measured at the identified parameters (mm). |e| is the Euclidean position error of each measurement.</p>\n");
    s.html(table(
        &STATS_HEAD,
        &[
            stats_row("x", &r.x),
            stats_row("y", &r.y),
            stats_row("z", &r.z),
            stats_row("|e|", &r.norm),
        ],
        &[1, 2, 3, 4, 5],
    ));
    if let Some(o) = &r.orientation {
        s.html(table(
            &STATS_HEAD_DEG,
            &[stats_row("orientation", o)],
            &[1, 2, 3, 4, 5],
        ));
    }
    let with_xyz: Vec<_> = r
        .per_measurement
        .iter()
        .filter_map(|m| m.xyz.map(|v| (m.pose, v)))
        .collect();
    if with_xyz.is_empty() {
        s.html("<p class=\"note\">This estimate holds no per-measurement residuals (written by an older armcal, or no position measurements), so the residual plots are left out.</p>\n");
    } else {
        let axis = |k: usize| with_xyz.iter().map(|(_, v)| v[k]).collect::<Vec<f64>>();
        let panels = vec![
            ("x residual".to_string(), axis(0)),
            ("y residual".to_string(), axis(1)),
            ("z residual".to_string(), axis(2)),
        ];
        let bins = ((with_xyz.len() as f64).sqrt().ceil() as usize).clamp(8, 30);
        s.figure(
            histogram_figure(&format!("Residual distribution — {label}"), "residual (mm)", &panels, bins)?,
            format!(
                "Histograms of the x, y and z residuals of the {} position measurements of <em>{}</em> (mm). Centred, bell-shaped histograms of width ≈ the instrument σ mean the model explains the data; skew or heavy tails point at model errors or outliers.",
                with_xyz.len(),
                escape(label)
            ),
        );
        let per_pose = |k: usize| {
            let all: Vec<(f64, f64)> = with_xyz.iter().map(|(p, v)| (*p as f64, v[k])).collect();
            envelope(&all, MAX_POINTS)
        };
        let shown = if with_xyz.len() > MAX_POINTS {
            format!(
                " The plot shows at most {} of the {} measurements per component: of every {} consecutive ones, the smallest and the largest residual (so every extreme and every spike is drawn; the histograms and statistics use all of them).",
                thousands(MAX_POINTS),
                thousands(with_xyz.len()),
                with_xyz.len().div_ceil(MAX_POINTS / 2)
            )
        } else {
            String::new()
        };
        s.figure(
            series_figure(
                &format!("Residuals per pose — {label}"),
                "pose (configuration number in the data file)",
                "residual (mm)",
                &[
                    ("x".to_string(), per_pose(0)),
                    ("y".to_string(), per_pose(1)),
                    ("z".to_string(), per_pose(2)),
                ],
                &[Reference {
                    label: "0".into(),
                    value: 0.0,
                }],
            )?,
            format!(
                "Residual components of every measurement of <em>{}</em> against its pose number (mm). A pattern over the poses (a trend, a group of large residuals) shows where the model misses the robot.{shown}",
                escape(label)
            ),
        );
    }

    if let Some(v) = &e.validation {
        s.html(format!(
            "<h3>Held-out validation</h3>\n<p class=\"note\">Position error on {} configurations not used in the fit ({} used), for the nominal model, the nominal robot with only the base, tool, instrument and target frames fitted, and the full calibration (mm).</p>\n",
            v.test_configurations, v.train_configurations
        ));
        s.html(table(
            &STATS_HEAD,
            &[
                stats_row("nominal", &v.nominal),
                stats_row("frames only", &v.frames_only),
                stats_row("calibrated", &v.calibrated),
            ],
            &[1, 2, 3, 4, 5],
        ));
        let cats: Vec<String> = ["RMS", "95th percentile", "max"].map(String::from).to_vec();
        let vals = |st: &ErrorStats| vec![st.rms, st.p95, st.max];
        s.figure(
            bar_figure(
                &format!("Held-out position error before and after calibration — {label}"),
                "position error (mm)",
                &cats,
                &[
                    ("nominal model".into(), vals(&v.nominal)),
                    ("frames only".into(), vals(&v.frames_only)),
                    ("calibrated".into(), vals(&v.calibrated)),
                ],
                None,
                false,
            )?,
            format!(
                "Held-out position error of <em>{}</em> on {} configurations the fit did not see (mm): nominal model, frames-only fit and full calibration.",
                escape(label),
                v.test_configurations
            ),
        );
        if let Some(o) = &v.orientation {
            s.html("<p class=\"note\">Orientation error of the held-out pose measurements: the angle of the rotation between the measured and the predicted orientation (degrees).</p>\n");
            s.html(table(
                &STATS_HEAD_DEG,
                &[
                    stats_row("nominal", &o.nominal),
                    stats_row("frames only", &o.frames_only),
                    stats_row("calibrated", &o.calibrated),
                ],
                &[1, 2, 3, 4, 5],
            ));
        }
    }
    if !e.outliers.is_empty() {
        let orows: Vec<Vec<String>> = e
            .outliers
            .iter()
            .map(|o| {
                vec![
                    escape(&o.configuration),
                    o.line.to_string(),
                    fixed(o.standardized, 2),
                    fixed(o.weight, 3),
                ]
            })
            .collect();
        s.html("<h3>Outliers (robust fit)</h3>\n");
        s.html(table(
            &["configuration", "data line", "‖r‖/s", "weight"],
            &orows,
            &[1, 2, 3],
        ));
    }
    Ok(s)
}

/// `n` with a thin space between groups of three digits ("100 000").
fn thousands(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push('\u{202f}');
        }
        out.push(c);
    }
    out
}
