//! What a design gives, before anything is measured: predicted C_p (paper §1.1), C_s at
//! the working configurations, observability indices and every criterion's value — for a
//! planned design or one a user made by hand; with its constraint margins, the record of
//! `armcal evaluate` ([`evaluate_design`]).

use crate::cell::Cell;
use crate::design::cell_constraints::{tracker_shift, TrackerShift};
use crate::design::plan::{constraint_set, CellConstraints, DesignMargin};
use crate::design::record::{kind_margins, KindMargin};
use crate::design::{Criterion, DesignModel, DesignObjective, InformationWorkspace};
use crate::identify::model_floor::{model_floor, ModelFloor};
use crate::identify::uncertainty::{self, Observability, TcpCovariance};
use crate::identify::Problem;
use crate::model::identifiability::Measurement;
use crate::Error;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// Predicted precision of a design.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DesignAssessment {
    /// Free parameters, the order of `c_p`.
    pub parameters: Vec<String>,
    /// Predicted σ of each free parameter (mm, rad).
    pub sigma: Vec<f64>,
    /// The predicted covariance of the free parameters, C_p (paper §1.1).
    pub c_p: DMatrix<f64>,
    /// tr(C_p)/n_p (the paper's φ_A(C_p), mm and rad unscaled).
    pub phi_a_cp: f64,
    /// C_s at each working configuration.
    pub tcp: Vec<TcpCovariance>,
    /// The predicted TCP precision along each working path (none in files of an older armcal).
    #[serde(default)]
    pub paths: Vec<PathPrecision>,
    /// The observability indices O1…O5 of the design's Jacobian.
    pub observability: Observability,
    /// Every criterion's value (see [`Criterion`]).
    pub criteria: Vec<(Criterion, f64)>,
    /// The model floor beside C_s at the working poses (`design_floor`); `None` without
    /// working poses, for distance measurements, or in files of an older armcal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model_floor: Option<ModelFloor>,
}

/// The predicted TCP position precision along a working path: the KPI value
/// `v = (1/3) tr C_s` (mm², paper eq. 24) at each of its configurations, summarised.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PathPrecision {
    /// The path's name (`[[working_path]] name`).
    pub name: String,
    /// `v` at each configuration in path order (mm²).
    pub kpi: Vec<f64>,
    /// Mean of `v` along the path (mm²): the path's term in the mean KPI.
    pub mean_kpi: f64,
    /// Largest `v` along the path (mm²).
    pub max_kpi: f64,
    /// Where it is largest (1-based configuration of the path).
    pub worst: usize,
}

/// The [`PathPrecision`] of each of `cell`'s working paths under the parameter covariance
/// `cp`, from the KPI rows of `d` (the paths' configurations follow the working poses there).
pub fn path_precision(cell: &Cell, d: &DesignModel, cp: &DMatrix<f64>) -> Vec<PathPrecision> {
    let mut block = cell.working.len();
    cell.working_paths
        .iter()
        .map(|p| {
            let kpi: Vec<f64> = (block..block + p.q.len())
                .map(|k| {
                    let g = d.kpi_rows.rows(3 * k, 3);
                    (g * cp).component_mul(&g).sum() / 3.0
                })
                .collect();
            block += p.q.len();
            let (worst, max_kpi) =
                kpi.iter()
                    .enumerate()
                    .fold(
                        (0, f64::NEG_INFINITY),
                        |b, (i, &v)| if v > b.1 { (i, v) } else { b },
                    );
            PathPrecision {
                name: p.name.clone(),
                mean_kpi: kpi.iter().sum::<f64>() / kpi.len() as f64,
                max_kpi,
                worst: worst + 1,
                kpi,
            }
        })
        .collect()
}

/// The predicted precision of `design` (internal units) for `cell`, before anything is measured.
///
/// `C_p = (FᵀF)⁻¹` of the σ-weighted identification Jacobian F at the nominal (book §5.3)
/// and `C_s = G C_p Gᵀ` at every working pose (paper eq. 19 and appendix): what `identify` will report on
/// these poses if the robot is close to its drawing and the instrument's σ is right.
///
/// ```
/// use armcal::assess;
/// use armcal::model::random_configurations;
///
/// # fn main() -> armcal::Result<()> {
/// let cell = armcal::cell::builtin::paper_cell()?;
/// let few = assess(&cell, &random_configurations(&cell.model, 30, 1))?;
/// let more = assess(&cell, &random_configurations(&cell.model, 120, 1))?;
/// // Four times the poses: about a quarter of the TCP variance (C_s ∝ 1/N).
/// let ratio = more.tcp[0].kpi / few.tcp[0].kpi;
/// assert!(ratio > 0.1 && ratio < 0.5, "{ratio}");
/// # Ok(())
/// # }
/// ```
pub fn assess(cell: &Cell, design: &[Vec<f64>]) -> Result<DesignAssessment, Error> {
    let d = DesignModel::from_cell(cell)?;
    let mut ws = InformationWorkspace::new(&d);
    let data_rows = d.rows() * design.len();
    let mut j = DMatrix::zeros(data_rows + d.prior_rows.nrows(), d.n());
    for (i, q) in design.iter().enumerate() {
        d.model
            .check_joints(q)
            .map_err(|e| Error::Input(format!("pose {}: {e}", i + 1)))?;
        d.jacobian(&mut ws, q);
        j.rows_mut(i * d.rows(), d.rows()).copy_from(&ws.jac);
    }
    // the cell's prior information, after the poses' rows
    j.rows_mut(data_rows, d.prior_rows.nrows())
        .copy_from(&d.prior_rows);
    let names: Vec<String> = d
        .free
        .iter()
        .map(|&i| d.model.registry.get(i).name.clone())
        .collect();
    let unc = uncertainty::parameter_uncertainty(&j, &DVector::zeros(j.nrows()), &names)?;
    let wnames: Vec<String> = cell.working.iter().map(|w| w.name.clone()).collect();
    let working: Vec<Vec<f64>> = cell.working.iter().map(|w| w.q.clone()).collect();
    let mut tcp = uncertainty::with_base_frame(
        uncertainty::tcp_covariance(&d.kpi_rows, &unc.covariance, &wnames),
        &uncertainty::tcp_jacobian_world(&d.model, &d.params, &d.free, &working),
        &unc.covariance,
    );
    if d.measures_orientation() {
        tcp = uncertainty::with_orientation(
            tcp,
            &uncertainty::tcp_orientation_jacobian(&d.model, &d.params, &d.free, &working),
            &unc.covariance,
        );
    }
    let mut criteria = Vec::new();
    for c in Criterion::ALL {
        if matches!(c, Criterion::Kpi | Criterion::KpiMax) && d.kpi_weights.is_empty() {
            continue;
        }
        let obj = DesignObjective::new(&d, c, &[]);
        let mut ows = obj.workspace(design.len());
        criteria.push((c, obj.value_and_gradient(&mut ows, &design.concat(), None)?));
    }
    Ok(DesignAssessment {
        model_floor: design_floor(cell, design)?,
        paths: path_precision(cell, &d, &unc.covariance),
        phi_a_cp: unc.covariance.trace() / names.len() as f64,
        parameters: names,
        sigma: unc.sigma,
        c_p: unc.covariance,
        tcp,
        observability: uncertainty::observability(j.rows(0, data_rows)),
        criteria,
    })
}

/// The model floor ([`crate::identify::model_floor`]) of measuring `design` on the nominal
/// robot as `simulate` does (a point target's position, a frame target's pose), with the
/// cell's fixed-parameter prior: what the fixed parameters add to the predicted C_s. The
/// planner's KPI leaves it out: for a parameter fixed because the data cannot separate it the
/// floor does not depend on the design. `None` without working poses or for distance
/// measurements.
pub fn design_floor(cell: &Cell, design: &[Vec<f64>]) -> Result<Option<ModelFloor>, Error> {
    if cell.working.is_empty() || cell.measurement == Measurement::Distance {
        return Ok(None);
    }
    let poses: Vec<(String, Vec<f64>)> = design
        .iter()
        .enumerate()
        .map(|(i, q)| ((i + 1).to_string(), q.clone()))
        .collect();
    let params = cell.model.nominal();
    let data = crate::sim::predict(&cell.model, &params, &poses, None, cell.measurement)?;
    let problem = Problem::new(&cell.model, &data, &cell.noise())?;
    let (_, j) = problem.residual_and_jacobian(&params);
    let cp =
        uncertainty::information_inverse(&crate::linalg::gram(j.as_view()), &problem.free_names())?;
    Ok(Some(model_floor(
        &problem,
        &params,
        &j,
        &cp,
        &cell.working,
        &cell.fixed_prior,
        &[],
    )))
}

/// What `armcal evaluate --json` prints: a design's assessment and how it meets the cell's
/// constraints at the nominal parameters.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DesignEvaluation {
    /// The cell's name.
    pub cell: String,
    /// Number of poses.
    pub poses: usize,
    /// The predicted precision ([`assess`]).
    pub assessment: DesignAssessment,
    /// The poses (1-based) outside the joint bounds (the limits less the cell's joint
    /// margin) or below a constraint's required value (the cell's clearance).
    pub infeasible_poses: Vec<usize>,
    /// The smallest constraint margin over the design (none without constraints).
    pub min_margin: Option<DesignMargin>,
    /// The smallest margin of every kind of constraint against the cell's `[design]`
    /// clearance and joint margin ([`kind_margins`]).
    pub margins: Vec<KindMargin>,
    /// The poses that stay measurable with the instrument displaced (`evaluate
    /// --tracker-shift-mm D`, `tracker_shift`); absent unless asked for.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tracker_shift: Option<TrackerShift>,
}

impl DesignEvaluation {
    /// The record as JSON (keys in alphabetical order, see `crate::json`).
    pub fn to_json(&self) -> Result<String, Error> {
        crate::json::sorted_pretty(self)
    }
}

/// The assessment of `design` (internal units) for `cell`, its infeasible poses, its
/// smallest margin and the margins per constraint kind, with or without the collision and
/// line-of-sight constraints; with `tracker_shift_mm`, which poses stay measurable with the
/// instrument that far off in any direction (`tracker_shift`).
pub fn evaluate_design(
    cell: &Cell,
    design: &[Vec<f64>],
    collisions: bool,
    tracker_shift_mm: Option<f64>,
) -> Result<DesignEvaluation, Error> {
    let assessment = assess(cell, design)?;
    let set = constraint_set(cell, collisions)?;
    let params = cell.model.nominal();
    let cons = CellConstraints::new(&set, &params);
    Ok(DesignEvaluation {
        cell: cell.name.clone(),
        poses: design.len(),
        assessment,
        infeasible_poses: (0..design.len())
            .filter(|&i| !cons.feasible(&design[i]))
            .map(|i| i + 1)
            .collect(),
        min_margin: cons.design_margin(design),
        margins: kind_margins(cell, design, collisions)?,
        tracker_shift: tracker_shift_mm
            .map(|d| tracker_shift(cell, design, d))
            .transpose()?,
    })
}
