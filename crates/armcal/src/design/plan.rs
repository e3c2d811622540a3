//! The planner: a feasible candidate pool, multi-start exchange, continuous refinement
//! under the constraints, a strict feasibility check, travel ordering, and the optimality
//! bound. Every solver reports its status, iterations and time.
//!
//! (Over 600 lines: one algorithm — pool, starts, refinement, checks — with its settings and
//! its result record.)

use crate::cell::Cell;
use crate::design::baselines::random_feasible;
use crate::design::bound::{has_bound, optimality_bound, OptimalityBound};
use crate::design::cell_constraints::{ConstraintSet, ConstraintSettings, ConstraintWorkspace};
use crate::design::exchange::{exchange, ExchangeSettings};
use crate::design::information::DesignModel;
use crate::design::objective::DesignObjective;
use crate::design::order::order_for_travel;
use crate::design::refine::{refine, ConfigurationConstraints, RefineSettings};
use crate::design::Criterion;
use crate::linalg::unit_diagonal;
use crate::progress::{Observer, Shared};
use crate::solve::Status;
use crate::Error;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::cell::RefCell;
use std::time::{Duration, Instant};

/// Relative gain below which an exchange sweep counts as no progress when the continuous
/// refinement follows.
pub const EXCHANGE_TOLERANCE_BEFORE_REFINEMENT: f64 = 1e-3;

/// The largest design [`plan`] computes. Planning time grows with the number of poses
/// (`examples/paper-cell.toml`, KPI, 2 starts on 2 cores, self-collisions checked: 1 000
/// poses 1.9 s, 5 000 poses 15 s), faster than linearly, so 100 000 poses would run for
/// hours; and a design that large gains nothing from being optimal pose by pose: C_p of
/// N measurements shrinks as 1/N, so a planned design of a few thousand poses, measured
/// repeatedly, reaches the same uncertainty.
pub const MAX_POSES: usize = 5_000;

/// Settings of [`plan`].
#[derive(Clone, Debug)]
pub struct PlanSettings {
    /// Number N of measurement configurations to design.
    pub poses: usize,
    /// The criterion minimised (default KPI, paper eq. 24).
    pub criterion: Criterion,
    /// Collision and line-of-sight constraints (the incidence limit applies whenever the
    /// cell sets one).
    pub collisions: bool,
    /// Independent exchange + refinement runs (in parallel).
    pub starts: usize,
    /// Seed of the candidate pool; start `s` of the exchange uses `seed + 7919 s`.
    pub seed: u64,
    /// Feasible random configurations in the candidate pool.
    pub pool: usize,
    /// Random draws allowed to fill the pool.
    pub max_draws: usize,
    /// Skip the continuous refinement (exchange only).
    pub exchange_only: bool,
    /// Settings of the continuous refinement.
    pub refine: RefineSettings,
}

impl Default for PlanSettings {
    fn default() -> Self {
        PlanSettings {
            poses: 60,
            criterion: Criterion::Kpi,
            collisions: true,
            starts: 2,
            seed: 1,
            // After the continuous refinement a larger pool or more exchange sweeps no longer
            // change the result (60 KPI poses, paper cell: 500 and 1500 candidates end
            // within 0.1 %), so the pool is sized for the exchange's start only.
            pool: 500,
            max_draws: 2_000_000,
            exchange_only: false,
            refine: RefineSettings::default(),
        }
    }
}

/// Smallest constraint margin of a design.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DesignMargin {
    /// Name of the constraint with the smallest value (see [`ConstraintSet::names`]).
    pub constraint: String,
    /// Index (from 0) of the pose where it occurs.
    pub pose: usize,
    /// The constraint value `g(q)`: mm for distances, `cos β − cos β_max` for the incidence;
    /// negative when violated.
    pub value: f64,
}

/// What a planner run produced.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PlanResult {
    /// The criterion minimised.
    pub criterion: Criterion,
    /// Its value for `design`.
    pub value: f64,
    /// The design, ordered for travel (internal units).
    pub design: Vec<Vec<f64>>,
    /// Every pose within the joint limits and every constraint ≥ 0.
    pub feasible: bool,
    /// Smallest constraint value over the design (`None` when the set has no constraints).
    pub min_margin: Option<DesignMargin>,
    /// Constraints checked at each pose.
    pub constraints_per_pose: usize,
    /// Robot capsule pairs not checked: they overlap at every sampled configuration
    /// ([`ConstraintSet::pairs_in_contact`]).
    #[serde(default)]
    pub pairs_in_contact: Vec<String>,
    /// Robot capsules that move with a joint and are checked against each other, the
    /// obstacles and the half-spaces ([`ConstraintSet::arm_capsules`]); 0: the arm has no
    /// collision model, and "feasible" says nothing about collisions.
    #[serde(default)]
    pub arm_capsules: usize,
    /// Where the robot's capsules come from ([`crate::robots::Robot::collision`]).
    #[serde(default)]
    pub collision_model: String,
    /// Random draws made to fill the candidate pool.
    pub pool_draws: usize,
    /// Criterion value after the exchange, before the refinement (NaN when no feasible pool
    /// could be drawn).
    pub exchange_value: f64,
    /// Sweeps of the best start's exchange.
    pub exchange_sweeps: usize,
    /// How the refinement ended
    /// ([`RefineResult::describe`](crate::design::refine::RefineResult::describe), with a
    /// note when its design was rejected); `None` when it did not run.
    pub refine_status: Option<String>,
    /// Refinement iterations (0 when it did not run).
    pub refine_iterations: usize,
    /// How the planner ended, in the shared vocabulary: the refinement's status when its
    /// design is the result; converged (`exchange`) when the exchange design is (no
    /// refinement, or its design rejected); infeasible when no feasible pool could be drawn.
    #[serde(default = "exchange_converged")]
    pub status: Status,
    /// Optimality bound and efficiency of the design (criteria with [`has_bound`] only).
    pub bound: Option<OptimalityBound>,
    /// When no feasible pool could be drawn: each constraint that blocks random
    /// configurations, with the fraction of draws (within the joint limits) it rejects.
    pub blocking: Vec<(String, f64)>,
    /// Wall-clock time of the run.
    pub time: Duration,
}

/// The status of a design the exchange made (no step of it lowers the criterion).
pub(crate) fn exchange_converged() -> Status {
    Status::Converged {
        criterion: "exchange".into(),
    }
}

/// The report when the cell's constraints leave (almost) no feasible configuration: which
/// constraints block the draws, and the best design found — the `poses` draws with the
/// largest smallest margin — marked infeasible.
fn infeasible_report(
    d: &DesignModel,
    set: &ConstraintSet,
    settings: &PlanSettings,
    t0: Instant,
) -> PlanResult {
    let draws = 20_000;
    let qs = crate::model::random_configurations(&d.model, draws, settings.seed);
    let mut ws = set.workspace();
    let mut values = vec![0.0; set.len()];
    let mut counts = vec![0usize; set.len()];
    let mut scored: Vec<(f64, usize)> = Vec::with_capacity(draws);
    for (k, q) in qs.iter().enumerate() {
        set.evaluate(&mut ws, &d.params, q, &mut values, None);
        let mut worst = f64::INFINITY;
        for (i, v) in values.iter().enumerate() {
            let slack = v - set.required(i);
            if slack < 0.0 {
                counts[i] += 1;
            }
            worst = worst.min(slack);
        }
        scored.push((worst, k));
    }
    let mut blocking: Vec<(String, f64)> = counts
        .iter()
        .enumerate()
        .filter(|(_, c)| **c > 0)
        .map(|(i, c)| (set.name(i).to_string(), *c as f64 / draws as f64))
        .collect();
    blocking.sort_by(|a, b| b.1.total_cmp(&a.1));
    scored.sort_by(|a, b| b.0.total_cmp(&a.0));
    let design: Vec<Vec<f64>> = scored
        .iter()
        .take(settings.poses)
        .map(|(_, k)| qs[*k].clone())
        .collect();
    let objective = DesignObjective::new(d, settings.criterion, &[]);
    let mut ows = objective.workspace(design.len());
    let value = objective
        .value_and_gradient(&mut ows, &design.concat(), None)
        .unwrap_or(f64::NAN);
    let params = d.params.clone();
    let cons = CellConstraints::new(set, &params);
    PlanResult {
        criterion: settings.criterion,
        value,
        min_margin: cons.design_margin(&design),
        design,
        feasible: false,
        constraints_per_pose: set.len(),
        pairs_in_contact: set.pairs_in_contact().to_vec(),
        arm_capsules: set.arm_capsules(),
        collision_model: set.collision_model().to_string(),
        pool_draws: draws,
        exchange_value: f64::NAN,
        exchange_sweeps: 0,
        refine_status: None,
        refine_iterations: 0,
        status: Status::Infeasible {
            reason: format!("no feasible configuration in {draws} random draws"),
        },
        bound: None,
        blocking,
        time: t0.elapsed(),
    }
}

/// The best of the planner's starts from one candidate pool: design, value, exchange value,
/// exchange sweeps, and the refinement's status and iterations (if it ran).
#[derive(Clone, Debug)]
pub struct PoolDesign {
    /// The design (internal units: rad, mm), not yet ordered for travel.
    pub design: Vec<Vec<f64>>,
    /// Its criterion value.
    pub value: f64,
    /// The criterion value of that start's exchange design.
    pub exchange_value: f64,
    /// Sweeps of that start's exchange.
    pub sweeps: usize,
    /// The refinement's status text and iterations; `None` when it did not run (exchange only).
    pub refine: Option<(String, usize)>,
    /// How the start ended ([`PlanResult::status`]).
    pub status: Status,
    /// Whether the design is the refined one (false: the exchange design, the refinement did
    /// not run or its design was rejected).
    pub refined: bool,
}

/// Adapts a cell's [`ConstraintSet`] to the refinement's constraint interface.
pub struct CellConstraints<'a> {
    /// The constraints of one configuration.
    pub set: &'a ConstraintSet,
    /// Model parameters at which they are evaluated (internal units: mm, rad).
    pub params: &'a [f64],
    ws: RefCell<ConstraintWorkspace>,
}

impl<'a> CellConstraints<'a> {
    /// `set` at `params`.
    pub fn new(set: &'a ConstraintSet, params: &'a [f64]) -> Self {
        CellConstraints {
            set,
            params,
            ws: RefCell::new(set.workspace()),
        }
    }

    /// Whether `q` is within the limits and satisfies every constraint.
    pub fn feasible(&self, q: &[f64]) -> bool {
        self.set.feasible(&mut self.ws.borrow_mut(), self.params, q)
    }

    /// The smallest margin over a design.
    pub fn design_margin(&self, design: &[Vec<f64>]) -> Option<DesignMargin> {
        let mut best: Option<DesignMargin> = None;
        let mut ws = self.ws.borrow_mut();
        for (i, q) in design.iter().enumerate() {
            if let Some(m) = self.set.min_margin_at(&mut ws, self.params, q) {
                if best.as_ref().is_none_or(|b| m.value < b.value) {
                    best = Some(DesignMargin {
                        constraint: m.name.to_string(),
                        pose: i,
                        value: m.value,
                    });
                }
            }
        }
        best
    }
}

/// Margins the refinement keeps from every constraint boundary, so that the first-order
/// corrections of its projection still leave a strictly feasible design: 1e-4 in the
/// cosine of the incidence angle (≈ 0.01° at 30°), 0.05 mm for distances.
const INCIDENCE_MARGIN: f64 = 1e-4;
const DISTANCE_MARGIN: f64 = 0.05;

impl CellConstraints<'_> {
    /// Where the refinement keeps constraint `i`: its required value (the cell's clearance,
    /// [`ConstraintSet::required`]) plus the margin from that boundary — none from a
    /// constant constraint that needs no clearance: no move can widen it, and a feasible pool
    /// configuration already satisfies it.
    fn margin(&self, i: usize) -> f64 {
        let required = self.set.required(i);
        if self.set.is_constant(i) && required == 0.0 {
            return 0.0;
        }
        required
            + match self.set.kind(i) {
                crate::design::ConstraintKind::Incidence => INCIDENCE_MARGIN,
                _ => DISTANCE_MARGIN,
            }
    }
}

impl ConfigurationConstraints for CellConstraints<'_> {
    fn len(&self) -> usize {
        self.set.len()
    }

    fn evaluate(&self, q: &[f64], values: &mut [f64], jacobian: Option<&mut [f64]>) {
        self.set
            .evaluate(&mut self.ws.borrow_mut(), self.params, q, values, jacobian);
        for (i, v) in values.iter_mut().enumerate() {
            *v -= self.margin(i);
        }
    }

    fn evaluate_rows(
        &self,
        q: &[f64],
        rows: &[usize],
        values: &mut [f64],
        jacobian: Option<&mut [f64]>,
    ) {
        self.set.evaluate_rows(
            &mut self.ws.borrow_mut(),
            self.params,
            q,
            rows,
            values,
            jacobian,
        );
        for &i in rows {
            values[i] -= self.margin(i);
        }
    }
}

/// Smallest singular-value ratio of the column-normalised Jacobian a refined design must
/// keep, so that a design the refinement drove towards a direction the criterion barely sees
/// (the tracker frame for the KPI, with the fewest poses) stays fittable: identify refuses a
/// ratio below about 1e-7 ([`crate::identify::uncertainty::information_inverse`]), and it
/// fits at the true robot, not at the nominal one the design was planned at. A campaign's
/// first 9-pose batch refined to a ratio of 1.3e-6 at the nominal was rank deficient for
/// identify at the simulated truth (`campaign simulate --seed 3`); 60-pose KPI designs keep
/// about 3e-3, a campaign's later batches 2e-3.
const MIN_SINGULAR_RATIO: f64 = 1e-4;

/// Whether the information matrix `M` (= JᵀJ) has, column-normalised, every singular value of
/// J above [`MIN_SINGULAR_RATIO`] times the largest.
fn well_conditioned(m: &nalgebra::DMatrix<f64>) -> bool {
    let Ok((s, _)) = unit_diagonal(m) else {
        return false;
    };
    let eig = s.symmetric_eigenvalues();
    let (lo, hi) = eig
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
    lo > MIN_SINGULAR_RATIO * MIN_SINGULAR_RATIO * hi
}

/// The constraint set of a cell for planning, with the cell's `[design]` clearance and
/// joint margin.
pub fn constraint_set(cell: &Cell, collisions: bool) -> Result<ConstraintSet, Error> {
    ConstraintSet::new(
        cell,
        &ConstraintSettings {
            incidence: cell
                .instrument
                .as_ref()
                .and_then(|i| i.max_incidence)
                .is_some(),
            collisions,
            line_of_sight: collisions,
            ..ConstraintSettings::default()
        }
        .with_clearance(&cell.design),
    )
}

/// Plans `settings.poses` measurement configurations for `cell`, augmenting `measured`;
/// `observer` follows the starts, their exchange and their refinement.
///
/// The design minimises `settings.criterion` (default: the paper's KPI criterion, the mean of
/// (1/3) tr C_s over the cell's working poses, paper eq. 19) under the joint limits, the
/// instrument's incidence limit and line of sight and, with `settings.collisions`, the
/// capsule collision model (paper §3–4).
///
/// ```
/// use armcal::{assess, plan, Cell, PlanSettings};
/// use armcal::Silent;
///
/// # fn main() -> armcal::Result<()> {
/// let cell = armcal::cell::builtin::paper_cell()?;
/// let settings = PlanSettings { poses: 20, collisions: false, starts: 1, ..PlanSettings::default() };
/// let planned = plan(&cell, &settings, &[], &mut Silent)?;
/// assert!(planned.feasible);
/// assert_eq!(planned.design.len(), 20);
/// // What the design predicts, and that the criterion is that prediction.
/// let predicted = assess(&cell, &planned.design)?;
/// let kpi = predicted.tcp.iter().map(|t| t.kpi).sum::<f64>() / predicted.tcp.len() as f64;
/// assert!((kpi - planned.value).abs() <= 1e-9 * kpi);
/// # Ok(())
/// # }
/// ```
pub fn plan(
    cell: &Cell,
    settings: &PlanSettings,
    measured: &[Vec<f64>],
    observer: &mut dyn Observer,
) -> Result<PlanResult, Error> {
    if settings.poses > MAX_POSES {
        return Err(Error::Input(format!(
            "a design of {} poses is more than the {} armcal plans: planning time grows with the number of poses (on the paper cell 1 000 poses take about 2 s, 5 000 about 15 s, {} many times that), and beyond a few thousand poses an optimal design gains nothing over measuring a smaller planned design repeatedly (C_p shrinks as 1/N either way); plan at most {} poses",
            settings.poses, MAX_POSES, settings.poses, MAX_POSES
        )));
    }
    let t0 = Instant::now();
    let d = DesignModel::from_cell(cell)?;
    let set = constraint_set(cell, settings.collisions)?;
    let params = d.params.clone();
    let (pool, draws) = {
        let cons = CellConstraints::new(&set, &params);
        match random_feasible(
            &d.model,
            settings.pool.max(settings.poses),
            settings.seed,
            settings.max_draws,
            |q| cons.feasible(q),
        ) {
            Ok(p) => p,
            Err(_) => return Ok(infeasible_report(&d, &set, settings, t0)),
        }
    };
    let objective = DesignObjective::new(&d, settings.criterion, measured);
    let PoolDesign {
        design,
        value,
        exchange_value,
        sweeps,
        refine: refine_info,
        status,
        ..
    } = design_from_pool(&d, &set, &pool, settings, measured, observer)?;
    let order = order_for_travel(&design);
    let design: Vec<Vec<f64>> = order.iter().map(|&i| design[i].clone()).collect();
    let cons = CellConstraints::new(&set, &params);
    let feasible = design.iter().all(|q| cons.feasible(q));
    let min_margin = cons.design_margin(&design);
    let bound = if has_bound(settings.criterion) {
        Some(optimality_bound(&objective, &design, &pool, 20, || {
            let cons = CellConstraints::new(&set, &params);
            move |q: &[f64]| cons.feasible(q)
        })?)
    } else {
        None
    };
    Ok(PlanResult {
        criterion: settings.criterion,
        value,
        design,
        feasible,
        min_margin,
        constraints_per_pose: set.len(),
        pairs_in_contact: set.pairs_in_contact().to_vec(),
        arm_capsules: set.arm_capsules(),
        collision_model: set.collision_model().to_string(),
        pool_draws: draws,
        exchange_value,
        exchange_sweeps: sweeps,
        refine_status: refine_info.as_ref().map(|r| r.0.clone()),
        refine_iterations: refine_info.map(|r| r.1).unwrap_or(0),
        status,
        bound,
        blocking: Vec::new(),
        time: t0.elapsed(),
    })
}

/// Starts run in all, as a multiple of `PlanSettings::starts`, when no start's refined design
/// was accepted. A design of about the fewest poses that identify the free set (a campaign's
/// first batch) has no redundancy: its criterion is rough, the exchange ends anywhere from
/// 50 to 10⁴, and a refinement often ends near rank deficiency and is rejected. Measured on
/// the paper cell with the default margins, 9 poses, seeds 1–8: with 2 starts, 3 of 8 seeds
/// kept an exchange design of KPI 48–109 mm² (σ 7–10 mm) where the others refined to 2.4–2.8
/// mm² (σ 1.6 mm); with 8 starts, all 8 refined to 2.42–2.78 mm². A plan whose refinement
/// is accepted runs only the starts it was given.
const STARTS_WHEN_NONE_REFINED: usize = 4;

/// Runs `settings.starts` exchange + refinement starts (in parallel) from the feasible
/// candidate `pool` and returns the best design; a refined design that violates a
/// constraint is replaced by its exchange design; when no start's refined design was
/// accepted, more starts run ([`STARTS_WHEN_NONE_REFINED`]). The planner's core, shared with
/// the paper's study (which reuses one pool for several criteria). `observer` receives the
/// task `planning starts` with a step per finished start, and (interleaved, from the
/// parallel starts) each start's exchange and refinement.
pub fn design_from_pool(
    d: &DesignModel,
    set: &ConstraintSet,
    pool: &[Vec<f64>],
    settings: &PlanSettings,
    measured: &[Vec<f64>],
    observer: &mut dyn Observer,
) -> Result<PoolDesign, Error> {
    let prior_rows = DesignObjective::new(d, settings.criterion, measured).prior_rows;
    let (lo, hi) = set.joint_bounds();
    let starts = settings.starts.max(1);
    observer.start("planning starts", Some(starts));
    let shared = Shared::new(observer);
    let run = |s: usize| -> Result<PoolDesign, Error> {
        let mut observer = &shared;
        let ex = exchange(
            d,
            settings.criterion,
            pool,
            &prior_rows,
            settings.poses,
            &ExchangeSettings {
                seed: settings.seed.wrapping_add(s as u64 * 7919),
                // The refinement moves every pose afterwards: sweeps that gain less
                // than 0.1 % do not change where it ends.
                tolerance: if settings.exchange_only {
                    ExchangeSettings::default().tolerance
                } else {
                    EXCHANGE_TOLERANCE_BEFORE_REFINEMENT
                },
                ..ExchangeSettings::default()
            },
            &mut observer,
        )?;
        let start: Vec<Vec<f64>> = ex.chosen.iter().map(|&i| pool[i].clone()).collect();
        if settings.exchange_only {
            observer.step();
            return Ok(PoolDesign {
                design: start,
                value: ex.value,
                exchange_value: ex.value,
                sweeps: ex.sweeps,
                refine: None,
                status: exchange_converged(),
                refined: false,
            });
        }
        let cons = CellConstraints::new(set, &d.params);
        let obj = DesignObjective::new(d, settings.criterion, measured);
        let r = refine(
            &obj,
            &start,
            lo,
            hi,
            (!set.is_empty()).then_some(&cons as &dyn ConfigurationConstraints),
            &settings.refine,
            &mut observer,
        )?;
        observer.step();
        // Only a design that violates nothing and that identify can fit counts; otherwise
        // keep the exchange design.
        let ok = r.q.iter().all(|q| cons.feasible(q)) && well_conditioned(&obj.information(&r.q));
        if ok && r.value <= ex.value {
            Ok(PoolDesign {
                refine: Some((r.describe(), r.iterations)),
                status: r.status,
                design: r.q,
                value: r.value,
                exchange_value: ex.value,
                sweeps: ex.sweeps,
                refined: true,
            })
        } else {
            Ok(PoolDesign {
                design: start,
                value: ex.value,
                exchange_value: ex.value,
                sweeps: ex.sweeps,
                refine: Some((
                    format!(
                        "{} (refined design rejected: {})",
                        r.describe(),
                        if ok {
                            "no better"
                        } else {
                            "infeasible or near rank deficient"
                        }
                    ),
                    r.iterations,
                )),
                status: exchange_converged(),
                refined: false,
            })
        }
    };
    let mut runs: Vec<Result<PoolDesign, Error>> = (0..starts).into_par_iter().map(run).collect();
    let none_refined = runs.iter().all(|r| r.as_ref().is_ok_and(|p| !p.refined));
    if !settings.exchange_only && none_refined {
        runs.extend(
            (starts..STARTS_WHEN_NONE_REFINED * starts)
                .into_par_iter()
                .map(run)
                .collect::<Vec<_>>(),
        );
    }
    observer.finish();
    let mut best: Option<PoolDesign> = None;
    for r in runs {
        let r = r?;
        if best.as_ref().is_none_or(|b| r.value < b.value) {
            best = Some(r);
        }
    }
    Ok(best.expect("at least one start"))
}
