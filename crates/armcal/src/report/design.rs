//! The report section of one design: how it was made (criterion, solver statistics, the
//! optimality bound and efficiency), its predicted precision (C_p, C_s), the poses as joint
//! plots against the joint limits, the smallest margin of every kind of constraint, and for
//! a design chosen from the user's pose pool the pool row of each pose and the rows refused.

use super::estimate::observability_table;
use super::figures::{bar_figure, joint_figure, JointTrace};
use super::html::{escape, facts, fixed, number, table, Section};
use crate::design::user_pool::PoolReport;
use crate::design::Criterion;
use crate::design::DesignRecord;
use crate::Error;

/// What a criterion measures (all are minimised; paper §2.1–2.3, book §4.5).
pub fn criterion_description(c: Criterion) -> &'static str {
    match c {
        Criterion::A => "A: tr(C_p)/n_p, the paper's φ_A(C_p)",
        Criterion::D => "D: log det(C_p)/n_p",
        Criterion::E => "E: largest eigenvalue of C_p",
        Criterion::Kpi => "KPI: (1/3) tr(C_s) at the working pose, the paper's φ_A(C_s) (eq. 24)",
        Criterion::KpiMax => {
            "KPI-max: the largest (1/3) tr(C_s) over the working poses and paths (smooth maximum)"
        }
        Criterion::O1 => "O1: −log of observability index O1",
        Criterion::O2 => "O2: −log of observability index O2",
        Criterion::O3 => "O3: −log of observability index O3",
        Criterion::O4 => "O4: −log of observability index O4",
        Criterion::O5 => "O5: −log of observability index O5",
    }
}

/// The section for design `d`, labelled `label` (plain text), anchored at `id`.
pub fn design_section(id: &str, label: &str, d: &DesignRecord) -> Result<Section, Error> {
    let mut s = Section::new(id, &format!("Design: {label}"));
    let a = &d.assessment;
    let mut rows = vec![
        ("cell", escape(&d.cell)),
        ("method", escape(&d.method)),
        (
            "poses",
            format!(
                "{} configurations{}; collision and line-of-sight constraints {}",
                d.poses.len(),
                match d.measured {
                    0 => String::new(),
                    m => format!(
                        " planned to augment {m} measured poses (the criterion and the \
                         predicted precision are of all {} together)",
                        m + d.poses.len()
                    ),
                },
                if d.collisions { "on" } else { "off" }
            ),
        ),
    ];
    if let Some(p) = &d.plan {
        rows.push((
            "criterion",
            format!(
                "{} = {}",
                escape(criterion_description(p.criterion)),
                number(p.value)
            ),
        ));
        let refinement = format!(
            "refinement: {} ({} iterations)",
            escape(p.refine_status.as_deref().unwrap_or("skipped")),
            p.refine_iterations
        );
        rows.push((
            "solver",
            match &d.pool {
                Some(pool) => format!(
                    "{} → {}; {refinement}",
                    escape(&pool.selection),
                    number(pool.selection_value)
                ),
                None => format!(
                    "candidate pool from {} random draws; exchange: {} after {} sweeps; {refinement}",
                    p.pool_draws,
                    number(p.exchange_value),
                    p.exchange_sweeps,
                ),
            },
        ));
        rows.push((
            "feasibility",
            format!(
                "{} constraints per pose; {}",
                p.constraints_per_pose,
                if p.feasible {
                    "every pose feasible".to_string()
                } else {
                    "<span class=\"flag\">the design violates constraints</span>".to_string()
                }
            ),
        ));
        match &p.bound {
            Some(b) => rows.push((
                "optimality bound",
                match b.efficiency {
                    Some(e) => format!(
                        "no {}-pose design can go below {}; this design's value {}, efficiency {} (1 = optimal)",
                        d.poses.len(),
                        number(b.lower_bound),
                        number(b.value),
                        fixed(e, 3)
                    ),
                    None => format!(
                        "none: the bound found ({}) is not positive, so it says nothing about this design",
                        number(b.lower_bound)
                    ),
                },
            )),
            None => rows.push((
                "optimality bound",
                "none for this criterion (not convex in the information matrix)".into(),
            )),
        }
        if !p.time.is_zero() {
            rows.push((
                "planning time",
                format!("{} s", fixed(p.time.as_secs_f64(), 2)),
            ));
        }
    }
    rows.push((
        "predicted C_p",
        format!(
            "φ_A(C_p) = tr(C_p)/n_p = {} ({} free parameters; mm and rad)",
            number(a.phi_a_cp),
            a.parameters.len()
        ),
    ));
    for t in &a.tcp {
        let c = &t.covariance;
        rows.push((
            "predicted C_s",
            format!(
                "at <em>{}</em>: (1/3) tr C_s = {} mm², TCP σ = {} mm (σ_x {}, σ_y {}, σ_z {} mm)",
                escape(&t.name),
                number(t.kpi),
                number(t.kpi.sqrt()),
                number(c[(0, 0)].sqrt()),
                number(c[(1, 1)].sqrt()),
                number(c[(2, 2)].sqrt())
            ),
        ));
        if let Some(v) = t.orientation_kpi_deg2 {
            rows.push((
                "predicted C_ω",
                format!(
                    "at <em>{}</em>: TCP orientation (1/3) tr C_ω = {} deg², σ = {} deg (not in the KPI)",
                    escape(&t.name),
                    number(v),
                    number(v.sqrt())
                ),
            ));
        }
    }
    for p in &a.paths {
        rows.push((
            "predicted C_s",
            format!(
                "along <em>{}</em> ({} configurations): (1/3) tr C_s mean {} mm², largest {} mm² (TCP σ {} mm) at configuration {}",
                escape(&p.name),
                p.kpi.len(),
                number(p.mean_kpi),
                number(p.max_kpi),
                number(p.max_kpi.sqrt()),
                p.worst
            ),
        ));
    }
    if let Some(pool) = &d.pool {
        rows.push(("pose pool", pool_summary(pool)));
    }
    s.html(facts(&rows));
    if let Some(pool) = &d.pool {
        pool_tables(&mut s, pool);
    }

    s.html("<h3>Criteria and observability</h3>\n<p class=\"note\">Every criterion's value for this design (minimised; computed with the instrument's stated σ), and the observability indices of its identification Jacobian (larger is better).</p>\n");
    let crow: Vec<Vec<String>> = a
        .criteria
        .iter()
        .map(|(c, v)| vec![escape(criterion_description(*c)), number(*v)])
        .collect();
    s.html(table(&["criterion", "value"], &crow, &[1]));
    s.html(observability_table(&a.observability));

    let traces: Vec<JointTrace> = d
        .joints
        .iter()
        .enumerate()
        .map(|(j, r)| JointTrace {
            name: r.name.clone(),
            unit: r.unit.clone(),
            lower: r.lower,
            upper: r.upper,
            values: d
                .poses
                .iter()
                .map(|q| q.get(j).copied().unwrap_or(f64::NAN))
                .collect(),
        })
        .collect();
    s.figure(
        joint_figure(&format!("Joint values of the {} poses — {label}", d.poses.len()), &traces)?,
        format!(
            "The {} poses of <em>{}</em> in measuring order, one panel per joint ({}); the red lines are the joint limits. Poses spread over each joint's range excite that joint's parameters.",
            d.poses.len(),
            escape(label),
            d.joints
                .first()
                .map(|j| escape(&j.unit))
                .unwrap_or_default()
        ),
    );

    if !d.margins.is_empty() {
        s.html("<h3>Constraint margins</h3>\n<p class=\"note\">The smallest margin of each kind of constraint over all poses, and where it occurs. Distances (mm) are clearances between robot capsules, obstacles, half-spaces and the laser beam; the incidence margin is the angle left before the reflector's acceptance limit (deg); the joint-limit margin is the distance of the closest joint from its limit. A negative margin is a violation. <em>Required</em> is what the cell's <code>[design]</code> asks for (<code>incidence_margin_deg</code> for the incidence, <code>line_of_sight_margin_mm</code> for the beam, <code>clearance_mm</code> for the other distances, <code>joint_margin_deg</code> for joints); a constraint no pose can change (a base standing on the floor) is exempt. The smallest clearance is highlighted.</p>\n");
        let mm: Vec<usize> = (0..d.margins.len())
            .filter(|&i| d.margins[i].unit == "mm" && d.margins[i].kind != "joint limits")
            .collect();
        let smallest_mm = mm
            .iter()
            .copied()
            .min_by(|&i, &j| d.margins[i].value.total_cmp(&d.margins[j].value));
        let mrows: Vec<Vec<String>> = d
            .margins
            .iter()
            .enumerate()
            .map(|(i, m)| {
                vec![
                    format!(
                        "{}{}",
                        if Some(i) == smallest_mm { "!" } else { "" },
                        escape(&m.kind)
                    ),
                    m.per_pose.to_string(),
                    format!("{} {}", fixed(m.value, 2), escape(&m.unit)),
                    format!("{} {}", fixed(m.required, 2), escape(&m.unit)),
                    if m.meets {
                        "yes"
                    } else {
                        "<strong>no</strong>"
                    }
                    .to_string(),
                    escape(&m.constraint),
                    m.pose.to_string(),
                ]
            })
            .collect();
        s.html(table(
            &[
                "constraint kind",
                "per pose",
                "smallest margin",
                "required",
                "meets",
                "constraint",
                "pose",
            ],
            &mrows,
            &[1, 2, 3, 6],
        ));
        if !mm.is_empty() {
            let cats: Vec<String> = mm.iter().map(|&i| d.margins[i].kind.clone()).collect();
            let vals: Vec<f64> = mm.iter().map(|&i| d.margins[i].value).collect();
            let hl = smallest_mm.and_then(|k| mm.iter().position(|&i| i == k));
            s.figure(
                bar_figure(
                    &format!("Smallest clearance per constraint kind — {label}"),
                    "smallest margin over the design (mm)",
                    &cats,
                    &[("smallest margin".into(), vals)],
                    hl.map(|c| (0, c)),
                    true,
                )?,
                format!(
                    "Smallest clearance of each distance constraint kind over the {} poses of <em>{}</em> (mm; logarithmic axis when every clearance is positive); the tightest is marked. An optimised design typically rests on some constraints (clearances near the cell's required clearance plus the planner's 0.05 mm margin).",
                    d.poses.len(),
                    escape(label)
                ),
            );
        }
    }
    Ok(s)
}

/// Most infeasible pool rows listed on the page; the design record lists them all.
const INFEASIBLE_ROWS_SHOWN: usize = 200;

/// The pose pool of a design planned with `plan --pool`, in one line.
fn pool_summary(pool: &PoolReport) -> String {
    let refinement = match pool.refine_radius {
        Some(r) => format!(
            "refined within ±{} per joint (deg; mm for a prismatic joint) of the pool poses, largest joint move {}",
            number(r),
            fixed(pool.largest_move, 4)
        ),
        None => "not refined: the design is pool rows exactly".into(),
    };
    format!(
        "<code>{}</code>: {} rows, {} feasible, {} infeasible (never chosen); {refinement}",
        escape(&pool.file),
        pool.rows,
        pool.feasible,
        pool.infeasible.len()
    )
}

/// The pool row behind each pose of the design, and the infeasible rows with their cause.
fn pool_tables(s: &mut Section, pool: &PoolReport) {
    s.html("<h3>Pose pool</h3>\n<p class=\"note\">The pool row (1-based, header not counted) and <code>pose_id</code> of each pose of the design, in design-file order: a refined pose started from that row.</p>\n");
    let chosen: Vec<Vec<String>> = pool
        .chosen
        .iter()
        .enumerate()
        .map(|(k, r)| vec![(k + 1).to_string(), r.row.to_string(), escape(&r.id)])
        .collect();
    s.html(table(
        &["design pose", "pool row", "pose_id"],
        &chosen,
        &[0, 1],
    ));
    if pool.infeasible.is_empty() {
        return;
    }
    let shown = pool.infeasible.len().min(INFEASIBLE_ROWS_SHOWN);
    s.html(format!(
        "<p class=\"note\">Infeasible pool rows{}: the violated constraint with the smallest margin (a joint past its limit comes first). They were never chosen.</p>\n",
        if shown < pool.infeasible.len() {
            format!(
                " (the first {shown} of {}; the design record's <code>pool.infeasible</code> lists all)",
                pool.infeasible.len()
            )
        } else {
            String::new()
        }
    ));
    let infeasible: Vec<Vec<String>> = pool.infeasible[..shown]
        .iter()
        .map(|r| {
            vec![
                r.pose.row.to_string(),
                escape(&r.pose.id),
                escape(&r.constraint),
                format!("{} {}", fixed(r.margin, 3), escape(&r.unit)),
            ]
        })
        .collect();
    s.html(table(
        &["pool row", "pose_id", "violated constraint", "margin"],
        &infeasible,
        &[0, 3],
    ));
}
