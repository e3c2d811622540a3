//! The book's optimal (linear-quadratic) accuracy compensator (book §5.3, Zhuang et al.).
//!
//! The joint corrections `u_k = Δq_{c,k}` are applied one joint at a time, as the stages of
//! the first-order discrete-time system (book eq. 5.82 / 5.120)
//! `x_{k+1} = x_k + b_k u_k`, `x_1 = x_c`, k = 1, …, N,
//! where `x` is the linearised task error (the 12-vector of `[n; o; a; p]` deviations of the
//! redundant model, book eq. 5.117, or the 6-vector `[d; δ]` of the reduced-order model,
//! eq. 5.148) and `b_k` the k-th column of the error model's joint Jacobian. The corrections
//! minimise (book eq. 5.83 / 5.123)
//! `J(u) = x_{N+1}ᵀ Q x_{N+1} + Σ_k γ_k u_k²`
//! with Q symmetric nonnegative definite and every γ_k > 0. [`optimal_compensation`]
//! solves it by the backward Riccati recursion of eqs. 5.85–5.87, with the book's own
//! errata applied (eq. 5.126 must read `P_{k+1} = P_k + P_k b_{N−k} k_{N−k}ᵀ` as in 5.86,
//! and the denominator of 5.105 is `b_{N−k}ᵀ P_k b_{N−k} + γ_{N−k}`, as in 5.85).
//!
//! The result equals the batch damped least-squares solution
//! `u = −(BᵀQB + Γ)⁻¹ BᵀQ x_c`, Γ = diag(γ_k), which is what `compensate::ik` uses.
//!
//! The weighting of the redundant 12-vector and of the reduced 6-vector are related by
//! [`reduced_order_weight`] (book eqs. 5.161–5.170): with the relative weights of
//! eq. 5.135, `Q_x = diag(k1 ×9, k2/‖p‖² ×3)`, the reduced model minimises the same cost
//! with `Q_y = diag(k2/‖p‖² ×3, 2 k1 ×3)` ([`relative_weights`]).

use crate::error::{Error, Result};
use nalgebra::{DMatrix, DVector, Matrix3, Matrix6, SMatrix};

/// Result of [`optimal_compensation`].
#[derive(Clone, Debug)]
pub struct LqrResult {
    /// The optimal controls `u_1*, …, u_N*` (the joint corrections, book eq. 5.119).
    pub controls: DVector<f64>,
    /// The feedback gains: row k is `k_kᵀ` (book eq. 5.85), so that `u_k* = k_kᵀ x_k`
    /// (eq. 5.84) along the optimal trajectory.
    pub gains: DMatrix<f64>,
    /// `P_N` of the recursion (book eq. 5.86).
    pub p_final: DMatrix<f64>,
    /// The minimum cost `J* = x_1ᵀ P_N x_1` (book eq. 5.88).
    pub cost: f64,
    /// The terminal error `x_{N+1}` reached with the optimal controls (eq. 5.82).
    pub terminal_error: DVector<f64>,
}

/// The N-stage optimal compensator (book eqs. 5.82–5.88): minimises
/// `x_{N+1}ᵀ Q x_{N+1} + Σ γ_k u_k²` subject to `x_{k+1} = x_k + b_k u_k`, `x_1 = x_c`,
/// where `b_k` is column k of `b` (n × N), `q` is the n × n terminal weight and `gammas`
/// the N control weights.
///
/// Backward recursion, k = 0, …, N − 1 (book eqs. 5.85–5.87):
/// `k_{N−k}ᵀ = −b_{N−k}ᵀ P_k / (b_{N−k}ᵀ P_k b_{N−k} + γ_{N−k})`,
/// `P_{k+1} = P_k + P_k b_{N−k} k_{N−k}ᵀ`, `P_0 = Q`;
/// then forward `u_k = k_kᵀ x_k` (eq. 5.84) and `J* = x_1ᵀ P_N x_1` (eq. 5.88).
///
/// Errors: inconsistent dimensions, non-finite entries, an asymmetric Q, or a γ_k that is
/// not strictly positive (the book's condition that keeps every u_k finite, §5.3.1).
pub fn optimal_compensation(
    b: &DMatrix<f64>,
    q: &DMatrix<f64>,
    gammas: &[f64],
    x_c: &DVector<f64>,
) -> Result<LqrResult> {
    let (n, stages) = b.shape();
    if q.shape() != (n, n) {
        return Err(Error::Input(format!(
            "optimal compensator: Q is {}×{}, the state has {n} rows (B is {n}×{stages})",
            q.nrows(),
            q.ncols()
        )));
    }
    if x_c.len() != n {
        return Err(Error::Input(format!(
            "optimal compensator: x_c has {} entries, B has {n} rows",
            x_c.len()
        )));
    }
    if gammas.len() != stages {
        return Err(Error::Input(format!(
            "optimal compensator: {} control weights γ for {stages} stages (columns of B)",
            gammas.len()
        )));
    }
    if let Some(k) = gammas.iter().position(|g| !(g.is_finite() && *g > 0.0)) {
        return Err(Error::Input(format!(
            "optimal compensator: γ_{} = {} must be finite and strictly positive (book §5.3.1)",
            k + 1,
            gammas[k]
        )));
    }
    if b.iter()
        .chain(q.iter())
        .chain(x_c.iter())
        .any(|v| !v.is_finite())
    {
        return Err(Error::Input(
            "optimal compensator: B, Q or x_c has a non-finite entry".to_string(),
        ));
    }
    let scale = q.amax().max(f64::MIN_POSITIVE);
    for i in 0..n {
        for j in 0..i {
            if (q[(i, j)] - q[(j, i)]).abs() > 1e-12 * scale {
                return Err(Error::Input(format!(
                    "optimal compensator: Q is not symmetric (Q[{i},{j}] = {}, Q[{j},{i}] = {})",
                    q[(i, j)],
                    q[(j, i)]
                )));
            }
        }
    }

    // Backward recursion (eqs. 5.85–5.87). `p` is P_k; `pb` = P_k b_{N−k}; `gain` = k_{N−k}.
    let mut p = q.clone();
    let mut gains = DMatrix::zeros(stages, n);
    let mut pb = DVector::zeros(n);
    let mut gain = DVector::zeros(n);
    for k in 0..stages {
        let stage = stages - 1 - k; // 0-based index of stage N − k
        let bk = b.column(stage);
        pb.gemv(1.0, &p, &bk, 0.0);
        let denominator = bk.dot(&pb) + gammas[stage];
        // b_{N−k}ᵀ P_k = (P_k b_{N−k})ᵀ since P_k is symmetric.
        gain.copy_from(&pb);
        gain.scale_mut(-1.0 / denominator);
        gains.row_mut(stage).copy_from(&gain.transpose());
        // Eq. 5.86: P_{k+1} = P_k + (P_k b_{N−k}) k_{N−k}ᵀ.
        p.ger(1.0, &pb, &gain, 1.0);
    }

    // Forward pass: u_k = k_kᵀ x_k, x_{k+1} = x_k + b_k u_k (eqs. 5.84, 5.82).
    let mut x = x_c.clone();
    let mut controls = DVector::zeros(stages);
    for k in 0..stages {
        let u = gains.row(k).transpose().dot(&x);
        controls[k] = u;
        x.axpy(u, &b.column(k), 1.0);
    }
    pb.gemv(1.0, &p, x_c, 0.0);
    let cost = x_c.dot(&pb);
    Ok(LqrResult {
        controls,
        gains,
        p_final: p,
        cost,
        terminal_error: x,
    })
}

/// Multiplications and additions of one compensation (book §5.3.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OperationCount {
    /// Number of multiplications M.
    pub multiplications: usize,
    /// Number of additions A.
    pub additions: usize,
}

/// Operation count `T_op` of the compensator for an n-dimensional state and N stages
/// (joints), given B and x_c, without computing J* (book §5.3.4):
///
/// * full Q (eq. 5.172):
///   `(N − 1)[2n(n + 1)(M + A) + n²A] + n(n + 1)(M + A) + n²A + 2Nn(M + A)`;
/// * diagonal Q (eq. 5.173):
///   `(N − 2)[2n(n + 1)(M + A) + n²A] + n(n + 5)(M + A) + n²A + 2Nn(M + A)`.
///
/// The formulas are the book's as printed; they are meant for N ≥ 2 (eq. 5.173 counts the
/// first and last stages separately), so N < 2 with a diagonal Q is an error, as is N = 0.
pub fn operation_count(n: usize, stages: usize, diagonal_q: bool) -> Result<OperationCount> {
    let minimum = if diagonal_q { 2 } else { 1 };
    if stages < minimum {
        return Err(Error::Input(format!(
            "operation count: {stages} stages; book eq. {} needs N ≥ {minimum}",
            if diagonal_q { "5.173" } else { "5.172" }
        )));
    }
    let per_stage = 2 * n * (n + 1); // the (M + A) of one k_{N−k} and one P_k update
    let square = n * n; // the extra additions of one P_k update
    let (repeated, first) = if diagonal_q {
        (stages - 2, n * (n + 5))
    } else {
        (stages - 1, n * (n + 1))
    };
    let both = repeated * per_stage + first + 2 * stages * n;
    Ok(OperationCount {
        multiplications: both,
        additions: both + repeated * square + square,
    })
}

/// The linear map `x = M y` from the reduced-order error `y = [d; δ]` (translation and
/// rotation of the differential transform `δT_N`, tool frame, book eq. 5.143) to the
/// redundant 12-vector `x = [dn; do; da; dp]` of `dT_N = T_N δT_N` (eq. 5.142), with
/// `rot = [n o a]` (eq. 5.109). Row by row this is the book's list after eq. 5.171:
/// `dn = o δz − a δy`, `do = a δx − n δz`, `da = n δy − o δx`, `dp = n dx + o dy + a dz`.
pub fn pose_error_map(rot: &Matrix3<f64>) -> SMatrix<f64, 12, 6> {
    let (n, o, a) = (rot.column(0), rot.column(1), rot.column(2));
    let mut m = SMatrix::<f64, 12, 6>::zeros();
    for i in 0..3 {
        // dn (rows 0–2): δy (col 4), δz (col 5)
        m[(i, 4)] = -a[i];
        m[(i, 5)] = o[i];
        // do (rows 3–5): δx, δz
        m[(3 + i, 3)] = a[i];
        m[(3 + i, 5)] = -n[i];
        // da (rows 6–8): δx, δy
        m[(6 + i, 3)] = -o[i];
        m[(6 + i, 4)] = n[i];
        // dp (rows 9–11): dx, dy, dz
        m[(9 + i, 0)] = n[i];
        m[(9 + i, 1)] = o[i];
        m[(9 + i, 2)] = a[i];
    }
    m
}

/// The reduced-order weight `Q_y` with `yᵀ Q_y y = xᵀ Q_x x` for `x = M y`
/// ([`pose_error_map`]) and a diagonal `Q_x = diag(q_x)` (book proposition, eqs. 5.161–5.168):
/// `Q_y = [[Qᵘ, 0], [0, Qˡ]]` with `Qᵘ_ij = c_iᵀ Q_{10–12} c_j` for `c = (n, o, a)` (eq. 5.163)
/// and `Qˡ` (eq. 5.164) with off-diagonal entries `−nᵀQ_{7–9}o`, `−nᵀQ_{4–6}a`,
/// `−oᵀQ_{1–3}a` as printed. The diagonal of `Qˡ` is computed from the book's own
/// x–y relations: `aᵀQ_{4–6}a + oᵀQ_{7–9}o`, `aᵀQ_{1–3}a + nᵀQ_{7–9}n`,
/// `oᵀQ_{1–3}o + nᵀQ_{4–6}n`; the book prints the vectors of each pair swapped
/// (e.g. `oᵀQ_{4–6}o + aᵀQ_{7–9}a`), which differs unless each 3×3 block of Q_x is a
/// multiple of the identity (as in eq. 5.169, where both give 5.170).
pub fn reduced_order_weight(rot: &Matrix3<f64>, q_x: &[f64; 12]) -> Matrix6<f64> {
    let (n, o, a) = (rot.column(0), rot.column(1), rot.column(2));
    // uᵀ Q_{block b} v with Q_{block b} = diag(q_x[3b..3b+3]).
    let form = |block: usize, u: &nalgebra::VectorView3<f64>, v: &nalgebra::VectorView3<f64>| {
        (0..3)
            .map(|i| u[i] * q_x[3 * block + i] * v[i])
            .sum::<f64>()
    };
    let c = [&n, &o, &a];
    let mut q = Matrix6::zeros();
    for i in 0..3 {
        for j in 0..3 {
            q[(i, j)] = form(3, c[i], c[j]);
        }
    }
    q[(3, 3)] = form(1, &a, &a) + form(2, &o, &o);
    q[(4, 4)] = form(0, &a, &a) + form(2, &n, &n);
    q[(5, 5)] = form(0, &o, &o) + form(1, &n, &n);
    q[(3, 4)] = -form(2, &n, &o);
    q[(3, 5)] = -form(1, &n, &a);
    q[(4, 5)] = -form(0, &o, &a);
    q[(4, 3)] = q[(3, 4)];
    q[(5, 3)] = q[(3, 5)];
    q[(5, 4)] = q[(4, 5)];
    q
}

/// The book's relative weighting (eqs. 5.135 and 5.170) for accuracy weights `k1`
/// (orientation) and `k2` (position) at a task point whose position has norm `p_norm`:
/// `Q_x = diag(k1 ×9, k2/‖p‖² ×3)` for the redundant 12-vector and the equivalent
/// `Q_y = diag(k2/‖p‖² ×3, 2 k1 ×3)` for the reduced 6-vector.
pub fn relative_weights(k1: f64, k2: f64, p_norm: f64) -> ([f64; 12], [f64; 6]) {
    let position = k2 / (p_norm * p_norm);
    let mut q_x = [k1; 12];
    q_x[9..].fill(position);
    let q_y = [position, position, position, 2.0 * k1, 2.0 * k1, 2.0 * k1];
    (q_x, q_y)
}
