//! The information a measurement configuration carries: `M(q) = J(q)ᵀ W J(q)` with `J` the
//! identification Jacobian of what the instrument measures there w.r.t. the free parameters
//! and `W = Σ⁻¹` (paper §1.1: `C = (F₁ᵀF₁)⁻¹`), and the derivative w.r.t. q of a weighted sum
//! `⟨Ω, W^{1/2}J⟩` through the foundation's mixed derivative
//! ([`identification_jacobian_dq_along`]): every design gradient is one.
//!
//! The rows are those of the identification of the data the design will give: at each
//! configuration the measurements `simulate` writes ([`crate::sim::measurement_at`]: a point
//! target's position, a frame target's pose, the tool frame's pose in a full-pose cell),
//! each with its Jacobian rows ([`MeasurementKind::jacobian_rows`], book §4.3: 3 position
//! rows, or 3 position and 3 rotation rows) divided by its σ from the noise model exactly as
//! identification weighs it ([`NoiseModel::row_sigmas`]), over the free set identification
//! estimates (the model's free parameters). At the nominal parameters and a zero residual,
//! `Jᵀ W J` is the information of [`crate::identify::Problem`] on that data.

use crate::cell::Cell;
use crate::measure::NoiseModel;
use crate::model::{
    forward_kinematics, identification_jacobian, identification_jacobian_dq_along, AlongWorkspace,
    Data, Model, Observed, Rows,
};
use crate::Error;
use nalgebra::DMatrix;

#[cfg(doc)]
use crate::measure::MeasurementKind;

/// What the design optimises over: the model at its nominal parameters, the free columns,
/// the measured frames with their rows and σ's, and the KPI rows (TCP at the working
/// configurations).
#[derive(Clone, Debug)]
pub struct DesignModel {
    /// The cell's model (internal units: mm, rad).
    pub model: Model,
    /// Its nominal parameters, at which the Jacobians are evaluated.
    pub params: Vec<f64>,
    /// Parameter index of each column.
    pub free: Vec<usize>,
    /// What each configuration measures, in row order: the observed frame and its rows
    /// (3 position rows, or 6 pose rows for a frame target or the tool frame of a full-pose
    /// cell).
    pub observed: Vec<(Observed, Rows)>,
    /// σ of each row of one configuration's block (mm for a position row, rad for a rotation
    /// row): [`NoiseModel::row_sigmas`] of its measurement at the reference configuration,
    /// the first KPI configuration (the joints at mid-range without one). Only the range
    /// noise model depends on it; held constant, so that the weights do not depend on q.
    pub sigma: Vec<f64>,
    /// 1/σ of each row of [`DesignModel::sigma`].
    inverse_sigma: Vec<f64>,
    /// `G`: 3 rows per KPI configuration ([`Cell::kpi_configurations`]: the working poses,
    /// then the working paths' configurations), TCP position w.r.t. the free parameters.
    pub kpi_rows: DMatrix<f64>,
    /// Weight of each KPI configuration in the mean KPI.
    pub kpi_weights: Vec<f64>,
    /// The cell's prior information over the free columns, as whitened rows
    /// (`crate::model::prior::prior_rows`): part of every design's information.
    pub prior_rows: DMatrix<f64>,
}

impl DesignModel {
    /// The design model of a cell: its free parameters, what its instrument measures (the
    /// cell's `measurement`: positions or full poses), the instrument noise, and its working
    /// configurations.
    pub fn from_cell(cell: &Cell) -> Result<DesignModel, Error> {
        let mut model = cell.model.clone();
        // A planned pose carries no payload: the payload terms are not designed for (measure
        // the plan with and without the payload to identify them).
        for (i, _) in crate::identify::payload_terms(&cell.model) {
            model
                .registry
                .set_status(i, crate::model::ParameterStatus::Fixed);
        }
        let params = model.nominal();
        let free = model.registry.free();
        if free.is_empty() {
            return Err(Error::Input(
                "the cell has no free parameters to design for".into(),
            ));
        }
        let kpi = cell.kpi_configurations();
        let working: Vec<Vec<f64>> = kpi.iter().map(|(q, _)| q.to_vec()).collect();
        let kpi_rows = crate::identify::uncertainty::tcp_jacobian(&model, &params, &free, &working);
        let noise = cell.noise();
        if let NoiseModel::PerMeasurement { .. } = noise {
            return Err(Error::Input(
                "pose design needs a noise model with known σ (constant or range), not per-measurement".into(),
            ));
        }
        let reference = working.first().cloned().unwrap_or_else(|| {
            let mid = |j: &crate::model::Joint| 0.5 * (j.lower + j.upper);
            model.joints.iter().map(mid).collect()
        });
        let mut data = Data::new(&model);
        forward_kinematics(&model, &mut data, &params, &reference);
        let mut observed = Vec::new();
        let mut sigma = Vec::new();
        for obs in crate::sim::observed_frames(&model) {
            let m = crate::sim::measurement_at(&model, &data, 0, obs, cell.measurement);
            let rows = m
                .kind
                .jacobian_rows()
                .expect("a configuration's measurements are positions and poses");
            let s = noise.row_sigmas(&m).map_err(|e| {
                Error::Input(format!(
                    "{}: a design weighs each measurement as identification does: {e}",
                    cell.origin
                ))
            })?;
            sigma.extend_from_slice(&s[..rows.count()]);
            observed.push((obs, rows));
        }
        let prior_rows = crate::model::prior::prior_rows(&model.registry, &free)?.0;
        Ok(DesignModel {
            model,
            params,
            free,
            observed,
            inverse_sigma: sigma.iter().map(|s| 1.0 / s).collect(),
            sigma,
            kpi_rows,
            kpi_weights: kpi.iter().map(|(_, w)| *w).collect(),
            prior_rows,
        })
    }

    /// Number of free parameters n_p.
    pub fn n(&self) -> usize {
        self.free.len()
    }

    /// Rows per configuration (3 per observed position, 6 per observed pose).
    pub fn rows(&self) -> usize {
        self.sigma.len()
    }

    /// Whether the instrument measures an orientation (a pose's rotation rows): the design
    /// then also predicts the TCP orientation's covariance.
    pub fn measures_orientation(&self) -> bool {
        self.observed.iter().any(|(_, rows)| *rows == Rows::Pose)
    }

    /// Number of joints (entries of a configuration).
    pub fn dof(&self) -> usize {
        self.model.dof()
    }
}

/// Buffers for per-configuration information and its q-derivative.
pub struct InformationWorkspace {
    /// Kinematics of the last configuration of [`DesignModel::jacobian`].
    pub data: Data<f64>,
    /// Buffers of [`DesignModel::jacobian_dq_along`].
    pub along: AlongBuffers,
    /// Whitened Jacobian `W^{1/2} J` of one configuration.
    pub jac: DMatrix<f64>,
}

impl InformationWorkspace {
    /// Buffers sized for `d`: one configuration's kinematics and whitened Jacobian.
    pub fn new(d: &DesignModel) -> Self {
        InformationWorkspace {
            data: Data::new(&d.model),
            along: AlongBuffers::new(d),
            jac: DMatrix::zeros(d.rows(), d.n()),
        }
    }
}

/// Buffers of [`DesignModel::jacobian_dq_along`].
pub struct AlongBuffers {
    along: AlongWorkspace,
    /// `W^{1/2} Ω` (rows × n).
    weight: DMatrix<f64>,
}

impl AlongBuffers {
    /// Buffers sized for `d`.
    pub fn new(d: &DesignModel) -> Self {
        AlongBuffers {
            along: AlongWorkspace::new(&d.model),
            weight: DMatrix::zeros(d.rows(), d.n()),
        }
    }
}

impl DesignModel {
    /// Whitened Jacobian of one configuration into `ws.jac` (its kinematics in `ws.data`).
    pub fn jacobian(&self, ws: &mut InformationWorkspace, q: &[f64]) {
        self.jacobian_into(&mut ws.data, q, &mut ws.jac, 0);
    }

    /// Whitened Jacobian `W^{1/2} J` of the configuration `q` into rows `row..row + rows` of
    /// `out` (n columns), with its kinematics into `data` (for
    /// [`DesignModel::jacobian_dq_along`]).
    pub fn jacobian_into(
        &self,
        data: &mut Data<f64>,
        q: &[f64],
        out: &mut DMatrix<f64>,
        row: usize,
    ) {
        forward_kinematics(&self.model, data, &self.params, q);
        let mut at = row;
        for &(obs, rows) in &self.observed {
            identification_jacobian(&self.model, data, obs, rows, &self.free, out, at);
            at += rows.count();
        }
        self.whiten(out, row);
    }

    /// `∂/∂q_k ⟨Ω, W^{1/2}J⟩` for every joint k into `out`, at the configuration whose
    /// kinematics `data` holds ([`DesignModel::jacobian_into`]); `omega` is rows × n. Equal
    /// to `⟨W^{1/2}Ω, ∂J/∂q_k⟩` ([`identification_jacobian_dq_along`] per target).
    pub fn jacobian_dq_along(
        &self,
        data: &Data<f64>,
        buffers: &mut AlongBuffers,
        omega: &DMatrix<f64>,
        out: &mut [f64],
    ) {
        buffers.weight.copy_from(omega);
        self.whiten(&mut buffers.weight, 0);
        out.fill(0.0);
        let mut at = 0;
        for &(obs, rows) in &self.observed {
            identification_jacobian_dq_along(
                &self.model,
                &mut buffers.along,
                data,
                obs,
                rows,
                &self.free,
                &buffers.weight,
                at,
                out,
            );
            at += rows.count();
        }
    }

    /// Divides rows `row..row + rows` (one configuration's block) by their σ, multiplying
    /// with 1/σ down each column (the matrix is column-major).
    fn whiten(&self, m: &mut DMatrix<f64>, row: usize) {
        let (height, rows) = (m.nrows(), self.rows());
        for column in m.as_mut_slice().chunks_mut(height) {
            for (x, s) in column[row..row + rows].iter_mut().zip(&self.inverse_sigma) {
                *x *= s;
            }
        }
    }

    /// Information matrix `Σ_i J_iᵀ W J_i` of a set of configurations.
    pub fn information(&self, ws: &mut InformationWorkspace, qs: &[Vec<f64>]) -> DMatrix<f64> {
        let n = self.n();
        let mut m = DMatrix::zeros(n, n);
        for q in qs {
            self.jacobian(ws, q);
            m.gemm_tr(1.0, &ws.jac, &ws.jac, 1.0);
        }
        m
    }
}
