//! Confidence ellipses of the TCP position (paper Figure 7): the 3-D linearised confidence
//! ellipsoid `{δ : δᵀ C_s⁻¹ δ ≤ k²}` of the TCP at a working pose, projected onto the
//! xy, xz and yz planes.
//!
//! The shadow of that ellipsoid on the coordinate plane (i, j) is the ellipse
//! `{y : yᵀ C_ij⁻¹ y ≤ k²}` with `C_ij` the 2×2 submatrix of C_s (the marginal covariance),
//! so each projection needs only the submatrix and the same k. With `k² = χ²₃(p)` the
//! ellipsoid holds the TCP with probability p, as in the paper's 95 % regions.

use crate::Error;
use nalgebra::Matrix3;
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// A coordinate plane of the instrument frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Plane {
    /// The x–y plane (coordinates 0 and 1).
    Xy,
    /// The x–z plane (coordinates 0 and 2).
    Xz,
    /// The y–z plane (coordinates 1 and 2).
    Yz,
}

impl Plane {
    /// The three planes, in the order the report draws them.
    pub const ALL: [Plane; 3] = [Plane::Xy, Plane::Xz, Plane::Yz];

    /// The two coordinate indices (0 = x, 1 = y, 2 = z).
    pub fn axes(self) -> (usize, usize) {
        match self {
            Plane::Xy => (0, 1),
            Plane::Xz => (0, 2),
            Plane::Yz => (1, 2),
        }
    }

    /// Axis names, e.g. ("x", "y").
    pub fn axis_names(self) -> (&'static str, &'static str) {
        let n = ["x", "y", "z"];
        let (i, j) = self.axes();
        (n[i], n[j])
    }

    /// The 2×2 submatrix of a 3×3 covariance for this plane.
    pub fn project(self, c: &Matrix3<f64>) -> [[f64; 2]; 2] {
        let (i, j) = self.axes();
        [[c[(i, i)], c[(i, j)]], [c[(j, i)], c[(j, j)]]]
    }
}

/// The scale k of the region `δᵀ C⁻¹ δ ≤ k²` holding a `dof`-dimensional Gaussian with
/// probability `p`: `k = √(χ²_dof⁻¹(p))`.
pub fn confidence_scale(dof: usize, p: f64) -> Result<f64, Error> {
    if !(p > 0.0 && p < 1.0) || dof == 0 {
        return Err(Error::Input(format!(
            "confidence level {p} with {dof} degrees of freedom: need 0 < p < 1 and dof ≥ 1"
        )));
    }
    let chi2 = ChiSquared::new(dof as f64).map_err(|e| Error::Numerical(e.to_string()))?;
    Ok(chi2.inverse_cdf(p).sqrt())
}

/// Semi-axes (major, minor) and the major axis' angle from the first axis (rad) of the
/// ellipse `yᵀ C⁻¹ y = k²` for a symmetric positive semidefinite 2×2 `c`: the semi-axes are
/// `k √λ₁ ≥ k √λ₂` with λ the eigenvalues `(a + d)/2 ± √(((a − d)/2)² + b²)`, and the major
/// axis points at `½ atan2(2b, a − d)`.
pub fn ellipse_axes(c: [[f64; 2]; 2], k: f64) -> (f64, f64, f64) {
    let (a, b, d) = (c[0][0], 0.5 * (c[0][1] + c[1][0]), c[1][1]);
    let mean = 0.5 * (a + d);
    let radius = (0.25 * (a - d) * (a - d) + b * b).sqrt();
    let (l1, l2) = (mean + radius, (mean - radius).max(0.0));
    (k * l1.sqrt(), k * l2.sqrt(), 0.5 * (2.0 * b).atan2(a - d))
}

/// `n` points on the ellipse `yᵀ C⁻¹ y = k²` (closed: the last point repeats the first),
/// centred at the origin: `y(t) = R(θ) (r₁ cos t, r₂ sin t)` with the semi-axes and angle
/// of [`ellipse_axes`].
pub fn ellipse_points(c: [[f64; 2]; 2], k: f64, n: usize) -> Vec<(f64, f64)> {
    let (r1, r2, theta) = ellipse_axes(c, k);
    let (s, co) = theta.sin_cos();
    (0..=n.max(3))
        .map(|i| {
            let t = std::f64::consts::TAU * i as f64 / n.max(3) as f64;
            let (u, v) = (r1 * t.cos(), r2 * t.sin());
            (co * u - s * v, s * u + co * v)
        })
        .collect()
}
