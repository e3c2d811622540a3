//! The verdict panels a report opens with: for every estimate, is it good? — did the
//! solver converge, how much better is the held-out error, what does the χ² test say, were
//! there outliers, what could not be identified and why. For every design, the prediction
//! it makes and whether its poses keep the constraints. Everything is read from the
//! records ([`Estimate::verdicts`], [`Estimate::validation`], the design's assessment and
//! margins); nothing is fitted again.

use super::estimate::code_spans;
use super::html::{escape, facts, fixed, number, Section};
use crate::accuracy::ErrorStats;
use crate::design::DesignRecord;
use crate::identify::model_floor::ModelFloor;
use crate::identify::uncertainty::TcpCovariance;
use crate::identify::{is_frame_parameter, Chi2Outcome, Estimate};
use crate::model::Model;
use crate::Error;

/// How an estimate or a design fares.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Grade {
    /// Nothing to check.
    Good,
    /// Usable; read the flagged lines.
    Check,
    /// Not usable as it is (the fit did not converge or records no verdicts; a design
    /// violates its constraints).
    Bad,
}

impl Grade {
    /// The CSS class of the panel.
    pub fn class(self) -> &'static str {
        match self {
            Grade::Good => "good",
            Grade::Check => "check",
            Grade::Bad => "bad",
        }
    }
}

/// One line of a panel: its key, its HTML and whether it lowers the grade.
struct Line {
    key: &'static str,
    html: String,
    grade: Grade,
}

fn flagged(html: String, grade: Grade) -> String {
    if grade == Grade::Good {
        html
    } else {
        format!("<span class=\"flag\">{html}</span>")
    }
}

/// What a calibration's held-out error is compared with: the drawing's kinematics with the
/// frames (instrument, targets, base, tool) fitted on the same data, when the fit adjusts
/// more than those frames; the nominal model otherwise (a frames-only cell, where the
/// frames-only fit is the calibration itself). The nominal model alone is no baseline for a
/// link calibration: its error is mostly where the instrument stands, which any fit places.
fn held_out_baseline(e: &Estimate) -> Option<(&'static str, &ErrorStats)> {
    let v = e.validation.as_ref()?;
    let calibrates_links = Model::from_spec(&e.model).is_ok_and(|m| {
        e.free.iter().any(|name| {
            m.registry
                .index_of(name)
                .is_some_and(|i| !is_frame_parameter(&m, i))
        })
    });
    Some(if calibrates_links {
        ("the drawing's kinematics, frames fitted", &v.frames_only)
    } else {
        ("the nominal model", &v.nominal)
    })
}

/// The held-out improvement `1 − after/before` of the RMS error over
/// `held_out_baseline` (`None` without a validation or with a zero baseline error).
pub fn held_out_gain(e: &Estimate) -> Option<f64> {
    let v = e.validation.as_ref()?;
    let (_, before) = held_out_baseline(e)?;
    gain(before, &v.calibrated)
}

/// `1 − after/before` of the RMS error (`None` with a zero `before`).
fn gain(before: &ErrorStats, after: &ErrorStats) -> Option<f64> {
    (before.rms > 0.0).then(|| 1.0 - after.rms / before.rms)
}

fn estimate_lines(e: &Estimate) -> Vec<Line> {
    let sol = &e.solver;
    let mut lines = Vec::new();
    let solver = format!(
        "{}{}, {} iterations",
        sol.method.words(),
        sol.robust
            .map(|l| format!(" with robust {l:?} loss"))
            .unwrap_or_default(),
        sol.iterations
    );
    lines.push(match &e.verdicts {
        Some(v) if v.solver.is_converged() => Line {
            key: "status",
            html: format!("{}: {}", escape(&v.solver.to_string()), solver),
            grade: Grade::Good,
        },
        Some(v) => Line {
            key: "status",
            html: format!(
                "did not converge ({}): {}; the parameters are not a least-squares solution",
                escape(&v.solver.to_string()),
                solver
            ),
            grade: Grade::Bad,
        },
        None => Line {
            key: "status",
            html: format!("no verdict recorded (written by an older armcal): unverified; {solver}"),
            grade: Grade::Bad,
        },
    });
    lines.push(match (&e.validation, held_out_baseline(e)) {
        (Some(v), Some((baseline, before))) => {
            let worse = v.calibrated.rms > before.rms;
            Line {
                key: "held-out error",
                html: format!(
                    "RMS {} mm with {baseline} → {} mm calibrated ({}; max {} → {} mm) on {} configurations the fit did not see; nothing fitted: RMS {} mm",
                    fixed(before.rms, 3),
                    fixed(v.calibrated.rms, 3),
                    gain(before, &v.calibrated)
                        .map(|g| if g >= 0.0 {
                            format!("−{} %", fixed(100.0 * g, 0))
                        } else {
                            format!("+{} %: worse than {baseline}", fixed(-100.0 * g, 0))
                        })
                        .unwrap_or_else(|| "–".into()),
                    fixed(before.max, 3),
                    fixed(v.calibrated.max, 3),
                    v.test_configurations,
                    fixed(v.nominal.rms, 3)
                ),
                grade: if worse { Grade::Check } else { Grade::Good },
            }
        }
        _ => Line {
            key: "held-out error",
            html: "not measured: this estimate was made without held-out or test data, so its accuracy on new poses is unknown".into(),
            grade: Grade::Check,
        },
    });
    if let Some(line) = e.verdicts.as_ref().and_then(|v| fit_line(&v.fit)) {
        lines.push(line);
    }
    if let Some(v) = &e.verdicts {
        let grade = if v.chi2.outcome == Chi2Outcome::Consistent {
            Grade::Good
        } else {
            Grade::Check
        };
        lines.push(Line {
            key: "χ² test",
            html: flagged(escape(&v.chi2.meaning), grade),
            grade,
        });
    }
    lines.push(match (sol.robust, e.outliers.len()) {
        (None, _) => Line {
            key: "outliers",
            html: format!(
                "not tested (plain least squares); largest residual {} mm, 95 % of them below {} mm",
                fixed(e.residuals.norm.max, 3),
                fixed(e.residuals.norm.p95, 3)
            ),
            grade: Grade::Good,
        },
        (Some(_), 0) => Line {
            key: "outliers",
            html: "none flagged by the robust fit".into(),
            grade: Grade::Good,
        },
        (Some(_), n) => Line {
            key: "outliers",
            html: flagged(
                format!(
                    "{n} of {} measurements flagged and left out of χ² and C_p (listed under the estimate)",
                    e.measurements
                ),
                Grade::Check,
            ),
            grade: Grade::Check,
        },
    });
    if let Some(v) = &e.verdicts {
        let grade = if v.identifiability.is_short() {
            Grade::Check
        } else {
            Grade::Good
        };
        let mut html = flagged(escape(&v.identifiability.meaning), grade);
        if !e.fixed_reasons.is_empty() {
            let why: Vec<String> = e
                .fixed_reasons
                .iter()
                .map(|(n, r)| {
                    format!(
                        "<li><code>{}</code>: {}</li>",
                        escape(n),
                        code_spans(&escape(r))
                    )
                })
                .collect();
            html.push_str(&format!(
                "<details><summary>{} parameter{} not identifiable, and why</summary><ul>{}</ul></details>",
                why.len(),
                if why.len() == 1 { "" } else { "s" },
                why.concat()
            ));
        }
        if !e.strong_correlations.is_empty() {
            html.push_str(&format!(
                "<br>{} pairs of parameters correlated with |ρ| &gt; 0.95 (poorly separated by these data)",
                e.strong_correlations.len()
            ));
        }
        lines.push(Line {
            key: "identifiability",
            html,
            grade,
        });
    }
    lines.extend(tcp_lines("TCP σ", &e.tcp, e.model_floor.as_ref()));
    lines
}

/// The TCP σ at every working pose, `√((1/3) tr C)`: of the measurement term C_s and, when
/// the fixed parameters have a stated prior, of the total C_s + C_floor
/// ([`crate::identify::model_floor`]), which is what the TCP is known to; a floor larger
/// than the measurement term is flagged, since more measurements of this design will not
/// lower it.
fn tcp_lines(key: &'static str, tcp: &[TcpCovariance], floor: Option<&ModelFloor>) -> Vec<Line> {
    tcp.iter()
        .enumerate()
        .map(|(k, t)| {
            let measurement = format!(
                "{} mm at <em>{}</em> from the measurements ((1/3) tr C_s = {} mm²)",
                number(t.kpi.sqrt()),
                escape(&t.name),
                number(t.kpi)
            );
            match floor.and_then(|f| f.tcp.get(k)).filter(|f| f.kpi > 0.0) {
                Some(f) => {
                    let grade = if f.kpi > t.kpi {
                        Grade::Check
                    } else {
                        Grade::Good
                    };
                    Line {
                        key,
                        html: flagged(
                            format!(
                                "{} mm with the fixed parameters' model floor ({} mm² of (1/3) tr C_s + C_floor); {measurement}",
                                number((t.kpi + f.kpi).sqrt()),
                                number(t.kpi + f.kpi)
                            ),
                            grade,
                        ),
                        grade,
                    }
                }
                None => Line {
                    key,
                    html: measurement,
                    grade: Grade::Good,
                },
            }
        })
        .collect()
}

/// What the checks of the fit found (units, blunders, a gross misfit, the sign and zero
/// diagnosis), and how a refused fit was accepted; `None` when they found nothing.
fn fit_line(fit: &crate::identify::FitChecks) -> Option<Line> {
    let mut found = fit.reasons();
    if found.is_empty() {
        return None;
    }
    let grade = if fit.refuses() {
        found.push(match &fit.accepted {
            Some(how) => format!("this estimate does not fit its data; accepted with {how}"),
            None => "this estimate does not fit its data".to_string(),
        });
        Grade::Bad
    } else {
        Grade::Check
    };
    let html = found
        .iter()
        .map(|f| flagged(code_spans(&escape(f)), grade))
        .collect::<Vec<_>>()
        .join("<br>");
    Some(Line {
        key: "model and data",
        html,
        grade,
    })
}

/// The grade of an estimate: the worst of its lines.
pub fn estimate_grade(e: &Estimate) -> Grade {
    estimate_lines(e)
        .iter()
        .map(|l| l.grade)
        .max()
        .unwrap_or(Grade::Good)
}

fn headline(grade: Grade, good: &str, check: &str, bad: &str) -> String {
    format!(
        "<p class=\"headline\">{}</p>\n",
        match grade {
            Grade::Good => good,
            Grade::Check => check,
            Grade::Bad => bad,
        }
    )
}

fn panel(kind: &str, label: &str, grade: Grade, head: String, lines: &[Line]) -> String {
    let rows: Vec<(&str, String)> = lines.iter().map(|l| (l.key, l.html.clone())).collect();
    format!(
        "<div class=\"verdict-panel {}\" data-verdict=\"{}\" data-kind=\"{kind}\">\n<h3>{}: {}</h3>\n{head}{}</div>\n",
        grade.class(),
        grade.class(),
        kind,
        escape(label),
        facts(&rows)
    )
}

fn design_lines(d: &DesignRecord) -> Vec<Line> {
    let mut lines = Vec::new();
    let violated: Vec<String> = d
        .margins
        .iter()
        .filter(|m| m.value < 0.0)
        .map(|m| {
            format!(
                "{} {} {} at pose {}",
                escape(&m.kind),
                fixed(m.value, 2),
                escape(&m.unit),
                m.pose
            )
        })
        .collect();
    let infeasible = d.plan.as_ref().is_some_and(|p| !p.feasible);
    lines.push(if violated.is_empty() && !infeasible {
        Line {
            key: "constraints",
            html: if d.margins.is_empty() {
                format!(
                    "{} poses; no constraint margins recorded (collision and line-of-sight constraints {})",
                    d.poses.len(),
                    if d.collisions { "on" } else { "off" }
                )
            } else {
                format!("{} poses, every constraint kept", d.poses.len())
            },
            grade: Grade::Good,
        }
    } else {
        Line {
            key: "constraints",
            html: flagged(
                format!(
                    "the design violates constraints{}",
                    if violated.is_empty() {
                        String::new()
                    } else {
                        format!(": {}", violated.join("; "))
                    }
                ),
                Grade::Bad,
            ),
            grade: Grade::Bad,
        }
    });
    lines.extend(tcp_lines(
        "predicted TCP σ",
        &d.assessment.tcp,
        d.assessment.model_floor.as_ref(),
    ));
    if let Some(b) = d.plan.as_ref().and_then(|p| p.bound.as_ref()) {
        lines.push(Line {
            key: "optimality",
            html: match b.efficiency {
                Some(e) => format!(
                    "efficiency {} of the optimality bound (1 = no design of {} poses can do better)",
                    fixed(e, 3),
                    d.poses.len()
                ),
                None => "no positive optimality bound for this design".into(),
            },
            grade: Grade::Good,
        });
    }
    lines
}

/// The verdict section: a panel per estimate, then one per design, of `estimates` and
/// `designs` (label, record); `None` when there is neither.
pub fn verdict_section(
    id: &str,
    estimates: &[(&str, &Estimate)],
    designs: &[(&str, &DesignRecord)],
) -> Result<Option<Section>, Error> {
    if estimates.is_empty() && designs.is_empty() {
        return Ok(None);
    }
    let mut s = Section::new(id, "Verdict");
    s.html("<p class=\"note\">Is it good? One panel per estimate (and per design), read from the records: green — nothing to check; amber — usable, read the flagged lines; red — not usable as it is.</p>\n<div class=\"verdicts\">\n");
    for (label, e) in estimates {
        let lines = estimate_lines(e);
        let grade = lines.iter().map(|l| l.grade).max().unwrap_or(Grade::Good);
        let head = headline(
            grade,
            "Good: the fit converged, the residuals agree with the stated σ and the held-out error fell.",
            "Usable, with caveats: read the flagged lines.",
            "Not usable as it is: the fit is not a verified least-squares solution.",
        );
        s.html(panel("Estimate", label, grade, head, &lines));
    }
    for (label, d) in designs {
        let lines = design_lines(d);
        let grade = lines.iter().map(|l| l.grade).max().unwrap_or(Grade::Good);
        let head = headline(
            grade,
            "Measurable as planned: every constraint kept.",
            "Usable, with caveats.",
            "Not measurable as it is: poses violate the cell's constraints.",
        );
        s.html(panel("Design", label, grade, head, &lines));
    }
    s.html("</div>\n");
    Ok(Some(s))
}
