//! Joint-axis identification by circle point analysis (book §4.6, after Stone): a target on
//! the arm is measured while one joint moves and the others stand still. A revolute joint
//! moves the target on a circle whose normal through its centre is the joint axis; a
//! prismatic joint moves it on a line parallel to the joint axis. From the axes found
//! with every other joint at its zero reference, the zero-reference model (book §2.8.2)
//! follows directly ([`axes_to_zrp`]), from it the DH model ([`axes_to_dh`], by
//! [`convert::zrp_to_dh`]), and Stone's S-model from frames placed on the axes
//! ([`axes_to_s_model`], book §4.6.5.1).
//!
//! Fits (all in the measuring instrument's frame, mm):
//! * [`fit_plane`]: total least squares plane through the centred points (SVD, book
//!   §4.6.2's principal axis method);
//! * [`fit_circle`]: plane fit and the algebraic (Kåsa) circle in the plane — linear least
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
//! `ν = 2n − dim θ` (circle: 6 parameters, line: 4). [`identify_axes`] reports each axis'
//! direction σ as an angle and its point σ across the axis, and warns
//! ([`JointAxis::warning`]) when an axis is not to be trusted.

use crate::model::chain::{LinkSpec, Model, ModelSpec};
use crate::model::convert;
use crate::model::link::{Convention, Joint, JointKind, LinkGeometry};
use crate::model::pose::Pose;
use crate::Error;
use nalgebra::{DMatrix, DVector, Matrix2, Matrix3, Vector3};

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
    pub centre: Vector3<f64>,
    /// Unit normal, oriented so that the points, in the order given, turn positively
    /// (right-handed) about it.
    pub normal: Vector3<f64>,
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
fn principal_axes(points: &[Vector3<f64>]) -> (Vector3<f64>, [Vector3<f64>; 3], [f64; 3]) {
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

/// Total least squares plane: `(unit normal, centroid, rms distance)`. The normal is the
/// right singular vector of the smallest singular value of the centred points; its sign is
/// arbitrary. Needs at least 3 points.
pub fn fit_plane(points: &[Vector3<f64>]) -> Result<(Vector3<f64>, Vector3<f64>, f64), Error> {
    check_finite(points, 3, "a plane fit")?;
    let (centroid, axes, s) = principal_axes(points);
    Ok((axes[2], centroid, s[2] / (points.len() as f64).sqrt()))
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

/// The shortest sweep (rad, at most a full turn) of `n` evenly spread points at radius `r`
/// and noise σ whose planned σ's ([`planned_circle_covariance`]) are within
/// [`MAX_SIGMA_DIRECTION_DEG`] and [`MAX_SIGMA_POINT_MM`]; `None` if not even a full turn
/// reaches them. Bisection to 0.1°, the σ's falling with the span.
pub fn span_for_limits(r: f64, n: usize, sigma: f64) -> Option<f64> {
    let within = |span: f64| {
        planned_circle_covariance(r, n, span, sigma).is_some_and(|c| {
            c.sigma_direction() <= MAX_SIGMA_DIRECTION_DEG.to_radians()
                && c.sigma_point() <= MAX_SIGMA_POINT_MM
        })
    };
    let full = 2.0 * std::f64::consts::PI * (n.max(2) - 1) as f64 / n.max(2) as f64;
    if !within(full) {
        return None;
    }
    let (mut lo, mut hi) = (0.0, full);
    while hi - lo > 0.1f64.to_radians() {
        let mid = 0.5 * (lo + hi);
        if within(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

/// Measurements of one joint's motion: full joint vectors in which only `joint` varies,
/// and the measured target position (instrument frame, mm) at each.
#[derive(Clone, Debug, PartialEq)]
pub struct JointSweep {
    /// Index of the swept joint (0-based).
    pub joint: usize,
    pub q: Vec<Vec<f64>>,
    pub points: Vec<Vector3<f64>>,
}

/// One identified joint axis, in the instrument frame, valid for the configuration
/// `reference` of the other joints.
#[derive(Clone, Debug, PartialEq)]
pub struct JointAxis {
    /// Name of the joint's link in the model (e.g. `j3`).
    pub link: String,
    pub joint: Joint,
    /// Unit direction: a positive joint motion turns positively about it (revolute) or
    /// moves along it (prismatic).
    pub direction: Vector3<f64>,
    /// A point on the axis: the circle centre (revolute) or the centroid of the points
    /// (prismatic: the line has no location that matters).
    pub point: Vector3<f64>,
    /// Unit vector perpendicular to `direction`: from the centre towards the point of the
    /// lowest joint value, projected on the plane of rotation (revolute, book eq. 4.299), or
    /// any perpendicular (prismatic). The x axis of the joint's S-model frame.
    pub x_axis: Vector3<f64>,
    /// Circle radius (revolute) or 0 (prismatic), mm.
    pub radius: f64,
    /// RMS residual of the circle or line fit, mm.
    pub rms: f64,
    /// The joint vector of the sweep with the swept joint set to 0: the configuration the
    /// axis belongs to.
    pub reference: Vec<f64>,
    /// Number of points of the sweep.
    pub points: usize,
    /// Range of the swept joint's values (largest − smallest), rad or mm.
    pub span: f64,
    /// Linearised covariance of `direction` and `point` in the basis (`x_axis`,
    /// `direction × x_axis`); `None` for an exact fit (3 points on a circle, 2 on a line).
    pub covariance: Option<AxisCovariance>,
    /// Why the axis is not to be trusted, how badly, and what to do ([`trust_warning`]);
    /// `None` for a trustworthy axis.
    pub warning: Option<String>,
}

/// The axes of all joints, in joint order.
#[derive(Clone, Debug, PartialEq)]
pub struct AxesResult {
    pub model: String,
    pub axes: Vec<JointAxis>,
}

impl AxesResult {
    /// The warnings of the axes not to be trusted, in joint order.
    pub fn warnings(&self) -> impl Iterator<Item = &str> {
        self.axes.iter().filter_map(|a| a.warning.as_deref())
    }
}

/// A revolute sweep shorter than this (deg) gets a warning even when its σ's are small: the
/// axis then rests on the arc's sagitta `r (1 − cos(span/2))` (3.4 % of the radius at 30°),
/// and its σ's grow like 1/span² (the points' spread across the chord, which fixes the
/// plane's tilt and the centre, is ≈ 0.15 r θ² √n for a half-span θ), so a systematic point
/// error `e` that the residuals do not show (a target mount's eccentricity, a wobbling
/// joint) tilts the axis by ≈ e / sagitta rad, unseen by the σ's.
pub const MIN_REVOLUTE_SPAN_DEG: f64 = 30.0;
/// Largest RMS direction error of a trustworthy axis, deg (9 mm at 1 m).
pub const MAX_SIGMA_DIRECTION_DEG: f64 = 0.5;
/// Largest RMS error of a trustworthy revolute axis' position across the axis, mm.
pub const MAX_SIGMA_POINT_MM: f64 = 2.0;
/// Largest residual RMS per radius of a trustworthy revolute axis: above it the target is
/// too close to the axis for the noise.
pub const MAX_RMS_PER_RADIUS: f64 = 0.01;
/// Fewest degrees of freedom of σ̂ for a trustworthy σ: σ̂²ν/σ² is χ²(ν), so σ̂ is uncertain
/// by ≈ ±1/√(2ν) (±25 % at ν = 8).
pub const MIN_NOISE_DOF: usize = 8;

/// The warning for an axis not to be trusted, or `None`: an exact fit (no σ), a σ of the
/// direction above [`MAX_SIGMA_DIRECTION_DEG`] or of the point above [`MAX_SIGMA_POINT_MM`]
/// (revolute; a prismatic axis' location does not matter), σ̂ from fewer than
/// [`MIN_NOISE_DOF`] degrees of freedom, a revolute sweep shorter than
/// [`MIN_REVOLUTE_SPAN_DEG`], or a residual RMS above [`MAX_RMS_PER_RADIUS`] of the radius.
/// It names the joint, the sweep, the σ's against their limits and the remedies, sized to
/// reach the limits with the same σ̂: the sweep from the planned σ's ([`span_for_limits`]),
/// a prismatic travel by σ ∝ 1/travel, the points by σ ∝ 1/√n (exact for repeated poses),
/// and — when only the direction is over its limit — the target's distance from the axis by
/// σ_dir ∝ 1/radius (exact: scaling the points by k scales the normal's columns of `J` by k
/// and leaves the centre's and the radius' alone).
pub fn trust_warning(a: &JointAxis) -> Option<String> {
    let revolute = a.joint.kind == JointKind::Revolute;
    let (span, unit) = if revolute {
        (a.span.to_degrees(), "°")
    } else {
        (a.span, " mm")
    };
    let (params, what) = if revolute { (6, "circle") } else { (4, "line") };
    // Points for ν = 2n − params ≥ MIN_NOISE_DOF.
    let min_points = (MIN_NOISE_DOF + params).div_ceil(2);
    let mut problems = Vec::new();
    let mut fixes = Vec::new();
    let mut sigmas = String::new();
    match &a.covariance {
        None => {
            problems.push(format!(
                "{} points fit a {what} exactly, so neither the noise nor the σ's can be estimated",
                a.points
            ));
            fixes.push(format!("measure at least {min_points} points"));
        }
        Some(cov) => {
            let sd = cov.sigma_direction().to_degrees();
            let sp = cov.sigma_point();
            sigmas = format!(", σ direction {sd:.3}°");
            if revolute {
                sigmas += &format!(", σ point across the axis {sp:.3} mm");
            }
            let k_dir = sd / MAX_SIGMA_DIRECTION_DEG;
            let k_point = if revolute {
                sp / MAX_SIGMA_POINT_MM
            } else {
                0.0
            };
            if k_dir > 1.0 {
                problems.push(format!(
                    "σ direction {sd:.3}° is {k_dir:.1} × the limit {MAX_SIGMA_DIRECTION_DEG}°"
                ));
            }
            if k_point > 1.0 {
                problems.push(format!(
                    "σ point {sp:.3} mm is {k_point:.1} × the limit {MAX_SIGMA_POINT_MM} mm"
                ));
            }
            let k = k_dir.max(k_point);
            if k > 1.0 {
                let mut ways = vec![
                    if !revolute {
                        format!("a travel of about {:.0} mm (σ ∝ 1/travel)", span * k)
                    } else if let Some(s) = span_for_limits(a.radius, a.points, cov.sigma_noise) {
                        format!(
                            "a sweep of {:.0}° with as many points",
                            s.to_degrees().ceil()
                        )
                    } else {
                        "(not even a full turn with as many points)".into()
                    },
                    format!(
                        "about {:.0} points (σ ∝ 1/√n)",
                        (a.points as f64 * k * k).ceil()
                    ),
                ];
                if revolute && k_point <= 1.0 {
                    ways.push(format!(
                        "a target about {:.0} mm from the axis (σ direction ∝ 1/radius)",
                        a.radius * k_dir
                    ));
                }
                fixes.push(format!("to reach the limits: {}", ways.join(", or ")));
            }
            if cov.dof < MIN_NOISE_DOF {
                problems.push(format!(
                    "σ̂ = {:.3} mm rests on {} degrees of freedom (±{:.0} %)",
                    cov.sigma_noise,
                    cov.dof,
                    100.0 / (2.0 * cov.dof as f64).sqrt()
                ));
                fixes.push(format!("measure at least {min_points} points"));
            }
        }
    }
    if revolute && span < MIN_REVOLUTE_SPAN_DEG {
        let sagitta = a.radius * (1.0 - (a.span / 2.0).cos());
        problems.push(format!(
            "the sweep is shorter than {MIN_REVOLUTE_SPAN_DEG}°: the axis rests on the arc's \
             {sagitta:.2} mm sagitta, so a systematic point error of e mm that the residuals do \
             not show tilts it by about e/{sagitta:.2} rad"
        ));
        fixes.push(format!("sweep at least {MIN_REVOLUTE_SPAN_DEG}°"));
    }
    if revolute && a.rms > MAX_RMS_PER_RADIUS * a.radius {
        problems.push(format!(
            "the residual RMS is {:.1} % of the radius (limit {:.0} %)",
            100.0 * a.rms / a.radius,
            100.0 * MAX_RMS_PER_RADIUS
        ));
        fixes.push("put the target farther from the axis".into());
    }
    if problems.is_empty() {
        return None;
    }
    let radius = if revolute {
        format!(", radius {:.1} mm", a.radius)
    } else {
        String::new()
    };
    Some(format!(
        "{} axis not to be trusted ({} points over {span:.1}{unit}{radius}, residual RMS {:.3} mm{sigmas}): {}. Remedy: {}.",
        a.joint.name,
        a.points,
        a.rms,
        problems.join("; "),
        fixes.join("; ")
    ))
}

/// Identifies every joint axis of `model` from one sweep per joint (circle point analysis,
/// book §4.6.3–4.6.4). The points of each sweep are sorted by the joint value, so the
/// direction is signed by the positive joint motion; a revolute sweep needs at least 3
/// distinct joint values, a prismatic one 2.
///
/// The points of joint i's sweep are measured with the other joints at the sweep's values,
/// so the axis found is joint i's axis *in that configuration* (`JointAxis::reference`).
/// For a zero-reference model ([`axes_to_zrp`]) every joint must be swept with all others
/// at 0; sweeps made in the book's sequential way (joints j+1… at arbitrary values) still
/// give correct axes here, but only those with the others at 0 build a zero-reference model.
///
/// Each axis carries the linearised covariance of its fit ([`AxisCovariance`]) and, if it
/// is not to be trusted, a warning ([`trust_warning`]).
///
/// Errors: a joint not swept or swept twice, mismatched lengths, a joint vector of the
/// wrong size, another joint that moves during a sweep, or a degenerate fit.
pub fn identify_axes(model: &Model, sweeps: &[JointSweep]) -> Result<AxesResult, Error> {
    let dof = model.dof();
    let mut found: Vec<Option<JointAxis>> = vec![None; dof];
    for (k, s) in sweeps.iter().enumerate() {
        let what = format!("sweep {} (joint {})", k + 1, s.joint + 1);
        if s.joint >= dof {
            return Err(Error::Input(format!(
                "{what}: model `{}` has {dof} joints",
                model.name
            )));
        }
        if found[s.joint].is_some() {
            return Err(Error::Input(format!("{what}: joint swept twice")));
        }
        if s.q.len() != s.points.len() {
            return Err(Error::Input(format!(
                "{what}: {} joint vectors but {} points",
                s.q.len(),
                s.points.len()
            )));
        }
        if s.q.is_empty() {
            return Err(Error::Input(format!("{what}: no measurements")));
        }
        let mut reference = s.q[0].clone();
        if reference.len() != dof {
            return Err(Error::Input(format!(
                "{what}: joint vectors need {dof} values, got {}",
                reference.len()
            )));
        }
        reference[s.joint] = 0.0;
        for (i, q) in s.q.iter().enumerate() {
            if q.len() != dof {
                return Err(Error::Input(format!(
                    "{what}: joint vector {} has {} values, the model {dof}",
                    i + 1,
                    q.len()
                )));
            }
            if !q.iter().all(|v| v.is_finite()) {
                return Err(Error::Input(format!(
                    "{what}: joint vector {} is not finite",
                    i + 1
                )));
            }
            if let Some(j) = (0..dof).find(|&j| j != s.joint && q[j] != reference[j]) {
                return Err(Error::Input(format!(
                    "{what}: joint {} moves ({} then {}); only the swept joint may move",
                    j + 1,
                    reference[j],
                    q[j]
                )));
            }
        }
        let mut order: Vec<usize> = (0..s.q.len()).collect();
        order.sort_by(|&a, &b| s.q[a][s.joint].total_cmp(&s.q[b][s.joint]));
        let pts: Vec<Vector3<f64>> = order.iter().map(|&i| s.points[i]).collect();
        let distinct = order
            .windows(2)
            .filter(|w| s.q[w[0]][s.joint] != s.q[w[1]][s.joint])
            .count()
            + 1;
        let span = s.q[order[order.len() - 1]][s.joint] - s.q[order[0]][s.joint];
        let joint = model.joints[s.joint].clone();
        let link = model
            .links
            .iter()
            .find(|l| l.joint == Some(s.joint))
            .map(|l| l.spec.name.clone())
            .unwrap_or_else(|| format!("j{}", s.joint + 1));
        let axis = match joint.kind {
            JointKind::Revolute => {
                if distinct < 3 {
                    return Err(Error::Input(format!(
                        "{what}: a revolute joint needs at least 3 distinct joint values"
                    )));
                }
                let c = fit_circle(&pts).map_err(|e| Error::Input(format!("{what}: {e}")))?;
                JointAxis {
                    link,
                    joint,
                    x_axis: c.x_axis,
                    direction: c.normal,
                    point: c.centre,
                    radius: c.radius,
                    rms: c.rms,
                    reference,
                    points: pts.len(),
                    span,
                    covariance: c.covariance,
                    warning: None,
                }
            }
            JointKind::Prismatic => {
                if distinct < 2 {
                    return Err(Error::Input(format!(
                        "{what}: a prismatic joint needs at least 2 distinct joint values"
                    )));
                }
                let l = fit_line(&pts).map_err(|e| Error::Input(format!("{what}: {e}")))?;
                JointAxis {
                    link,
                    joint,
                    x_axis: l.x_axis,
                    direction: l.direction,
                    point: l.point,
                    radius: 0.0,
                    rms: l.rms,
                    reference,
                    points: pts.len(),
                    span,
                    covariance: l.covariance,
                    warning: None,
                }
            }
        };
        let warning = trust_warning(&axis);
        found[s.joint] = Some(JointAxis { warning, ..axis });
    }
    let axes = found
        .into_iter()
        .enumerate()
        .map(|(j, a)| a.ok_or_else(|| Error::Input(format!("joint {} was not swept", j + 1))))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(AxesResult {
        model: model.name.clone(),
        axes,
    })
}

/// Tolerance on the other joints being at the zero reference (rad or mm).
const AT_ZERO: f64 = 1e-12;

/// Errors unless every axis was swept with all other joints at 0.
fn check_zero_reference(axes: &AxesResult) -> Result<(), Error> {
    for (i, a) in axes.axes.iter().enumerate() {
        if let Some(j) = a.reference.iter().position(|v| v.abs() > AT_ZERO) {
            return Err(Error::Input(format!(
                "joint {} was swept with joint {} at {} instead of 0: a model at the zero \
                 reference needs every joint swept with all others at 0",
                i + 1,
                j + 1,
                a.reference[j]
            )));
        }
    }
    Ok(())
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

/// Zero-reference model from the identified axes: identity `base` frame6, one `zrp` link
/// per joint (axis `u` = direction, `p` = the axis point, offset 0) and the `tool` frame6
/// `tool_pose_at_zero`, the measured target frame at q = 0. Its world is the instrument
/// frame the points were measured in, so the spec has no instrument and no targets.
///
/// Errors unless every axis was swept with all other joints at 0 (see [`identify_axes`]).
pub fn axes_to_zrp(axes: &AxesResult, tool_pose_at_zero: &Pose<f64>) -> Result<ModelSpec, Error> {
    let mut links = vec![LinkSpec {
        name: "base".into(),
        geometry: LinkGeometry::frame6([0.0; 3], [0.0; 3]),
        joint: None,
    }];
    check_zero_reference(axes)?;
    for a in &axes.axes {
        let p = match a.joint.kind {
            JointKind::Revolute => a.point.into(),
            JointKind::Prismatic => [0.0; 3],
        };
        links.push(LinkSpec {
            name: a.link.clone(),
            geometry: LinkGeometry::zrp(a.direction.into(), p, 0.0),
            joint: Some(a.joint.clone()),
        });
    }
    let (xyz, rpy) = tool_pose_at_zero.to_xyz_rpy();
    links.push(LinkSpec {
        name: "tool".into(),
        geometry: LinkGeometry::frame6(xyz, rpy),
        joint: None,
    });
    let spec = ModelSpec {
        name: format!("{}-cpa", axes.model),
        instrument: None,
        links,
        targets: vec![],
    };
    Model::from_spec(&spec)?;
    Ok(spec)
}

/// Below this `sin α` consecutive S-model z axes are treated as parallel.
const S_PARALLEL: f64 = 1e-9;

/// Stone's S-model link parameters `(β, r, l, α, γ, b)` of a relative transform
/// `B = Rz(β) Tz(r) Tx(l) Rx(α) Rz(γ) Tz(b)` (book eq. 4.304 with `Tz(b)`, errata 8).
/// With the next z axis not parallel (`sin α` above [`S_PARALLEL`]), β and γ come from
/// the third row and column of the rotation (eqs. 4.314–4.316, 4.310, 4.313) and `r, l, b`
/// from `p = r z + l Rz(β) x + b a`; with parallel z axes `b = 0`, `l` is the in-plane
/// distance and β its direction (the common normal through the origin).
fn s_model_params(b: &Pose<f64>) -> [f64; 6] {
    let (n, a, p) = (b.rot.column(0), b.rot.column(2), b.trans);
    let sin_alpha = a.x.hypot(a.y);
    let alpha = sin_alpha.atan2(a.z);
    if sin_alpha > S_PARALLEL {
        let beta = a.x.atan2(-a.y);
        let gamma = n.z.atan2(b.rot[(2, 1)]);
        let xb = Vector3::new(beta.cos(), beta.sin(), 0.0);
        let m = Matrix3::from_columns(&[Vector3::z(), xb, a.into_owned()]);
        let rlb = m.lu().solve(&p).unwrap_or_else(Vector3::zeros);
        return [beta, rlb[0], rlb[1], alpha, gamma, rlb[2]];
    }
    // Rz(β) Rx(α) Rz(γ) with α = 0 or π: the x column turns by β + γ or β − γ.
    let l = p.x.hypot(p.y);
    let beta = if l > 0.0 { p.y.atan2(p.x) } else { 0.0 };
    let nx = n.y.atan2(n.x);
    let gamma = if a.z > 0.0 { nx - beta } else { beta - nx };
    [beta, p.z, l, alpha, gamma, 0.0]
}

/// Stone's S-model from the identified axes (book §4.6.5.1): frame j on axis j with its
/// origin at the circle centre (prismatic: the mean point), z along the signed axis and x
/// towards the first measured point ([`JointAxis::x_axis`]); `base` is the fixed frame6 of
/// frame 1 in the instrument frame (the book's `B₀ B₁`), each joint link the S-model link
/// `Sⱼ⁻¹ Sⱼ₊₁` (eq. 4.302) and the last joint's link `Sₙ⁻¹ T₀` to the measured target frame
/// at q = 0 (`tool_pose_at_zero`), followed by an identity `tool`. Forward kinematics are
/// exact for all q. Errors unless every axis was swept with all other joints at 0.
pub fn axes_to_s_model(
    axes: &AxesResult,
    tool_pose_at_zero: &Pose<f64>,
) -> Result<ModelSpec, Error> {
    check_zero_reference(axes)?;
    let frames: Vec<Pose<f64>> = axes
        .axes
        .iter()
        .map(|a| {
            let z = a.direction.normalize();
            let x = (a.x_axis - z * a.x_axis.dot(&z)).normalize();
            Pose {
                rot: Matrix3::from_columns(&[x, z.cross(&x), z]),
                trans: a.point,
            }
        })
        .collect();
    let Some(first) = frames.first() else {
        return Err(Error::Input("no joint axes to build an S-model on".into()));
    };
    let frame6 = |name: &str, pose: &Pose<f64>| {
        let (xyz, rpy) = pose.to_xyz_rpy();
        LinkSpec {
            name: name.into(),
            geometry: LinkGeometry::frame6(xyz, rpy),
            joint: None,
        }
    };
    let mut links = vec![frame6("base", first)];
    for (i, a) in axes.axes.iter().enumerate() {
        let next = frames.get(i + 1).unwrap_or(tool_pose_at_zero);
        let rel = frames[i].inverse().compose(next);
        links.push(LinkSpec {
            name: a.link.clone(),
            geometry: LinkGeometry::new(Convention::SModel, s_model_params(&rel).to_vec()),
            joint: Some(a.joint.clone()),
        });
    }
    links.push(frame6("tool", &Pose::identity()));
    let spec = ModelSpec {
        name: format!("{}-cpa-s", axes.model),
        instrument: None,
        links,
        targets: vec![],
    };
    Model::from_spec(&spec)?;
    Ok(spec)
}

/// DH model from the identified axes: [`axes_to_zrp`] then [`convert::zrp_to_dh`] (with
/// `nominal` choosing Hayati links and the signs, as there).
pub fn axes_to_dh(
    axes: &AxesResult,
    tool_pose_at_zero: &Pose<f64>,
    nominal: Option<&ModelSpec>,
) -> Result<ModelSpec, Error> {
    convert::zrp_to_dh(&axes_to_zrp(axes, tool_pose_at_zero)?, nominal)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::kinematics::{forward_kinematics, tool_pose, Data};
    use crate::robots;
    use crate::sim::{perturbed_truth, Perturbation};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    /// The paper robot with a point target 300 mm off the flange and off axis 6.
    fn paper_with_target() -> Model {
        let mut spec = robots::robot("paper").unwrap().spec;
        spec.targets.push(LinkSpec {
            name: "smr".into(),
            geometry: LinkGeometry::point([120.0, -80.0, 300.0]),
            joint: None,
        });
        Model::from_spec(&spec).unwrap()
    }

    /// Sweeps every joint over ±`half_span` (deg, clamped to its limits) in 15 steps, others
    /// at 0.
    fn sweeps(
        model: &Model,
        truth: &[f64],
        half_span: f64,
        sigma: f64,
        seed: u64,
    ) -> Vec<JointSweep> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let normal = Normal::new(0.0, 1.0).unwrap();
        let mut data = Data::<f64>::new(model);
        let (lo, hi) = model.joint_limits();
        (0..model.dof())
            .map(|j| {
                let a = lo[j].max(-half_span.to_radians());
                let b = hi[j].min(half_span.to_radians());
                let mut s = JointSweep {
                    joint: j,
                    q: vec![],
                    points: vec![],
                };
                for i in 0..15 {
                    let mut q = vec![0.0; model.dof()];
                    q[j] = a + (b - a) * i as f64 / 14.0;
                    forward_kinematics(model, &mut data, truth, &q);
                    let noise = Vector3::from_fn(|_, _| sigma * normal.sample(&mut rng));
                    s.points.push(data.targets[0].trans + noise);
                    s.q.push(q);
                }
                s
            })
            .collect()
    }

    /// True axes at q = 0: direction `w`, point `w × v / |w|²`.
    fn true_axes(model: &Model, truth: &[f64]) -> Vec<(Vector3<f64>, Vector3<f64>)> {
        let mut data = Data::<f64>::new(model);
        forward_kinematics(model, &mut data, truth, &vec![0.0; model.dof()]);
        data.joint_twists
            .iter()
            .map(|t| {
                let n2 = t.w.norm_squared();
                (t.w / n2.sqrt(), t.w.cross(&t.v) / n2)
            })
            .collect()
    }

    /// (angle between directions, distance of the fitted point from the true line).
    fn axis_errors(a: &JointAxis, t: &(Vector3<f64>, Vector3<f64>)) -> (f64, f64) {
        let angle = a.direction.cross(&t.0).norm().atan2(a.direction.dot(&t.0));
        let dist = (a.point - t.1).cross(&t.0).norm();
        (angle, dist)
    }

    fn target_at_zero(model: &Model, truth: &[f64]) -> Pose<f64> {
        let mut data = Data::<f64>::new(model);
        forward_kinematics(model, &mut data, truth, &vec![0.0; model.dof()]);
        data.targets[0]
    }

    /// Largest FK difference (mm; rotation matrices, Frobenius ≈ √2 × angle) between `spec`'s tool and the truth's target.
    fn fk_error(model: &Model, truth: &[f64], spec: &ModelSpec) -> (f64, f64) {
        let m = Model::from_spec(spec).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let (lo, hi) = model.joint_limits();
        let mut data = Data::<f64>::new(model);
        let (mut dp, mut dr) = (0.0f64, 0.0f64);
        for _ in 0..50 {
            let q: Vec<f64> = (0..model.dof())
                .map(|j| rng.random_range(lo[j]..=hi[j]))
                .collect();
            forward_kinematics(model, &mut data, truth, &q);
            let t = data.targets[0];
            let p = tool_pose(&m, &m.nominal(), &q);
            dp = dp.max((p.trans - t.trans).norm());
            // Frobenius norm: `rotation_angle_to` (an arccos) bottoms out near 1e-8.
            dr = dr.max((p.rot - t.rot).norm());
        }
        (dp, dr)
    }

    fn truth(model: &Model) -> Vec<f64> {
        let p = Perturbation {
            all: true,
            ..Default::default()
        };
        perturbed_truth(model, &p, 11)
    }

    #[test]
    fn noise_free_axes_are_exact_and_rebuild_the_robot() {
        let model = paper_with_target();
        let truth = truth(&model);
        let result = identify_axes(&model, &sweeps(&model, &truth, 30.0, 0.0, 1)).unwrap();
        let t = true_axes(&model, &truth);
        for (a, t) in result.axes.iter().zip(&t) {
            let (angle, dist) = axis_errors(a, t);
            eprintln!(
                "noise-free {}: angle {angle:.2e} rad, distance {dist:.2e} mm, r {:.1} mm, rms {:.1e}",
                a.link, a.radius, a.rms
            );
            assert!(angle < 1e-9 && dist < 1e-9, "{}: {angle} {dist}", a.link);
        }
        let tool = target_at_zero(&model, &truth);
        let zrp = axes_to_zrp(&result, &tool).unwrap();
        let (dp, dr) = fk_error(&model, &truth, &zrp);
        eprintln!("noise-free ZRP FK error: {dp:.2e} mm, {dr:.2e} rad");
        assert!(dp < 1e-6 && dr < 1e-9, "{dp} {dr}");
        let nominal = robots::robot("paper").unwrap().spec;
        let dh = axes_to_dh(&result, &tool, Some(&nominal)).unwrap();
        let (dp, dr) = fk_error(&model, &truth, &dh);
        eprintln!("noise-free DH FK error: {dp:.2e} mm, {dr:.2e} rad");
        assert!(dp < 1e-6 && dr < 1e-9, "{dp} {dr}");
        let sm = axes_to_s_model(&result, &tool).unwrap();
        let (dp, dr) = fk_error(&model, &truth, &sm);
        eprintln!("noise-free S-model FK error: {dp:.2e} mm, {dr:.2e} rad");
        assert!(dp < 1e-6 && dr < 1e-9, "{dp} {dr}");
    }

    /// Linearised precision of a circle fit with n points of noise σ per coordinate on an
    /// arc: the plane tilts about the chord by ≈ σ/s₂ and the centre moves along the arc's
    /// bisector by ≈ σ r/s₂, where s₂ = √n × (RMS in-plane spread of the points across the
    /// chord) is the second singular value of the centred points (the centre and radius
    /// columns of the geometric Jacobian differ only by that spread). For ±30°, 15 points,
    /// r = 300 mm: s₂ ≈ 45 mm, σ = 0.01 → 2e-4 rad, 0.07 mm. The test allows 5 of these
    /// (and √2 for the distance, which has a tilt and an in-plane part).
    #[test]
    fn noisy_axes_are_within_their_precision() {
        let model = paper_with_target();
        let truth = truth(&model);
        let sigma = 0.01;
        let sw = sweeps(&model, &truth, 30.0, sigma, 2);
        let result = identify_axes(&model, &sw).unwrap();
        let t = true_axes(&model, &truth);
        for ((a, t), s) in result.axes.iter().zip(&t).zip(&sw) {
            let (_, _, sv) = principal_axes(&s.points);
            let (angle, dist) = axis_errors(a, t);
            let angle_bound = 5.0 * sigma / sv[1];
            let dist_bound = 5.0 * 2f64.sqrt() * sigma * a.radius / sv[1];
            eprintln!(
                "σ = {sigma} mm {}: angle {angle:.2e} rad (bound {angle_bound:.2e}), distance \
                 {dist:.2e} mm (bound {dist_bound:.2e}), rms {:.2e} mm",
                a.link, a.rms
            );
            assert!(angle < angle_bound, "{}: angle {angle}", a.link);
            assert!(dist < dist_bound, "{}: distance {dist}", a.link);
            assert!(a.rms < 3.0 * sigma, "{}: rms {}", a.link, a.rms);
        }
        let tool = target_at_zero(&model, &truth);
        let nominal = robots::robot("paper").unwrap().spec;
        for (what, spec) in [
            ("ZRP", axes_to_zrp(&result, &tool).unwrap()),
            ("DH", axes_to_dh(&result, &tool, Some(&nominal)).unwrap()),
            ("S-model", axes_to_s_model(&result, &tool).unwrap()),
        ] {
            let (dp, dr) = fk_error(&model, &truth, &spec);
            eprintln!("σ = {sigma} mm {what} FK error (exact tool at 0): {dp:.3} mm, {dr:.2e}");
        }
    }

    /// `n` points with noise σ per coordinate on an arc of `span` (rad, starting at angle
    /// `start`) of the circle (centre, normal, radius) = (c, z, r) of a frame tilted
    /// arbitrarily, evenly spaced.
    fn noisy_arc(
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
    fn suggested_span_reaches_the_limits() {
        let (r, n, sigma) = (300.0, 13, 1.0);
        let span = span_for_limits(r, n, sigma).unwrap();
        // The warning's sweep, made with the same noise: the RMS errors of the axes fitted
        // to it meet the tighter of the two limits.
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        let (_, c, normal) = noisy_arc(r, span, n, 0.0, &mut rng);
        let (mut angle2, mut dist2) = (0.0, 0.0);
        let runs = 300;
        for _ in 0..runs {
            let f = fit_circle(&noisy_arc(r, span, n, sigma, &mut rng).0).unwrap();
            angle2 += f.normal.angle(&normal).powi(2);
            dist2 += (f.centre - c).cross(&normal).norm_squared();
        }
        let k_dir = (angle2 / runs as f64).sqrt().to_degrees() / MAX_SIGMA_DIRECTION_DEG;
        let k_point = (dist2 / runs as f64).sqrt() / MAX_SIGMA_POINT_MM;
        eprintln!(
            "r {r} mm, {n} points, σ {sigma} mm: sweep {:.1}° gives σ direction {k_dir:.3} and σ \
             point {k_point:.3} × their limits (Monte Carlo)",
            span.to_degrees()
        );
        assert!(
            (0.85..1.1).contains(&k_dir.max(k_point)),
            "{k_dir} {k_point}"
        );
        // Shorter sweeps do not reach them; a full turn at 50 mm noise does not either.
        let planned = planned_circle_covariance(r, n, 0.95 * span, sigma).unwrap();
        assert!(
            planned.sigma_direction().to_degrees() > MAX_SIGMA_DIRECTION_DEG
                || planned.sigma_point() > MAX_SIGMA_POINT_MM
        );
        assert!(span_for_limits(r, n, 50.0).is_none());
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
    fn untrustworthy_axes_are_warned_about() {
        let model = paper_with_target();
        let truth = truth(&model);
        // A long clean sweep: every axis trusted, with small σ's.
        let clean = identify_axes(&model, &sweeps(&model, &truth, 60.0, 0.01, 3)).unwrap();
        for a in &clean.axes {
            let cov = a.covariance.as_ref().unwrap();
            eprintln!(
                "±60°, σ 0.01 mm {}: σ direction {:.4}°, σ point {:.4} mm, σ̂ {:.4} mm",
                a.link,
                cov.sigma_direction().to_degrees(),
                cov.sigma_point(),
                cov.sigma_noise
            );
            assert!(a.warning.is_none(), "{:?}", a.warning);
        }
        assert_eq!(clean.warnings().count(), 0);
        // σ = 1 mm on ±12°: every axis warned about, with its numbers and remedies.
        let noisy = identify_axes(&model, &sweeps(&model, &truth, 12.0, 1.0, 3)).unwrap();
        let t = true_axes(&model, &truth);
        for (a, t) in noisy.axes.iter().zip(&t) {
            let w = a.warning.as_deref().expect("a warning");
            eprintln!("{w}");
            let cov = a.covariance.as_ref().unwrap();
            let sd = cov.sigma_direction().to_degrees();
            assert!(sd > MAX_SIGMA_DIRECTION_DEG, "{}: {sd}", a.link);
            assert!(w.starts_with(&a.joint.name), "{w}");
            for needle in [
                "over 24.0°",
                &format!("σ direction {sd:.3}°"),
                "shorter than 30°",
                "a sweep of ",
                "° with as many points",
                "points (σ ∝ 1/√n)",
            ] {
                assert!(w.contains(needle), "{needle}: {w}");
            }
            // The σ's say how far off the axis is: the actual error is within 4 σ.
            let (angle, dist) = axis_errors(a, t);
            assert!(angle < 4.0 * cov.sigma_direction(), "{}: {angle}", a.link);
            assert!(dist < 4.0 * cov.sigma_point(), "{}: {dist}", a.link);
        }
        // Three points: an exact fit, no σ, a warning asking for more points.
        let mut few = sweeps(&model, &truth, 30.0, 0.01, 3);
        for s in &mut few {
            s.q.truncate(3);
            s.points.truncate(3);
        }
        let r = identify_axes(&model, &few).unwrap();
        let w = r.axes[0].warning.as_deref().unwrap();
        assert!(r.axes[0].covariance.is_none());
        assert!(
            w.contains("fit a circle exactly") && w.contains("at least 7 points"),
            "{w}"
        );
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
        let (n, c, rms) = fit_plane(&pts).unwrap();
        assert!(n.cross(&Vector3::z()).norm() < 1e-12 && (c.z - 3.0).abs() < 1e-12);
        assert!(rms < 1e-12);
    }

    #[test]
    fn prismatic_axis_and_zero_reference_check() {
        let spec = ModelSpec {
            name: "rp".into(),
            instrument: None,
            links: vec![
                LinkSpec {
                    name: "base".into(),
                    geometry: LinkGeometry::frame6([0.0; 3], [0.0; 3]),
                    joint: None,
                },
                LinkSpec {
                    name: "j1".into(),
                    geometry: LinkGeometry::zrp([0.1, 0.0, 1.0], [10.0, 20.0, 0.0], 0.0),
                    joint: Some(Joint {
                        name: "q1".into(),
                        kind: JointKind::Revolute,
                        lower: -3.0,
                        upper: 3.0,
                    }),
                },
                LinkSpec {
                    name: "j2".into(),
                    geometry: LinkGeometry::zrp([1.0, 0.2, 0.1], [0.0; 3], 0.0),
                    joint: Some(Joint {
                        name: "d2".into(),
                        kind: JointKind::Prismatic,
                        lower: -500.0,
                        upper: 500.0,
                    }),
                },
                LinkSpec {
                    name: "tool".into(),
                    geometry: LinkGeometry::frame6([300.0, 50.0, 40.0], [0.1, 0.2, 0.3]),
                    joint: None,
                },
            ],
            targets: vec![],
        };
        let model = Model::from_spec(&spec).unwrap();
        let params = model.nominal();
        let sweep = |j: usize, vals: &[f64], other: f64| {
            let q: Vec<Vec<f64>> = vals
                .iter()
                .map(|&v| {
                    let mut q = vec![other; 2];
                    q[j] = v;
                    q
                })
                .collect();
            let points = q
                .iter()
                .map(|q| tool_pose(&model, &params, q).trans)
                .collect();
            JointSweep {
                joint: j,
                q,
                points,
            }
        };
        // Joint values out of order: the sign comes from the joint values, not the order.
        let sw = vec![
            sweep(0, &[0.2, -0.3, 0.0, 0.4], 0.0),
            sweep(1, &[50.0, -20.0, 10.0], 0.0),
        ];
        let r = identify_axes(&model, &sw).unwrap();
        let t = true_axes(&model, &params);
        assert!(axis_errors(&r.axes[0], &t[0]).0 < 1e-12);
        assert!(axis_errors(&r.axes[0], &t[0]).1 < 1e-9);
        let d = r.axes[1].direction;
        assert!((d - Vector3::new(1.0, 0.2, 0.1).normalize()).norm() < 1e-12);
        let zrp = axes_to_zrp(&r, &tool_pose(&model, &params, &[0.0, 0.0])).unwrap();
        let m = Model::from_spec(&zrp).unwrap();
        let s =
            Model::from_spec(&axes_to_s_model(&r, &tool_pose(&model, &params, &[0.0; 2])).unwrap())
                .unwrap();
        for q in [[0.5, 100.0], [-1.0, -30.0]] {
            let a = tool_pose(&m, &m.nominal(), &q);
            let b = tool_pose(&model, &params, &q);
            assert!((a.trans - b.trans).norm() < 1e-9);
            let c = tool_pose(&s, &s.nominal(), &q);
            assert!((c.trans - b.trans).norm() < 1e-9 && (c.rot - b.rot).norm() < 1e-12);
        }
        // Swept with the other joint away from zero: axes come out, a ZRP build refuses.
        let sw = vec![
            sweep(0, &[0.2, -0.3, 0.0], 0.0),
            sweep(1, &[50.0, -20.0, 10.0], 0.5),
        ];
        let r = identify_axes(&model, &sw).unwrap();
        assert!(axes_to_zrp(&r, &Pose::identity()).is_err());
        assert!(axes_to_s_model(&r, &Pose::identity()).is_err());
        // Another joint moving within a sweep, a missing joint.
        let mut bad = sweep(0, &[0.2, -0.3, 0.0], 0.0);
        bad.q[1][1] = 1.0;
        assert!(identify_axes(&model, &[bad, sweep(1, &[1.0, 2.0], 0.0)]).is_err());
        assert!(identify_axes(&model, &[sweep(1, &[1.0, 2.0], 0.0)]).is_err());
    }
}
