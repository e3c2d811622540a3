//! The identification least-squares problem (paper eqs. 5–6, book §4.3): the residual
//! vector of every measurement block, whitened by its σ, plus prior rows for parameters
//! with a prior, and the analytic Jacobian w.r.t. the free parameters.

use crate::measure::residual::{residual_rows, Prediction};
use crate::measure::{Dataset, MeasurementKind, NoiseModel};
use crate::model::prior::prior_rows;
use crate::model::{
    forward_kinematics, identification_jacobian, observed_pose, Data, Model, Observed, Rows,
};
use crate::Error;
use nalgebra::{DMatrix, DVector};

/// Data of an identification problem; immutable, shareable.
#[derive(Clone, Debug)]
pub struct Problem<'a> {
    /// The model whose parameters are identified.
    pub model: &'a Model,
    /// The measurements.
    pub data: &'a Dataset,
    /// Parameter index of each estimated column.
    pub free: Vec<usize>,
    /// Prior rows `W` over the free columns, appended after the data rows: the prior adds
    /// `W p_free − prior_offset` to the residual (`crate::model::prior`).
    pub prior_rows: DMatrix<f64>,
    /// `W μ` of the prior rows.
    pub prior_offset: DVector<f64>,
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
    /// Measurement indices grouped by configuration: those of configuration `c` are
    /// `by_config[config_start[c]..config_start[c + 1]]` (an evaluation visits each
    /// configuration once and keeps no per-configuration Jacobian).
    by_config: Vec<usize>,
    /// Offsets into `by_config`, one per configuration and one past the end.
    config_start: Vec<usize>,
    /// The payload each configuration carried, an index into the model's payloads.
    payloads: Vec<Option<usize>>,
}

/// Buffers for evaluating a [`Problem`]: their size does not depend on the number of
/// measurements.
pub struct Workspace {
    data: Data<f64>,
    /// Predictions of every slot at the configuration being visited.
    current: Vec<Prediction>,
    /// Kinematics and prediction at the other configuration of a distance measurement.
    other_data: Data<f64>,
    other: Prediction,
    block_r: [f64; 6],
}

impl<'a> Problem<'a> {
    /// Sets up the problem: free parameters from the model's registry statuses, σ of every
    /// row from the noise model. Checks the data against the model.
    pub fn new(model: &'a Model, data: &'a Dataset, noise: &NoiseModel) -> Result<Self, Error> {
        let free = model.registry.free();
        let stations: Vec<&str> = (0..model.stations.len())
            .filter_map(|s| model.station_name(s))
            .collect();
        if data.stations != stations {
            return Err(Error::Input(format!(
                "{}: the data's instrument stations ({}) are not those of model `{}` ({}); \
                 a model with the data's stations: `Model::with_stations`",
                data.source,
                data.stations.join(", "),
                model.name,
                stations.join(", ")
            )));
        }
        let payloads = data.model_payloads(model)?;
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
            let s = noise.row_sigmas(m)?;
            sigmas.extend_from_slice(&s[..m.kind.rows()]);
        }
        let (prior_rows, prior_offset) = prior_rows(&model.registry, &free)?;
        let rows = sigmas.len();
        let (by_config, config_start) = group_by_config(data);
        Ok(Problem {
            model,
            data,
            free,
            prior_rows,
            prior_offset,
            sigmas,
            row_of,
            slots,
            slot_of,
            row_weights: vec![1.0; rows],
            by_config,
            config_start,
            payloads,
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
        self.sigmas.len() + self.prior_rows.nrows()
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
            current: vec![Prediction::new(self.free.len()); self.slots.len()],
            other_data: Data::new(self.model),
            other: Prediction::new(self.free.len()),
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

    /// The prediction (pose and, if asked, 6 × n Jacobian) of slot `slot` at the current
    /// kinematics `data`.
    fn predict_slot(&self, data: &Data<f64>, slot: usize, p: &mut Prediction, with_jacobian: bool) {
        let obs = self.slots[slot];
        p.pose = observed_pose(data, obs);
        if with_jacobian {
            identification_jacobian(self.model, data, obs, Rows::Pose, &self.free, &mut p.jac, 0);
        }
    }

    /// Calls `f(i, a, b, block)` for every measurement `i` with the prediction `a` at its
    /// configuration and, for a distance between poses, `b` at the other one, and a
    /// residual buffer; configuration by configuration, each configuration's kinematics
    /// computed once.
    fn visit(
        &self,
        ws: &mut Workspace,
        params: &[f64],
        with_jacobian: bool,
        mut f: impl FnMut(usize, &Prediction, Option<&Prediction>, &mut [f64; 6]),
    ) {
        let Workspace {
            data,
            current,
            other_data,
            other,
            block_r,
        } = ws;
        for (c, q) in self.data.configurations.iter().enumerate() {
            let measurements = &self.by_config[self.config_start[c]..self.config_start[c + 1]];
            if measurements.is_empty() {
                continue;
            }
            data.station = self.data.station_of(c);
            data.payload = self.payloads[c];
            forward_kinematics(self.model, data, params, q);
            for (s, p) in current.iter_mut().enumerate() {
                self.predict_slot(data, s, p, with_jacobian);
            }
            for &i in measurements {
                let slot = self.slot_of[i];
                let b = match &self.data.measurements[i].kind {
                    MeasurementKind::Distance { other: o, .. } => {
                        let q = &self.data.configurations[*o];
                        other_data.station = self.data.station_of(*o);
                        other_data.payload = self.payloads[*o];
                        forward_kinematics(self.model, other_data, params, q);
                        self.predict_slot(other_data, slot, other, with_jacobian);
                        Some(&*other)
                    }
                    _ => None,
                };
                f(i, &current[slot], b, block_r);
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
        let mut scratch = None;
        let (with_j, jac) = jacobian_or_scratch(jac, &mut scratch, self.free.len());
        self.visit(ws, params, with_j, |i, a, b, block_r| {
            let m = &self.data.measurements[i];
            let row = self.row_of[i];
            let jrow = if with_j { row } else { 0 };
            residual_rows(&m.kind, a, b, block_r, jac, jrow);
            whiten(
                m.kind.rows(),
                block_r,
                row,
                (&self.row_weights, &self.sigmas),
                r,
                jac,
                with_j,
            );
        });
        let n = self.sigmas.len();
        for k in 0..self.prior_rows.nrows() {
            let w = self.prior_rows.row(k);
            r[n + k] = self
                .free
                .iter()
                .zip(w.iter())
                .map(|(&i, x)| x * params[i])
                .sum::<f64>()
                - self.prior_offset[k];
            if with_j {
                jac.row_mut(n + k).copy_from(&w);
            }
        }
    }

    /// Unwhitened position error (mm) of every position-bearing measurement at `params`
    /// (distances and planes: the scalar error). One entry per measurement.
    pub fn errors(&self, ws: &mut Workspace, params: &[f64]) -> Vec<f64> {
        let mut dummy = DMatrix::zeros(6, self.free.len());
        let mut errors = vec![0.0; self.data.measurements.len()];
        self.visit(ws, params, false, |i, a, b, block_r| {
            let m = &self.data.measurements[i];
            residual_rows(&m.kind, a, b, block_r, &mut dummy, 0);
            errors[i] = match m.kind.rows() {
                1 => block_r[0].abs(),
                _ => (block_r[0].powi(2) + block_r[1].powi(2) + block_r[2].powi(2)).sqrt(),
            };
        });
        errors
    }

    /// Orientation error (rad) of every pose measurement at `params`: the angle of the
    /// rotation `R_model R_measᵀ` between the predicted and the measured orientation, `‖φ‖`
    /// of its rotation vector `φ = log(R_model R_measᵀ)` (the residual's rotation rows);
    /// `None` for the measurements without an orientation. One entry per measurement.
    pub fn orientation_errors(&self, ws: &mut Workspace, params: &[f64]) -> Vec<Option<f64>> {
        let mut dummy = DMatrix::zeros(6, self.free.len());
        let mut errors = vec![None; self.data.measurements.len()];
        self.visit(ws, params, false, |i, a, b, block_r| {
            let m = &self.data.measurements[i];
            if let MeasurementKind::Pose { .. } = m.kind {
                residual_rows(&m.kind, a, b, block_r, &mut dummy, 0);
                let angle = (block_r[3].powi(2) + block_r[4].powi(2) + block_r[5].powi(2)).sqrt();
                errors[i] = Some(angle);
            }
        });
        errors
    }
}

/// The Jacobian an `evaluate` writes into: the caller's (`true`: rows at each measurement's
/// own row), or, for a residual alone, a 6 × `columns` scratch in `scratch` that every
/// measurement's block overwrites at row 0 (`false`: [`residual_rows`] writes its Jacobian
/// rows unconditionally, and nothing reads them).
pub(crate) fn jacobian_or_scratch<'a>(
    jac: Option<&'a mut DMatrix<f64>>,
    scratch: &'a mut Option<DMatrix<f64>>,
    columns: usize,
) -> (bool, &'a mut DMatrix<f64>) {
    match jac {
        Some(j) => (true, j),
        None => (false, scratch.insert(DMatrix::zeros(6, columns))),
    }
}

/// Writes the `rows` residual rows of one measurement (`block_r`, unwhitened) into `r` at
/// `row`, each times `√weight / σ` (`weights_sigmas`: every data row's), and scales the same
/// rows of `jac` (already written there by [`residual_rows`]) if `with_j`.
pub(crate) fn whiten(
    rows: usize,
    block_r: &[f64; 6],
    row: usize,
    (weights, sigmas): (&[f64], &[f64]),
    r: &mut DVector<f64>,
    jac: &mut DMatrix<f64>,
    with_j: bool,
) {
    for k in 0..rows {
        let w = weights[row + k].sqrt() / sigmas[row + k];
        r[row + k] = block_r[k] * w;
        if with_j {
            jac.row_mut(row + k).scale_mut(w);
        }
    }
}

/// Measurement indices grouped by configuration (a counting sort, measurement order kept
/// within a configuration) and the offsets of each configuration's group.
fn group_by_config(data: &Dataset) -> (Vec<usize>, Vec<usize>) {
    let mut start = vec![0usize; data.configurations.len() + 1];
    for m in &data.measurements {
        start[m.config + 1] += 1;
    }
    for c in 0..data.configurations.len() {
        start[c + 1] += start[c];
    }
    let mut next = start.clone();
    let mut by_config = vec![0; data.measurements.len()];
    for (i, m) in data.measurements.iter().enumerate() {
        by_config[next[m.config]] = i;
        next[m.config] += 1;
    }
    (by_config, start)
}
