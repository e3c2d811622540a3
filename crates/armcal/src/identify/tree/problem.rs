//! The least-squares problem of a tree ([`TreeProblem`]): every measurement row through its
//! target's branch, whitened, with the Jacobian over the tree's free parameters; what the
//! solvers see of a tree ([`crate::identify::solver::LeastSquares`]).

use crate::identify::problem::{jacobian_or_scratch, whiten};
use crate::identify::solver::LeastSquares;
use crate::measure::residual::{residual_rows, Prediction};
use crate::measure::{Dataset, MeasurementKind, NoiseModel};
use crate::model::jacobian::Rows;
use crate::model::tree::kinematics::{
    branch_kinematics, tree_identification_jacobian, tree_observed_pose, TreeData,
};
use crate::model::tree::Tree;
use crate::model::Observed;
use crate::Error;
use nalgebra::{DMatrix, DVector};

/// The least-squares problem of a tree: every measurement's whitened residual rows through
/// its target's branch, Jacobian columns over the tree's free parameters.
pub(crate) struct TreeProblem<'a> {
    pub(super) tree: &'a Tree,
    pub(super) data: &'a Dataset,
    /// Tree registry index of each estimated column.
    pub(super) free: Vec<usize>,
    sigmas: Vec<f64>,
    row_of: Vec<usize>,
    row_weights: Vec<f64>,
    /// Per configuration, its measurements.
    by_config: Vec<Vec<usize>>,
}

/// Buffers of one evaluation of a [`TreeProblem`].
pub(crate) struct TreeWorkspace {
    data: TreeData<f64>,
    prediction: Prediction,
    evaluated: Vec<bool>,
    block_r: [f64; 6],
}

impl<'a> TreeProblem<'a> {
    /// The problem of `data` on `tree` with the tree parameters `free` estimated; checks
    /// every row against the tree (a target of the tree, a position or pose of a frame,
    /// one value per tree joint) and takes each row's σ from `noise`.
    pub(crate) fn new(
        tree: &'a Tree,
        data: &'a Dataset,
        noise: &NoiseModel,
        free: Vec<usize>,
    ) -> Result<Self, Error> {
        let src = &data.source;
        if !data.stations.is_empty() {
            return Err(Error::Input(format!(
                "{src}: a tree is fitted from one instrument station for now; the data name \
                 stations ({})",
                data.stations.join(", ")
            )));
        }
        if data.carries_payloads() {
            return Err(Error::Input(format!(
                "{src}: a tree fit takes no payloads yet (a `payload` column)"
            )));
        }
        for (c, q) in data.configurations.iter().enumerate() {
            if q.len() != tree.dof() || q.iter().any(|x| !x.is_finite()) {
                return Err(Error::Input(format!(
                    "{src}: configuration `{}` has {} joint values or a non-finite one; tree \
                     `{}` has {} joints",
                    data.config_ids[c],
                    q.len(),
                    tree.name,
                    tree.dof()
                )));
            }
        }
        let mut sigmas = Vec::with_capacity(data.rows());
        let mut row_of = Vec::with_capacity(data.measurements.len());
        let mut by_config = vec![Vec::new(); data.configurations.len()];
        for (i, m) in data.measurements.iter().enumerate() {
            let line = m.line;
            let k = match m.observed {
                Observed::Target(k) if k < tree.targets.len() => k,
                _ => {
                    return Err(Error::Input(format!(
                        "{src}: line {line}: a row of a tree names the target it saw (a \
                         `target` column: {})",
                        tree.targets
                            .iter()
                            .map(|t| t.0.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    )))
                }
            };
            match &m.kind {
                MeasurementKind::Position { .. } => {}
                MeasurementKind::Pose { .. } => {
                    let (name, b, local) = &tree.targets[k];
                    if !tree.branches[*b].model.target_is_frame(*local) {
                        return Err(Error::Input(format!(
                            "{src}: line {line}: a pose measurement needs a frame target, \
                             `{name}` is a point"
                        )));
                    }
                }
                other => {
                    return Err(Error::Input(format!(
                        "{src}: line {line}: a tree is fitted from positions and poses for \
                         now, not from a {} measurement",
                        other.name()
                    )))
                }
            }
            by_config[m.config].push(i);
            row_of.push(sigmas.len());
            let s = noise.row_sigmas(m)?;
            sigmas.extend_from_slice(&s[..m.kind.rows()]);
        }
        let rows = sigmas.len();
        Ok(TreeProblem {
            tree,
            data,
            free,
            sigmas,
            row_of,
            row_weights: vec![1.0; rows],
            by_config,
        })
    }

    /// Names of the free parameters, in column order.
    pub(super) fn free_names(&self) -> Vec<String> {
        self.free
            .iter()
            .map(|&i| self.tree.registry.get(i).name.clone())
            .collect()
    }

    /// Calls `f(i, prediction, block)` for every measurement `i` with the prediction of its
    /// target (and, if asked, its Jacobian over the free columns), configuration by
    /// configuration, each branch measured there evaluated once.
    fn visit(
        &self,
        ws: &mut TreeWorkspace,
        params: &[f64],
        with_jacobian: bool,
        mut f: impl FnMut(usize, &Prediction, &mut [f64; 6]),
    ) {
        for (c, measurements) in self.by_config.iter().enumerate() {
            ws.evaluated.fill(false);
            let q = &self.data.configurations[c];
            for &i in measurements {
                let Observed::Target(t) = self.data.measurements[i].observed else {
                    unreachable!("checked by TreeProblem::new")
                };
                let b = self.tree.targets[t].1;
                if !ws.evaluated[b] {
                    branch_kinematics(self.tree, &mut ws.data, b, params, q);
                    ws.evaluated[b] = true;
                }
                ws.prediction.pose = tree_observed_pose(self.tree, &ws.data, t);
                if with_jacobian {
                    tree_identification_jacobian(
                        self.tree,
                        &mut ws.data,
                        t,
                        Rows::Pose,
                        &self.free,
                        &mut ws.prediction.jac,
                        0,
                    );
                }
                f(i, &ws.prediction, &mut ws.block_r);
            }
        }
    }

    /// Position error (mm) of every measurement at `params`, one entry per measurement.
    pub(super) fn position_errors(&self, params: &[f64]) -> Vec<f64> {
        let mut ws = self.workspace();
        let mut dummy = DMatrix::zeros(6, self.free.len());
        let mut errors = vec![0.0; self.data.measurements.len()];
        self.visit(&mut ws, params, false, |i, a, block_r| {
            residual_rows(
                &self.data.measurements[i].kind,
                a,
                None,
                block_r,
                &mut dummy,
                0,
            );
            errors[i] = (block_r[0].powi(2) + block_r[1].powi(2) + block_r[2].powi(2)).sqrt();
        });
        errors
    }
}

impl LeastSquares for TreeProblem<'_> {
    type Workspace = TreeWorkspace;

    fn workspace(&self) -> TreeWorkspace {
        TreeWorkspace {
            data: TreeData::new(self.tree),
            prediction: Prediction::new(self.free.len()),
            evaluated: vec![false; self.tree.branches.len()],
            block_r: [0.0; 6],
        }
    }

    fn rows(&self) -> usize {
        self.sigmas.len()
    }

    fn data_rows(&self) -> usize {
        self.sigmas.len()
    }

    fn columns(&self) -> usize {
        self.free.len()
    }

    fn evaluate(
        &self,
        ws: &mut TreeWorkspace,
        params: &[f64],
        r: &mut DVector<f64>,
        jac: Option<&mut DMatrix<f64>>,
    ) {
        let mut scratch = None;
        let (with_j, jac) = jacobian_or_scratch(jac, &mut scratch, self.free.len());
        self.visit(ws, params, with_j, |i, a, block_r| {
            let m = &self.data.measurements[i];
            let row = self.row_of[i];
            let jrow = if with_j { row } else { 0 };
            residual_rows(&m.kind, a, None, block_r, jac, jrow);
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
    }

    fn free_values(&self, params: &[f64]) -> DVector<f64> {
        DVector::from_iterator(self.free.len(), self.free.iter().map(|&i| params[i]))
    }

    fn set_free(&self, params: &mut [f64], x: &DVector<f64>) {
        for (k, &i) in self.free.iter().enumerate() {
            params[i] = x[k];
        }
    }

    fn row_of(&self) -> &[usize] {
        &self.row_of
    }

    fn dataset(&self) -> &Dataset {
        self.data
    }

    fn row_weights_mut(&mut self) -> &mut Vec<f64> {
        &mut self.row_weights
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::tree::TreeCell;
    use crate::model::identifiability::Measurement;
    use crate::sim::tree::simulate_tree;
    use crate::sim::Perturbation;

    /// The Jacobian of the stacked, whitened residual of both arms' rows (a coupled wrist
    /// joint, position rows of one arm and pose rows of the other) against central finite
    /// differences of the residual, at a point off the solution.
    #[test]
    fn the_stacked_tree_jacobian_matches_finite_differences() {
        let text = include_str!("../../../../../examples/dual-arm-tree-cell.toml")
            .replace(
                "joint_name = \"r_t\"\n",
                "joint_name = \"r_t\"\ncoupled = { r_r = -1, offset_deg = 10 }\n",
            )
            .replace(
                "name = \"smr_l\"\nlink = \"l6\"\nxyz_mm = [-20, 30, 80]",
                "name = \"smr_l\"\nlink = \"l6\"\nxyz_mm = [-20, 30, 80]\nrpy_deg = [10, -20, 30]",
            );
        let cell = TreeCell::from_toml(&text, "t.toml").unwrap();
        let tree = &cell.tree;
        let poses: Vec<(String, Vec<f64>)> = (0..6)
            .map(|i| {
                let q = (0..tree.dof())
                    .map(|j| 0.3 * ((i * 7 + j * 3) as f64).sin())
                    .collect();
                (format!("{i}"), q)
            })
            .collect();
        let right = simulate_tree(
            tree,
            Measurement::Position,
            Some(&cell.noise),
            &poses,
            &[0],
            &Perturbation::default(),
            1,
        )
        .unwrap();
        let left = simulate_tree(
            tree,
            Measurement::Pose,
            Some(&cell.noise),
            &poses,
            &[1],
            &Perturbation::default(),
            2,
        )
        .unwrap();
        let mut data = right.data;
        data.append(&left.data);
        assert!(data
            .measurements
            .iter()
            .any(|m| matches!(m.kind, MeasurementKind::Pose { .. })));
        let free = (0..tree.param_count()).collect();
        let problem = TreeProblem::new(tree, &data, &cell.noise, free).unwrap();
        let mut params = tree.nominal();
        for (i, p) in params.iter_mut().enumerate() {
            *p += 1e-3 * ((i as f64) * 1.3).cos();
        }
        let (_, j) = problem.residual_and_jacobian_at(&params);
        let h = 1e-6;
        let mut worst: f64 = 0.0;
        for c in 0..problem.columns() {
            let (mut up, mut down) = (params.clone(), params.clone());
            up[c] += h;
            down[c] -= h;
            let fd = (problem.residual_and_jacobian_at(&up).0
                - problem.residual_and_jacobian_at(&down).0)
                / (2.0 * h);
            for r in 0..problem.rows() {
                let scale = 1.0 + j[(r, c)].abs();
                worst = worst.max((fd[r] - j[(r, c)]).abs() / scale);
            }
        }
        assert!(worst < 1e-5, "worst relative difference {worst:e}");
    }
}
