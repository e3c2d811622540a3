//! Completeness and identifiability of a model for a measurement type.
//!
//! (Over 600 lines: one analysis — the stacked, column-scaled factor, its rank, the greedy
//! minimal set, the explanation of every left-out parameter and the variance inflation of
//! every kept one all read the same factor; split, it would be passed between files.)
//!
//! The book's count (book §2.3, eq. 2.49): a complete, minimal model of a serial robot has
//! `N = 4R + 2P + 6` parameters. What a calibration can identify also depends on what is
//! measured: a point instead of a full pose loses the tool orientation (3), distances lose
//! the placement of the robot (6), and special geometry loses more (book Prop. 4.7.3: 25
//! instead of 27 for the PUMA when the tool origin lies on axis 6).
//!
//! The numerical analysis stacks the identification Jacobian over random configurations,
//! scales every column to unit norm (so mm and rad compare), and
//! * counts the rank by SVD and by QR with column pivoting;
//! * picks the minimal identifiable set greedily in a preference order (instrument, targets,
//!   base, tool, then links from base to tip), keeping a parameter only if its scaled column
//!   is not in the span of those already kept (Gram–Schmidt with re-orthogonalisation);
//! * explains every parameter left out by the kept parameters its column is a combination
//!   of ("`j1.theta` cannot be separated from `tracker.rz`, ...").

use crate::linalg::{singular_values_of_factor, RowCompressor};
use crate::model::chain::Model;
use crate::model::jacobian::{identification_jacobian, Observed, Rows};
use crate::model::kinematics::{forward_kinematics, Data};
use crate::model::link::JointKind;
use crate::model::registry::{ParameterStatus, Segment};
use crate::model::sampling::random_configurations;
use crate::Error;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// What the instrument measures, for the identifiability analysis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Measurement {
    /// Full 6-D pose of the frame targets (or of the tool frame if there are none).
    Pose,
    /// Position of every point target (or of the tool origin if there are none).
    Position,
    /// Distances between the positions at successive configurations (ball bar, or a
    /// tracker used as a distance meter): the placement of the robot is not observable.
    Distance,
}

impl Measurement {
    /// The measurement in words, for output: `pose`, `position`, `distance`.
    pub fn words(self) -> &'static str {
        match self {
            Measurement::Pose => "pose",
            Measurement::Position => "position",
            Measurement::Distance => "distance",
        }
    }

    /// Parses `pose` (or `full-pose`), `position` or `distance`; `None` otherwise.
    pub fn from_name(s: &str) -> Option<Measurement> {
        match s {
            "pose" | "full-pose" => Some(Measurement::Pose),
            "position" => Some(Measurement::Position),
            "distance" => Some(Measurement::Distance),
            _ => None,
        }
    }
}

/// Settings of the analysis.
#[derive(Clone, Debug)]
pub struct IdentifiabilitySettings {
    /// What the instrument measures: decides which Jacobian rows are stacked.
    pub measurement: Measurement,
    /// Number of random configurations (uniform within the joint limits).
    pub poses: usize,
    /// Seed of the random configurations (same seed, same result).
    pub seed: u64,
    /// A scaled column whose component orthogonal to the kept columns is below this is
    /// dependent; also the relative singular-value threshold of the rank.
    pub tolerance: f64,
    /// The instrument station of each configuration of [`analyze_at`] (an index into
    /// [`Model::stations`]); empty: the configurations are spread over the model's stations
    /// in turn (as [`analyze`]'s random ones always are).
    pub stations: Vec<usize>,
    /// The payload each configuration of [`analyze_at`] carried (an index into
    /// [`Model::payloads`], `None`: none); `None`: the configurations carry, in turn, no
    /// payload and each of the model's payloads (as [`analyze`]'s random ones always do: a
    /// payload term is generically identifiable from measurements with and without it).
    pub payloads: Option<Vec<Option<usize>>>,
}

impl Default for IdentifiabilitySettings {
    fn default() -> Self {
        IdentifiabilitySettings {
            measurement: Measurement::Position,
            poses: 60,
            seed: 1,
            tolerance: 1e-8,
            stations: Vec::new(),
            payloads: None,
        }
    }
}

/// Why a parameter is not in the identifiable set.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Exclusion {
    /// Registry name of the excluded parameter.
    pub name: String,
    /// Sentence: no effect on the measurement, or which kept parameters it cannot be
    /// separated from.
    pub reason: String,
    /// Kept parameters whose combination reproduces this one's effect, with the
    /// coefficient in column-normalised units, largest first.
    pub partners: Vec<(String, f64)>,
}

/// The book's completeness count for the model's joints.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Completeness {
    /// Number of revolute joints `R`.
    pub revolute: usize,
    /// Number of prismatic joints `P`.
    pub prismatic: usize,
    /// `4R + 2P + 6` (book eq. 2.49): parameters of a complete, minimal model of the
    /// pose of the tool relative to the world.
    pub complete_pose_model: usize,
    /// What the measurement type identifies in generic geometry (see `expected_count`).
    pub expected_for_measurement: Option<usize>,
}

/// Result of the analysis.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Identifiability {
    /// Measurement type analysed.
    pub measurement: Measurement,
    /// Number of random configurations stacked.
    pub poses: usize,
    /// The book's parameter counts for this joint set (book eq. 2.49).
    pub completeness: Completeness,
    /// Parameters analysed (free or with prior).
    pub candidates: Vec<String>,
    /// Parameters the user or cell fixed; not analysed.
    pub fixed: Vec<String>,
    /// Rank of the column-normalised Jacobian: singular values above `tolerance · σmax`.
    pub rank_svd: usize,
    /// Rank by QR with column pivoting: `|R_ii|` above `tolerance · |R_00|`.
    pub rank_qr: usize,
    /// Singular values of the column-normalised Jacobian of all candidates, descending.
    pub singular_values: Vec<f64>,
    /// The minimal identifiable set, in registry order.
    pub identifiable: Vec<String>,
    /// Condition number σmax/σmin of the column-normalised Jacobian of the identifiable set.
    pub condition_number: f64,
    /// Variance inflation of each identifiable parameter, in the order of `identifiable`:
    /// `VIFᵢ = [(JᵀJ)⁻¹]ᵢᵢ ‖Jᵢ‖² = 1 / sin² θᵢ`, θᵢ the angle between its column and the
    /// span of the other identifiable columns (Belsley, Kuh & Welsch 1980, *Regression
    /// Diagnostics*, §3.1): 1 for a column orthogonal to the others, large for one that is
    /// nearly their combination (a target a fraction of a millimetre from the last axis).
    #[serde(default)]
    pub variance_inflation: Vec<f64>,
    /// Candidates left out of the identifiable set, each with the reason.
    pub excluded: Vec<Exclusion>,
}

/// An identifiable set counted the one way `model` and `identify` state it: the geometric
/// parameters, which the generic count (`expected_count`) covers, and the non-geometric
/// terms (joint compliance, periodic gear errors) apart.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct IdentifiableCount {
    /// Geometric parameters (kinematic, frames, targets).
    pub geometric: usize,
    /// Non-geometric terms ([`Model::is_joint_correction`]).
    pub nongeometric: usize,
}

impl IdentifiableCount {
    /// The count of the parameters `set` (registry indices of `model`).
    pub fn of(model: &Model, set: impl IntoIterator<Item = usize>) -> IdentifiableCount {
        let (mut geometric, mut nongeometric) = (0, 0);
        for i in set {
            if model.is_joint_correction(i) {
                nongeometric += 1;
            } else {
                geometric += 1;
            }
        }
        IdentifiableCount {
            geometric,
            nongeometric,
        }
    }
}

impl std::fmt::Display for IdentifiableCount {
    /// `31 geometric parameters` and, with terms, ` + 15 non-geometric terms`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} geometric parameters", self.geometric)?;
        if self.nongeometric > 0 {
            write!(f, " + {} non-geometric terms", self.nongeometric)?;
        }
        Ok(())
    }
}

impl Identifiability {
    /// Its identifiable set counted as [`IdentifiableCount`] (`model`: the model analysed).
    pub fn count(&self, model: &Model) -> IdentifiableCount {
        IdentifiableCount::of(
            model,
            self.identifiable
                .iter()
                .filter_map(|n| model.registry.index_of(n)),
        )
    }
}

/// Number of parameters a measurement type can identify for a model in generic geometry,
/// where the book gives a count: `4R + 2P + 6` for a full pose; `4R + 2P + 3` for the
/// position of one point (the tool orientation is not measured, book §4.7, Prop. 4.7.3);
/// `4R + 2P − 3` for distances of one point (the placement of the robot, 6, is lost).
/// `None` for several points, whose count depends on their layout. Each instrument station
/// after the first adds 6 to a pose or position count ([`crate::model::station`]).
pub fn expected_count(model: &Model, m: Measurement) -> Option<usize> {
    let (r, p) = joint_counts(model);
    let stations = 6 * model.stations.len().saturating_sub(1);
    let base = 4 * r + 2 * p;
    let single_point = model.targets.len() <= 1;
    match m {
        Measurement::Pose => Some(base + 6 + stations),
        Measurement::Position if single_point => Some(base + 3 + stations),
        Measurement::Distance if single_point => (base + 3).checked_sub(6),
        _ => None,
    }
}

fn joint_counts(model: &Model) -> (usize, usize) {
    let r = model
        .joints
        .iter()
        .filter(|j| j.kind == JointKind::Revolute)
        .count();
    (r, model.dof() - r)
}

/// Preference rank of a parameter when choosing the identifiable set (lower is kept first).
fn preference(model: &Model, i: usize) -> (usize, usize) {
    let p = model.registry.get(i);
    let last = model.links.len() - 1;
    let link_of = |i: usize| {
        model
            .links
            .iter()
            .position(|l| i >= l.first_param && i < l.first_param + l.param_count())
    };
    let group = match p.segment {
        Segment::Instrument => 0,
        Segment::Target(_) => 1,
        Segment::Chain => match link_of(i) {
            Some(0) => 2,
            Some(l) if l == last => 3,
            _ => 4,
        },
    };
    (group, i)
}

/// The observed frames and rows for a measurement type.
fn observations(model: &Model, m: Measurement) -> Vec<(Observed, Rows)> {
    let frames: Vec<usize> = (0..model.targets.len())
        .filter(|&k| model.target_is_frame(k))
        .collect();
    let points: Vec<usize> = (0..model.targets.len())
        .filter(|&k| !model.target_is_frame(k))
        .collect();
    match m {
        Measurement::Pose => {
            if frames.is_empty() {
                vec![(Observed::Tool, Rows::Pose)]
            } else {
                frames
                    .into_iter()
                    .map(|k| (Observed::Target(k), Rows::Pose))
                    .collect()
            }
        }
        Measurement::Position | Measurement::Distance => {
            if model.targets.is_empty() {
                vec![(Observed::Tool, Rows::Position)]
            } else {
                points
                    .into_iter()
                    .chain(frames)
                    .map(|k| (Observed::Target(k), Rows::Position))
                    .collect()
            }
        }
    }
}

/// Stacked identification Jacobian for a measurement type over configurations `qs`, one
/// column per entry of `columns`, configuration `i` measured from station `at(i).0` carrying
/// payload `at(i).1`.
fn stacked_jacobian_at(
    model: &Model,
    params: &[f64],
    qs: &[Vec<f64>],
    at: &dyn Fn(usize) -> (usize, Option<usize>),
    m: Measurement,
    columns: &[usize],
) -> DMatrix<f64> {
    let obs = observations(model, m);
    let per_pose: usize = obs.iter().map(|(_, r)| r.count()).sum();
    let mut data = Data::new(model);
    let mut full = DMatrix::zeros(per_pose * qs.len(), columns.len());
    for (i, q) in qs.iter().enumerate() {
        (data.station, data.payload) = at(i);
        forward_kinematics(model, &mut data, params, q);
        let mut row = i * per_pose;
        for &(o, r) in &obs {
            identification_jacobian(model, &data, o, r, columns, &mut full, row);
            row += r.count();
        }
    }
    if m != Measurement::Distance {
        return full;
    }
    // Distance between the point at pose i and at pose i+1: row = d̂ᵀ (J_i − J_{i+1}).
    let mut positions = Vec::with_capacity(qs.len());
    for (i, q) in qs.iter().enumerate() {
        (data.station, data.payload) = at(i);
        forward_kinematics(model, &mut data, params, q);
        positions.push(
            obs.iter()
                .map(|&(o, _)| crate::model::jacobian::observed_position(&data, o))
                .collect::<Vec<_>>(),
        );
    }
    let pairs = qs.len().saturating_sub(1);
    let mut dist = DMatrix::zeros(pairs * obs.len(), columns.len());
    for i in 0..pairs {
        for (k, _) in obs.iter().enumerate() {
            let d = positions[i][k] - positions[i + 1][k];
            let n = d.norm();
            if n < 1e-9 {
                continue;
            }
            let dh = d / n;
            for c in 0..columns.len() {
                let mut s = 0.0;
                for a in 0..3 {
                    s += dh[a]
                        * (full[(i * per_pose + 3 * k + a, c)]
                            - full[((i + 1) * per_pose + 3 * k + a, c)]);
                }
                dist[(i * obs.len() + k, c)] = s;
            }
        }
    }
    dist
}

/// Configurations stacked per block of [`stacked_factor`].
const FACTOR_BLOCK: usize = 256;

/// The triangular factor of [`stacked_jacobian_at`] (`linalg`) and its number of rows, built
/// a block of configurations at a time (a distance block overlaps the next by one
/// configuration, so every successive pair is stacked once).
fn stacked_factor(
    model: &Model,
    params: &[f64],
    qs: &[Vec<f64>],
    opts: &IdentifiabilitySettings,
    columns: &[usize],
) -> (DMatrix<f64>, usize) {
    let m = opts.measurement;
    let overlap = usize::from(m == Measurement::Distance);
    let mut factor = RowCompressor::new(columns.len());
    let mut start = 0;
    let stations = model.stations.len().max(1);
    let payload_states = model.payloads.len() + 1;
    while start + overlap < qs.len() {
        let end = (start + FACTOR_BLOCK + overlap).min(qs.len());
        let at = |i: usize| {
            let i = start + i;
            let station = opts.stations.get(i).copied().unwrap_or(i % stations);
            let payload = match &opts.payloads {
                Some(given) => given.get(i).copied().flatten(),
                None => (i % payload_states).checked_sub(1),
            };
            (station, payload)
        };
        let block = stacked_jacobian_at(model, params, &qs[start..end], &at, m, columns);
        factor.add_rows(block.as_view());
        start = end - overlap;
    }
    let rows = factor.rows();
    (factor.finish(), rows)
}

/// Analyses which free parameters of `model` can be identified at `params` from the given
/// measurement type.
pub fn analyze(
    model: &Model,
    params: &[f64],
    opts: &IdentifiabilitySettings,
) -> Result<Identifiability, Error> {
    let qs = random_configurations(model, opts.poses.max(2), opts.seed);
    analyze_at(model, params, &qs, opts)
}

/// As [`analyze`], at given configurations (e.g. a user's measurement poses).
pub fn analyze_at(
    model: &Model,
    params: &[f64],
    qs: &[Vec<f64>],
    opts: &IdentifiabilitySettings,
) -> Result<Identifiability, Error> {
    for q in qs {
        model.check_measured_joints(q)?;
    }
    let mut candidates: Vec<usize> = model.registry.free();
    let fixed: Vec<String> = (0..model.param_count())
        .filter(|&i| model.registry.get(i).status == ParameterStatus::Fixed)
        .map(|i| model.registry.get(i).name.clone())
        .collect();
    candidates.sort_by_key(|&i| preference(model, i));
    // Everything below depends on the stacked Jacobian only through inner products of its
    // columns, so it runs on its n × n triangular factor (`linalg`), built a block of
    // configurations at a time: memory and time stay flat in the number of configurations.
    let (factor, m) = stacked_factor(model, params, qs, opts, &candidates);
    let name = |i: usize| model.registry.get(i).name.clone();
    let names: Vec<String> = candidates.iter().map(|&i| name(i)).collect();
    let s = select(factor, m, &names, opts.measurement, opts.tolerance);
    let (rv, pr) = joint_counts(model);
    Ok(s.into_report(
        &candidates,
        &name,
        fixed,
        opts.measurement,
        qs.len(),
        Completeness {
            revolute: rv,
            prismatic: pr,
            complete_pose_model: 4 * rv + 2 * pr + 6,
            expected_for_measurement: expected_count(model, opts.measurement),
        },
    ))
}

/// What the analysis of a stacked factor finds, by position in the candidate list (shared by
/// serial models and trees, [`crate::model::tree::identifiability`]).
pub(crate) struct Selection {
    /// Rank by SVD of the column-normalised factor.
    pub rank_svd: usize,
    /// Rank by QR with column pivoting.
    pub rank_qr: usize,
    /// Singular values, descending.
    pub singular_values: Vec<f64>,
    /// Kept candidates (position in the candidate list) with their variance inflation.
    pub kept: Vec<(usize, f64)>,
    /// Condition number of the kept columns.
    pub condition_number: f64,
    /// The candidates left out, with the reason.
    pub excluded: Vec<Exclusion>,
}

impl Selection {
    /// The analysis record of this selection over `candidates` (parameter indices in
    /// preference order, as given to [`select`], named by `name`), with the parameters the
    /// user fixed, the measurement and number of configurations analysed and the
    /// completeness count.
    pub(crate) fn into_report(
        self,
        candidates: &[usize],
        name: &dyn Fn(usize) -> String,
        fixed: Vec<String>,
        measurement: Measurement,
        poses: usize,
        completeness: Completeness,
    ) -> Identifiability {
        let mut identifiable: Vec<(usize, f64)> =
            self.kept.iter().map(|&(k, v)| (candidates[k], v)).collect();
        identifiable.sort_by_key(|&(i, _)| i);
        let mut sorted = candidates.to_vec();
        sorted.sort();
        Identifiability {
            measurement,
            poses,
            completeness,
            candidates: sorted.into_iter().map(name).collect(),
            fixed,
            rank_svd: self.rank_svd,
            rank_qr: self.rank_qr,
            singular_values: self.singular_values,
            variance_inflation: identifiable.iter().map(|&(_, v)| v).collect(),
            identifiable: identifiable.into_iter().map(|(i, _)| name(i)).collect(),
            condition_number: self.condition_number,
            excluded: self.excluded,
        }
    }
}

/// The rank, the greedy minimal set (candidates in preference order, `names`), the
/// explanation of every left-out candidate and the variance inflation of every kept one,
/// from the triangular factor of the stacked Jacobian (`m` rows stacked).
pub(crate) fn select(
    factor: DMatrix<f64>,
    m: usize,
    names: &[String],
    measurement: Measurement,
    tolerance: f64,
) -> Selection {
    // Column scaling to unit norm; zero columns stay zero.
    let norms: Vec<f64> = (0..factor.ncols())
        .map(|c| factor.column(c).norm())
        .collect();
    let max_norm = norms.iter().cloned().fold(0.0, f64::max);
    let mut scaled = factor;
    for (c, &n) in norms.iter().enumerate() {
        if n > 1e-12 * max_norm.max(1e-300) {
            scaled.column_mut(c).unscale_mut(n);
        } else {
            scaled.column_mut(c).fill(0.0);
        }
    }

    let sv = singular_values_of_factor(&scaled, m);
    let smax = sv.first().copied().unwrap_or(0.0);
    let rank_svd = sv
        .iter()
        .filter(|&&s| s > tolerance * smax.max(1e-300))
        .count();
    let rank_qr = if scaled.ncols() > 0 && m > 0 {
        let r = scaled.clone().col_piv_qr().r();
        let d0 = r[(0, 0)].abs();
        (0..m.min(r.ncols()))
            .filter(|&i| r[(i, i)].abs() > tolerance * d0.max(1e-300))
            .count()
    } else {
        0
    };

    // Greedy selection in preference order (Gram–Schmidt, twice for stability).
    let mut basis: Vec<DVector<f64>> = Vec::new();
    let mut kept = Vec::new();
    let mut dropped = Vec::new();
    for (c, &norm) in norms.iter().enumerate() {
        let mut v = scaled.column(c).into_owned();
        if norm <= 1e-12 * max_norm.max(1e-300) {
            dropped.push(c);
            continue;
        }
        for _ in 0..2 {
            for b in &basis {
                let d = b.dot(&v);
                v.axpy(-d, b, 1.0);
            }
        }
        let n = v.norm();
        if n > tolerance.sqrt() {
            basis.push(v / n);
            kept.push(c);
        } else {
            dropped.push(c);
        }
    }

    let kept_matrix = DMatrix::from_fn(scaled.nrows(), kept.len(), |r, k| scaled[(r, kept[k])]);
    let condition_number = if kept.is_empty() {
        f64::INFINITY
    } else {
        let s = kept_matrix.clone().svd(false, false).singular_values;
        s.max() / s.min()
    };
    let qr = kept_matrix.clone().qr();
    let (q, r) = (qr.q(), qr.r());
    let vif_by_kept = variance_inflation(&r);
    let mut excluded = Vec::new();
    for &c in &dropped {
        let pname = names[c].clone();
        if norms[c] <= 1e-12 * max_norm.max(1e-300) {
            excluded.push(Exclusion {
                reason: format!(
                    "`{pname}` has no effect on the {} measurement",
                    measurement_name(measurement)
                ),
                name: pname,
                partners: Vec::new(),
            });
            continue;
        }
        let a = scaled.column(c).into_owned();
        let coef = r
            .solve_upper_triangular(&(q.transpose() * &a))
            .unwrap_or_else(|| DVector::zeros(kept.len()));
        let mut partners: Vec<(String, f64)> = coef
            .iter()
            .enumerate()
            .filter(|(_, x)| x.abs() > 1e-6)
            .map(|(k, &x)| (names[kept[k]].clone(), x))
            .collect();
        partners.sort_by(|a, b| {
            b.1.abs()
                .partial_cmp(&a.1.abs())
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        let shown: Vec<String> = partners
            .iter()
            .take(4)
            .map(|(n, _)| format!("`{n}`"))
            .collect();
        let more = if partners.len() > 4 {
            format!(" and {} more", partners.len() - 4)
        } else {
            String::new()
        };
        // No partner above the threshold: the column is within rounding of the others'
        // span without a named combination (values so large every digit is lost).
        let reason = if shown.is_empty() {
            format!(
                "`{pname}` cannot be separated from the other parameters numerically: its effect on the {} measurement is lost in rounding",
                measurement_name(measurement)
            )
        } else {
            format!(
                "`{pname}` cannot be separated from {}{more}: its effect on the {} measurement is a combination of theirs",
                shown.join(", "),
                measurement_name(measurement)
            )
        };
        excluded.push(Exclusion {
            reason,
            name: pname,
            partners,
        });
    }
    Selection {
        rank_svd,
        rank_qr,
        singular_values: sv,
        kept: kept.into_iter().zip(vif_by_kept).collect(),
        condition_number,
        excluded,
    }
}

/// The variance inflation of every column of a matrix with unit-norm columns from the
/// triangular factor `r` of its QR decomposition: `(JᵀJ)⁻¹ = R⁻¹R⁻ᵀ`, so `VIFᵢ` is the
/// squared norm of row `i` of `R⁻¹` (∞ for a singular factor).
fn variance_inflation(r: &DMatrix<f64>) -> Vec<f64> {
    let n = r.ncols();
    match r.clone().try_inverse() {
        Some(inv) if n > 0 => (0..n).map(|i| inv.row(i).norm_squared()).collect(),
        _ => vec![f64::INFINITY; n],
    }
}

fn measurement_name(m: Measurement) -> &'static str {
    match m {
        Measurement::Pose => "pose",
        Measurement::Position => "position",
        Measurement::Distance => "distance",
    }
}

impl Identifiability {
    /// Fixes every excluded parameter of `model` (the free set becomes the minimal
    /// identifiable set).
    pub fn apply(&self, model: &mut Model) -> Result<(), Error> {
        for e in &self.excluded {
            let i = model.registry.require(&e.name)?;
            model.registry.set_status(i, ParameterStatus::Fixed);
        }
        Ok(())
    }
}
