//! `armcal identify`: calibrate the cell's free parameters from a data file.

use super::digits::{decimals_or_digits, fixed};
use super::output::{
    load_cell, load_data, load_estimate, load_station_data, station_files, AcceptUnconverged,
    Outputs,
};
use super::progress::Progress;
use anyhow::bail;
use armcal::{
    identify, Candidate, ErrorStats, Estimate, FramesRefit, IdentifySettings, LmSettings, Loss,
    Method, NonGeometric, NonGeometricChoice, ParameterEstimate, SolverReport, TermVerdict,
    ToleranceSettings,
};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// Cell file or built-in robot.
    #[arg(long)]
    pub cell: String,
    /// Data file (CSV). Repeat it, each as `STATION=FILE`, for one fit over the data of
    /// several instrument stations (every row of FILE measured from STATION; a `station`
    /// column names the station row by row instead): each station gets its own instrument
    /// pose, `<instrument>@<STATION>.x` …, the robot is shared.
    #[arg(long, required = true)]
    pub data: Vec<String>,
    /// Fraction of configurations held out at random for validation, in [0, 1).
    #[arg(long, default_value_t = 0.0, value_parser = holdout_fraction, allow_negative_numbers = true)]
    pub holdout: f64,
    /// Validate on this data file of the same cell instead (the whole --data is fitted).
    #[arg(long, conflicts_with = "holdout")]
    pub test: Option<PathBuf>,
    /// Robust estimation (IRLS) with this loss.
    #[arg(long, value_parser = ["huber", "cauchy"])]
    pub robust: Option<String>,
    /// Solver.
    #[arg(long, default_value = "lm", value_parser = ["lm", "gn", "kalman"])]
    pub method: String,
    /// Iteration limit of Levenberg–Marquardt and Gauss–Newton (per run: the frames-first
    /// stage and each robust reweighting are runs of their own; the Kalman filter keeps its
    /// own limit).
    #[arg(long, default_value_t = ToleranceSettings::default().max_iterations)]
    pub max_iterations: usize,
    /// Seed of the held-out split.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output estimate (JSON).
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite an existing output file.
    #[arg(long)]
    pub force: bool,
    /// No progress display.
    #[arg(long)]
    pub quiet: bool,
    /// `frames`: keep every robot (link) parameter of --estimate and re-fit only the
    /// instrument, base, tool and target frames (a re-installed tracker, a re-mounted
    /// probe). Needs --estimate, of the same cell.
    #[arg(long, value_parser = ["frames"], requires = "estimate")]
    pub refit: Option<String>,
    /// The estimate (estimate.json of the same cell) whose robot parameters --refit keeps.
    #[arg(long, requires = "refit")]
    pub estimate: Option<PathBuf>,
    /// The cell's non-geometric terms ([parameters] compliance / periodic; a tree cell's
    /// bending counts as compliance) the fit keeps:
    /// `as-cell` (all), `none` (the kinematic model), `compliance`, `periodic`, `both`, or
    /// `auto`: the candidate chosen by k-fold cross-validation on the training data (the
    /// fewest terms within one standard error of the best held-out RMS), every candidate's
    /// table printed and kept in the estimate.
    #[arg(long, default_value = "as-cell", value_parser = ["as-cell", "none", "compliance", "periodic", "both", "auto"])]
    pub nongeometric: String,
    /// Folds of the cross-validation of `--nongeometric auto` (seeded by --seed).
    #[arg(long, default_value_t = 5)]
    pub folds: usize,
    /// Write the estimate although the model does not fit the data (a gross misfit) or the
    /// data's or the model's units look wrong; the estimate, and every output made with it,
    /// then says so.
    #[arg(long)]
    pub accept_misfit: bool,
    /// Try every joint sign and zero hypothesis on the data (a quick fit each) even when the
    /// fit shows no gross misfit (it always runs on an unexplained one).
    #[arg(long)]
    pub diagnose_signs: bool,
    #[command(flatten)]
    pub accept: AcceptUnconverged,
}

/// The flag that accepts a refused fit.
const ACCEPT_MISFIT: &str = "--accept-misfit";

pub fn run(a: &Args) -> anyhow::Result<()> {
    let cell_path = Path::new(&a.cell);
    if cell_path.is_file() && armcal::describes_tree(cell_path)? {
        return super::tree::identify(a, cell_path);
    }
    let files = station_files(&a.data);
    let mut inputs = vec![Path::new(&a.cell)];
    inputs.extend(files.iter().map(|(_, f)| f.as_path()));
    inputs.extend(a.test.as_deref());
    inputs.extend(a.estimate.as_deref());
    let outputs = Outputs::plan(a.force, &inputs, &[&a.out])?;
    let cell = load_cell(&a.cell)?;
    let data = load_station_data(&cell, &files)?;
    let test = a.test.as_deref().map(|t| load_data(&cell, t)).transpose()?;
    let refit = match &a.estimate {
        Some(path) => Some(FramesRefit {
            estimate: load_estimate(path, &a.accept, Some(&cell.model))?.0,
            origin: path.display().to_string(),
            acceptance: a.accept.acceptance(),
        }),
        None => None,
    };
    let opts = settings(a, test, refit);
    let est = identify(&cell, &data, &opts, &mut Progress::new(a.quiet))?;
    if let Some(fit) = est.verdicts.as_ref().map(|v| &v.fit) {
        if fit.refuses() && !a.accept_misfit {
            print_summary(&est);
            bail!(
                "{}\nno estimate written: correct the data or the cell, or pass {ACCEPT_MISFIT} to write it anyway (marked as not fitting its data)",
                fit.reasons().join("\n")
            );
        }
    }
    outputs.commit(&[(&a.out, &serde_json::to_string_pretty(&est)?)])?;
    print_summary(&est);
    println!("\nestimate → {}", a.out.display());
    if !est.solver.status.is_converged() {
        bail!(
            "the fit did not converge ({}); check the cell's nominal model and the data (units, joint columns), or fix weakly identifiable parameters",
            est.solver.status
        );
    }
    Ok(())
}

/// The library's settings of a fit from the flags, with the test data and the frames
/// refit read.
pub fn settings(
    a: &Args,
    test: Option<armcal::Dataset>,
    refit: Option<FramesRefit>,
) -> IdentifySettings {
    IdentifySettings {
        method: Method::from_name(&a.method).expect("clap checked"),
        robust: a.robust.as_deref().and_then(Loss::from_name),
        holdout: a.holdout,
        test,
        seed: a.seed,
        lm: LmSettings {
            tolerances: ToleranceSettings {
                max_iterations: a.max_iterations,
                ..Default::default()
            },
            ..Default::default()
        },
        refit,
        start: None,
        nongeometric: match a.nongeometric.as_str() {
            "as-cell" => NonGeometric::AsCell,
            "auto" => NonGeometric::Auto { folds: a.folds },
            other => NonGeometric::Only(Candidate::from_name(other).expect("clap checked")),
        },
        diagnose_signs: a.diagnose_signs,
        accept_misfit: a.accept_misfit.then(|| ACCEPT_MISFIT.to_string()),
    }
}

/// `--holdout`: a fraction in [0, 1).
fn holdout_fraction(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(h) if (0.0..1.0).contains(&h) => Ok(h),
        Ok(h) => Err(format!(
            "{h} is not a fraction in [0, 1) (0: no held-out validation)"
        )),
        Err(e) => Err(format!("not a number: {e}")),
    }
}

/// The human-readable summary of an estimate.
pub fn print_summary(e: &Estimate) {
    println!(
        "{}: {} measurements at {} configurations from {}",
        e.cell, e.measurements, e.configurations, e.data
    );
    print_solver_and_parameters(&e.solver, &e.parameters, 14);
    if !e.fixed_reasons.is_empty() {
        println!("\nfixed (not identifiable):");
        for (_, r) in &e.fixed_reasons {
            println!("  - {r}");
        }
    }
    if let Some(r) = &e.refit {
        println!(
            "\nframes refit: the {} robot parameters kept from {} (cell `{}`, fitted on {})",
            r.kept, r.estimate, r.cell, r.data
        );
    }
    if let Some(d) = &e.rank_deficit {
        println!("\nbelow the generic count: {d}");
    }
    print_nongeometric(&e.nongeometric);
    print_choice(e.nongeometric_choice.as_ref());
    if !e.strong_correlations.is_empty() {
        println!("\nstrongly correlated pairs (|ρ| > 0.95):");
        for (a, b, r) in &e.strong_correlations {
            println!("  {a} ~ {b}: ρ = {r:.3}");
        }
    }
    let u = &e.uncertainty;
    println!(
        "\nvariance factor σ̂₀² = {:.3} (χ² = {:.1}, {} dof, p = {:.3}): {}",
        u.variance_factor, u.chi2, u.dof, u.p_value, u.verdict
    );
    if !e.outliers.is_empty() {
        println!(
            "  on the {} measurements kept; the {} outliers are left out of χ² and C_p",
            e.measurements - e.outliers.len(),
            e.outliers.len()
        );
    }
    for f in &e.far_from_nominal {
        println!(
            "warning: {} = {:.3} deg is {:.1} deg from nominal {:.3} deg: {}",
            f.name,
            f.estimate_deg,
            (f.estimate_deg - f.nominal_deg).abs(),
            f.nominal_deg,
            f.reason
        );
    }
    if let Some(v) = &e.verdicts {
        println!("χ² verdict: {}", v.chi2.meaning);
        println!("identifiability: {}", v.identifiability.meaning);
        print_fit_checks(&v.fit);
    }
    let r = &e.residuals;
    println!("residuals (mm)      RMS        max        p95");
    for (n, s) in [("x", &r.x), ("y", &r.y), ("z", &r.z), ("|e|", &r.norm)] {
        println!("  {n:<6} {:>12.4} {:>10.4} {:>10.4}", s.rms, s.max, s.p95);
    }
    if let Some(s) = &r.orientation {
        println!(
            "orientation (deg)   mean {:.4}  RMS {:.4}  max {:.4}  p95 {:.4}",
            s.mean, s.rms, s.max, s.p95
        );
    }
    for (t, c) in e.tcp.iter().zip(&e.tcp_constrained) {
        println!(
            "TCP at `{}`: σ = ({}, {}, {}) mm, (1/3) tr C_s = {} mm² (eq. 19: {})",
            t.name,
            decimals_or_digits(t.covariance[(0, 0)].sqrt(), 4),
            decimals_or_digits(t.covariance[(1, 1)].sqrt(), 4),
            decimals_or_digits(t.covariance[(2, 2)].sqrt(), 4),
            decimals_or_digits(t.kpi, 5),
            decimals_or_digits(c.trace() / 3.0, 5)
        );
        if let Some(f) = e.model_floor.as_ref().and_then(|f| f.at(&t.name)) {
            let total = t.covariance + f.covariance;
            let largest: Vec<String> = f
                .contributions
                .iter()
                .take(3)
                .map(|(n, v)| format!("{n} {}", decimals_or_digits(*v, 5)))
                .collect();
            println!(
                "  model floor (fixed parameters at their stated prior): σ = ({}, {}, {}) mm, (1/3) tr C_floor = {} mm²{}",
                decimals_or_digits(f.covariance[(0, 0)].sqrt(), 4),
                decimals_or_digits(f.covariance[(1, 1)].sqrt(), 4),
                decimals_or_digits(f.covariance[(2, 2)].sqrt(), 4),
                decimals_or_digits(f.kpi, 5),
                if largest.is_empty() {
                    String::new()
                } else {
                    format!(" (largest: {} mm²)", largest.join(", "))
                }
            );
            println!(
                "  total (C_s + C_floor): σ = ({}, {}, {}) mm, (1/3) tr = {} mm²",
                decimals_or_digits(total[(0, 0)].sqrt(), 4),
                decimals_or_digits(total[(1, 1)].sqrt(), 4),
                decimals_or_digits(total[(2, 2)].sqrt(), 4),
                decimals_or_digits(total.trace() / 3.0, 5)
            );
        }
    }
    let o = &e.observability;
    println!(
        "observability O1 {:.4e}  O2 {:.4e}  O3 {:.4e}  O4 {:.4e}  O5 {:.4e}; condition number (column-scaled) {:.1}",
        o.o1, o.o2, o.o3, o.o4, o.o5, o.condition_number
    );
    if let Some(s) = e.robust_scale {
        println!("robust scale of the whitened residuals: {s:.3}");
    }
    if !e.outliers.is_empty() {
        println!("outliers ({}):", e.outliers.len());
        for o in &e.outliers {
            println!(
                "  line {} (pose {}): {:.1} robust σ, weight {:.3}",
                o.line, o.configuration, o.standardized, o.weight
            );
        }
    }
    if let Some(v) = &e.validation {
        println!(
            "\nheld-out validation: {} configurations (fit on {}): {}",
            v.test_configurations, v.train_configurations, v.test_data
        );
        const SHOWN: usize = 12;
        let more = v.test_ids.len().saturating_sub(SHOWN);
        println!(
            "  validation pose ids: {}{} (both sides: `validation` in the estimate)",
            v.test_ids[..v.test_ids.len() - more].join(", "),
            if more > 0 {
                format!(", … and {more} more")
            } else {
                String::new()
            }
        );
        let calibrated = if e.refit.is_some() {
            "frames refitted"
        } else {
            "calibrated"
        };
        println!("  model                     mean       RMS       max       p95   (mm)");
        print_stats_rows([
            ("nominal", &v.nominal),
            ("nominal + frames fitted", &v.frames_only),
            (calibrated, &v.calibrated),
        ]);
        if let Some(o) = &v.orientation {
            println!("  orientation               mean       RMS       max       p95  (deg)");
            print_stats_rows([
                ("nominal", &o.nominal),
                ("nominal + frames fitted", &o.frames_only),
                (calibrated, &o.calibrated),
            ]);
        }
        let groups = [
            ("station", v.errors_by_station()),
            ("temperature", v.errors_by_temperature(0.5)),
        ];
        for (what, rows) in groups.iter().filter(|(_, g)| !g.is_empty()) {
            println!("  {calibrated}, per {what}: n, position mean / RMS / max / p95 (mm), orientation (deg), mean °C");
            for g in rows {
                let o = g.orientation.as_ref().map_or(String::new(), |o| {
                    format!(
                        "  {:.4} / {:.4} / {:.4} / {:.4}",
                        o.mean, o.rms, o.max, o.p95
                    )
                });
                let t = g
                    .temperature_c
                    .map_or(String::new(), |t| format!("  {t:.2} °C"));
                let p = &g.position;
                println!(
                    "    {:<16} {:>5}  {:.4} / {:.4} / {:.4} / {:.4}{o}{t}",
                    g.group, p.count, p.mean, p.rms, p.max, p.p95
                );
            }
        }
    }
}

/// The solver line and the table of the free parameters (nominal, estimate, σ, unit) of a
/// serial or a tree estimate; `name_width` is the width of the name column.
pub fn print_solver_and_parameters(
    solver: &SolverReport,
    parameters: &[ParameterEstimate],
    name_width: usize,
) {
    println!(
        "solver {}{}: {} after {} iterations, {:.1} ms",
        solver.method.words(),
        solver
            .robust
            .map(|l| format!(" + robust {}", l.words()))
            .unwrap_or_default(),
        solver.status,
        solver.iterations,
        solver.time_ms
    );
    println!(
        "\n{:<name_width$} {:>14} {:>14} {:>12} {:>5}",
        "parameter", "nominal", "estimate", "± σ", "unit"
    );
    for p in parameters.iter().filter(|p| p.free) {
        println!(
            "{:<name_width$} {:>14} {:>14} {:>12.5} {:>5}",
            p.name,
            fixed(p.nominal, 5),
            fixed(p.estimate, 5),
            p.sigma.unwrap_or(f64::NAN),
            p.unit
        );
    }
}

/// What the checks of the fit found: units, blunders, a gross misfit, a robot far from its
/// drawing, the sign and zero diagnosis, and whether a refused fit was accepted.
fn print_fit_checks(fit: &armcal::FitChecks) {
    for u in &fit.units {
        println!("UNITS ({}): {}", u.subject, u.message);
    }
    if !fit.blunders.is_empty() {
        println!(
            "BLUNDERS: {} lie farther from the other measurements than the model allows by more than the plausible model error ({:.1} mm): remove them, or fit with --robust huber",
            fit.blunder_rows(),
            fit.plausible_mm
        );
    }
    if let Some(m) = &fit.misfit {
        println!("MISFIT: {}", m.message);
    }
    if let Some(f) = &fit.far {
        println!("FAR FROM NOMINAL: {}", f.message);
    }
    if let Some(d) = &fit.diagnosis {
        println!("sign and zero diagnosis: {}", d.message);
    }
    if let Some(how) = &fit.accepted {
        println!("ACCEPTED with {how}: this estimate does not fit its data; every output made with it says so");
    }
}

/// One line per model of the held-out table: mean, RMS, max and p95.
fn print_stats_rows(rows: [(&str, &ErrorStats); 3]) {
    for (n, s) in rows {
        println!(
            "  {n:<24} {:>8.4} {:>9.4} {:>9.4} {:>9.4}",
            s.mean, s.rms, s.max, s.p95
        );
    }
}

/// `--nongeometric auto`: every candidate's cross-validated held-out errors and the choice.
pub(super) fn print_choice(choice: Option<&NonGeometricChoice>) {
    let Some(c) = choice else {
        return;
    };
    println!(
        "
non-geometric terms chosen by {}-fold cross-validation on the {} training configurations:",
        c.folds, c.configurations
    );
    println!(
        "  {:<26} {:>5} {:>9} {:>9} {:>9} {:>9}",
        "candidate", "terms", "mean", "RMS", "± s.e.", "max (mm)"
    );
    for s in &c.candidates {
        let mark = if s.candidate == c.chosen {
            "  ← chosen"
        } else {
            ""
        };
        println!(
            "  {:<26} {:>5} {:>9.4} {:>9.4} {:>9.4} {:>9.4}{mark}",
            s.candidate.words(),
            s.terms,
            s.held_out.mean,
            s.held_out.rms,
            s.standard_error,
            s.held_out.max
        );
    }
    println!("  rule: {}", c.rule);
}

/// The gate of the non-geometric terms: per term estimate ± σ, its largest correlation with
/// another parameter, the share of its effect the others cannot absorb, and the verdict.
pub(super) fn print_nongeometric(verdicts: &[TermVerdict]) {
    if verdicts.is_empty() {
        return;
    }
    println!(
        "
non-geometric terms (compliance κ in µrad per m of lever, periodic amplitudes in arcsec):"
    );
    println!("  term                        estimate ± σ          max |ρ| with another    not absorbed   verdict");
    for v in verdicts {
        let rho = v
            .most_correlated
            .as_ref()
            .map_or("-".to_string(), |(n, r)| format!("{r:+.3} ({n})"));
        let verdict = match (v.separable, v.wrong_sign) {
            (false, _) => "not separable",
            (true, true) => "WRONG SIGN: the arm rises against gravity",
            (true, false) => "separable",
        };
        println!(
            "  {:<26} {:>9.1} ± {:<8.1} {:<23} {:>8.1} %   {verdict}",
            v.name,
            v.estimate,
            v.sigma,
            rho,
            100.0 * v.unabsorbed
        );
    }
}
