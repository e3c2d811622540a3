//! `armcal campaign`: the adaptive measurement campaign (paper §6) — `start` plans the
//! first batch, `step` takes a measured batch and stops or plans the next, `status` says
//! where a campaign stands, `simulate` runs the loop against a virtual robot, `study`
//! compares it with one-shot and random designs over seeded runs.

use super::output::{load_cell, load_cell_to_measure, load_data, with_note, NoteStyle, Outputs};
use super::progress::Progress;
use anyhow::Context;
use armcal::Perturbation;
use armcal::{
    campaign_coverage as coverage, campaign_coverage_with_floor as coverage_with_floor,
    campaign_poses_summary as poses_summary, campaign_study, CampaignRunOutcome,
    CampaignStudySettings as StudySettings,
};
use armcal::{
    campaign_simulate, campaign_start, campaign_step_with, CampaignDecision as Decision,
    CampaignPlanner as Planner, CampaignSettings, CampaignState, CampaignStep,
    CampaignStepSettings, StepResult, CAMPAIGN_JOINT_TOLERANCE,
};
use std::path::{Path, PathBuf};

#[derive(clap::Subcommand)]
pub enum Command {
    /// Plan the first batch (the fewest poses that identify the free set, KPI criterion,
    /// every cell constraint); writes DIR/next.csv and DIR/campaign.json.
    Start(StartArgs),
    /// Add the measured batch (the poses of DIR/next.csv), identify, and stop at the target
    /// or write the next batch to DIR/next.csv.
    Step(StepArgs),
    /// Poses measured, σ per working pose, predicted poses still needed.
    Status(StatusArgs),
    /// The same loop against a simulated robot and instrument; writes DIR/campaign.json.
    Simulate(SimulateArgs),
    /// Poses needed by the adaptive campaign vs a one-shot KPI design sized to the target vs
    /// random poses, and the coverage of the stopping claim, over seeded virtual robots.
    Study(StudyArgs),
}

#[derive(clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub command: Command,
}

/// What every campaign takes: the cell, the target, batch and budget.
#[derive(clap::Args)]
pub struct Target {
    /// Cell file or built-in robot.
    #[arg(long)]
    pub cell: String,
    /// Stop when every working pose's TCP σ = √((1/3) tr C_s) is at or below this (mm).
    #[arg(long)]
    pub target_sigma_mm: f64,
    /// Poses per batch after the first.
    #[arg(long, default_value_t = 5)]
    pub batch: usize,
    /// The most poses to measure in all (default: no limit; `simulate`: 2000).
    #[arg(long)]
    pub budget: Option<usize>,
}

impl Target {
    fn settings(&self, seed: u64) -> CampaignSettings {
        CampaignSettings {
            target_sigma_mm: self.target_sigma_mm,
            batch: self.batch,
            budget: self.budget,
            seed,
            planner: Planner::Kpi,
            prior: None,
        }
    }

    /// The cell's file as an absolute path (so `step` finds it from any directory), or the
    /// built-in name.
    fn source(&self) -> String {
        std::fs::canonicalize(&self.cell)
            .map(|p| p.display().to_string())
            .unwrap_or_else(|_| self.cell.clone())
    }
}

#[derive(clap::Args)]
pub struct StartArgs {
    #[command(flatten)]
    pub target: Target,
    /// Seed of the planner's candidate pools.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The campaign's directory (campaign.json, next.csv, estimate.json).
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite an existing campaign in DIR.
    #[arg(long)]
    pub force: bool,
    /// No progress display.
    #[arg(long)]
    pub quiet: bool,
}

#[derive(clap::Args)]
pub struct StepArgs {
    /// The campaign's directory.
    pub dir: PathBuf,
    /// The measured batch: a data file of the cell with the poses of DIR/next.csv.
    #[arg(long)]
    pub data: PathBuf,
    /// How far a measured joint value may be from the planned one in DIR/next.csv (deg; mm
    /// for a prismatic joint): the resolution the controller reports its joints with.
    #[arg(long, default_value_t = CAMPAIGN_JOINT_TOLERANCE)]
    pub joint_tolerance_deg: f64,
    /// Poses of DIR/next.csv the instrument could not measure (ids, comma-separated: the
    /// beam blocked, the reflector turned too far): the data file lacks them, the state
    /// records them and the campaign goes on without them.
    #[arg(long, value_delimiter = ',')]
    pub unmeasurable: Vec<String>,
    /// No progress display.
    #[arg(long)]
    pub quiet: bool,
}

#[derive(clap::Args)]
pub struct StatusArgs {
    /// The campaign's directory.
    pub dir: PathBuf,
}

#[derive(clap::Args)]
pub struct SimulateArgs {
    #[command(flatten)]
    pub target: Target,
    /// Seed of the virtual robot, its measurement noise and the planner.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// σ (mm, per axis) of where the virtual instrument stands off the cell's position: a
    /// tracker set up by tape measure is centimetres off.
    #[arg(long, default_value_t = 20.0, value_name = "MM")]
    pub instrument_offset_mm: f64,
    /// Output directory (campaign.json, estimate.json, truth.json).
    #[arg(long)]
    pub out: PathBuf,
    /// Perturb the virtual robot's fixed parameters by the cell's stated prior too
    /// (`[parameters] fixed_prior`, `fixed_priors`): the coverage then tests the model floor.
    #[arg(long)]
    pub perturb_fixed: bool,
    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
    /// No progress display.
    #[arg(long)]
    pub quiet: bool,
}

#[derive(clap::Args)]
pub struct StudyArgs {
    /// Cell file or built-in robot.
    #[arg(long)]
    pub cell: String,
    /// Target TCP σ's (mm), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "0.7,0.6,0.5")]
    pub targets: Vec<f64>,
    /// Seeded runs per target.
    #[arg(long, default_value_t = 20)]
    pub runs: usize,
    /// Poses per batch of the adaptive and the random campaign.
    #[arg(long, default_value_t = 5)]
    pub batch: usize,
    /// Perturb the virtual robot's fixed parameters by the cell's stated prior too
    /// (`[parameters] fixed_prior`, `fixed_priors`): the coverage then tests the model floor.
    #[arg(long)]
    pub perturb_fixed: bool,
    /// Output record (JSON).
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite an existing output file.
    #[arg(long)]
    pub force: bool,
    /// No progress display.
    #[arg(long)]
    pub quiet: bool,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    match &a.command {
        Command::Start(a) => run_start(a),
        Command::Step(a) => run_step(a),
        Command::Status(a) => run_status(a),
        Command::Simulate(a) => run_simulate(a),
        Command::Study(a) => run_study(a),
    }
}

/// The campaign's files in `dir`.
pub(super) struct Files {
    pub(super) state: PathBuf,
    pub(super) next: PathBuf,
    pub(super) estimate: PathBuf,
}

impl Files {
    pub(super) fn of(dir: &Path) -> Files {
        Files {
            state: dir.join("campaign.json"),
            next: dir.join("next.csv"),
            estimate: dir.join("estimate.json"),
        }
    }
}

/// `next.csv` of a state: the poses to measure, or (stopped) none, with a note saying why.
fn next_csv(cell: &armcal::Cell, state: &CampaignState) -> anyhow::Result<String> {
    let poses: Vec<(String, Vec<f64>)> = state
        .next
        .iter()
        .map(|p| (p.id.clone(), p.q(&cell.model)))
        .collect();
    let refs: Vec<(String, &[f64])> = poses
        .iter()
        .map(|(id, q)| (id.clone(), q.as_slice()))
        .collect();
    let text = cell.write_poses(&refs)?;
    let note = (state.decision != Decision::Measure).then(|| {
        format!(
            "armcal: the campaign has stopped ({}); nothing more to measure",
            state.decision.words()
        )
    });
    Ok(with_note(text, note.as_deref(), NoteStyle::Hash))
}

fn run_start(a: &StartArgs) -> anyhow::Result<()> {
    let files = Files::of(&a.out);
    let outputs = Outputs::plan(
        a.force,
        &[Path::new(&a.target.cell)],
        &[&files.state, &files.next],
    )?;
    let cell = load_cell_to_measure(&a.target.cell)?;
    let state = campaign_start(
        &cell,
        &a.target.source(),
        &a.target.settings(a.seed),
        &mut Progress::new(a.quiet),
    )?;
    outputs.commit(&[
        (&files.state, &state.to_json()?),
        (&files.next, &next_csv(&cell, &state)?),
    ])?;
    println!(
        "campaign on `{}`: target TCP σ ≤ {} mm at {}; {}",
        cell.name,
        state.settings.target_sigma_mm,
        state.working.join(", "),
        first_batch(&state)
    );
    println!(
        "measure {} → then `armcal campaign step {} --data MEASURED.csv`",
        files.next.display(),
        a.out.display()
    );
    Ok(())
}

/// The first batch and the σ predicted once it is measured, with what the prediction
/// depends on: the planner's seed (another seed plans another first batch, and a minimal
/// batch's σ varies several-fold between seeds) and the model it is evaluated at.
fn first_batch(state: &CampaignState) -> String {
    format!(
        "first batch: {} poses (the fewest that identify the free set; planner seed {}), predicted σ {} mm (at the nominal model, the stated instrument σ)",
        state.first_batch,
        state.settings.seed,
        mm_list(&state.first_predicted_sigma_mm)
    )
}

fn read_state(dir: &Path) -> anyhow::Result<CampaignState> {
    let path = Files::of(dir).state;
    let text = armcal::read_capped(&path, armcal::TEXT_CAP).with_context(|| {
        format!(
            "reading {} (is {} a campaign directory?)",
            path.display(),
            dir.display()
        )
    })?;
    Ok(CampaignState::from_json(
        &text,
        &path.display().to_string(),
    )?)
}

fn run_step(a: &StepArgs) -> anyhow::Result<()> {
    let files = Files::of(&a.dir);
    let state = read_state(&a.dir)?;
    let outputs = Outputs::plan(
        true,
        &[a.data.as_path()],
        &[&files.state, &files.next, &files.estimate],
    )?;
    let cell = load_cell(&state.cell_source)?;
    let batch = load_data(&cell, &a.data)?;
    let settings = CampaignStepSettings {
        joint_tolerance: a.joint_tolerance_deg,
        unmeasurable: a.unmeasurable.clone(),
    };
    let r = campaign_step_with(
        &cell,
        &state,
        &batch,
        &settings,
        &mut Progress::new(a.quiet),
    )?;
    let written = step_files(&cell, &r, &files)?;
    let refs: Vec<(&Path, &str)> = written
        .iter()
        .map(|(p, t)| (p.as_path(), t.as_str()))
        .collect();
    outputs.commit(&refs)?;
    print_last_step(&r.state, &files);
    Ok(())
}

/// What a step writes into the campaign's directory: the state, `next.csv` and (with a
/// fit) the estimate.
pub(super) fn step_files(
    cell: &armcal::Cell,
    r: &StepResult,
    files: &Files,
) -> anyhow::Result<Vec<(PathBuf, String)>> {
    let mut written = vec![
        (files.state.clone(), r.state.to_json()?),
        (files.next.clone(), next_csv(cell, &r.state)?),
    ];
    if let Some(e) = &r.estimate {
        written.push((files.estimate.clone(), serde_json::to_string_pretty(e)?));
    }
    Ok(written)
}

/// The last step of `state` and the decision, as `campaign step` prints them.
pub(super) fn print_last_step(state: &CampaignState, files: &Files) {
    let last = state.steps.last().expect("a step");
    print_step(state.steps.len(), last);
    print_decision(state, files);
}

fn mm_list(v: &[f64]) -> String {
    v.iter()
        .map(|s| format!("{s:.4}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// One line (two with a fit) per step: poses, fit, σ per working pose.
fn print_step(k: usize, s: &CampaignStep) {
    let fit = match (&s.fit, &s.fit_error) {
        (Some(f), _) => format!(
            "fit {} after {} iterations{}, σ̂₀² = {} ({} dof), C_s × {:.3}",
            if f.status.is_converged() {
                "converged".to_string()
            } else {
                format!("not converged ({})", f.status)
            },
            f.iterations,
            if f.warm_start { " (warm start)" } else { "" },
            f.variance_factor
                .map_or("–".to_string(), |v| format!("{v:.3}")),
            f.dof,
            f.covariance_scale
        ),
        (None, Some(e)) => format!("no fit: {e}"),
        (None, None) => "no fit".into(),
    };
    println!(
        "step {k}: {} poses measured (+{}); {fit}",
        s.measured,
        s.poses.len()
    );
    if !s.unmeasurable.is_empty() {
        let ids: Vec<&str> = s.unmeasurable.iter().map(|p| p.id.as_str()).collect();
        println!(
            "  not measured (the instrument could not): pose{} {}",
            if ids.len() == 1 { "" } else { "s" },
            ids.join(", ")
        );
    }
    for w in &s.working {
        println!(
            "  `{}`: σ = {:.4} mm (axes {:.4}, {:.4}, {:.4}; 95 % ellipsoid semi-axes {:.3}, {:.3}, {:.3} mm){}",
            w.name,
            w.sigma_mm,
            w.axes_mm[0],
            w.axes_mm[1],
            w.axes_mm[2],
            w.ellipsoid_95_mm[0],
            w.ellipsoid_95_mm[1],
            w.ellipsoid_95_mm[2],
            match (w.true_error_mm, w.true_error_inside_95) {
                (Some(e), Some(inside)) => format!(
                    "; true error {:.3} mm, {} the ellipsoid",
                    (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt(),
                    if inside { "inside" } else { "outside" }
                ),
                _ => String::new(),
            }
        );
        if let Some(f) = w.floor_sigma_mm {
            println!(
                "    model floor (fixed parameters at their stated prior): σ = {f:.4} mm, not reduced by more poses{}",
                match w.true_error_inside_95_with_floor {
                    Some(inside) => format!(
                        "; true error {} the ellipsoid of C_s + C_floor",
                        if inside { "inside" } else { "outside" }
                    ),
                    None => String::new(),
                }
            );
        }
    }
}

fn print_decision(state: &CampaignState, files: &Files) {
    let Some(last) = state.steps.last() else {
        return;
    };
    match state.decision {
        Decision::Measure => println!(
            "→ {}: {}; measure the {} poses of {} (predicted σ {} mm after them; about {} poses in all)",
            state.decision.words(),
            last.reason,
            state.next.len(),
            files.next.display(),
            mm_list(&last.predicted_next_sigma_mm),
            last.predicted_total_poses.unwrap_or(0)
        ),
        _ => println!(
            "→ {} after {} poses: {} (σ as √((1/3) tr C_s), C_s scaled by max(1, σ̂₀²); {:.0} % ellipsoids eᵀC_s⁻¹e ≤ {:.3})",
            state.decision.words(),
            state.measured(),
            last.reason,
            100.0 * state.confidence,
            state.chi2_quantile
        ),
    }
}

fn run_status(a: &StatusArgs) -> anyhow::Result<()> {
    let state = read_state(&a.dir)?;
    let files = Files::of(&a.dir);
    println!(
        "campaign on `{}`: target TCP σ ≤ {} mm; {} poses measured in {} steps{}",
        state.cell,
        state.settings.target_sigma_mm,
        state.measured(),
        state.steps.len(),
        state
            .settings
            .budget
            .map(|b| format!(" (budget {b})"))
            .unwrap_or_default()
    );
    for (k, s) in state.steps.iter().enumerate() {
        print_step(k + 1, s);
    }
    match state.steps.last() {
        None => println!(
            "→ measure the first batch: the {} poses of {} (predicted σ {} mm)",
            state.next.len(),
            files.next.display(),
            mm_list(&state.first_predicted_sigma_mm)
        ),
        Some(last) => {
            print_decision(&state, &files);
            if let Some(total) = last.predicted_total_poses {
                println!(
                    "predicted poses still needed: about {} (from the design's predicted C_s, ∝ 1/N)",
                    total.saturating_sub(state.measured())
                );
            }
        }
    }
    Ok(())
}

fn run_simulate(a: &SimulateArgs) -> anyhow::Result<()> {
    let files = Files::of(&a.out);
    let truth_path = a.out.join("truth.json");
    let outputs = Outputs::plan(
        a.force,
        &[Path::new(&a.target.cell)],
        &[&files.state, &files.estimate, &truth_path],
    )?;
    if !(a.instrument_offset_mm.is_finite() && a.instrument_offset_mm >= 0.0) {
        anyhow::bail!(
            "--instrument-offset-mm {}: give a distance ≥ 0",
            a.instrument_offset_mm
        );
    }
    let cell = load_cell_to_measure(&a.target.cell)?;
    let sim = campaign_simulate(
        &cell,
        &a.target.source(),
        &a.target.settings(a.seed),
        &Perturbation {
            fixed: a.perturb_fixed.then(|| cell.fixed_prior.clone()),
            instrument_length: Some(a.instrument_offset_mm),
            ..Perturbation::default()
        },
        a.seed,
        &mut Progress::new(a.quiet),
    )?;
    let state_json = sim.state.to_json()?;
    let truth = sim.truth.to_json()?;
    let mut written = vec![
        (files.state.as_path(), state_json.as_str()),
        (truth_path.as_path(), truth.as_str()),
    ];
    let estimate = sim
        .estimate
        .as_ref()
        .map(serde_json::to_string_pretty)
        .transpose()?;
    written.extend(estimate.as_deref().map(|e| (files.estimate.as_path(), e)));
    outputs.commit(&written)?;
    println!(
        "simulated campaign on `{}` (virtual robot seed {}), target TCP σ ≤ {} mm; {}",
        cell.name,
        a.seed,
        a.target.target_sigma_mm,
        first_batch(&sim.state)
    );
    for (k, s) in sim.state.steps.iter().enumerate() {
        print_step(k + 1, s);
    }
    print_decision(&sim.state, &files);
    println!("state → {}", files.state.display());
    Ok(())
}

fn run_study(a: &StudyArgs) -> anyhow::Result<()> {
    let outputs = Outputs::plan(a.force, &[Path::new(&a.cell)], &[&a.out])?;
    let cell = load_cell(&a.cell)?;
    let record = campaign_study(
        &cell,
        &StudySettings {
            targets: a.targets.clone(),
            runs: a.runs,
            batch: a.batch,
            perturb_fixed: a.perturb_fixed,
            ..StudySettings::default()
        },
        &mut Progress::new(a.quiet),
    )?;
    outputs.commit(&[(&a.out, &record.to_json()?)])?;
    println!(
        "{} seeded runs per target on `{}`, batches of {} ({:.0} s)",
        a.runs, cell.name, a.batch, record.time_s
    );
    println!("target σ  adaptive: poses mean (min–max), reached, coverage 95 %   one-shot KPI: poses (predicted σ), reached, coverage   random: poses mean (min–max), reached");
    for r in &record.rows {
        let (am, amin, amax) = poses_summary(&r.adaptive);
        let (rm, rmin, rmax) = poses_summary(&r.random);
        let reached = |runs: &[CampaignRunOutcome]| {
            format!(
                "{}/{}",
                runs.iter().filter(|x| x.reached).count(),
                runs.len()
            )
        };
        let cover = |runs: &[CampaignRunOutcome]| {
            let (c, n) = coverage(runs);
            let (f, _) = coverage_with_floor(runs);
            format!(
                "{:.0} % of {n} ({:.0} % with the model floor)",
                100.0 * c,
                100.0 * f
            )
        };
        println!(
            "{:.2} mm   {am:.1} ({amin}–{amax}), {}, {}   {} ({:.4} mm), {}, {}   {rm:.1} ({rmin}–{rmax}), {}",
            r.target_sigma_mm,
            reached(&r.adaptive),
            cover(&r.adaptive),
            r.one_shot_poses,
            r.one_shot_predicted_sigma_mm,
            reached(&r.one_shot),
            cover(&r.one_shot),
            reached(&r.random)
        );
    }
    println!("record → {}", a.out.display());
    Ok(())
}
