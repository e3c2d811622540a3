//! The information a measurement configuration carries: `M(q) = J(q)ᵀ W J(q)` with `J` the
//! identification Jacobian of the measured target positions w.r.t. the free parameters and
//! `W = Σ⁻¹` (paper §1.1: `C = (F₁ᵀF₁)⁻¹`), and the derivative w.r.t. q of a weighted sum
//! `⟨Ω, W^{1/2}J⟩` through the foundation's mixed derivative
//! ([`identification_jacobian_dq_along`]): every design gradient is one.

use crate::cell::Cell;
use crate::measure::NoiseModel;
use crate::model::{
    forward_kinematics, identification_jacobian, identification_jacobian_dq_along,
    observed_position, AlongWorkspace, Data, Model, Observed, Rows,
};
use crate::Error;
use nalgebra::DMatrix;

/// What the design optimises over: the model at its nominal parameters, the free columns,
/// the measured targets, row weights, and the KPI rows (TCP at the working configurations).
#[derive(Clone, Debug)]
pub struct DesignModel {
    /// The cell's model (internal units: mm, rad).
    pub model: Model,
    /// Its nominal parameters, at which the Jacobians are evaluated.
    pub params: Vec<f64>,
    /// Parameter index of each column.
    pub free: Vec<usize>,
    /// Observed targets (position rows, 3 each).
    pub observed: Vec<Observed>,
    /// σ (mm) of each position axis. The range noise model is evaluated at the distance
    /// from the instrument to the TCP at the first working configuration and then held
    /// constant, so that the weights do not depend on q.
    pub sigma: [f64; 3],
    /// `G`: 3 rows per KPI configuration ([`Cell::kpi_configurations`]: the working poses,
    /// then the working paths' configurations), TCP position w.r.t. the free parameters.
    pub kpi_rows: DMatrix<f64>,
    /// Weight of each KPI configuration in the mean KPI.
    pub kpi_weights: Vec<f64>,
    /// The cell's prior information over the free columns, as whitened rows
    /// ([`crate::model::prior::prior_rows`]): part of every design's information.
    pub prior_rows: DMatrix<f64>,
}

impl DesignModel {
    /// The design model of a cell: its free parameters, point targets (or the tool origin),
    /// the instrument noise, and its working configurations.
    pub fn from_cell(cell: &Cell) -> Result<DesignModel, Error> {
        let mut model = cell.model.clone();
        // A planned pose carries no payload: the payload terms are not designed for (measure
        // the plan with and without the payload to identify them).
        for (i, _) in crate::identify::payload_terms(&cell.model) {
            model.registry.set_status(i, crate::model::Status::Fixed);
        }
        let params = model.nominal();
        let free = model.registry.free();
        if free.is_empty() {
            return Err(Error::Input(
                "the cell has no free parameters to design for".into(),
            ));
        }
        let observed: Vec<Observed> = if model.targets.is_empty() {
            vec![Observed::Tool]
        } else {
            (0..model.targets.len()).map(Observed::Target).collect()
        };
        let kpi = cell.kpi_configurations();
        let working: Vec<Vec<f64>> = kpi.iter().map(|(q, _)| q.to_vec()).collect();
        let kpi_rows = crate::identify::uncertainty::tcp_jacobian(&model, &params, &free, &working);
        let noise = cell.noise();
        let sigma = match noise {
            NoiseModel::Constant { sigma, .. } => sigma,
            NoiseModel::Range { a, b_per_m } => {
                let range = match working.first() {
                    Some(q) => {
                        let mut d = Data::new(&model);
                        forward_kinematics(&model, &mut d, &params, q);
                        observed_position(&d, Observed::Tool).norm()
                    }
                    None => 0.0,
                };
                [a + b_per_m * range / 1000.0; 3]
            }
            NoiseModel::PerMeasurement { .. } => {
                return Err(Error::Input(
                    "pose design needs a noise model with known σ (constant or range), not per-measurement".into(),
                ))
            }
        };
        let prior_rows = crate::model::prior::prior_rows(&model.registry, &free)?.0;
        Ok(DesignModel {
            model,
            params,
            free,
            observed,
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

    /// Rows per configuration (3 per observed target).
    pub fn rows(&self) -> usize {
        3 * self.observed.len()
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
        for (k, &obs) in self.observed.iter().enumerate() {
            identification_jacobian(
                &self.model,
                data,
                obs,
                Rows::Position,
                &self.free,
                out,
                row + 3 * k,
            );
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
        for (k, &obs) in self.observed.iter().enumerate() {
            identification_jacobian_dq_along(
                &self.model,
                &mut buffers.along,
                data,
                obs,
                Rows::Position,
                &self.free,
                &buffers.weight,
                3 * k,
                out,
            );
        }
    }

    /// Divides rows `row..row + rows` (x, y, z of one target after another) by their
    /// axis's σ, multiplying with 1/σ down each column (the matrix is column-major).
    fn whiten(&self, m: &mut DMatrix<f64>, row: usize) {
        let (height, rows) = (m.nrows(), self.rows());
        let inverse = self.sigma.map(|s| 1.0 / s);
        for column in m.as_mut_slice().chunks_mut(height) {
            for axes in column[row..row + rows].chunks_exact_mut(3) {
                for (x, s) in axes.iter_mut().zip(&inverse) {
                    *x *= s;
                }
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
