//! The user's own pose pool: choose N of a given set of joint configurations (poses already
//! taught and known safe) for any criterion, under the cell's constraints, optionally
//! refined within a joint radius of the chosen pool poses.
//!
//! Every pool row is checked first against the joint limits and the cell's constraints (the
//! planner's set, [`constraint_set`]); an infeasible row is listed with the constraint it
//! violates and is never chosen. From the feasible rows, [`select_d`] chooses N by D
//! (greedy start, exchange by low-rank updates); for another criterion the exchange on that
//! criterion ([`exchange`]) continues from the D choice. With a radius `r` the continuous
//! refinement ([`refine_in_boxes`]) keeps pose i in `[max(q_lo, p_i − r), min(q_hi, p_i + r)]`
//! per joint, `p_i` its pool pose; a refined design that violates a constraint, leaves its
//! box or is no better is not used.

use crate::cell::Cell;
use crate::design::bound::{has_bound, optimality_bound};
use crate::design::exchange::{exchange, pool_jacobians, value_of, ExchangeSettings};
use crate::design::information::DesignModel;
use crate::design::objective::DesignObjective;
use crate::design::order::order_for_travel;
use crate::design::plan::{constraint_set, exchange_converged, CellConstraints, PlanResult};
use crate::design::refine::{refine_in_boxes, ConfigurationConstraints, RefineSettings};
use crate::design::selection::{select_d, SelectionSettings};
use crate::design::{ConstraintKind, ConstraintSet, Criterion};
use crate::progress::Observer;
use crate::Error;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Settings of [`plan_from_pool`].
#[derive(Clone, Debug)]
pub struct PoolSettings {
    /// Number N of poses to choose.
    pub poses: usize,
    /// The criterion minimised.
    pub criterion: Criterion,
    /// Collision and line-of-sight constraints (the incidence limit applies whenever the
    /// cell sets one).
    pub collisions: bool,
    /// Largest move of the refinement from each chosen pool pose, per joint, in the joint's
    /// display unit (deg; mm for a prismatic joint); `None`: no refinement, the design is
    /// pool rows.
    pub refine_radius: Option<f64>,
    /// Settings of the D selection.
    pub selection: SelectionSettings,
    /// Settings of the refinement.
    pub refine: RefineSettings,
}

impl Default for PoolSettings {
    fn default() -> Self {
        PoolSettings {
            poses: 60,
            criterion: Criterion::Kpi,
            collisions: true,
            refine_radius: None,
            selection: SelectionSettings::default(),
            refine: RefineSettings::default(),
        }
    }
}

/// One row of the pool file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PoolRow {
    /// Its data row (1-based, header not counted).
    pub row: usize,
    /// Its `pose_id` (the row number when the file has none).
    pub id: String,
}

/// A pool row the cell excludes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct InfeasibleRow {
    /// The row.
    #[serde(flatten)]
    pub pose: PoolRow,
    /// The violated constraint with the smallest margin: a constraint name (see
    /// [`ConstraintSet::names`]) or `joint limits: NAME`.
    pub constraint: String,
    /// Its margin (negative), in `unit`.
    pub margin: f64,
    /// `deg` (incidence angle beyond its limit, a revolute joint beyond its limit) or `mm`.
    pub unit: String,
}

/// Where a pool design came from: what the design record says about its pool.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PoolReport {
    /// The pool file.
    pub file: String,
    /// Its rows.
    pub rows: usize,
    /// Rows within the joint limits that satisfy every constraint.
    pub feasible: usize,
    /// The other rows, never chosen.
    pub infeasible: Vec<InfeasibleRow>,
    /// The pool row of each pose, in design-file order.
    pub chosen: Vec<PoolRow>,
    /// How the rows were chosen.
    pub selection: String,
    /// The criterion value of the chosen pool rows (before any refinement).
    pub selection_value: f64,
    /// The refinement radius per joint (display units: deg, mm), if any.
    pub refine_radius: Option<f64>,
    /// The largest joint move of a pose from its pool row (display units; 0 without
    /// refinement).
    pub largest_move: f64,
}

/// A plan from a pool: the planner's report and the pool's.
#[derive(Clone, Debug)]
pub struct PoolPlan {
    /// The planner's report (its design in internal units, ordered for travel).
    pub plan: PlanResult,
    /// Where the design came from.
    pub pool: PoolReport,
}

/// Why `q` is infeasible (`None`: it is feasible): the first joint outside its limits, else
/// the constraint with the smallest (negative) margin.
fn violation(
    cell: &Cell,
    set: &ConstraintSet,
    cons: &CellConstraints,
    q: &[f64],
) -> Option<(String, f64, String)> {
    if cons.feasible(q) {
        return None;
    }
    for (joint, v) in cell.model.joints.iter().zip(q) {
        let margin = (v - joint.lower).min(joint.upper - v);
        if margin < 0.0 {
            let unit = joint.kind.unit();
            return Some((
                format!("joint limits: {}", joint.name),
                margin * unit.display_factor(),
                unit.display_name().into(),
            ));
        }
    }
    let mut ws = set.workspace();
    match set.min_margin_at(&mut ws, cons.params, q) {
        Some(m) if m.value < 0.0 => {
            let max_incidence = cell.instrument.as_ref().and_then(|i| i.max_incidence);
            Some(match (m.kind, max_incidence) {
                (ConstraintKind::Incidence, Some(limit)) => {
                    let beta = (m.value + limit.cos()).clamp(-1.0, 1.0).acos();
                    (m.name.into(), (limit - beta).to_degrees(), "deg".into())
                }
                _ => (m.name.into(), m.value, "mm".into()),
            })
        }
        // Within the model's limits and every constraint ≥ 0, yet not feasible: the cell's
        // joint limits for planning are narrower than the model's.
        _ => Some(("joint limits (the cell's margin)".into(), 0.0, "deg".into())),
    }
}

/// Poses needed to identify `n` parameters with `rows` equations per pose, after the prior
/// information's rank.
fn minimum_poses(n: usize, rows: usize, prior_rank: usize) -> usize {
    n.saturating_sub(prior_rank).div_ceil(rows).max(1)
}

/// Plans `settings.poses` poses for `cell` from the user's pose pool given as values: its
/// joint rows (internal units: rad, mm), named `1`, `2`, … in messages and in the record
/// ([`plan_from_pool`] with the rows of a file).
///
/// ```
/// use armcal::model::random_configurations;
/// use armcal::{plan_pool, PoolSettings, Silent};
///
/// # fn main() -> armcal::Result<()> {
/// let cell = armcal::cell::builtin::paper_cell()?;
/// // The poses the user can reach (here random ones, of which the cell's constraints
/// // exclude most: the reflector faces away): choose the best 10.
/// let pool = random_configurations(&cell.model, 300, 4);
/// let settings = PoolSettings { poses: 10, ..PoolSettings::default() };
/// let chosen = plan_pool(&cell, &pool, &settings, &mut Silent)?;
/// assert_eq!(chosen.plan.design.len(), 10);
/// // Every chosen pose is one of the pool's rows.
/// assert!(chosen.plan.design.iter().all(|q| pool.contains(q)));
/// # Ok(())
/// # }
/// ```
pub fn plan_pool(
    cell: &Cell,
    pool: &[Vec<f64>],
    settings: &PoolSettings,
    observer: &mut dyn Observer,
) -> Result<PoolPlan, Error> {
    let rows: Vec<(String, Vec<f64>)> = pool
        .iter()
        .enumerate()
        .map(|(i, q)| ((i + 1).to_string(), q.clone()))
        .collect();
    plan_from_pool(cell, &rows, "pose pool", settings, &[], observer)
}

/// Plans `settings.poses` poses for `cell` from the rows of `pool` (pose id and joint values,
/// internal units, as [`read_configurations`](crate::measure::csv::read_configurations)
/// returns them) of the file `file`, augmenting the `measured` poses; `observer` follows
/// the selection and the refinement.
pub fn plan_from_pool(
    cell: &Cell,
    pool: &[(String, Vec<f64>)],
    file: &str,
    settings: &PoolSettings,
    measured: &[Vec<f64>],
    observer: &mut dyn Observer,
) -> Result<PoolPlan, Error> {
    let t0 = Instant::now();
    if let Some(r) = settings.refine_radius {
        if !(r.is_finite() && r > 0.0) {
            return Err(Error::Input(format!(
                "the refinement radius must be a positive number (deg, mm for a prismatic joint), got {r}"
            )));
        }
    }
    let d = DesignModel::from_cell(cell)?;
    let set = constraint_set(cell, settings.collisions)?;
    let cons = CellConstraints::new(&set, &d.params);
    let mut feasible_rows: Vec<usize> = Vec::new();
    let mut infeasible = Vec::new();
    for (r, (id, q)) in pool.iter().enumerate() {
        if q.len() != cell.model.dof() {
            return Err(Error::Input(format!(
                "{file}: row {} (`{id}`): {} joint values, the robot has {} joints",
                r + 1,
                q.len(),
                cell.model.dof()
            )));
        }
        if let Some(joint) = cell
            .model
            .joints
            .iter()
            .zip(q)
            .find(|(_, v)| !v.is_finite())
        {
            return Err(Error::Input(format!(
                "{file}: row {} (`{id}`): joint `{}` is not a finite number",
                r + 1,
                joint.0.name
            )));
        }
        let pose = PoolRow {
            row: r + 1,
            id: id.clone(),
        };
        match violation(cell, &set, &cons, q) {
            None => feasible_rows.push(r),
            Some((constraint, margin, unit)) => infeasible.push(InfeasibleRow {
                pose,
                constraint,
                margin,
                unit,
            }),
        }
    }
    let objective = DesignObjective::new(&d, settings.criterion, measured);
    let prior = &objective.prior_rows;
    let n = d.n();
    let rows = d.rows();
    let prior_rank = if prior.nrows() == 0 {
        0
    } else {
        prior.rank(1e-10 * prior.amax())
    };
    let minimum = minimum_poses(n, rows, prior_rank);
    let f = feasible_rows.len();
    let examples = || {
        let shown: Vec<String> = infeasible
            .iter()
            .take(5)
            .map(|r| format!("row {} (`{}`): {}", r.pose.row, r.pose.id, r.constraint))
            .collect();
        if shown.is_empty() {
            String::new()
        } else {
            format!(
                "; infeasible: {}{}",
                shown.join(", "),
                if infeasible.len() > 5 { ", …" } else { "" }
            )
        }
    };
    let needs = format!(
        "identifying the {n} free parameters with {rows} equations per pose needs at least {minimum} poses"
    );
    if f < minimum {
        return Err(Error::Input(format!(
            "{file}: only {f} of its {} rows are feasible; {needs}{}",
            pool.len(),
            examples()
        )));
    }
    if settings.poses < minimum {
        return Err(Error::Input(format!(
            "{} poses are too few: {needs}",
            settings.poses
        )));
    }
    if f < settings.poses {
        return Err(Error::Input(format!(
            "{file}: {f} of its {} rows are feasible, fewer than the {} poses asked for{}",
            pool.len(),
            settings.poses,
            examples()
        )));
    }
    let candidates: Vec<Vec<f64>> = feasible_rows.iter().map(|&r| pool[r].1.clone()).collect();
    let jp = pool_jacobians(&d, &candidates);
    let whole = prior.tr_mul(prior) + jp.tr_mul(&jp);
    if whole.clone().cholesky().is_none() {
        let rank = whole.rank(1e-12 * whole.amax());
        return Err(Error::Input(format!(
            "{file}: its {f} feasible rows together identify only {rank} of the {n} free parameters; add poses that move every joint"
        )));
    }
    let sel = select_d(
        &jp,
        rows,
        prior,
        settings.poses,
        &settings.selection,
        observer,
    )?;
    let mut selection = format!(
        "greedy D-optimal + exchange by low-rank updates ({} sweeps, {} exchanges)",
        sel.sweeps, sel.exchanges
    );
    let (chosen, sweeps) = if settings.criterion == Criterion::D {
        (sel.chosen, sel.sweeps)
    } else {
        let ex = exchange(
            &d,
            settings.criterion,
            &candidates,
            prior,
            settings.poses,
            &ExchangeSettings {
                start: Some(sel.chosen),
                ..ExchangeSettings::default()
            },
            observer,
        )?;
        selection.push_str(&format!(
            ", then the {} exchange ({} sweeps, {} exchanges)",
            settings.criterion.name(),
            ex.sweeps,
            ex.exchanges
        ));
        (ex.chosen, ex.sweeps)
    };
    let selection_value = value_of(&d, settings.criterion, &jp, prior, &chosen)?;
    let start: Vec<Vec<f64>> = chosen.iter().map(|&i| candidates[i].clone()).collect();
    let (design, value, refine_status, refine_iterations, status) = match settings.refine_radius {
        None => (
            start.clone(),
            selection_value,
            None,
            0,
            exchange_converged(),
        ),
        Some(radius) => {
            let (lower, upper) = boxes(&d, &start, radius);
            let r = refine_in_boxes(
                &objective,
                &start,
                &lower,
                &upper,
                (!set.is_empty()).then_some(&cons as &dyn ConfigurationConstraints),
                &settings.refine,
                observer,
            )?;
            let k = d.dof();
            let inside = r.q.iter().flatten().enumerate().all(|(i, x)| {
                let slack = 1e-12 * (1.0 + x.abs());
                *x >= lower[i] - slack && *x <= upper[i] + slack
            }) && r.q.len() * k == lower.len();
            let ok = r.q.iter().all(|q| cons.feasible(q));
            if ok && inside && r.value <= selection_value {
                let describe = r.describe();
                (r.q, r.value, Some(describe), r.iterations, r.status)
            } else {
                let why = if !ok {
                    "infeasible"
                } else if !inside {
                    "outside the radius"
                } else {
                    "no better"
                };
                (
                    start.clone(),
                    selection_value,
                    Some(format!("{} (refined design rejected: {why})", r.describe())),
                    r.iterations,
                    exchange_converged(),
                )
            }
        }
    };
    let order = order_for_travel(&design);
    let design: Vec<Vec<f64>> = order.iter().map(|&i| design[i].clone()).collect();
    let start: Vec<Vec<f64>> = order.iter().map(|&i| start[i].clone()).collect();
    let chosen_rows: Vec<PoolRow> = order
        .iter()
        .map(|&i| {
            let r = feasible_rows[chosen[i]];
            PoolRow {
                row: r + 1,
                id: pool[r].0.clone(),
            }
        })
        .collect();
    let largest_move = largest_move(&d, &design, &start);
    let feasible = design.iter().all(|q| cons.feasible(q));
    let bound = if has_bound(settings.criterion) {
        Some(optimality_bound(
            &objective,
            &design,
            &candidates,
            20,
            || {
                let cons = CellConstraints::new(&set, &d.params);
                move |q: &[f64]| cons.feasible(q)
            },
        )?)
    } else {
        None
    };
    let plan = PlanResult {
        criterion: settings.criterion,
        value,
        min_margin: cons.design_margin(&design),
        design,
        feasible,
        constraints_per_pose: set.len(),
        pairs_in_contact: set.pairs_in_contact().to_vec(),
        arm_capsules: set.arm_capsules(),
        collision_model: set.collision_model().to_string(),
        pool_draws: 0,
        exchange_value: selection_value,
        exchange_sweeps: sweeps,
        refine_status,
        refine_iterations,
        status,
        bound,
        blocking: Vec::new(),
        time: t0.elapsed(),
    };
    Ok(PoolPlan {
        plan,
        pool: PoolReport {
            file: file.into(),
            rows: pool.len(),
            feasible: f,
            infeasible,
            chosen: chosen_rows,
            selection,
            selection_value,
            refine_radius: settings.refine_radius,
            largest_move,
        },
    })
}

/// The box of each pose: its pool pose ± the radius (display units, converted per joint),
/// within the joint limits; N·k bounds each.
fn boxes(d: &DesignModel, start: &[Vec<f64>], radius: f64) -> (Vec<f64>, Vec<f64>) {
    let (lo, hi) = d.model.joint_limits();
    let mut lower = Vec::with_capacity(start.len() * lo.len());
    let mut upper = Vec::with_capacity(lower.capacity());
    for q in start {
        for (j, joint) in d.model.joints.iter().enumerate() {
            let r = radius / joint.kind.unit().display_factor();
            lower.push((q[j] - r).max(lo[j]));
            upper.push((q[j] + r).min(hi[j]));
        }
    }
    (lower, upper)
}

/// The largest `|q_ij − p_ij|` (display units) between a design and its pool poses.
fn largest_move(d: &DesignModel, design: &[Vec<f64>], start: &[Vec<f64>]) -> f64 {
    let mut m = 0.0f64;
    for (q, p) in design.iter().zip(start) {
        for ((a, b), joint) in q.iter().zip(p).zip(&d.model.joints) {
            m = m.max((a - b).abs() * joint.kind.unit().display_factor());
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::minimum_poses;

    #[test]
    fn minimum_poses_counts_equations() {
        assert_eq!(minimum_poses(27, 3, 0), 9);
        assert_eq!(minimum_poses(28, 3, 0), 10);
        assert_eq!(minimum_poses(27, 3, 27), 1);
        assert_eq!(minimum_poses(27, 6, 3), 4);
    }
}
