//! The whole workflow on the paper cell in one call: plan a KPI design with collision
//! avoidance and a random heuristic design, simulate a measurement campaign on a perturbed
//! "true" robot for each, identify, compensate a small working program, and evaluate on
//! held-out poses. Every intermediate file is returned for writing, with the records a report
//! shows ([`crate::workflow::demo`] adds the HTML report); the same seed gives the same files
//! (solver times are left out of them).

use crate::accuracy::ErrorStats;
use crate::compensate::program::{filter_joint_program, ProgramRecord};
use crate::compensate::IkSettings;
use crate::design::baselines::random_feasible;
use crate::design::plan::{constraint_set, plan, CellConstraints, PlanSettings};
use crate::design::{DesignModel, DesignRecord};
use crate::identify::{identify, Estimate, IdentifySettings};
use crate::measure::csv;
use crate::model::{forward_kinematics, observed_position, Data, Observed};
use crate::progress::Observer;
use crate::sim::{perturbed_truth, simulate, Perturbation, TruthRecord};
use crate::Error;
use serde::{Deserialize, Serialize};

/// Ends the demo's current stage and starts the next.
fn next_stage(observer: &mut dyn Observer, label: &str) {
    observer.finish();
    observer.start(label, None);
}

use crate::cell::builtin::PAPER_CELL_OBSTACLES as CELL;

/// One design's campaign.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Campaign {
    /// `heuristic` or `kpi`.
    pub design: String,
    /// Predicted σ of the TCP at the working pose, √((1/3) tr C_s) (mm).
    pub tcp_sigma_predicted: f64,
    /// |TCP(identified) − TCP(truth)| at the working pose (mm), this campaign.
    pub tcp_error_achieved: f64,
    /// Held-out position error of the identified model against the true robot (mm).
    pub held_out: ErrorStats,
    /// The same, per held-out pose (mm).
    pub held_out_errors: Vec<f64>,
}

/// The demo's numbers.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DemoSummary {
    /// The seed of the truth, the designs and the noise.
    pub seed: u64,
    /// Poses per design.
    pub poses: usize,
    /// Held-out position error of the nominal model against the true robot (mm).
    pub nominal_held_out: ErrorStats,
    /// The nominal model's error per held-out pose (mm).
    pub nominal_held_out_errors: Vec<f64>,
    /// The heuristic design's campaign.
    pub heuristic: Campaign,
    /// The KPI design's campaign.
    pub kpi: Campaign,
    /// Largest miss of the working program on the true robot: nominal joints and filtered
    /// joints (mm).
    pub program_miss_nominal: f64,
    /// (see `program_miss_nominal`)
    pub program_miss_compensated: f64,
    /// Efficiency of the KPI design against the optimality bound, if computed.
    pub kpi_bound_efficiency: Option<f64>,
    /// The working program compensated with the KPI design's estimate (`program.csv` →
    /// `program-corrected.csv`); `None` in summaries of an older armcal.
    #[serde(default)]
    pub program: Option<ProgramRecord>,
    /// The true robot the campaigns measured; `None` in summaries of an older armcal.
    #[serde(default)]
    pub truth: Option<TruthRecord>,
}

/// The demo: its summary, the files it produced (name, content) and the records a report
/// of it shows.
pub struct Demo {
    /// The demo's numbers.
    pub summary: DemoSummary,
    /// Every file of the demo but the report (name, content).
    pub files: Vec<(String, String)>,
    /// The cell calibrated (`cell.toml` among the files).
    pub cell: crate::cell::Cell,
    /// The records of the KPI and the heuristic design (`design-kpi.json`,
    /// `design-heuristic.json`).
    pub kpi_design: DesignRecord,
    /// (see `kpi_design`)
    pub heuristic_design: DesignRecord,
    /// The estimates from the two campaigns (`estimate-kpi.json`, `estimate-heuristic.json`).
    pub kpi_estimate: Estimate,
    /// (see `kpi_estimate`)
    pub heuristic_estimate: Estimate,
}

/// Runs the demo; each stage is a task of `observer` (named by a short label), and the
/// planner and identification report within it.
pub fn run_demo(seed: u64, observer: &mut dyn Observer) -> Result<Demo, Error> {
    let cell =
        crate::cell::Cell::from_toml(CELL, "paper-cell-obstacles.toml", std::path::Path::new("."))?;
    let model = &cell.model;
    let noise = cell.noise();
    let truth = perturbed_truth(model, &Perturbation::default(), seed);
    let mut files = vec![("cell.toml".to_string(), CELL.to_string())];
    let poses = 60;

    observer.start("planning the KPI design (collision avoidance on)", None);
    let mut plan_report = plan(
        &cell,
        &PlanSettings {
            poses,
            seed,
            ..PlanSettings::default()
        },
        &[],
        observer,
    )?;
    // Wall-clock time differs between runs: the demo's files leave it out (zero).
    plan_report.time = std::time::Duration::ZERO;
    let d = DesignModel::from_cell(&cell)?;
    let set = constraint_set(&cell, true)?;
    let cons = CellConstraints::new(&set, &d.params);
    next_stage(observer, "drawing the random heuristic design");
    let (heuristic, _) = random_feasible(model, poses, seed.wrapping_add(1), 2_000_000, |q| {
        cons.feasible(q)
    })?;
    files.push((
        "design-kpi.csv".into(),
        csv::write_configurations(model, &plan_report.design),
    ));
    files.push((
        "design-heuristic.csv".into(),
        csv::write_configurations(model, &heuristic),
    ));
    let kpi_record = DesignRecord::new(
        &cell,
        Some("cell.toml"),
        "KPI-optimal plan (exchange and refinement, collision avoidance on)",
        &plan_report.design,
        Some(plan_report.clone()),
        true,
    )?;
    let heuristic_record = DesignRecord::new(
        &cell,
        Some("cell.toml"),
        "random feasible poses (heuristic)",
        &heuristic,
        None,
        true,
    )?;
    for (name, record) in [
        ("design-kpi.json", &kpi_record),
        ("design-heuristic.json", &heuristic_record),
    ] {
        files.push((
            name.into(),
            serde_json::to_string_pretty(record).map_err(|e| Error::Output(e.to_string()))?,
        ));
    }

    // Held-out configurations: feasible poses not in either design.
    let (held_out, _) = random_feasible(model, 100, seed.wrapping_add(2), 2_000_000, |q| {
        cons.feasible(q)
    })?;
    let mut fk = Data::new(model);
    let positions = |params: &[f64], fk: &mut Data<f64>| -> Vec<nalgebra::Vector3<f64>> {
        held_out
            .iter()
            .map(|q| {
                forward_kinematics(model, fk, params, q);
                observed_position(fk, Observed::Target(0))
            })
            .collect()
    };
    let true_positions = positions(&truth, &mut fk);
    let errors_of = |params: &[f64], fk: &mut Data<f64>| -> Vec<f64> {
        positions(params, fk)
            .iter()
            .zip(&true_positions)
            .map(|(a, b)| (a - b).norm())
            .collect()
    };
    let nominal_held_out_errors = errors_of(&model.nominal(), &mut fk);
    let work = cell.working[0].q.clone();
    let tcp = |params: &[f64], fk: &mut Data<f64>| {
        forward_kinematics(model, fk, params, &work);
        observed_position(fk, Observed::Tool)
    };
    let tcp_truth = tcp(&truth, &mut fk);
    // The held-out poses measured without noise on the true robot: each estimate's
    // held-out validation is then its error against the truth.
    let mut held_out_truth = simulate(model, &truth, &held_out, None, 0)?;
    held_out_truth.source = format!(
        "{} feasible poses in neither design, measured without noise on the true robot",
        held_out.len()
    );

    let mut campaign = |name: &str,
                        design: &[Vec<f64>],
                        noise_seed: u64,
                        files: &mut Vec<(String, String)>|
     -> Result<(Campaign, Estimate), Error> {
        next_stage(
            observer,
            &format!("measuring and identifying ({name} design)"),
        );
        let data = simulate(model, &truth, design, Some(&noise), noise_seed)?;
        files.push((format!("data-{name}.csv"), csv::write_string(&data, model)?));
        let mut est = identify(
            &cell,
            &data,
            &IdentifySettings {
                seed,
                test: Some(held_out_truth.clone()),
                ..Default::default()
            },
            observer,
        )?;
        // Wall-clock time is the one thing that differs between runs: the demo's files
        // leave it out (0) so that the same seed gives identical files.
        est.solver.time_ms = 0.0;
        files.push((
            format!("estimate-{name}.json"),
            serde_json::to_string_pretty(&est).map_err(|e| Error::Output(e.to_string()))?,
        ));
        let p = est.params_for(model)?;
        let held_out_errors = errors_of(&p, &mut fk);
        let c = Campaign {
            design: name.into(),
            tcp_sigma_predicted: est.tcp.first().map(|t| t.kpi.sqrt()).unwrap_or(f64::NAN),
            tcp_error_achieved: (tcp(&p, &mut fk) - tcp_truth).norm(),
            held_out: ErrorStats::of(&held_out_errors),
            held_out_errors,
        };
        Ok((c, est))
    };
    let (heuristic_c, heuristic_est) =
        campaign("heuristic", &heuristic, seed.wrapping_add(10), &mut files)?;
    let (kpi_c, kpi_est) = campaign(
        "kpi",
        &plan_report.design,
        seed.wrapping_add(20),
        &mut files,
    )?;

    next_stage(observer, "compensating a working program");
    let calibrated = kpi_est.params_for(model)?;
    let program: Vec<(String, Vec<f64>)> = [
        [0.0, -30.0, 60.0, 0.0, -60.0, 0.0],
        [10.0, -25.0, 55.0, 5.0, -65.0, 10.0],
        [-10.0, -35.0, 65.0, -5.0, -55.0, -10.0],
        [5.0, -20.0, 50.0, 0.0, -70.0, 0.0],
        [-5.0, -40.0, 70.0, 0.0, -50.0, 0.0],
    ]
    .iter()
    .enumerate()
    .map(|(i, q)| {
        (
            format!("{}", i + 1),
            q.iter().map(|x: &f64| x.to_radians()).collect(),
        )
    })
    .collect();
    let rows = filter_joint_program(
        model,
        &model.nominal(),
        &calibrated,
        &program,
        &IkSettings::default(),
    );
    let (mut miss_nominal, mut miss_comp) = (0.0f64, 0.0f64);
    for row in &rows {
        forward_kinematics(model, &mut fk, &model.nominal(), &row.q_nominal);
        let wanted = fk.tool().trans;
        forward_kinematics(model, &mut fk, &truth, &row.q_nominal);
        miss_nominal = miss_nominal.max((fk.tool().trans - wanted).norm());
        forward_kinematics(model, &mut fk, &truth, &row.result.q);
        miss_comp = miss_comp.max((fk.tool().trans - wanted).norm());
    }
    files.push((
        "program.csv".into(),
        csv::write_configurations(
            model,
            &program.iter().map(|p| p.1.clone()).collect::<Vec<_>>(),
        ),
    ));
    files.push((
        "program-corrected.csv".into(),
        csv::write_configurations(
            model,
            &rows.iter().map(|r| r.result.q.clone()).collect::<Vec<_>>(),
        ),
    ));
    let summary = DemoSummary {
        seed,
        poses,
        nominal_held_out: ErrorStats::of(&nominal_held_out_errors),
        nominal_held_out_errors,
        heuristic: heuristic_c,
        kpi: kpi_c,
        program_miss_nominal: miss_nominal,
        program_miss_compensated: miss_comp,
        kpi_bound_efficiency: plan_report.bound.as_ref().and_then(|b| b.efficiency),
        program: Some(ProgramRecord::of(model, &rows)),
        truth: Some(TruthRecord::new(&cell.name, model, &truth, seed)),
    };
    files.push((
        "summary.json".into(),
        serde_json::to_string_pretty(&summary).map_err(|e| Error::Output(e.to_string()))?,
    ));

    observer.finish();
    Ok(Demo {
        summary,
        files,
        cell,
        kpi_design: kpi_record,
        heuristic_design: heuristic_record,
        kpi_estimate: kpi_est,
        heuristic_estimate: heuristic_est,
    })
}
