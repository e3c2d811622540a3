//! The design file: what `armcal plan` writes beside the design CSV (and `armcal demo` for
//! each of its designs), and what `armcal report` reads — the poses in user units, the
//! joint limits, the planner's report, the predicted precision and the smallest margin of
//! every kind of constraint.

use crate::cell::Cell;
use crate::design::assess::{assess, DesignAssessment};
use crate::design::plan::{constraint_set, plan, PlanResult, PlanSettings};
use crate::design::user_pool::{plan_from_pool, PoolReport, PoolSettings};
use crate::design::ConstraintKind;
use crate::model::rank_deficit::RankDeficit;
use crate::model::Model;
use crate::progress::Observer;
use crate::Error;
use serde::{Deserialize, Serialize};

/// A joint's name, display unit and limits (deg or mm).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JointRange {
    /// The joint's name.
    pub name: String,
    /// Its display unit (`deg` or `mm`).
    pub unit: String,
    /// Lower limit (display unit).
    pub lower: f64,
    /// Upper limit (display unit).
    pub upper: f64,
}

/// The smallest margin of one kind of constraint over a design.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct KindMargin {
    /// "incidence", "self-collision", "obstacle", "half-space", "line of sight" or
    /// "joint limits".
    pub kind: String,
    /// "deg" (incidence angle below its limit, distance of a joint from its limit) or "mm"
    /// (clearance between capsules, to a half-space, of the beam).
    pub unit: String,
    /// Constraints of this kind per pose.
    pub per_pose: usize,
    /// Smallest margin over the design (negative: violated).
    pub value: f64,
    /// The least margin the cell's `[design]` asks for (incidence_margin_deg for the
    /// incidence, line_of_sight_margin_mm for the beam, clearance_mm for the other distances,
    /// joint_margin_deg for revolute joints, 0 for prismatic joints).
    pub required: f64,
    /// Whether every constraint of the kind keeps its required value (a distance no
    /// configuration changes, such as a base column standing on the floor, is exempt from
    /// the clearance and needs only ≥ 0; see
    /// [`ConstraintSet::required`](crate::design::ConstraintSet::required)).
    pub meets: bool,
    /// The constraint (or joint) with the smallest margin, and its pose (1-based).
    pub constraint: String,
    /// The pose of that constraint (1-based).
    pub pose: usize,
}

/// Everything the report shows about a design.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DesignRecord {
    /// The cell's name.
    pub cell: String,
    /// The cell as given to the planner (a cell-file path or a built-in robot), so a report
    /// can rebuild it for the 3D view.
    pub cell_source: Option<String>,
    /// How the design was made (e.g. "KPI-optimal plan").
    pub method: String,
    /// Whether collision and line-of-sight constraints applied (the margins include them).
    pub collisions: bool,
    /// The joints' names, units and limits.
    pub joints: Vec<JointRange>,
    /// The poses in design-file order, display units (deg, mm).
    pub poses: Vec<Vec<f64>>,
    /// The planner's report (its `design` in internal units: rad, mm); absent for a design
    /// not planned by armcal.
    pub plan: Option<PlanResult>,
    /// The predicted precision ([`assess`]) of the poses already measured and the design
    /// together: what the calibration will have once the design is measured too.
    pub assessment: DesignAssessment,
    /// How many poses were already measured when the design was planned to augment them
    /// (`plan --measured`); the assessment and the planner's criterion value include them.
    #[serde(default)]
    pub measured: usize,
    /// The smallest margin of every kind of constraint ([`kind_margins`]).
    pub margins: Vec<KindMargin>,
    /// For a design chosen from the user's pose pool: the pool file, its size, its
    /// infeasible rows and the row of every pose.
    #[serde(default)]
    pub pool: Option<PoolReport>,
    /// Why the cell identifies fewer parameters than the generic count at the nominal, if it
    /// does (a target on the last joint axis, …): the note `model` prints
    /// ([`Cell::rank_deficit`]), which bounds what any design can identify.
    #[serde(default)]
    pub rank_deficit: Option<RankDeficit>,
}

/// Display factor (internal → display) and unit name of each joint of a model.
fn joint_units(model: &Model) -> Vec<(f64, &'static str)> {
    model
        .joints
        .iter()
        .map(|j| (j.kind.unit().display_factor(), j.kind.unit().display_name()))
        .collect()
}

fn kind_name(kind: ConstraintKind) -> &'static str {
    match kind {
        ConstraintKind::Incidence => "incidence",
        ConstraintKind::SelfCollision => "self-collision",
        ConstraintKind::Obstacle => "obstacle",
        ConstraintKind::HalfSpace => "half-space",
        ConstraintKind::LineOfSight => "line of sight",
    }
}

const KINDS: [ConstraintKind; 5] = [
    ConstraintKind::Incidence,
    ConstraintKind::SelfCollision,
    ConstraintKind::Obstacle,
    ConstraintKind::HalfSpace,
    ConstraintKind::LineOfSight,
];

/// The smallest margin per constraint kind over `design` (internal units), at the nominal
/// parameters, against what the cell's `[design]` requires. Incidence margins are angles:
/// with `v = cos β − cos β_max` (paper eq. 4), the margin is `β_max − β` in degrees.
/// Joint-limit margins are `min(q − q_lo, q_hi − q)`, one entry per display unit. A kind
/// meets its requirement when every constraint of it does (its value at least
/// [`ConstraintSet::required`](crate::design::ConstraintSet::required)).
pub fn kind_margins(
    cell: &Cell,
    design: &[Vec<f64>],
    collisions: bool,
) -> Result<Vec<KindMargin>, Error> {
    let set = constraint_set(cell, collisions)?;
    let params = cell.model.nominal();
    let mut ws = set.workspace();
    let mut values = vec![0.0; set.len()];
    let mut best: Vec<Option<KindMargin>> = vec![None; KINDS.len()];
    let mut meets = [true; KINDS.len()];
    let max_incidence = set.max_incidence();
    for (p, q) in design.iter().enumerate() {
        cell.model
            .check_joints(q)
            .map_err(|e| Error::Input(format!("pose {}: {e}", p + 1)))?;
        set.evaluate(&mut ws, &params, q, &mut values, None);
        for (i, v) in values.iter().enumerate() {
            let kind = set.kind(i);
            let k = KINDS
                .iter()
                .position(|x| *x == kind)
                .expect("every kind listed");
            meets[k] &= *v >= set.required(i);
            let value = match (kind, max_incidence) {
                (ConstraintKind::Incidence, Some(m)) => (m - set.incidence_angle(*v)).to_degrees(),
                _ => *v,
            };
            if best[k].as_ref().is_none_or(|b| value < b.value) {
                best[k] = Some(KindMargin {
                    kind: kind_name(kind).into(),
                    unit: if kind == ConstraintKind::Incidence {
                        "deg"
                    } else {
                        "mm"
                    }
                    .into(),
                    per_pose: set.count(kind),
                    value,
                    required: match kind {
                        ConstraintKind::Incidence => cell.design.incidence_margin.to_degrees(),
                        ConstraintKind::LineOfSight => cell.design.line_of_sight_margin,
                        _ => cell.design.clearance,
                    },
                    meets: true,
                    constraint: set.name(i).to_string(),
                    pose: p + 1,
                });
            }
        }
    }
    let mut out: Vec<KindMargin> = best
        .into_iter()
        .zip(meets)
        .filter_map(|(m, meets)| m.map(|m| KindMargin { meets, ..m }))
        .collect();
    let units = joint_units(&cell.model);
    for unit in ["deg", "mm"] {
        // The joint margin is for revolute joints (deg) only; met to the tolerance of a
        // pose read back from a design CSV.
        let required = if unit == "deg" {
            cell.design.joint_margin.to_degrees()
        } else {
            0.0
        };
        let mut m: Option<KindMargin> = None;
        for (p, q) in design.iter().enumerate() {
            for (j, (joint, (f, u))) in cell.model.joints.iter().zip(&units).enumerate() {
                if *u != unit {
                    continue;
                }
                let value = f * (q[j] - joint.lower).min(joint.upper - q[j]);
                if m.as_ref().is_none_or(|b| value < b.value) {
                    m = Some(KindMargin {
                        kind: "joint limits".into(),
                        unit: unit.into(),
                        per_pose: units.iter().filter(|x| x.1 == unit).count(),
                        value,
                        required,
                        meets: value
                            >= required
                                - crate::design::cell_constraints::JOINT_MARGIN_TOLERANCE
                                    .to_degrees(),
                        constraint: joint.name.clone(),
                        pose: p + 1,
                    });
                }
            }
        }
        out.extend(m);
    }
    Ok(out)
}

impl DesignRecord {
    /// The record of `design` (internal units) for `cell`: predicted precision, margins and,
    /// if it was planned, the planner's report.
    pub fn new(
        cell: &Cell,
        cell_source: Option<&str>,
        method: &str,
        design: &[Vec<f64>],
        plan: Option<PlanResult>,
        collisions: bool,
    ) -> Result<DesignRecord, Error> {
        DesignRecord::augmenting(cell, cell_source, method, design, &[], plan, collisions)
    }

    /// The record of `design` planned to augment the `measured` poses: the assessment is of
    /// both together (the design alone may not identify the free set), the margins of the
    /// design (collisions and line of sight with `collisions`).
    fn augmenting(
        cell: &Cell,
        cell_source: Option<&str>,
        method: &str,
        design: &[Vec<f64>],
        measured: &[Vec<f64>],
        plan: Option<PlanResult>,
        collisions: bool,
    ) -> Result<DesignRecord, Error> {
        let all: Vec<Vec<f64>> = measured.iter().chain(design).cloned().collect();
        let units = joint_units(&cell.model);
        let generic = cell.identifiability(&cell.identifiability_settings())?;
        let rank_deficit = cell.rank_deficit(&generic, &cell.model.nominal(), None)?;
        Ok(DesignRecord {
            cell: cell.name.clone(),
            cell_source: cell_source.map(String::from),
            method: method.into(),
            joints: cell
                .model
                .joints
                .iter()
                .zip(&units)
                .map(|(j, (f, u))| JointRange {
                    name: j.name.clone(),
                    unit: (*u).into(),
                    lower: j.lower * f,
                    upper: j.upper * f,
                })
                .collect(),
            poses: design
                .iter()
                .map(|q| q.iter().zip(&units).map(|(v, (f, _))| v * f).collect())
                .collect(),
            assessment: assess(cell, &all)?,
            measured: measured.len(),
            margins: kind_margins(cell, design, collisions)?,
            collisions,
            plan,
            pool: None,
            rank_deficit,
        })
    }

    /// Chooses a design for `cell` from the pose pool in the file `pool` (a joint CSV as
    /// [`read_configurations`](crate::measure::csv::read_configurations) reads it;
    /// [`plan_from_pool`], augmenting the `measured` poses) and makes its record.
    pub fn from_pool(
        cell: &Cell,
        cell_source: Option<&str>,
        method: &str,
        pool: &std::path::Path,
        settings: &PoolSettings,
        measured: &[Vec<f64>],
        observer: &mut dyn Observer,
    ) -> Result<DesignRecord, Error> {
        let rows = crate::measure::csv::read_configurations(pool, &cell.model, None)?;
        let planned = plan_from_pool(
            cell,
            &rows,
            &pool.display().to_string(),
            settings,
            measured,
            observer,
        )?;
        let design = planned.plan.design.clone();
        let mut record = DesignRecord::augmenting(
            cell,
            cell_source,
            method,
            &design,
            measured,
            Some(planned.plan),
            settings.collisions,
        )?;
        record.pool = Some(planned.pool);
        Ok(record)
    }

    /// Plans a design for `cell` ([`plan`], augmenting the `measured` poses) and makes its
    /// record; `method` says how it was asked for.
    pub fn planned(
        cell: &Cell,
        cell_source: Option<&str>,
        method: &str,
        settings: &PlanSettings,
        measured: &[Vec<f64>],
        observer: &mut dyn Observer,
    ) -> Result<DesignRecord, Error> {
        let report = plan(cell, settings, measured, observer)?;
        let design = report.design.clone();
        DesignRecord::augmenting(
            cell,
            cell_source,
            method,
            &design,
            measured,
            Some(report),
            settings.collisions,
        )
    }

    /// The poses in internal units (rad, mm) for `model`, whose joints must match the
    /// record's.
    pub fn design_for(&self, model: &Model) -> Result<Vec<Vec<f64>>, Error> {
        let names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
        let ours: Vec<&str> = self.joints.iter().map(|j| j.name.as_str()).collect();
        if names != ours {
            return Err(Error::Input(format!(
                "the design (cell `{}`, joints {}) does not fit model `{}` (joints {})",
                self.cell,
                ours.join(", "),
                model.name,
                names.join(", ")
            )));
        }
        let units = joint_units(model);
        Ok(self
            .poses
            .iter()
            .map(|q| q.iter().zip(&units).map(|(v, (f, _))| v / f).collect())
            .collect())
    }
}
