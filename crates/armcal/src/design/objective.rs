//! The design objective φ(q₁…q_N) = φ(M₀ + Σ_i J_iᵀWJ_i) and its exact gradient w.r.t. all
//! N×k joint values: `∂φ/∂q_ij = 2 ⟨W^{1/2}J_i Φ, W^{1/2} ∂J_i/∂q_j⟩_F`, O(N·n_p²) with the
//! mixed derivatives of the foundation — no finite differences, no Hessian.

use crate::design::criteria::{evaluate, Criterion};
use crate::design::information::{DesignModel, InformationWorkspace};
use crate::Error;
use nalgebra::DMatrix;

/// A criterion on a design model, with the information of poses already measured.
pub struct DesignObjective<'a> {
    pub design: &'a DesignModel,
    pub criterion: Criterion,
    /// Whitened Jacobian rows of configurations already measured (design augmentation).
    pub prior_rows: DMatrix<f64>,
}

/// Buffers for [`DesignObjective::value_and_gradient`].
pub struct ObjectiveWorkspace {
    info: InformationWorkspace,
    jacs: Vec<DMatrix<f64>>,
    jacs_dq: Vec<Vec<DMatrix<f64>>>,
    /// `W^{1/2}J_i Φ` of one configuration.
    j_phi: DMatrix<f64>,
}

impl<'a> DesignObjective<'a> {
    pub fn new(design: &'a DesignModel, criterion: Criterion, measured: &[Vec<f64>]) -> Self {
        let mut ws = InformationWorkspace::new(design);
        let rows = design.rows();
        let mut prior_rows = DMatrix::zeros(rows * measured.len(), design.n());
        for (i, q) in measured.iter().enumerate() {
            design.jacobian(&mut ws, q);
            prior_rows.rows_mut(i * rows, rows).copy_from(&ws.jac);
        }
        DesignObjective {
            design,
            criterion,
            prior_rows,
        }
    }

    pub fn workspace(&self, n_configs: usize) -> ObjectiveWorkspace {
        let d = self.design;
        ObjectiveWorkspace {
            info: InformationWorkspace::new(d),
            jacs: vec![DMatrix::zeros(d.rows(), d.n()); n_configs],
            jacs_dq: vec![vec![DMatrix::zeros(d.rows(), d.n()); d.dof()]; n_configs],
            j_phi: DMatrix::zeros(d.rows(), d.n()),
        }
    }

    /// φ at the configurations `q` (N×k values, configuration after configuration) and, if
    /// asked, its gradient (same layout).
    pub fn value_and_gradient(
        &self,
        ws: &mut ObjectiveWorkspace,
        q: &[f64],
        gradient: Option<&mut [f64]>,
    ) -> Result<f64, Error> {
        let k = self.design.dof();
        let rows = self.design.rows();
        let nconf = q.len() / k;
        let np = self.prior_rows.nrows();
        let mut stacked = DMatrix::zeros(np + rows * nconf, self.design.n());
        stacked.rows_mut(0, np).copy_from(&self.prior_rows);
        for i in 0..nconf {
            let qi = &q[i * k..(i + 1) * k];
            if gradient.is_some() {
                self.design.jacobian_dq(&mut ws.info, qi);
                for (dst, src) in ws.jacs_dq[i].iter_mut().zip(&ws.info.jac_dq) {
                    dst.copy_from(src);
                }
            } else {
                self.design.jacobian(&mut ws.info, qi);
            }
            ws.jacs[i].copy_from(&ws.info.jac);
            stacked
                .rows_mut(np + rows * i, rows)
                .copy_from(&ws.info.jac);
        }
        let r = triangular_factor(stacked);
        let cv = evaluate(self.criterion, &r, self.design)?;
        if let Some(g) = gradient {
            for i in 0..nconf {
                ws.j_phi.gemm(1.0, &ws.jacs[i], &cv.gradient, 0.0);
                for j in 0..k {
                    g[i * k + j] = 2.0 * ws.j_phi.dot(&ws.jacs_dq[i][j]);
                }
            }
        }
        Ok(cv.value)
    }

    /// Information matrix of configurations (prior included).
    pub fn information(&self, q: &[Vec<f64>]) -> DMatrix<f64> {
        let mut ws = InformationWorkspace::new(self.design);
        self.prior_rows.tr_mul(&self.prior_rows) + self.design.information(&mut ws, q)
    }
}

/// `R` (n × n, upper triangular) with `RᵀR = AᵀA`, by Householder QR of `A` (rows ≥ n);
/// zero rows pad a short `A`.
pub fn triangular_factor(a: DMatrix<f64>) -> DMatrix<f64> {
    let n = a.ncols();
    let a = if a.nrows() < n {
        let mut p = DMatrix::zeros(n, n);
        p.rows_mut(0, a.nrows()).copy_from(&a);
        p
    } else {
        a
    };
    a.qr().r()
}
