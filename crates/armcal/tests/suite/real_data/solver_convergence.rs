//! Real data: the fits of the real data sets converge at the default settings, on seeds
//! 1–20 of their 70/30 held-out split, within a bounded number of Levenberg–Marquardt
//! iterations per solver run (issue 30, item 6), and the checks of the fit (units,
//! blunders, gross misfit, far from the drawing) raise no false alarm on them. Every Levenberg–Marquardt run of
//! a fit counts (the free-set and non-geometric refits); the frames-first stage runs
//! silently and is not counted. `measure_iterations` prints the table of every set.
//!
//! Measured table (min / median / max over seeds 1–20 of each fit's longest run) and its
//! history: README "Identification" (`identify` options).

use super::motoman_calibration::motoman;
use super::ur10_stations::{series, ur10_cell};
use armcal::{identify, Cell, Dataset, Estimate, IdentifySettings, Observer};
use rayon::prelude::*;

/// Records the iterations of every Levenberg–Marquardt run it observes.
#[derive(Default)]
struct Runs {
    /// Iterations of each finished run.
    done: Vec<usize>,
    /// Open tasks: `Some(iterations)` for a solver run.
    open: Vec<Option<usize>>,
    /// The lowest cost after each iteration of the current run, and of the longest run.
    costs: Vec<f64>,
    longest: Vec<f64>,
}

impl Observer for Runs {
    fn start(&mut self, task: &str, _total: Option<usize>) {
        self.open.push((task == "Levenberg–Marquardt").then_some(0));
    }
    fn iteration(&mut self, iteration: usize, _cost: f64, _damping: f64) {
        if let Some(Some(k)) = self.open.last_mut() {
            *k = (*k).max(iteration);
            let low = self.costs.last().map_or(_cost, |c: &f64| c.min(_cost));
            self.costs.resize(iteration, low);
            self.costs[iteration - 1] = low;
        }
    }
    fn finish(&mut self) {
        if let Some(Some(k)) = self.open.pop() {
            self.done.push(k);
            if self.costs.len() > self.longest.len() {
                self.longest = std::mem::take(&mut self.costs);
            }
            self.costs.clear();
        }
    }
}

/// The real data sets with their cells `examples/*-cell.toml` (`nongeometric`: the
/// non-geometric cells `examples/*-nongeometric-cell.toml`).
fn sets(nongeometric: bool) -> Vec<(String, Cell, Dataset)> {
    let kind = if nongeometric {
        "nongeometric-cell"
    } else {
        "cell"
    };
    let mut sets = Vec::new();
    for arm in ["right", "left"] {
        let (cell, data) = motoman(&format!("{arm}-{kind}"), arm);
        sets.push((format!("motoman {arm} {kind}"), cell, data));
    }
    let cell = ur10_cell(&format!("ur10-leica-{kind}"));
    for s in ["B", "D"] {
        let data = series(&cell, s);
        sets.push((format!("ur10 {s} {kind}"), cell.clone(), data));
    }
    sets
}

/// The fit of `data` at the default settings with 30 % held out at random by `seed` and
/// the iteration limit `max_iterations`, and its solver runs' iterations.
fn fit(cell: &Cell, data: &Dataset, seed: u64, max_iterations: usize) -> (Estimate, Vec<usize>) {
    let (est, runs) = fit_runs(cell, data, seed, max_iterations);
    (est, runs.done)
}

fn fit_runs(cell: &Cell, data: &Dataset, seed: u64, max_iterations: usize) -> (Estimate, Runs) {
    let mut opts = IdentifySettings {
        holdout: 0.3,
        seed,
        ..Default::default()
    };
    opts.lm.tolerances.max_iterations = max_iterations;
    let mut runs = Runs::default();
    let est = identify(cell, data, &opts, &mut runs).unwrap();
    (est, runs)
}

/// Every fit of `sets` on `seeds` converges at the default settings, every solver run
/// within `bound(name)` iterations, and no check of the fit refuses it (units, gross
/// misfit, a robot link angle 90°+ from its drawing) or names a blunder.
fn converge_within(
    sets: Vec<(String, Cell, Dataset)>,
    seeds: std::ops::RangeInclusive<u64>,
    bound: impl Fn(&str) -> usize + Sync,
) {
    let cases: Vec<(usize, u64)> = (0..sets.len())
        .flat_map(|s| seeds.clone().map(move |seed| (s, seed)))
        .collect();
    let failures: Vec<String> = cases
        .into_par_iter()
        .filter_map(|(s, seed)| {
            let (name, cell, data) = &sets[s];
            let default = IdentifySettings::default().lm.tolerances.max_iterations;
            let (est, runs) = fit(cell, data, seed, default);
            let checks = &est.verdicts.as_ref().unwrap().fit;
            let ok = est.solver.status.is_converged()
                && runs.iter().all(|&k| k <= bound(name))
                && !checks.refuses()
                && checks.far.is_none()
                && checks.blunders.is_empty();
            (!ok).then(|| {
                format!(
                    "{name} seed {seed}: runs {runs:?}, {}, checks {:?}",
                    est.solver.status,
                    checks.reasons()
                )
            })
        })
        .collect();
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The kinematic cells of the Motoman arms and the UR10 series B and D on seeds 1–20:
/// bound 60 (measured 25–42 right, 14–33 left, 3 and 6 on the UR10). Before the
/// frames-first start held the undetermined reflector offset and Levenberg–Marquardt
/// became a trust-region method with geodesic acceleration the right arm needed 101–536
/// (over the default limit 200 on 13 of 20 seeds: `identify` failed), the left 71–184.
#[test]
fn every_kinematic_fit_converges_on_20_seeds_without_a_false_alarm() {
    converge_within(sets(false), 1..=20, |_| 60);
}

/// The non-geometric cells (compliance and periodic terms; with `free = "auto"` the gate
/// drops the inseparable terms one by one, a refit each) on seeds 1–20: bound 60 on the
/// Motoman right arm and the UR10 (measured 24–34, 3–4, 6–7), 120 on the left arm
/// (18–99). The left arm's refits after a dropped term start from the conditional fit
/// (the others absorb the term, `free_set::DroppedTerm`); from the term alone at nominal
/// they took up to 182 (seed 9; 131 on seed 16, 112 on seed 7), over this bound. Its
/// longest run left (99, seed 16) is a refit whose minimum lies far along the curved
/// valley of `b2.theta`, `b2.d` and the reflector offset: even the geodesically
/// accelerated step is valid only to about twice the accepted length there. Before the
/// trust region and the acceleration: first runs of 252–2000+ on the Motoman.
///
/// Why 99 (seed 16, the refit with 33 free parameters after the 9th dropped term; traced
/// per trial): the scaled `JᵀJ` has eigenvalues 1e-10 … 13, the refit reaches the valley
/// floor in 3 iterations (½χ² 566 → 141.5) and then walks about 1.6·10⁵ scaled units
/// along it to 139.48, each step ~1.2–2.4·10³. A step of 2.3·10³ is accepted (ratio
/// ≈ 0.8), twice that fails (ratio −5 … −18, acceleration only 2–5 % of the step: the
/// model's error grows like a third-order path error), so the radius cycles ×2, ×2, ×¼
/// and one trial in three is lost. Measured alternatives (whole table, seeds 1–20; max of
/// right / left / right-ng / left-ng / UR10 D-ng; today 42 / 33 / 34 / 99 / 7): shrink
/// ½ 89 on left-ng; Nielsen's radius update (grow by 1/max(⅓, 1 − (2ρ − 1)³), shrink by
/// ν = 2, 4, …) 32 / 28 / 38 / 76 / 8; its shrink alone 35 / 28 / 37 / 89 / 7; its growth
/// alone 40 / 30 / 34 / 86 / 9; Transtrum & Sethna's uphill acceptance (2012 §5,
/// (1 − β)² C′ ≤ C) 53 / 27 / 55 / 59 / 12, with Nielsen's update 45 / 27 / 65 / 51 / 9;
/// the Dennis–Gay–Welsch (NL2SOL) quasi-Newton term 563 on that refit. None lowers the
/// left-ng maximum without raising another set's, so the solver is unchanged.
#[test]
fn every_nongeometric_fit_converges_on_20_seeds_without_a_false_alarm() {
    converge_within(sets(true), 1..=20, |name| {
        if name.starts_with("motoman left") {
            120
        } else {
            60
        }
    });
}

/// The table of iterations per seed of every real data set (kinematic and non-geometric
/// cells) with the iteration limit `LM_MAX` (default 2000), and per set the minimum,
/// median and maximum over the seeds of the longest run; with `LM_TABLE=dir`, every seed's
/// estimate (free parameters with σ, final cost) to `dir/<set>.txt`:
/// `LM_MAX=2000 cargo test -p armcal --test suite measure_iterations -- --ignored --nocapture`.
#[test]
#[ignore = "a measurement (minutes), not a check"]
fn measure_iterations() {
    let max = std::env::var("LM_MAX").map_or(2000, |s| s.parse().unwrap());
    let out = std::env::var("LM_TABLE").ok();
    let mut summary = Vec::new();
    for (name, cell, data) in sets(false).into_iter().chain(sets(true)) {
        let t = std::time::Instant::now();
        let rows: Vec<(usize, String, String)> = (1..=20u64)
            .into_par_iter()
            .map(|seed| {
                let (est, all) = fit_runs(&cell, &data, seed, max);
                let runs = all.done.clone();
                let c = &all.longest;
                let trace: Vec<String> = [1usize, 10, 20, 30, 50, 100, 200, 400, 800]
                    .iter()
                    .filter(|&&k| k < c.len())
                    .map(|&k| format!("{k}:{:.2e}", c[k - 1] - c[c.len() - 1]))
                    .collect();
                let params: Vec<String> = est
                    .parameters
                    .iter()
                    .filter(|p| p.free)
                    .map(|p| format!("{} {:.9e} {:.3e}", p.name, p.estimate, p.sigma.unwrap()))
                    .collect();
                let fit = est
                    .verdicts
                    .as_ref()
                    .map(|v| v.fit.reasons())
                    .unwrap_or_default();
                let line = format!(
                    "{name} seed {seed}: runs {runs:?} {} cost {:.6e} checks {fit:?} trace {}",
                    est.solver.status,
                    est.solver.history.last().unwrap(),
                    trace.join(" ")
                );
                let table = format!(
                    "seed {seed} cost {:.9e} status {}\n{}\n",
                    est.solver.history.last().unwrap(),
                    est.solver.status,
                    params.join("\n")
                );
                (runs.iter().copied().max().unwrap_or(0), line, table)
            })
            .collect();
        for (_, line, _) in &rows {
            println!("{line}");
        }
        if let Some(dir) = &out {
            let text: String = rows.iter().map(|r| r.2.clone()).collect();
            std::fs::write(format!("{dir}/{}.txt", name.replace(' ', "-")), text).unwrap();
        }
        let mut longest: Vec<usize> = rows.iter().map(|r| r.0).collect();
        longest.sort();
        summary.push(format!(
            "{name}: longest run min {} median {} max {} ({:.1} s)",
            longest[0],
            longest[longest.len() / 2],
            longest[longest.len() - 1],
            t.elapsed().as_secs_f64()
        ));
    }
    for s in summary {
        println!("{s}");
    }
}
