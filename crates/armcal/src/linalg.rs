//! The triangular factor of a tall matrix, built by blocks of rows (sequential QR,
//! Golub & Van Loan §5.2): for `A` (m × n) with `A = QR`, the n × n upper-triangular `R`
//! has `AᵀA = RᵀR`, the singular values of `A` (with `n − m` zeros when m < n), the same
//! column norms, inner products between columns and least-squares solutions. Analyses of a
//! Jacobian with hundreds of thousands of rows (rank, singular values, a greedy column
//! selection) run on `R`, in memory and time independent of m after one pass over the rows.
//!
//! Each block `[R; rows]` is reduced by Householder QR, which is backward stable column by
//! column, so columns of very different scale (mm and rad) keep their relative accuracy.
//!
//! Beside it, two small kernels more than one module needs: the scaling of an information
//! matrix to unit diagonal, and a vectorisable inner product.

use nalgebra::{DMatrix, DMatrixView};

/// Rows gathered before a reduction, per column of the matrix.
const ROWS_PER_COLUMN: usize = 8;

/// Accumulates the rows of a tall matrix into its triangular factor.
pub struct RowCompressor {
    /// The current `R` (first `n` rows) and the rows gathered since the last reduction.
    buffer: DMatrix<f64>,
    /// Rows of `buffer` in use (at least `n`: the `R` block).
    filled: usize,
    /// Rows added in total.
    rows: usize,
}

impl RowCompressor {
    /// A compressor for rows of `n` columns.
    pub fn new(n: usize) -> Self {
        RowCompressor {
            buffer: DMatrix::zeros(n + ROWS_PER_COLUMN * n.max(1), n),
            filled: n,
            rows: 0,
        }
    }

    /// Adds the rows of `block` (with the compressor's number of columns).
    pub fn add_rows(&mut self, block: DMatrixView<f64>) {
        let n = self.buffer.ncols();
        debug_assert_eq!(block.ncols(), n);
        let mut done = 0;
        while done < block.nrows() {
            if self.filled == self.buffer.nrows() {
                self.reduce();
            }
            let take = (self.buffer.nrows() - self.filled).min(block.nrows() - done);
            self.buffer
                .view_mut((self.filled, 0), (take, n))
                .copy_from(&block.rows(done, take));
            self.filled += take;
            done += take;
        }
        self.rows += block.nrows();
    }

    /// Reduces the gathered rows into the `R` block.
    fn reduce(&mut self) {
        let n = self.buffer.ncols();
        if self.filled == n || n == 0 {
            return;
        }
        let r = self.buffer.rows(0, self.filled).into_owned().qr().r();
        self.buffer.fill(0.0);
        self.buffer.view_mut((0, 0), (n, n)).copy_from(&r);
        self.filled = n;
    }

    /// Rows added in total (the m of `A`).
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// The n × n upper-triangular factor `R` with `AᵀA = RᵀR`.
    pub fn finish(mut self) -> DMatrix<f64> {
        self.reduce();
        let n = self.buffer.ncols();
        self.buffer.rows(0, n).into_owned()
    }
}

/// Rows per block of [`gram`].
const GRAM_BLOCK: usize = 512;

/// `Σ aᵢ bᵢ` over the common length, in four interleaved sums that the compiler turns into
/// vector instructions (a single running sum is one long dependency chain: the planner's
/// exchange computes millions of these 27-term products, about 3× faster this way). It takes
/// plain slices (columns of column-major buffers), where nalgebra's `dot` needs a matrix view
/// built around each.
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut acc = [0.0; 4];
    let (ac, bc) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = ac
        .remainder()
        .iter()
        .zip(bc.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in ac.zip(bc) {
        for k in 0..4 {
            acc[k] += x[k] * y[k];
        }
    }
    (acc[0] + acc[2]) + (acc[1] + acc[3]) + tail
}

/// `AᵀA`, accumulated over blocks of rows so that each block's columns stay in cache (the
/// columns of a 10⁶-row Jacobian are 24 MB each; entry-by-entry dot products would stream
/// them from memory n² times).
pub fn gram(a: DMatrixView<f64>) -> DMatrix<f64> {
    let n = a.ncols();
    let mut g = DMatrix::zeros(n, n);
    let mut start = 0;
    while start < a.nrows() {
        let k = GRAM_BLOCK.min(a.nrows() - start);
        let b = a.rows(start, k);
        g.gemm_tr(1.0, &b, &b, 1.0);
        start += k;
    }
    g
}

/// The triangular factor of `a` ([`RowCompressor`]), without copying `a`.
pub fn r_factor(a: DMatrixView<f64>) -> DMatrix<f64> {
    let mut c = RowCompressor::new(a.ncols());
    c.add_rows(a);
    c.finish()
}

/// The singular values of `a` from its factor `r` (n × n) and its row count `m`: those of
/// `r`, descending, the `n − m` structural zeros of a wide `a` left out.
pub fn singular_values_of_factor(r: &DMatrix<f64>, m: usize) -> Vec<f64> {
    if r.ncols() == 0 {
        return Vec::new();
    }
    let mut s: Vec<f64> = r
        .clone()
        .svd(false, false)
        .singular_values
        .iter()
        .copied()
        .collect();
    s.sort_by(|a, b| b.total_cmp(a));
    s.truncate(m.min(r.ncols()));
    s
}

/// `D⁻¹ M D⁻¹` with `D = diag(√M_ii)`: a symmetric positive semi-definite `M` (an
/// information matrix) scaled to unit diagonal, so that a test of its conditioning does not
/// depend on the parameters' units; with the scales `√M_ii`. `Err(i)`: the first `i` with
/// `M_ii ≤ 0` (or not a number), a parameter without effect.
pub fn unit_diagonal(m: &DMatrix<f64>) -> Result<(DMatrix<f64>, Vec<f64>), usize> {
    let n = m.nrows();
    if let Some(i) = (0..n).find(|&i| m[(i, i)].is_nan() || m[(i, i)] <= 0.0) {
        return Err(i);
    }
    let d: Vec<f64> = (0..n).map(|i| m[(i, i)].sqrt()).collect();
    Ok((DMatrix::from_fn(n, n, |a, b| m[(a, b)] / (d[a] * d[b])), d))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random(m: usize, n: usize, seed: u64) -> DMatrix<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        // Columns of very different scale, as mm and rad columns of a Jacobian.
        DMatrix::from_fn(m, n, |_, c| {
            rng.random_range(-1.0..1.0) * 10f64.powi(c as i32 % 4 - 2)
        })
    }

    #[test]
    fn factor_reproduces_the_gram_matrix_and_singular_values() {
        for (m, n) in [(1000, 7), (5, 9), (37, 37), (3, 1)] {
            let a = random(m, n, m as u64);
            let r = r_factor(a.as_view());
            assert_eq!(r.shape(), (n, n));
            for i in 0..n {
                for j in 0..i {
                    assert_eq!(r[(i, j)], 0.0, "R is upper triangular");
                }
            }
            let g = a.tr_mul(&a);
            let err = (r.tr_mul(&r) - &g).abs().max();
            assert!(err <= 1e-12 * g.abs().max(), "{m}×{n}: {err}");
            let direct: Vec<f64> = {
                let mut s: Vec<f64> = a
                    .clone()
                    .svd(false, false)
                    .singular_values
                    .iter()
                    .copied()
                    .collect();
                s.sort_by(|a, b| b.total_cmp(a));
                s
            };
            let from_r = singular_values_of_factor(&r, m);
            assert_eq!(from_r.len(), direct.len());
            for (x, y) in from_r.iter().zip(&direct) {
                assert!((x - y).abs() <= 1e-10 * direct[0], "{m}×{n}: {x} vs {y}");
            }
        }
    }

    #[test]
    fn blocked_gram_is_the_gram_matrix() {
        let a = random(2000, 5, 9);
        let g = gram(a.as_view());
        let direct = a.tr_mul(&a);
        assert!((&g - &direct).abs().max() <= 1e-12 * direct.abs().max());
        assert_eq!(g, g.transpose(), "exactly symmetric");
    }

    #[test]
    fn rows_added_in_pieces_give_the_factor_of_the_whole() {
        let a = random(500, 6, 3);
        let mut c = RowCompressor::new(6);
        for start in (0..500).step_by(13) {
            let k = 13.min(500 - start);
            c.add_rows(a.rows(start, k));
        }
        assert_eq!(c.rows(), 500);
        let r = c.finish();
        let g = a.tr_mul(&a);
        assert!((r.tr_mul(&r) - &g).abs().max() <= 1e-12 * g.abs().max());
    }

    /// Unit diagonal, the correlations kept, the scales returned; a zero diagonal named.
    #[test]
    fn unit_diagonal_scales_to_correlations() {
        let m = DMatrix::from_row_slice(2, 2, &[4.0, 3.0, 3.0, 9.0]);
        let (s, d) = unit_diagonal(&m).unwrap();
        assert_eq!(d, vec![2.0, 3.0]);
        assert_eq!(s, DMatrix::from_row_slice(2, 2, &[1.0, 0.5, 0.5, 1.0]));
        let z = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 0.0]);
        assert_eq!(unit_diagonal(&z).unwrap_err(), 1);
    }
}
