//! The exchange's covariance bookkeeping: the design's `C = M⁻¹` seen through the pool,
//! kept up to date by rank updates as points are removed and added (see [`SweepState`]).

use crate::design::small_cholesky;
use nalgebra::DMatrix;

/// Smallest squared pivot of the Cholesky factor of `K = I − J_s C J_sᵀ` (of the order of
/// its least eigenvalue, 1 − the point's largest leverage) below which a design point counts
/// as essential: its removal leaves the information (nearly) singular, and a rank update
/// through `K⁻¹` would magnify rounding.
const ESSENTIAL_PIVOT: f64 = 1e-8;

/// The covariance of the current design as the exchange needs it, kept up to date by rank
/// updates (Woodbury) instead of a new inverse and a new `J_pool C` product for every slot:
/// `U = J_pool C`, `V = J_pool C Lᵀ` (A-type criteria), the diagonal blocks
/// `Q_x = J_x C J_xᵀ` of every pool point, and the removal in progress.
///
/// Removing point s: `C₋ = C + C J_sᵀ K⁻¹ J_s C`, `K = I − J_s C J_sᵀ`, so with
/// `W_x = J_x C J_sᵀ` (= `U_x J_sᵀ`) every candidate's `J_x C₋ J_xᵀ = Q_x + W_x K⁻¹ W_xᵀ` and
/// `J_x C₋ Lᵀ = V_x + W_x K⁻¹ V_s` cost O(rows² · (rows + columns of L)) each, and W costs
/// O(pool rows · rows · n) per slot, where a new `J_pool C₋` costs O(pool rows · n²). Adding
/// x: `C' = C₋ − C₋ J_xᵀ S⁻¹ J_x C₋`, `S = I + J_x C₋ J_xᵀ`.
///
/// Every pool-sized buffer has one row per pool row (column-major), so that the products
/// of a slot, W and the rank updates of U and V, run along whole columns of pool rows
/// (vectorised updates `y += a x`, no dot-product reductions).
pub(super) struct SweepState<'a> {
    rows: usize,
    /// `J` of the pool (pool rows × n).
    j: &'a DMatrix<f64>,
    /// `U` (pool rows × n), `V` (pool rows × columns of L).
    u: DMatrix<f64>,
    v: DMatrix<f64>,
    /// `Q_x`, rows × rows row-major per pool point.
    q: Vec<f64>,
    /// Of the rank update in progress, point p with `inv` = `K⁻¹` (a removal) or `S⁻¹` (an
    /// addition): `W = U J_pᵀ` (pool rows × rows), `W · inv`, `inv` (row-major),
    /// `U_pᵀ inv` (n × rows), `V_pᵀ inv` (columns of L × rows).
    w: DMatrix<f64>,
    wk: DMatrix<f64>,
    inv: Vec<f64>,
    us_k: DMatrix<f64>,
    vs_k: DMatrix<f64>,
    /// A candidate's S (row-major; its Cholesky factor in place) and a column of `V'_x`.
    s_buf: Vec<f64>,
    v_col: Vec<f64>,
}

impl<'a> SweepState<'a> {
    pub(super) fn new(jp: &'a DMatrix<f64>, rows: usize, l_rows: usize) -> Self {
        let (pool_rows, n) = jp.shape();
        SweepState {
            rows,
            j: jp,
            u: DMatrix::zeros(pool_rows, n),
            v: DMatrix::zeros(pool_rows, l_rows),
            q: vec![0.0; pool_rows * rows],
            w: DMatrix::zeros(pool_rows, rows),
            wk: DMatrix::zeros(pool_rows, rows),
            inv: vec![0.0; rows * rows],
            us_k: DMatrix::zeros(n, rows),
            vs_k: DMatrix::zeros(l_rows, rows),
            s_buf: vec![0.0; rows * rows],
            v_col: vec![0.0; rows],
        }
    }

    /// `C = M⁻¹` of the design `chosen` (prior included) and everything derived from it;
    /// false if M is singular.
    pub(super) fn refresh(
        &mut self,
        prior: &DMatrix<f64>,
        l: Option<&DMatrix<f64>>,
        chosen: &[usize],
    ) -> bool {
        let rows = self.rows;
        let mut m = prior.tr_mul(prior);
        for &i in chosen {
            let ji = self.j.rows(i * rows, rows);
            m.gemm_tr(1.0, &ji, &ji, 1.0);
        }
        let Some(ch) = m.cholesky() else {
            return false;
        };
        let c = ch.inverse();
        self.u.gemm(1.0, self.j, &c, 0.0);
        if let Some(l) = l {
            self.v.gemm(1.0, &self.u, &l.transpose(), 0.0);
        }
        self.q.fill(0.0);
        add_block_products(&mut self.q, rows, &self.u, self.j, 1.0);
        true
    }

    /// Starts the removal of pool point `s` from the design: `W`, `K⁻¹` and the products
    /// with it; false if the point is essential ([`ESSENTIAL_PIVOT`]).
    pub(super) fn remove(&mut self, s: usize) -> bool {
        // K = I − Q_s (symmetrised), factored in s_buf, its inverse into inv.
        let rows = self.rows;
        let q = &self.q[s * rows * rows..(s + 1) * rows * rows];
        for a in 0..rows {
            for b in 0..rows {
                let qab = 0.5 * (q[a * rows + b] + q[b * rows + a]);
                self.s_buf[a * rows + b] = if a == b { 1.0 } else { 0.0 } - qab;
            }
        }
        let l = &mut self.s_buf;
        if !small_cholesky::factor(l, rows)
            || (0..rows).any(|a| l[a * rows + a] * l[a * rows + a] < ESSENTIAL_PIVOT)
        {
            return false;
        }
        small_cholesky::inverse(l, &mut self.inv, rows);
        self.products_with(s);
        self.through_inverse(s);
        true
    }

    /// `W = U J_pᵀ` of pool point `p`: column b is `Σ_c U[:, c] J[p·rows + b, c]`.
    fn products_with(&mut self, p: usize) {
        let rows = self.rows;
        self.w.fill(0.0);
        add_rank_product(&mut self.w, &self.u, |b, c| self.j[(p * rows + b, c)]);
    }

    /// `W · inv`, `U_pᵀ inv` and `V_pᵀ inv` of pool point `p` (`inv` symmetric).
    fn through_inverse(&mut self, p: usize) {
        let rows = self.rows;
        self.wk.fill(0.0);
        add_rank_product(&mut self.wk, &self.w, |a, b| self.inv[b * rows + a]);
        for (m, out) in [(&self.u, &mut self.us_k), (&self.v, &mut self.vs_k)] {
            for b in 0..rows {
                for r in 0..m.ncols() {
                    out[(r, b)] = (0..rows)
                        .map(|a| m[(p * rows + a, r)] * self.inv[a * rows + b])
                        .sum();
                }
            }
        }
    }

    /// `S = I + J_x C₋ J_xᵀ = I + Q_x + W_x K⁻¹ W_xᵀ` of candidate `x` into `s_buf`
    /// (row-major) and its Cholesky factor in place; false if it is not positive definite.
    fn factor_s(&mut self, x: usize) -> bool {
        let rows = self.rows;
        let r0 = x * rows;
        for a in 0..rows {
            for b in 0..=a {
                let wkw: f64 = (0..rows)
                    .map(|c| self.wk[(r0 + a, c)] * self.w[(r0 + b, c)])
                    .sum();
                let sab = self.q[r0 * rows + a * rows + b] + wkw + if a == b { 1.0 } else { 0.0 };
                self.s_buf[a * rows + b] = sab;
                self.s_buf[b * rows + a] = sab;
            }
        }
        small_cholesky::factor(&mut self.s_buf, rows)
    }

    /// The score of adding candidate `x` to the design without the removed point (lower is
    /// better): `−tr(S⁻¹ V'_x V'_xᵀ) = −‖L_S⁻¹ V'_x‖²` for A-type criteria (the change of
    /// `tr(L C Lᵀ)`), `−log det S` otherwise (minus the change of log det M); `None` if S is
    /// not positive definite.
    pub(super) fn score(&mut self, x: usize, a_type: bool) -> Option<f64> {
        let rows = self.rows;
        let r0 = x * rows;
        if !self.factor_s(x) {
            return None;
        }
        if !a_type {
            return Some(
                -2.0 * (0..rows)
                    .map(|a| self.s_buf[a * rows + a].ln())
                    .sum::<f64>(),
            );
        }
        // Column c of V'_x = V_x + W_x (K⁻¹ V_s).
        let mut tr = 0.0;
        for c in 0..self.v.ncols() {
            for a in 0..rows {
                self.v_col[a] = self.v[(r0 + a, c)]
                    + (0..rows)
                        .map(|b| self.w[(r0 + a, b)] * self.vs_k[(c, b)])
                        .sum::<f64>();
            }
            small_cholesky::forward(&self.s_buf, &mut self.v_col, rows);
            tr += self.v_col.iter().map(|v| v * v).sum::<f64>();
        }
        Some(-tr)
    }

    /// Completes the exchange started by [`Self::remove`] by adding pool point `x`: U, V
    /// and the Q blocks by the removal's and the addition's rank updates. False (nothing
    /// changed) if `S` is not positive definite.
    pub(super) fn replace(&mut self, x: usize) -> bool {
        let rows = self.rows;
        // S = I + J_x C₋ J_xᵀ: its inverse now, before anything changes.
        if !self.factor_s(x) {
            return false;
        }
        small_cholesky::inverse(&self.s_buf, &mut self.inv, rows);
        // Removal: U₋ = U + W (K⁻¹ U_s), V₋ likewise, Q₋_x = Q_x + (W_x K⁻¹) W_xᵀ.
        add_rank_product(&mut self.u, &self.w, |c, b| self.us_k[(c, b)]);
        add_rank_product(&mut self.v, &self.w, |c, b| self.vs_k[(c, b)]);
        add_block_products(&mut self.q, rows, &self.wk, &self.w, 1.0);
        // Addition: Y = U₋ J_xᵀ (into w); U' = U₋ − Y (S⁻¹ U₋_x), V' likewise,
        // Q'_x = Q₋_x − (Y_x S⁻¹) Y_xᵀ.
        self.products_with(x);
        self.through_inverse(x);
        add_rank_product(&mut self.u, &self.w, |c, b| -self.us_k[(c, b)]);
        add_rank_product(&mut self.v, &self.w, |c, b| -self.vs_k[(c, b)]);
        add_block_products(&mut self.q, rows, &self.wk, &self.w, -1.0);
        true
    }
}

/// `Q_x[a][b] += sign · Σ_c a[x·rows + a, c] · b[x·rows + b, c]` for every pool point x
/// (rows × rows row-major blocks in `q`; `a` and `b` pool rows × the same columns).
fn add_block_products(q: &mut [f64], rows: usize, a: &DMatrix<f64>, b: &DMatrix<f64>, sign: f64) {
    for (ac, bc) in a.column_iter().zip(b.column_iter()) {
        let (ac, bc) = (ac.as_slice(), bc.as_slice());
        for ((qx, ax), bx) in q
            .chunks_exact_mut(rows * rows)
            .zip(ac.chunks_exact(rows))
            .zip(bc.chunks_exact(rows))
        {
            for (qa, ai) in qx.chunks_exact_mut(rows).zip(ax) {
                let f = sign * ai;
                qa.iter_mut().zip(bx).for_each(|(y, x)| *y += f * x);
            }
        }
    }
}

/// `m[:, c] += Σ_b k(c, b) · w[:, b]` for every column c of the pool-sized buffer `m` (`w`:
/// pool rows × r): W, `W · inv` and the rank updates of U and V, as column updates.
fn add_rank_product(m: &mut DMatrix<f64>, w: &DMatrix<f64>, k: impl Fn(usize, usize) -> f64) {
    let height = m.nrows();
    if height == 0 {
        return;
    }
    for (c, mc) in m.as_mut_slice().chunks_exact_mut(height).enumerate() {
        for (b, wb) in w.as_slice().chunks_exact(height).enumerate() {
            axpy(k(c, b), wb, mc);
        }
    }
}

/// `y += a x` over slices (the compiler vectorises it; nalgebra's `axpy` on a column view
/// goes through strides and does not).
fn axpy(a: f64, x: &[f64], y: &mut [f64]) {
    y.iter_mut().zip(x).for_each(|(y, x)| *y += a * x);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::Cell;
    use crate::design::criteria::{kpi_matrix, Criterion};
    use crate::design::exchange::{minimum_poses, pool_jacobians, value_of};
    use crate::design::DesignModel;
    use crate::model::random_configurations;

    fn paper_pool() -> (DesignModel, Vec<Vec<f64>>) {
        let cell = Cell::from_toml(
            crate::cell::builtin::PAPER_CELL,
            "paper-cell.toml",
            std::path::Path::new("."),
        )
        .unwrap();
        let d = DesignModel::from_cell(&cell).unwrap();
        let pool = random_configurations(&d.model, 80, 5);
        (d, pool)
    }

    fn max_difference(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
        let scale = b.amax().max(1e-300);
        (a - b).amax() / scale
    }

    /// Each candidate's score is the exact change of the criterion (KPI: `tr(L C Lᵀ)`; D:
    /// minus the change of log det M), and after a run of exchanges the rank-updated U, V
    /// and Q blocks agree with the ones formed anew.
    #[test]
    fn rank_updates_match_exact_evaluation() {
        let (d, pool) = paper_pool();
        let jp = pool_jacobians(&d, &pool);
        let l = kpi_matrix(&d).unwrap();
        let prior = DMatrix::zeros(0, d.n());
        let rows = d.rows();
        let mut chosen: Vec<usize> = (0..30).collect();
        let mut state = SweepState::new(&jp, rows, l.nrows());
        assert!(state.refresh(&prior, Some(&l), &chosen));
        let kpi = |set: &[usize]| value_of(&d, Criterion::Kpi, &jp, &prior, set).unwrap();
        let log_det = |set: &[usize]| {
            let mut m = DMatrix::zeros(d.n(), d.n());
            for &i in set {
                let ji = jp.rows(i * rows, rows);
                m.gemm_tr(1.0, &ji, &ji, 1.0);
            }
            m.cholesky()
                .unwrap()
                .l()
                .diagonal()
                .iter()
                .map(|x| 2.0 * x.ln())
                .sum::<f64>()
        };
        for (step, slot) in [3usize, 17, 0, 29, 11, 5].into_iter().enumerate() {
            let removed = chosen[slot];
            assert!(state.remove(removed));
            let mut others = chosen.clone();
            others.remove(slot);
            let x = 30 + 7 * step;
            let mut with_x = others.clone();
            with_x.push(x);
            // tr(L C Lᵀ) = 3 · KPI (kpi_matrix carries the 1/3).
            let exact = kpi(&with_x) - kpi(&others);
            let score = state.score(x, true).unwrap();
            assert!(
                (score - exact).abs() <= 1e-8 * exact.abs(),
                "KPI score {score} vs {exact}"
            );
            let exact_d = -(log_det(&with_x) - log_det(&others));
            let score_d = state.score(x, false).unwrap();
            assert!(
                (score_d - exact_d).abs() <= 1e-8 * exact_d.abs().max(1.0),
                "D score {score_d} vs {exact_d}"
            );
            assert!(state.replace(x));
            chosen[slot] = x;
        }
        let (u, v, q) = (state.u.clone(), state.v.clone(), state.q.clone());
        assert!(state.refresh(&prior, Some(&l), &chosen));
        assert!(
            max_difference(&u, &state.u) < 1e-9,
            "U drifted: {}",
            max_difference(&u, &state.u)
        );
        assert!(
            max_difference(&v, &state.v) < 1e-9,
            "V drifted: {}",
            max_difference(&v, &state.v)
        );
        let qmax = state.q.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for (a, b) in q.iter().zip(&state.q) {
            assert!((a - b).abs() < 1e-9 * qmax, "Q drifted: {a} vs {b}");
        }
    }

    /// A point whose removal leaves the information singular is essential: `remove` refuses it.
    #[test]
    fn an_essential_point_is_kept() {
        let (d, pool) = paper_pool();
        let jp = pool_jacobians(&d, &pool);
        let rows = d.rows();
        // The fewest poses: every one of them is needed.
        let needed = minimum_poses(&d, &DMatrix::zeros(0, d.n()));
        let chosen: Vec<usize> = (0..needed).collect();
        let prior = DMatrix::zeros(0, d.n());
        let mut state = SweepState::new(&jp, rows, 0);
        assert!(
            state.refresh(&prior, None, &chosen),
            "{needed} random poses identify the set"
        );
        assert!((0..needed).all(|s| !state.remove(chosen[s])));
        // One pose more: no single pose is essential any more.
        let chosen: Vec<usize> = (0..needed + 1).collect();
        assert!(state.refresh(&prior, None, &chosen));
        assert!((0..=needed).all(|s| state.remove(chosen[s])));
    }
}
