//! Cholesky factorisation and solves of small dense symmetric positive definite systems
//! (a few rows: the per-candidate updates of the exchange, the constraint corrections of
//! the refinement's projection), in place on row-major slices, without allocation.

/// Overwrites the lower triangle of `a` (row-major `n × n`) with `L`, `A = L Lᵀ`. Returns
/// false (leaving `a` partly overwritten) if `A` is not positive definite.
pub fn factor(a: &mut [f64], n: usize) -> bool {
    for j in 0..n {
        let mut d = a[j * n + j];
        for p in 0..j {
            d -= a[j * n + p] * a[j * n + p];
        }
        if d <= 0.0 || !d.is_finite() {
            return false;
        }
        let d = d.sqrt();
        a[j * n + j] = d;
        for i in j + 1..n {
            let mut v = a[i * n + j];
            for p in 0..j {
                v -= a[i * n + p] * a[j * n + p];
            }
            a[i * n + j] = v / d;
        }
    }
    true
}

/// Solves `L Lᵀ x = b` in place (`l` from [`factor`]).
pub fn solve(l: &[f64], b: &mut [f64], n: usize) {
    forward(l, b, n);
    for i in (0..n).rev() {
        let mut v = b[i];
        for p in i + 1..n {
            v -= l[p * n + i] * b[p];
        }
        b[i] = v / l[i * n + i];
    }
}

/// Solves `L y = b` in place (forward substitution; `l` from [`factor`]): `‖y‖² = bᵀA⁻¹b`.
pub fn forward(l: &[f64], b: &mut [f64], n: usize) {
    for i in 0..n {
        let mut v = b[i];
        for p in 0..i {
            v -= l[i * n + p] * b[p];
        }
        b[i] = v / l[i * n + i];
    }
}

/// `A⁻¹` (row-major `n × n`) into `inv`, from `l` of [`factor`]: row c solves `A x = e_c`
/// (A⁻¹ is symmetric, so its rows are its columns).
pub fn inverse(l: &[f64], inv: &mut [f64], n: usize) {
    inv.fill(0.0);
    for (c, row) in inv.chunks_mut(n).enumerate() {
        row[c] = 1.0;
        solve(l, row, n);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_random_spd_system() {
        let n = 4;
        let g = [
            1.0, 0.3, -0.2, 0.5, 0.1, 2.0, 0.4, -0.3, 0.7, -0.1, 1.5, 0.2, 0.0, 0.6, -0.4, 1.1,
        ];
        // A = G Gᵀ + I.
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                a[i * n + j] = (0..n).map(|p| g[i * n + p] * g[j * n + p]).sum::<f64>()
                    + if i == j { 1.0 } else { 0.0 };
            }
        }
        let x = [0.5, -1.0, 2.0, 0.25];
        let mut b: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|j| a[i * n + j] * x[j]).sum())
            .collect();
        let mut l = a.clone();
        assert!(factor(&mut l, n));
        solve(&l, &mut b, n);
        for (bi, xi) in b.iter().zip(x) {
            assert!((bi - xi).abs() < 1e-12);
        }
        // A⁻¹ A = I, and ‖L⁻¹b‖² = bᵀA⁻¹b.
        let mut inv = vec![0.0; n * n];
        inverse(&l, &mut inv, n);
        for i in 0..n {
            for j in 0..n {
                let v: f64 = (0..n).map(|p| inv[i * n + p] * a[p * n + j]).sum();
                assert!((v - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12);
            }
        }
        let mut y = x.to_vec();
        forward(&l, &mut y, n);
        let quad: f64 = (0..n)
            .map(|i| (0..n).map(|j| x[i] * inv[i * n + j] * x[j]).sum::<f64>())
            .sum();
        assert!((y.iter().map(|v| v * v).sum::<f64>() - quad).abs() < 1e-12 * quad);
        let mut not_pd = vec![1.0, 2.0, 2.0, 1.0];
        assert!(!factor(&mut not_pd, 2));
    }
}
