//! The identification least-squares problem (paper eqs. 5–6, book §4.3): the residual
//! vector of every measurement block, whitened by its σ, plus prior rows for parameters
//! with a prior, and the analytic Jacobian w.r.t. the free parameters.

use crate::measure::residual::{residual_rows, Prediction};
use crate::measure::{Dataset, MeasurementKind, NoiseModel};
use crate::model::{
    forward_kinematics, identification_jacobian, observed_pose, Data, Model, Observed, Rows, Status,
};
use crate::Error;
use nalgebra::{DMatrix, DVector};

/// A parameter with a Gaussian prior: residual row `(p − nominal)/σ` (MAP estimation).
#[derive(Clone, Debug)]
pub struct Prior {
    /// Column (index into the free set).
    pub column: usize,
    /// Prior mean: the parameter's nominal value (internal units: mm, rad).
    pub mean: f64,
    /// Prior standard deviation (internal units: mm, rad).
    pub sigma: f64,
}

/// Data of an identification problem; immutable, shareable.
#[derive(Clone, Debug)]
pub struct Problem<'a> {
    /// The model whose parameters are identified.
    pub model: &'a Model,
    /// The measurements.
    pub data: &'a Dataset,
    /// Parameter index of each estimated column.
    pub free: Vec<usize>,
    /// Prior rows, appended after the data rows in this order.
    pub priors: Vec<Prior>,
    /// σ of every data row, in row order.
    pub sigmas: Vec<f64>,
    /// First row of each measurement.
    pub row_of: Vec<usize>,
    /// Observed frames used at each configuration (slots of the prediction cache).
    slots: Vec<Observed>,
    /// `slot_of[measurement]`: slot index of its observed frame.
    slot_of: Vec<usize>,
    /// Per-row weight multipliers (robust estimation); 1 by default.
    pub row_weights: Vec<f64>,
}

/// Buffers for evaluating a [`Problem`].
pub struct Workspace {
    data: Data<f64>,
    predictions: Vec<Prediction>,
    block_r: [f64; 6],
}

impl<'a> Problem<'a> {
    /// Sets up the problem: free parameters from the model's registry statuses, σ of every
    /// row from the noise model. Checks the data against the model.
    pub fn new(model: &'a Model, data: &'a Dataset, noise: &NoiseModel) -> Result<Self, Error> {
        let free = model.registry.free();
        for (c, q) in data.configurations.iter().enumerate() {
            model.check_measured_joints(q).map_err(|e| {
                Error::Input(format!("configuration `{}`: {e}", data.config_ids[c]))
            })?;
        }
        let mut slots: Vec<Observed> = Vec::new();
        let mut slot_of = Vec::with_capacity(data.measurements.len());
        let mut sigmas = Vec::with_capacity(data.rows());
        let mut row_of = Vec::with_capacity(data.measurements.len());
        for m in &data.measurements {
            if let Observed::Target(k) = m.observed {
                if k >= model.targets.len() {
                    return Err(Error::Input(format!(
                        "line {}: target {k} does not exist in model `{}`",
                        m.line, model.name
                    )));
                }
            }
            if m.config >= data.configurations.len() {
                return Err(Error::Input(format!(
                    "line {}: unknown configuration",
                    m.line
                )));
            }
            if let MeasurementKind::Pose { .. } = m.kind {
                let is_frame = match m.observed {
                    Observed::Tool => true,
                    Observed::Target(k) => model.target_is_frame(k),
                };
                if !is_frame {
                    return Err(Error::Input(format!(
                        "line {}: a pose measurement needs a frame target, `{}` is a point",
                        m.line,
                        match m.observed {
                            Observed::Target(k) => model.targets[k].spec.name.as_str(),
                            Observed::Tool => "tool",
                        }
                    )));
                }
            }
            let slot = match slots.iter().position(|s| *s == m.observed) {
                Some(s) => s,
                None => {
                    slots.push(m.observed);
                    slots.len() - 1
                }
            };
            slot_of.push(slot);
            row_of.push(sigmas.len());
            let range = match &m.kind {
                MeasurementKind::Position { value, .. } => value.norm(),
                MeasurementKind::Pose { value, .. } => value.trans.norm(),
                _ => 0.0,
            };
            let s = noise.sigmas(m, range)?;
            sigmas.extend_from_slice(&s[..m.kind.rows()]);
        }
        let mut priors = Vec::new();
        for (column, &i) in free.iter().enumerate() {
            if let Status::Prior { sigma } = model.registry.get(i).status {
                priors.push(Prior {
                    column,
                    mean: model.registry.get(i).nominal,
                    sigma,
                });
            }
        }
        let rows = sigmas.len();
        Ok(Problem {
            model,
            data,
            free,
            priors,
            sigmas,
            row_of,
            slots,
            slot_of,
            row_weights: vec![1.0; rows],
        })
    }

    /// Checks that the problem can determine its free parameters: at least one, and no
    /// fewer residual rows than free parameters.
    pub fn check_determined(&self) -> Result<(), Error> {
        if self.free.is_empty() {
            return Err(Error::Input("no free parameters to identify".into()));
        }
        if self.rows() < self.free.len() {
            return Err(Error::Input(format!(
                "{} residual rows from {} measurements cannot determine {} free parameters; measure more poses or fix parameters",
                self.data_rows(),
                self.data.measurements.len(),
                self.free.len()
            )));
        }
        Ok(())
    }

    /// Names of the free parameters, in column order.
    pub fn free_names(&self) -> Vec<String> {
        self.free
            .iter()
            .map(|&i| self.model.registry.get(i).name.clone())
            .collect()
    }

    /// Whitened residual and Jacobian at `params` (allocating; for one-off evaluations).
    pub fn residual_and_jacobian(&self, params: &[f64]) -> (DVector<f64>, DMatrix<f64>) {
        let mut ws = self.workspace();
        let mut r = DVector::zeros(self.rows());
        let mut j = DMatrix::zeros(self.rows(), self.columns());
        self.evaluate(&mut ws, params, &mut r, Some(&mut j));
        (r, j)
    }

    /// The parameter covariance and tests at `params` (the predicted C_p if `params` are the
    /// truth or an estimate).
    pub fn uncertainty_at(&self, params: &[f64]) -> Result<super::ParameterUncertainty, Error> {
        let (r, j) = self.residual_and_jacobian(params);
        super::uncertainty::parameter_uncertainty(&j, &r, &self.free_names())
    }

    /// Rows of the whitened residual (data rows + prior rows).
    pub fn rows(&self) -> usize {
        self.sigmas.len() + self.priors.len()
    }

    /// Number of data rows (without priors).
    pub fn data_rows(&self) -> usize {
        self.sigmas.len()
    }

    /// Columns of the Jacobian: the number of free parameters.
    pub fn columns(&self) -> usize {
        self.free.len()
    }

    /// Buffers for evaluating this problem.
    pub fn workspace(&self) -> Workspace {
        Workspace {
            data: Data::new(self.model),
            predictions: vec![
                Prediction::new(self.free.len());
                self.slots.len() * self.data.configurations.len()
            ],
            block_r: [0.0; 6],
        }
    }

    /// Values of the free parameters in a full parameter vector.
    pub fn free_values(&self, params: &[f64]) -> DVector<f64> {
        DVector::from_iterator(self.free.len(), self.free.iter().map(|&i| params[i]))
    }

    /// Writes free values into a full parameter vector.
    pub fn set_free(&self, params: &mut [f64], x: &DVector<f64>) {
        for (k, &i) in self.free.iter().enumerate() {
            params[i] = x[k];
        }
    }

    /// Model predictions (pose and 6 × n Jacobian) at every configuration and slot.
    fn predict(&self, ws: &mut Workspace, params: &[f64], with_jacobian: bool) {
        let ns = self.slots.len();
        for (c, q) in self.data.configurations.iter().enumerate() {
            forward_kinematics(self.model, &mut ws.data, params, q);
            for (s, &obs) in self.slots.iter().enumerate() {
                let p = &mut ws.predictions[c * ns + s];
                p.pose = observed_pose(&ws.data, obs);
                if with_jacobian {
                    identification_jacobian(
                        self.model,
                        &ws.data,
                        obs,
                        Rows::Pose,
                        &self.free,
                        &mut p.jac,
                        0,
                    );
                }
            }
        }
    }

    /// Whitened residual `r` (length [`Problem::rows`]) and, if asked, its Jacobian w.r.t.
    /// the free parameters, at the full parameter vector `params`.
    pub fn evaluate(
        &self,
        ws: &mut Workspace,
        params: &[f64],
        r: &mut DVector<f64>,
        jac: Option<&mut DMatrix<f64>>,
    ) {
        let with_j = jac.is_some();
        self.predict(ws, params, with_j);
        let ns = self.slots.len();
        let mut scratch;
        let jac = match jac {
            Some(j) => j,
            None => {
                scratch = DMatrix::zeros(6, self.free.len());
                &mut scratch
            }
        };
        for (i, m) in self.data.measurements.iter().enumerate() {
            let a = &ws.predictions[m.config * ns + self.slot_of[i]];
            let b = match &m.kind {
                MeasurementKind::Distance { other, .. } => {
                    Some(&ws.predictions[other * ns + self.slot_of[i]])
                }
                _ => None,
            };
            let row = self.row_of[i];
            let rows = m.kind.rows();
            let jrow = if with_j { row } else { 0 };
            residual_rows(&m.kind, a, b, &mut ws.block_r, jac, jrow);
            for k in 0..rows {
                let w = self.row_weights[row + k].sqrt() / self.sigmas[row + k];
                r[row + k] = ws.block_r[k] * w;
                if with_j {
                    jac.row_mut(row + k).scale_mut(w);
                }
            }
        }
        let n = self.sigmas.len();
        for (k, pr) in self.priors.iter().enumerate() {
            r[n + k] = (params[self.free[pr.column]] - pr.mean) / pr.sigma;
            if with_j {
                jac.row_mut(n + k).fill(0.0);
                jac[(n + k, pr.column)] = 1.0 / pr.sigma;
            }
        }
    }

    /// Unwhitened position error (mm) of every position-bearing measurement at `params`
    /// (distances and planes: the scalar error). One entry per measurement.
    pub fn errors(&self, ws: &mut Workspace, params: &[f64]) -> Vec<f64> {
        self.predict(ws, params, false);
        let ns = self.slots.len();
        let mut dummy = DMatrix::zeros(6, self.free.len());
        self.data
            .measurements
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let a = &ws.predictions[m.config * ns + self.slot_of[i]];
                let b = match &m.kind {
                    MeasurementKind::Distance { other, .. } => {
                        Some(&ws.predictions[other * ns + self.slot_of[i]])
                    }
                    _ => None,
                };
                residual_rows(&m.kind, a, b, &mut ws.block_r, &mut dummy, 0);
                match m.kind.rows() {
                    1 => ws.block_r[0].abs(),
                    _ => (ws.block_r[0].powi(2) + ws.block_r[1].powi(2) + ws.block_r[2].powi(2))
                        .sqrt(),
                }
            })
            .collect()
    }
}
