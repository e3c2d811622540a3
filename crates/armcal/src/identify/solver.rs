//! What every identification solver reports ([`SolverResult`], with the shared
//! [`crate::solve::Status`]) and the stopping rules they share.

use crate::solve::Status;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use std::time::Duration;

/// Result of a solver run.
#[derive(Clone, Debug)]
pub struct SolverResult {
    /// Full parameter vector at the end.
    pub params: Vec<f64>,
    /// How the solver ended.
    pub status: Status,
    /// Iterations done.
    pub iterations: usize,
    /// Cost ½‖r‖² after each iteration (index 0: the start).
    pub history: Vec<f64>,
    /// Wall-clock time of the run.
    pub time: Duration,
    /// Whitened residual at the solution (data rows, then prior rows).
    pub residual: DVector<f64>,
    /// Whitened Jacobian at the solution, one column per free parameter.
    pub jacobian: DMatrix<f64>,
}

impl SolverResult {
    /// Cost ½‖r‖² of the whitened residual at the solution.
    pub fn cost(&self) -> f64 {
        0.5 * self.residual.norm_squared()
    }

    /// The same solution in the equivalent parameters `branch` (identical forward
    /// kinematics, so the same residual). The map has the diagonal Jacobian `S = diag(±1)`,
    /// so the Jacobian becomes `J S` (the columns of negated parameters change sign) and the
    /// covariance `(S JᵀJ S)⁻¹ = S C_p S`. `free`: the parameter of each column.
    pub fn in_branch(
        mut self,
        branch: &crate::model::branch::NearestBranch,
        free: &[usize],
    ) -> SolverResult {
        for (c, &i) in free.iter().enumerate() {
            if branch.signs[i] < 0.0 {
                self.jacobian.column_mut(c).neg_mut();
            }
        }
        self.params.clone_from(&branch.params);
        self
    }
}

/// Stopping rules shared by the iterative solvers.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ToleranceSettings {
    /// Largest number of iterations.
    pub max_iterations: usize,
    /// Relative reduction of the cost (actual and predicted) below which to stop.
    pub ftol: f64,
    /// Relative step (in Marquardt-scaled variables) below which to stop.
    pub xtol: f64,
    /// Largest cosine between the residual and a Jacobian column (MINPACK's gtol).
    pub gtol: f64,
    /// Levenberg–Marquardt also stops when what remains of the way to the minimum moves no
    /// parameter by more than this fraction of its standard deviation σᵢ (the Gauss–Newton
    /// step's `‖Jδ‖` in the whitened residual, corrected for the observed contraction;
    /// [`super::levenberg_marquardt`]).
    #[serde(default = "default_sigma_step")]
    pub sigma_step: f64,
}

fn default_sigma_step() -> f64 {
    1e-4
}

impl Default for ToleranceSettings {
    fn default() -> Self {
        ToleranceSettings {
            max_iterations: 200,
            ftol: 1e-14,
            xtol: 1e-12,
            gtol: 1e-12,
            sigma_step: default_sigma_step(),
        }
    }
}

/// MINPACK's gradient test: max over columns of |Jᵢᵀ r| / (‖Jᵢ‖ ‖r‖).
pub(crate) fn gradient_cosine(j: &DMatrix<f64>, r: &DVector<f64>) -> f64 {
    let rn = r.norm();
    if rn == 0.0 {
        return 0.0;
    }
    (0..j.ncols())
        .map(|c| {
            let col = j.column(c);
            let n = col.norm();
            if n == 0.0 {
                0.0
            } else {
                (col.dot(r) / (n * rn)).abs()
            }
        })
        .fold(0.0, f64::max)
}

/// The status of a solver that found no trial step lowering the cost: converged to machine
/// precision if the residual is orthogonal to every Jacobian column to six digits (gradient
/// cosine < 10⁻⁶), else `Diverged` with `reason` — a step that lowers nothing is never
/// convergence by itself.
pub(crate) fn no_decrease_status<W>(it: &Iterate<W>, reason: String) -> Status {
    if gradient_cosine(&it.j, &it.r) < 1e-6 {
        Status::Converged {
            criterion: "no further decrease possible (at machine precision)".into(),
        }
    } else {
        Status::Diverged { reason }
    }
}

/// A whitened least-squares problem as the solvers see it: a serial chain's
/// [`super::Problem`] or a kinematic tree's ([`super::tree`]). The solvers are generic over
/// it, so a tree is fitted by the same Levenberg–Marquardt, Gauss–Newton and IRLS code as a
/// serial chain (monomorphised: the serial path is unchanged).
pub(crate) trait LeastSquares {
    /// Buffers of one evaluation.
    type Workspace;
    /// Buffers for evaluating this problem.
    fn workspace(&self) -> Self::Workspace;
    /// Rows of the whitened residual (data rows, then prior rows).
    fn rows(&self) -> usize;
    /// Data rows (without priors).
    fn data_rows(&self) -> usize;
    /// Columns of the Jacobian: the free parameters.
    fn columns(&self) -> usize;
    /// Whitened residual and, if asked, its Jacobian at the full parameter vector `params`.
    fn evaluate(
        &self,
        ws: &mut Self::Workspace,
        params: &[f64],
        r: &mut DVector<f64>,
        jac: Option<&mut DMatrix<f64>>,
    );
    /// Values of the free parameters in a full parameter vector.
    fn free_values(&self, params: &[f64]) -> DVector<f64>;
    /// Writes free values into a full parameter vector.
    fn set_free(&self, params: &mut [f64], x: &DVector<f64>);
    /// The first row of each measurement.
    fn row_of(&self) -> &[usize];
    /// The data fitted (for the outliers a robust fit names).
    fn dataset(&self) -> &crate::measure::Dataset;
    /// The measurements: each one's first row and number of rows, in measurement order.
    fn blocks(&self) -> Vec<(usize, usize)> {
        self.row_of()
            .iter()
            .zip(&self.dataset().measurements)
            .map(|(&row, m)| (row, m.kind.rows()))
            .collect()
    }
    /// Per-row weight multipliers (robust estimation).
    fn row_weights_mut(&mut self) -> &mut Vec<f64>;
    /// Whitened residual and Jacobian at `params` (allocating; for one-off evaluations).
    fn residual_and_jacobian_at(&self, params: &[f64]) -> (DVector<f64>, DMatrix<f64>) {
        let mut ws = self.workspace();
        let mut r = DVector::zeros(self.rows());
        let mut j = DMatrix::zeros(self.rows(), self.columns());
        self.evaluate(&mut ws, params, &mut r, Some(&mut j));
        (r, j)
    }
}

impl LeastSquares for super::Problem<'_> {
    type Workspace = super::problem::Workspace;
    fn workspace(&self) -> Self::Workspace {
        super::Problem::workspace(self)
    }
    fn rows(&self) -> usize {
        super::Problem::rows(self)
    }
    fn data_rows(&self) -> usize {
        super::Problem::data_rows(self)
    }
    fn columns(&self) -> usize {
        super::Problem::columns(self)
    }
    fn evaluate(
        &self,
        ws: &mut Self::Workspace,
        params: &[f64],
        r: &mut DVector<f64>,
        jac: Option<&mut DMatrix<f64>>,
    ) {
        super::Problem::evaluate(self, ws, params, r, jac)
    }
    fn free_values(&self, params: &[f64]) -> DVector<f64> {
        super::Problem::free_values(self, params)
    }
    fn set_free(&self, params: &mut [f64], x: &DVector<f64>) {
        super::Problem::set_free(self, params, x)
    }
    fn row_of(&self) -> &[usize] {
        &self.row_of
    }
    fn dataset(&self) -> &crate::measure::Dataset {
        self.data
    }
    fn row_weights_mut(&mut self) -> &mut Vec<f64> {
        &mut self.row_weights
    }
}

/// The state every iterative solver carries: workspace, full parameter vector, whitened
/// residual and Jacobian at those parameters.
pub(crate) struct Iterate<W> {
    pub ws: W,
    pub params: Vec<f64>,
    pub r: DVector<f64>,
    pub j: DMatrix<f64>,
}

impl<W> Iterate<W> {
    /// Evaluates the problem at `start`; a non-finite residual is an error.
    pub fn start<P: LeastSquares<Workspace = W>>(
        problem: &P,
        start: &[f64],
    ) -> Result<Iterate<W>, crate::Error> {
        let mut it = Iterate {
            ws: problem.workspace(),
            params: start.to_vec(),
            r: DVector::zeros(problem.rows()),
            j: DMatrix::zeros(problem.rows(), problem.columns()),
        };
        it.update(problem);
        if !it.cost().is_finite() {
            return Err(crate::Error::Numerical(
                "the residual at the starting parameters is not finite".into(),
            ));
        }
        Ok(it)
    }

    /// Re-evaluates residual and Jacobian at `self.params`.
    pub fn update<P: LeastSquares<Workspace = W>>(&mut self, problem: &P) {
        problem.evaluate(&mut self.ws, &self.params, &mut self.r, Some(&mut self.j));
    }

    /// ½‖r‖².
    pub fn cost(&self) -> f64 {
        0.5 * self.r.norm_squared()
    }

    pub fn into_solution(
        self,
        status: Status,
        iterations: usize,
        history: Vec<f64>,
        t0: std::time::Instant,
    ) -> SolverResult {
        SolverResult {
            params: self.params,
            status,
            iterations,
            history,
            time: t0.elapsed(),
            residual: self.r,
            jacobian: self.j,
        }
    }
}
