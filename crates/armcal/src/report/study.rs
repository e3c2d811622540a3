//! The report section of `armcal study paper`: the paper's Tables 6–8 beside armcal's
//! numbers, and a Figure 8-style chart of the KPI design's improvement over the heuristic
//! and the φ_A(C_p)-optimal designs for each of the 90 notional manipulators.

use super::figures::{series_figure, Reference};
use super::html::{escape, fixed, table, Section};
use crate::study::paper::{
    StudyRecord, StudyRow, PAPER_GAINS, PAPER_NOTIONAL_GAINS, PAPER_SUMMARY, PAPER_TABLE6,
    PAPER_TABLE6_GAINS,
};
use crate::Error;

/// The paper's Table 7: (design, min and max without collision avoidance, min and max with
/// it) of (1/3) tr C_s over the 90 manipulators (mm²); the paper gives no heuristic range
/// without collision avoidance.
pub const PAPER_TABLE7: [(&str, f64, f64, f64, f64); 3] = [
    ("heuristic", f64::NAN, f64::NAN, 0.55, 0.71),
    ("C_p-optimal", 0.39, 0.39, 0.42, 0.45),
    ("C_s-optimal (KPI)", 0.33, 0.34, 0.34, 0.37),
];

fn pct(x: f64) -> String {
    if x.is_finite() {
        format!("{} %", fixed(100.0 * x, 0))
    } else {
        "–".into()
    }
}

fn design_values(r: &StudyRow) -> [f64; 3] {
    [r.heuristic, r.cp_optimal, r.cs_optimal]
}

fn notional(rows: &[StudyRow]) -> Vec<&StudyRow> {
    rows.iter()
        .filter(|r| r.robot.starts_with("paper-") && r.error.is_none())
        .collect()
}

/// The section for the given study results (one per collision setting, typically).
pub fn study_section(id: &str, studies: &[(String, &StudyRecord)]) -> Result<Section, Error> {
    let mut s = Section::new(id, "The paper's study: Tables 6–8 and Figure 8");
    s.html(format!("<p class=\"note\">(1/3) tr C_s at the working pose (mm²) for 60-pose designs: the heuristic (random measurable poses), the φ_A(C_p)-optimal and the φ_A(C_s)-optimal (KPI) design, each beside the value published by Jost et al. (2017), as the paper prints it (rounded to two decimals; a range only where the paper gives one). armcal's improvements are 1 − KPI design / other design; the paper's are the percentages it states. The paper's summary: {PAPER_GAINS}.</p>\n"));
    for (label, st) in studies {
        if st.rows.iter().any(|r| r.error.is_some()) {
            let failed: Vec<String> = st
                .rows
                .iter()
                .filter(|r| r.error.is_some())
                .map(|r| escape(&r.robot))
                .collect();
            s.html(format!(
                "<p class=\"note\"><span class=\"flag\">{}: no result for {}</span></p>\n",
                escape(label),
                failed.join(", ")
            ));
        }
    }

    // Table 6.
    let mut t6 = Vec::new();
    for (_, st) in studies {
        for r in st.rows.iter().filter(|r| r.robot.starts_with("kr")) {
            let p = PAPER_TABLE6.iter().find(|p| p.0 == r.robot);
            let (ph, pc, ps) = p.map_or((f64::NAN, f64::NAN, f64::NAN), |p| (p.1, p.2, p.3));
            // The paper's gains as it states them (§4.1), not recomputed from its table.
            let gains = PAPER_TABLE6_GAINS.iter().find(|g| g.0 == r.robot);
            let stated = |g: Option<u32>| match g {
                Some(g) if st.collisions => format!("{g} %"),
                _ => "–".into(),
            };
            // The paper's Table 6 is with collision avoidance.
            let paper = |x: f64| {
                if st.collisions {
                    fixed(x, 2)
                } else {
                    "–".into()
                }
            };
            t6.push(vec![
                escape(&r.robot),
                if st.collisions { "yes" } else { "no" }.into(),
                fixed(r.heuristic, 3),
                paper(ph),
                fixed(r.cp_optimal, 3),
                paper(pc),
                fixed(r.cs_optimal, 3),
                paper(ps),
                pct(r.gain_vs_heuristic),
                stated(gains.map(|g| g.1)),
                pct(r.gain_vs_cp),
                stated(gains.map(|g| g.2)),
            ]);
        }
    }
    if !t6.is_empty() {
        s.html("<h3>Table 6: KUKA KR 15, KR 300, KR 500</h3>\n");
        s.html(table(
            &[
                "robot",
                "collision avoidance",
                "heuristic",
                "paper",
                "C_p-optimal",
                "paper",
                "KPI",
                "paper",
                "KPI vs heuristic",
                "paper",
                "KPI vs C_p",
                "paper",
            ],
            &t6,
            &[2, 3, 4, 5, 6, 7, 8, 9, 10, 11],
        ));
    }

    // Tables 7 and 8 over the notional manipulators.
    let mut t7 = Vec::new();
    let mut t8 = Vec::new();
    for (_, st) in studies {
        let rows = notional(&st.rows);
        if rows.is_empty() {
            continue;
        }
        for (d, name) in ["heuristic", "C_p-optimal", "C_s-optimal (KPI)"]
            .iter()
            .enumerate()
        {
            let v: Vec<f64> = rows.iter().map(|r| design_values(r)[d]).collect();
            let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            let p7 = PAPER_TABLE7[d];
            let (plo, phi) = if st.collisions {
                (p7.3, p7.4)
            } else {
                (p7.1, p7.2)
            };
            let p8 = if st.collisions {
                PAPER_SUMMARY[d].2
            } else {
                PAPER_SUMMARY[d].1
            };
            let ca = if st.collisions { "yes" } else { "no" };
            t7.push(vec![
                (*name).into(),
                ca.into(),
                rows.len().to_string(),
                format!("{} – {}", fixed(lo, 3), fixed(hi, 3)),
                if plo.is_finite() {
                    format!("{} – {}", fixed(plo, 2), fixed(phi, 2))
                } else {
                    "–".into()
                },
            ]);
            t8.push(vec![
                (*name).into(),
                ca.into(),
                fixed(mean, 3),
                fixed(p8, 2),
            ]);
        }
    }
    if !t7.is_empty() {
        s.html("<h3>Table 7: range over the notional manipulators</h3>\n");
        s.html(table(
            &[
                "design",
                "collision avoidance",
                "manipulators",
                "armcal min – max",
                "paper min – max",
            ],
            &t7,
            &[2, 3, 4],
        ));
        s.html("<h3>Table 8: mean over the notional manipulators</h3>\n");
        s.html(table(
            &["design", "collision avoidance", "armcal mean", "paper mean"],
            &t8,
            &[2, 3],
        ));
    }

    // Figure 8.
    for (label, st) in studies {
        let rows = notional(&st.rows);
        if rows.is_empty() {
            continue;
        }
        let sorted = |f: fn(&StudyRow) -> f64| {
            let mut v: Vec<f64> = rows.iter().map(|r| 100.0 * f(r)).collect();
            v.sort_by(f64::total_cmp);
            v.iter()
                .enumerate()
                .map(|(i, x)| ((i + 1) as f64, *x))
                .collect::<Vec<(f64, f64)>>()
        };
        let col = |d: usize| {
            if st.collisions {
                PAPER_SUMMARY[d].2
            } else {
                PAPER_SUMMARY[d].1
            }
        };
        // With collision avoidance the paper states its mean gains (§4.2); without, it
        // gives only the Table 8 means, and the lines are their ratios, labelled so.
        let (paper_h, paper_c, source) = if st.collisions {
            (
                PAPER_NOTIONAL_GAINS.0 as f64,
                PAPER_NOTIONAL_GAINS.1 as f64,
                "paper §4.2",
            )
        } else {
            (
                100.0 * (1.0 - col(2) / col(0)),
                100.0 * (1.0 - col(2) / col(1)),
                "ratio of the paper's Table 8 means",
            )
        };
        let ca = if st.collisions { "with" } else { "without" };
        s.figure(
            series_figure(
                &format!("Improvement of the KPI design, {} manipulators, {ca} collision avoidance", rows.len()),
                "manipulator (sorted by improvement)",
                "improvement of (1/3) tr C_s (%)",
                &[
                    ("KPI vs heuristic".into(), sorted(|r| r.gain_vs_heuristic)),
                    ("KPI vs C_p-optimal".into(), sorted(|r| r.gain_vs_cp)),
                ],
                &[
                    Reference {
                        label: format!("{source}, mean vs heuristic: {paper_h:.0} %"),
                        value: paper_h,
                    },
                    Reference {
                        label: format!("{source}, mean vs C_p-optimal: {paper_c:.0} %"),
                        value: paper_c,
                    },
                ],
            )?,
            format!(
                "Figure 8 of the paper, as armcal computes it ({}): for each of the {} notional manipulators (λ = 650…1100 mm, μ = 600…1000 mm), how much smaller the KPI design's (1/3) tr C_s is than the heuristic design's and than the φ_A(C_p)-optimal design's, each curve sorted; dashed: the paper's mean improvements ({}).",
                escape(label),
                rows.len(),
                source
            ),
        );
    }
    Ok(s)
}
