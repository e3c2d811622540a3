//! Fits of points in space (all in the measuring instrument's frame, mm), with the
//! linearised covariance of the fitted axis — the geometry of circle point analysis
//! ([`crate::identify::circle_point`], book §4.6):
//!
//! * [`fit_circle`]: total least squares plane through the centred points (SVD, book
//!   §4.6.2's principal axis method) and the algebraic (Kåsa) circle in the plane — linear least
//!   squares on `x² + y² + D x + E y + F = 0` — as the start, then Gauss–Newton on Stone's
//!   geometric residuals (book eqs. 4.284–4.290): the 3-D distance of each point from the
//!   circle, split into its out-of-plane part `hᵢ` and its in-plane radial part `eᵢ`, over
//!   the centre, the normal and the radius ([`circle_residuals`]). Kåsa alone is biased
//!   towards small radii on a short, noisy arc; the geometric refinement removes that bias.
//! * [`fit_line`]: total least squares line (first principal axis), which minimises the
//!   points' distances across the line.
//!
//! Uncertainty ([`AxisCovariance`]): both fits minimise `rᵀr` over geometric residuals `r`
//! (two per point) whose first-order response to isotropic point noise `N(0, σ² I₃)` is the
//! noise's components along two orthonormal directions (circle: `n` and the radial `uᵢ`;
//! line: across the line), so `r` has covariance `σ² I`; the third component (along the
//! circle or the line) is absorbed by the unknown position of the point on it. Linearised
//! least squares (Seber & Wild, *Nonlinear Regression*, 1989, §2.1) then gives
//! `Cov θ = σ̂² (JᵀJ)⁻¹` with `J = ∂r/∂θ` at the solution and `σ̂² = rᵀr / ν`,
//! `ν = 2n − dim θ` (circle: 6 parameters, line: 4). [`identify_axes`](crate::identify::circle_point::identify_axes) reports each axis'
//! direction σ as an angle and its point σ across the axis, and warns
//! ([`JointAxis::warning`](crate::identify::circle_point::JointAxis::warning)) when an axis is not to be trusted.

use crate::Error;
use nalgebra::{DMatrix, DVector, Matrix2, Vector3};

/// Linearised covariance of a fitted axis (see the module documentation), expressed in the
/// orthonormal basis `(x, y)` of the plane perpendicular to the axis direction `u`: `x` the
/// fit's `x_axis`, `y = u × x`.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisCovariance {
    /// Point noise per coordinate estimated from the fit's residuals, `σ̂ = √(rᵀr / ν)`, mm.
    pub sigma_noise: f64,
    /// Degrees of freedom `ν` of σ̂: `2n − 6` for a circle, `2n − 4` for a line (n points).
    pub dof: usize,
    /// Covariance of the direction's small rotation `δu = a x + b y`: of `(a, b)`, rad².
    pub direction: Matrix2<f64>,
    /// Covariance of the axis point's displacement across the axis, `(x·δp, y·δp)`, mm²
    /// (along the axis the point is not defined).
    pub point: Matrix2<f64>,
}

impl AxisCovariance {
    /// From the residuals `r` and Jacobian `j` at a least-squares solution whose parameters
    /// start with the direction's `(a, b)`, and the 2 × p map `point` from the parameters to
    /// the point's displacement across the axis: `C = σ̂² (jᵀj)⁻¹`, direction block
    /// `C[0..2, 0..2]`, point `point · C · pointᵀ`. `None` with no degrees of freedom left
    /// (an exact fit: σ̂ unknown) or a singular `jᵀj`.
    fn from_least_squares(
        j: &DMatrix<f64>,
        r: &DVector<f64>,
        point: &DMatrix<f64>,
    ) -> Option<Self> {
        let dof = r.len().checked_sub(j.ncols()).filter(|&d| d > 0)?;
        Self::from_jacobian(j, point, (r.norm_squared() / dof as f64).sqrt(), dof)
    }

    /// As [`Self::from_least_squares`] with a given σ and ν.
    fn from_jacobian(
        j: &DMatrix<f64>,
        point: &DMatrix<f64>,
        sigma: f64,
        dof: usize,
    ) -> Option<Self> {
        let c = j.tr_mul(j).cholesky()?.inverse() * (sigma * sigma);
        let p = point * &c * point.transpose();
        Some(AxisCovariance {
            sigma_noise: sigma,
            dof,
            direction: c.fixed_view::<2, 2>(0, 0).into_owned(),
            point: Matrix2::new(p[(0, 0)], p[(0, 1)], p[(1, 0)], p[(1, 1)]),
        })
    }

    /// RMS angle between the fitted and the true direction, `√tr C_dir`, rad.
    pub fn sigma_direction(&self) -> f64 {
        self.direction.trace().sqrt()
    }

    /// RMS distance of the fitted point from the true axis, `√tr C_point`, mm.
    pub fn sigma_point(&self) -> f64 {
        self.point.trace().sqrt()
    }
}

/// A circle in space.
#[derive(Clone, Debug, PartialEq)]
pub struct Circle {
    /// Centre (mm, in the points' frame).
    pub centre: Vector3<f64>,
    /// Unit normal, oriented so that the points, in the order given, turn positively
    /// (right-handed) about it.
    pub normal: Vector3<f64>,
    /// Radius (mm).
    pub radius: f64,
    /// RMS distance of the points from the circle (in-plane and out-of-plane parts), mm.
    pub rms: f64,
    /// Unit vector in the circle's plane from the centre towards the first point.
    pub x_axis: Vector3<f64>,
    /// Linearised covariance of the normal and the centre (basis `x_axis`,
    /// `normal × x_axis`); `None` for 3 points, which a circle fits exactly.
    pub covariance: Option<AxisCovariance>,
}

/// A line in space.
#[derive(Clone, Debug, PartialEq)]
pub struct Line {
    /// Unit direction, from the first point towards the last.
    pub direction: Vector3<f64>,
    /// The centroid of the points.
    pub point: Vector3<f64>,
    /// RMS distance of the points from the line, mm.
    pub rms: f64,
    /// A unit vector perpendicular to `direction`.
    pub x_axis: Vector3<f64>,
    /// Linearised covariance of the direction and the point (basis `x_axis`,
    /// `direction × x_axis`); `None` for 2 points, which a line fits exactly.
    pub covariance: Option<AxisCovariance>,
}

/// Centroid and right singular vectors of the centred points, with singular values in
/// descending order.
pub(crate) fn principal_axes(
    points: &[Vector3<f64>],
) -> (Vector3<f64>, [Vector3<f64>; 3], [f64; 3]) {
    let n = points.len();
    let centroid = points.iter().sum::<Vector3<f64>>() / n as f64;
    // Zero rows (for fewer than 3 points) change neither singular vectors nor values.
    let m = DMatrix::from_fn(n.max(3), 3, |i, j| {
        if i < n {
            points[i][j] - centroid[j]
        } else {
            0.0
        }
    });
    let svd = m.svd(false, true);
    let vt = svd.v_t.expect("computed");
    let sv = &svd.singular_values;
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| sv[b].total_cmp(&sv[a]));
    let vec = |k: usize| Vector3::new(vt[(k, 0)], vt[(k, 1)], vt[(k, 2)]);
    (
        centroid,
        [vec(order[0]), vec(order[1]), vec(order[2])],
        [sv[order[0]], sv[order[1]], sv[order[2]]],
    )
}

fn check_finite(points: &[Vector3<f64>], min: usize, what: &str) -> Result<(), Error> {
    if points.len() < min {
        return Err(Error::Input(format!(
            "{what} needs at least {min} points, got {}",
            points.len()
        )));
    }
    if let Some(i) = points.iter().position(|p| !p.iter().all(|x| x.is_finite())) {
        return Err(Error::Input(format!(
            "{what}: point {} is not finite",
            i + 1
        )));
    }
    Ok(())
}

/// The orthonormal basis `(x, y = u × x)` across the unit vector `u`, `x` the part of `v`
/// perpendicular to `u`, normalised.
fn basis_across(u: &Vector3<f64>, v: &Vector3<f64>) -> [Vector3<f64>; 2] {
    let x = (v - u * u.dot(v)).normalize();
    [x, u.cross(&x)]
}

/// Total least squares line (the point is the centroid; the direction is oriented from the
/// first point towards the last) with its covariance. Needs at least 2 distinct points.
///
/// Covariance: parameters `θ = (a, b, v₁, v₂)` move the direction to `(d + a x + b y)/|…|`
/// and the point to `p + v₁ x + v₂ y`; the residuals of point i are its offsets across the
/// line, `(x·(pᵢ − p), y·(pᵢ − p))`, in the basis carried along with the direction
/// (`x → x − a d` to first order), so with `sᵢ = d·(pᵢ − p)` their rows of `J` are
/// `(−sᵢ, 0, −1, 0)` and `(0, −sᵢ, 0, −1)`. As `Σ sᵢ = 0` at the centroid this gives
/// `C_dir = σ̂² / Σ sᵢ² · I₂` and `C_point = σ̂² / n · I₂`, `ν = 2n − 4`.
pub fn fit_line(points: &[Vector3<f64>]) -> Result<Line, Error> {
    check_finite(points, 2, "a line fit")?;
    let (centroid, axes, s) = principal_axes(points);
    if s[0] <= 0.0 {
        return Err(Error::Input("a line fit needs two distinct points".into()));
    }
    let n = points.len();
    let mut d = axes[0];
    if d.dot(&(points[n - 1] - points[0])) < 0.0 {
        d = -d;
    }
    let basis = basis_across(&d, &any_perpendicular(&d));
    let mut r = DVector::zeros(2 * n);
    let mut j = DMatrix::zeros(2 * n, 4);
    for (i, p) in points.iter().enumerate() {
        let q = p - centroid;
        for k in 0..2 {
            r[2 * i + k] = basis[k].dot(&q);
            j[(2 * i + k, k)] = -d.dot(&q);
            j[(2 * i + k, 2 + k)] = -1.0;
        }
    }
    let mut point = DMatrix::zeros(2, 4);
    point[(0, 2)] = 1.0;
    point[(1, 3)] = 1.0;
    Ok(Line {
        direction: d,
        point: centroid,
        rms: (s[1] * s[1] + s[2] * s[2]).sqrt() / (n as f64).sqrt(),
        x_axis: basis[0],
        covariance: AxisCovariance::from_least_squares(&j, &r, &point),
    })
}

/// Stone's geometric residuals of the points from the circle `(c, n, r)` and their
/// Jacobian. Residuals `[h₁, e₁, h₂, e₂, …]` with `dᵢ = pᵢ − c`, `hᵢ = n·dᵢ` (out of plane)
/// and `eᵢ = |wᵢ| − r`, `wᵢ = dᵢ − n hᵢ` (in plane), so `hᵢ² + eᵢ²` is the squared distance
/// of `pᵢ` from the circle. The Jacobian is with respect to `θ = (a, b, c, r)`, the normal
/// moving as `n(a, b) = (n + a x + b y)/|n + a x + b y|` with `(x, y) = basis` across `n`
/// (so `∂n/∂a = x`, `∂n/∂b = y` at `a = b = 0`), and with `uᵢ = wᵢ/|wᵢ|`:
///
/// `∂h/∂(a, b) = (x·d, y·d)`, `∂h/∂c = −nᵀ`, `∂h/∂r = 0`;
/// `∂e/∂(a, b) = −h (u·x, u·y)`, `∂e/∂c = −uᵀ`, `∂e/∂r = −1`
///
/// (from `∂w/∂a = −x h − n (x·d)` and `∂w/∂c = −(I − n nᵀ)`, `u ⊥ n`). A point on the axis
/// (`w = 0`) gets `u = 0`.
pub fn circle_residuals(
    points: &[Vector3<f64>],
    c: &Vector3<f64>,
    n: &Vector3<f64>,
    r: f64,
    basis: &[Vector3<f64>; 2],
) -> (DVector<f64>, DMatrix<f64>) {
    let mut res = DVector::zeros(2 * points.len());
    let mut jac = DMatrix::zeros(2 * points.len(), 6);
    for (i, p) in points.iter().enumerate() {
        let d = p - c;
        let h = n.dot(&d);
        let w = d - n * h;
        let rho = w.norm();
        let u = if rho > 0.0 { w / rho } else { Vector3::zeros() };
        res[2 * i] = h;
        res[2 * i + 1] = rho - r;
        for k in 0..2 {
            jac[(2 * i, k)] = basis[k].dot(&d);
            jac[(2 * i + 1, k)] = -h * u.dot(&basis[k]);
        }
        for k in 0..3 {
            jac[(2 * i, 2 + k)] = -n[k];
            jac[(2 * i + 1, 2 + k)] = -u[k];
        }
        jac[(2 * i + 1, 5)] = -1.0;
    }
    (res, jac)
}

/// The circle moved by the step `θ = (a, b, δc, δr)` of [`circle_residuals`].
fn circle_step(
    c: &Vector3<f64>,
    n: &Vector3<f64>,
    r: f64,
    basis: &[Vector3<f64>; 2],
    step: &DVector<f64>,
) -> (Vector3<f64>, Vector3<f64>, f64) {
    (
        c + Vector3::new(step[2], step[3], step[4]),
        (n + basis[0] * step[0] + basis[1] * step[1]).normalize(),
        r + step[5],
    )
}

/// Most Gauss–Newton steps of the geometric circle fit.
const CIRCLE_ITERATIONS: usize = 50;

/// Circle through points in space: plane fit, algebraic (Kåsa) circle in the plane, then
/// Gauss–Newton on Stone's geometric residuals ([`circle_residuals`]) with step halving,
/// and the linearised covariance there (see the module documentation). The normal is
/// oriented so that consecutive points turn positively about it. Needs at least 3 points
/// that are not collinear.
pub fn fit_circle(points: &[Vector3<f64>]) -> Result<Circle, Error> {
    check_finite(points, 3, "a circle fit")?;
    let n = points.len();
    let (centroid, axes, s) = principal_axes(points);
    if s[1] <= 1e-12 * s[0].max(f64::MIN_POSITIVE) {
        return Err(Error::Input(
            "a circle fit needs points that are not collinear".into(),
        ));
    }
    let (e1, e2) = (axes[0], axes[1]);
    let xy: Vec<(f64, f64)> = points
        .iter()
        .map(|p| {
            let d = p - centroid;
            (d.dot(&e1), d.dot(&e2))
        })
        .collect();
    // Kåsa: x² + y² + D x + E y + F = 0, linear least squares.
    let a = DMatrix::from_fn(n, 3, |i, j| match j {
        0 => xy[i].0,
        1 => xy[i].1,
        _ => 1.0,
    });
    let b = DVector::from_fn(n, |i, _| -(xy[i].0 * xy[i].0 + xy[i].1 * xy[i].1));
    let sol = a
        .svd(true, true)
        .solve(&b, 1e-14)
        .map_err(|e| Error::Numerical(format!("circle fit: {e}")))?;
    let (cx, cy) = (-sol[0] / 2.0, -sol[1] / 2.0);
    let r2 = cx * cx + cy * cy - sol[2];
    if !(r2 > 0.0 && r2.is_finite()) {
        return Err(Error::Input(
            "circle fit: the points do not lie near a circle".into(),
        ));
    }
    let (mut centre, mut normal, mut r) = (centroid + e1 * cx + e2 * cy, axes[2], r2.sqrt());
    let mut basis = [e1, e2];
    for _ in 0..CIRCLE_ITERATIONS {
        let (res, jac) = circle_residuals(points, &centre, &normal, r, &basis);
        let Some(chol) = jac.tr_mul(&jac).cholesky() else {
            break;
        };
        let mut step = chol.solve(&(-jac.tr_mul(&res)));
        let ss = res.norm_squared();
        let accepted = loop {
            let (c, u, rr) = circle_step(&centre, &normal, r, &basis, &step);
            if circle_residuals(points, &c, &u, rr, &basis)
                .0
                .norm_squared()
                <= ss
            {
                (centre, normal, r) = (c, u, rr);
                break true;
            }
            step /= 2.0;
            if step.norm() <= 1e-15 * (r + centre.norm()) {
                break false;
            }
        };
        basis = basis_across(&normal, &basis[0]);
        if !accepted || step.norm() <= 1e-15 * (r + centre.norm()) {
            break;
        }
    }
    let turn: Vector3<f64> = points
        .windows(2)
        .map(|w| (w[0] - centre).cross(&(w[1] - centre)))
        .sum();
    if turn.dot(&normal) < 0.0 {
        normal = -normal;
    }
    let basis = basis_across(&normal, &(points[0] - centre));
    let (res, jac) = circle_residuals(points, &centre, &normal, r, &basis);
    Ok(Circle {
        centre,
        normal,
        radius: r,
        rms: (res.norm_squared() / n as f64).sqrt(),
        x_axis: basis[0],
        covariance: AxisCovariance::from_least_squares(&jac, &res, &circle_point_map(&basis)),
    })
}

/// The map from the circle parameters `(a, b, c, r)` of [`circle_residuals`] to the centre's
/// displacement across the axis, `(x·δc, y·δc)`.
fn circle_point_map(basis: &[Vector3<f64>; 2]) -> DMatrix<f64> {
    DMatrix::from_fn(2, 6, |i, j| match j {
        2..=4 => basis[i][j - 2],
        _ => 0.0,
    })
}

/// Linearised covariance of [`fit_circle`] for a planned sweep: `n` points evenly spread
/// over `span` (rad) of a circle of radius `r`, noise σ per coordinate — `σ² (JᵀJ)⁻¹` at the
/// noise-free points (frame-invariant, so computed for the circle about z at the origin).
pub fn planned_circle_covariance(
    r: f64,
    n: usize,
    span: f64,
    sigma: f64,
) -> Option<AxisCovariance> {
    let points: Vec<Vector3<f64>> = (0..n)
        .map(|i| {
            let t = span * i as f64 / (n.max(2) - 1) as f64;
            Vector3::new(r * t.cos(), r * t.sin(), 0.0)
        })
        .collect();
    let basis = [Vector3::x(), Vector3::y()];
    let (_, jac) = circle_residuals(&points, &Vector3::zeros(), &Vector3::z(), r, &basis);
    AxisCovariance::from_jacobian(
        &jac,
        &circle_point_map(&basis),
        sigma,
        (2 * n).saturating_sub(6),
    )
}

/// A unit vector perpendicular to the unit vector `d`.
fn any_perpendicular(d: &Vector3<f64>) -> Vector3<f64> {
    let e = if d.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    (e - d * d.dot(&e)).normalize()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use nalgebra::DVector;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    /// `n` points with noise σ per coordinate on an arc of `span` (rad, starting at angle
    /// `start`) of the circle (centre, normal, radius) = (c, z, r) of a frame tilted
    /// arbitrarily, evenly spaced.
    pub(crate) fn noisy_arc(
        r: f64,
        span: f64,
        n: usize,
        sigma: f64,
        rng: &mut ChaCha8Rng,
    ) -> (Vec<Vector3<f64>>, Vector3<f64>, Vector3<f64>) {
        let rot = nalgebra::Rotation3::from_euler_angles(0.4, -0.7, 1.1);
        let c = Vector3::new(120.0, -340.0, 910.0);
        let normal = rot * Vector3::z();
        let noise = Normal::new(0.0, 1.0).unwrap();
        let pts = (0..n)
            .map(|i| {
                let t = 0.3 + span * i as f64 / (n - 1) as f64;
                c + rot * Vector3::new(r * t.cos(), r * t.sin(), 0.0)
                    + Vector3::from_fn(|_, _| sigma * noise.sample(rng))
            })
            .collect();
        (pts, c, normal)
    }

    #[test]
    fn circle_jacobian_matches_finite_differences() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        // Noisy points and a circle off the optimum, so that h ≠ 0 and the coupling terms
        // −h (u·x, u·y) count.
        let (pts, c, n) = noisy_arc(200.0, 1.5, 9, 3.0, &mut rng);
        let c = c + Vector3::new(4.0, -2.0, 3.0);
        let n = (n + Vector3::new(0.05, 0.02, -0.03)).normalize();
        let r = 190.0;
        let basis = basis_across(&n, &Vector3::new(0.3, 1.0, -0.2));
        let (_, jac) = circle_residuals(&pts, &c, &n, r, &basis);
        let h = 1e-6;
        let mut worst = 0.0f64;
        for k in 0..6 {
            let mut step = DVector::zeros(6);
            step[k] = h;
            let (cp, np, rp) = circle_step(&c, &n, r, &basis, &step);
            let (cm, nm, rm) = circle_step(&c, &n, r, &basis, &(-step));
            let fd = (circle_residuals(&pts, &cp, &np, rp, &basis).0
                - circle_residuals(&pts, &cm, &nm, rm, &basis).0)
                / (2.0 * h);
            let err = (fd - jac.column(k)).amax() / jac.column(k).amax();
            worst = worst.max(err);
            assert!(err < 1e-6, "column {k}: relative error {err:.2e}");
        }
        eprintln!("circle Jacobian vs central differences: worst relative error {worst:.2e}");
    }

    /// Predicted σ over the Monte Carlo spread, for (RMS angle, RMS distance across the
    /// axis, and the direction's σ along the major and the minor axis of its covariance).
    /// `fit` returns a fitted (direction, point, x_axis, covariance); the prediction is the
    /// mean of the runs' covariances (each with its own σ̂), turned from each fit's basis
    /// (x_axis, direction × x_axis) into one across the true direction `u`; the truth is the
    /// spread of the errors about the true axis (u, p) there.
    fn monte_carlo_ratios(
        runs: usize,
        fit: impl Fn(&mut ChaCha8Rng) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>, AxisCovariance),
        (u, p): (Vector3<f64>, Vector3<f64>),
        seed: u64,
    ) -> [f64; 4] {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let b = basis_across(&u, &any_perpendicular(&u));
        let mut sums = [Matrix2::<f64>::zeros(); 4];
        for _ in 0..runs {
            let (d, q, x, cov) = fit(&mut rng);
            let fb = basis_across(&d, &x);
            let rot = Matrix2::from_fn(|i, j| b[i].dot(&fb[j]));
            let e = nalgebra::Vector2::new(b[0].dot(&d), b[1].dot(&d));
            let f = nalgebra::Vector2::new(b[0].dot(&(q - p)), b[1].dot(&(q - p)));
            sums[0] += e * e.transpose();
            sums[1] += f * f.transpose();
            sums[2] += rot * cov.direction * rot.transpose();
            sums[3] += rot * cov.point * rot.transpose();
        }
        let [dir, point, pred_dir, pred_point] = sums.map(|m| m / runs as f64);
        let eig = pred_dir.symmetric_eigen();
        let along = |c: &Matrix2<f64>, k: usize| {
            let v = eig.eigenvectors.column(k);
            (v.transpose() * c * v)[(0, 0)].sqrt()
        };
        [
            (pred_dir.trace() / dir.trace()).sqrt(),
            (pred_point.trace() / point.trace()).sqrt(),
            along(&pred_dir, 0) / along(&dir, 0),
            along(&pred_dir, 1) / along(&dir, 1),
        ]
    }

    #[test]
    fn circle_axis_sigma_matches_monte_carlo() {
        // (radius mm, span deg, points, σ mm): a clean medium sweep, 1 mm noise on a short
        // and on a medium sweep.
        for (r, span, n, sigma) in [
            (250.0, 90.0f64, 15, 0.05),
            (300.0, 24.0, 13, 1.0),
            (800.0, 40.0, 13, 1.0),
        ] {
            let mut rng = ChaCha8Rng::seed_from_u64(5);
            let (_, c, normal) = noisy_arc(r, span.to_radians(), n, 0.0, &mut rng);
            let fit = |rng: &mut ChaCha8Rng| {
                let (pts, _, _) = noisy_arc(r, span.to_radians(), n, sigma, rng);
                let f = fit_circle(&pts).unwrap();
                (f.normal, f.centre, f.x_axis, f.covariance.unwrap())
            };
            let ratios = monte_carlo_ratios(400, fit, (normal, c), 9);
            eprintln!(
                "circle r {r} mm, {span}°, {n} points, σ {sigma} mm: predicted/MC σ direction \
                 {:.3}, point {:.3}, major {:.3}, minor {:.3}",
                ratios[0], ratios[1], ratios[2], ratios[3]
            );
            for (k, q) in ratios.iter().enumerate() {
                assert!((0.8..1.2).contains(q), "ratio {k}: {q}");
            }
        }
    }

    #[test]
    fn line_axis_sigma_matches_monte_carlo() {
        let u = Vector3::new(0.3, -0.5, 0.8).normalize();
        let p = Vector3::new(400.0, 20.0, -150.0);
        let noise = Normal::new(0.0, 1.0).unwrap();
        let fit = |rng: &mut ChaCha8Rng| {
            let pts: Vec<_> = (0..10)
                .map(|i| {
                    p + u * (-100.0 + 20.0 * i as f64)
                        + Vector3::from_fn(|_, _| 0.2 * noise.sample(rng))
                })
                .collect();
            let l = fit_line(&pts).unwrap();
            (l.direction, l.point, l.x_axis, l.covariance.unwrap())
        };
        let ratios = monte_carlo_ratios(400, fit, (u, p), 4);
        eprintln!("line 180 mm, 10 points, σ 0.2 mm: predicted/MC {ratios:.3?}");
        for (k, q) in ratios.iter().enumerate() {
            assert!((0.8..1.2).contains(q), "ratio {k}: {q}");
        }
    }

    #[test]
    fn circle_sign_follows_point_order() {
        let pts: Vec<Vector3<f64>> = (0..5)
            .map(|i| {
                let a = 0.3 * i as f64;
                Vector3::new(1.0 + 2.0 * a.cos(), 2.0 * a.sin(), 3.0)
            })
            .collect();
        let c = fit_circle(&pts).unwrap();
        assert!((c.normal - Vector3::z()).norm() < 1e-12);
        assert!((c.centre - Vector3::new(1.0, 0.0, 3.0)).norm() < 1e-12);
        assert!((c.radius - 2.0).abs() < 1e-12);
        let rev: Vec<_> = pts.iter().rev().copied().collect();
        assert!((fit_circle(&rev).unwrap().normal + Vector3::z()).norm() < 1e-12);
        assert!(fit_circle(&pts[..2]).is_err());
        let line: Vec<_> = (0..4).map(|i| Vector3::new(i as f64, 0.0, 0.0)).collect();
        assert!(fit_circle(&line).is_err());
        let l = fit_line(&line).unwrap();
        assert!((l.direction - Vector3::x()).norm() < 1e-12 && l.rms < 1e-12);
    }
}
