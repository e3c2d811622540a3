//! Nonparametric compensation (book §5.4): the position error that remains after a
//! parametric calibration is approximated by multivariate polynomials of the joint
//! configuration or of the TCP position, fitted by least squares on training points.
//!
//! * [`chebyshev_nodes`] spaces training points along one axis at the zeros of the
//!   Chebyshev polynomial (Eq. 5.195), which minimises the worst-case interpolation error.
//! * [`PolynomialBasis`] is the full basis of total degree ≤ d in k variables, in the book's
//!   order (Eq. 5.188: β0 = 1, β1 = η1, β2 = η2, β3 = η3, β4 = η1², β5 = η1η2, …,
//!   β18 = η2η3², β19 = η3³): graded by degree, lexicographic within a degree.
//! * [`PolynomialCorrection`] fits one polynomial per component of a 3-vector error, on
//!   inputs normalised to [−1, 1] from the training data's range.
//! * [`ResidualCorrection`] fits it on a calibration data set's remaining position errors,
//!   for program filtering (`compensate::program`).

use crate::error::{Error, Result};
use crate::measure::{Dataset, MeasurementKind};
use crate::model::{forward_kinematics, observed_position, Data, Model};
use nalgebra::{DMatrix, Vector3};
use serde::{Deserialize, Serialize};

/// `n` Chebyshev-spaced points on `[a, b]` (Eq. 5.195, the zeros of the degree-`n`
/// Chebyshev polynomial mapped to the interval), in the book's order (k = 0 first, which
/// is the point nearest `b`):
/// x_k = ½[(b − a) cos((2k + 1)π / (2n)) + (a + b)], k = 0, …, n − 1.
pub fn chebyshev_nodes(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let c = ((2 * k + 1) as f64 * std::f64::consts::PI / (2 * n) as f64).cos();
            0.5 * ((b - a) * c + (a + b))
        })
        .collect()
}

/// Full polynomial basis of total degree ≤ `degree` in `vars` variables. Each term is a
/// vector of exponents; terms are ordered by degree, then lexicographically with the
/// exponent of the first variable decreasing (the book's β ordering, 0-based).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PolynomialBasis {
    /// Number of input variables k.
    pub vars: usize,
    /// Largest total degree d of a term.
    pub degree: usize,
    /// Exponents of every term, `terms[j][i]` = power of variable i in β_j.
    pub terms: Vec<Vec<u32>>,
}

impl PolynomialBasis {
    /// Every monomial of total degree ≤ `degree` in `vars` variables, in the book's β order
    /// (Eq. 5.188).
    pub fn new(vars: usize, degree: usize) -> Self {
        let mut terms = Vec::new();
        for g in 0..=degree {
            let mut e = vec![0u32; vars];
            push_degree(&mut terms, &mut e, 0, g as u32);
        }
        PolynomialBasis {
            vars,
            degree,
            terms,
        }
    }

    /// Number of terms, C(vars + degree, degree).
    pub fn len(&self) -> usize {
        self.terms.len()
    }

    /// True if the basis has no terms (never for a basis built by [`PolynomialBasis::new`]).
    pub fn is_empty(&self) -> bool {
        self.terms.is_empty()
    }

    /// Values of every term at `x` (`x.len() == vars`) written into `out`.
    pub fn eval_into(&self, x: &[f64], out: &mut [f64]) {
        debug_assert_eq!(x.len(), self.vars);
        debug_assert_eq!(out.len(), self.terms.len());
        for (o, t) in out.iter_mut().zip(&self.terms) {
            *o = t.iter().zip(x).map(|(&p, &v)| v.powi(p as i32)).product();
        }
    }

    /// Values of every term at `x`.
    pub fn eval(&self, x: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.terms.len()];
        self.eval_into(x, &mut out);
        out
    }
}

/// All exponent vectors of total degree `left` over variables `i..`, lexicographic with
/// the earlier variables' exponents decreasing.
fn push_degree(terms: &mut Vec<Vec<u32>>, e: &mut [u32], i: usize, left: u32) {
    if i + 1 >= e.len() {
        if let Some(n) = e.len().checked_sub(1) {
            e[n] = left;
            terms.push(e.to_vec());
            e[n] = 0;
        } else if left == 0 {
            terms.push(Vec::new());
        }
        return;
    }
    for p in (0..=left).rev() {
        e[i] = p;
        push_degree(terms, e, i + 1, left - p);
    }
    e[i] = 0;
}

/// A fitted polynomial correction: inputs (k variables) → 3-vector error.
#[derive(Clone, Debug)]
pub struct PolynomialCorrection {
    /// The monomials the correction is a combination of.
    pub basis: PolynomialBasis,
    /// Lower bound of every input over the training data; inputs are mapped linearly from
    /// [lower, upper] to [−1, 1].
    pub lower: Vec<f64>,
    /// Upper bound of every input over the training data.
    pub upper: Vec<f64>,
    /// Coefficients, one column per output component (basis.len() × 3).
    pub coefficients: DMatrix<f64>,
    /// RMS over the training points of the 3-vector residual norm after the fit.
    pub training_rms: f64,
    /// RMS of the 3-vector error norm before the fit (for comparison).
    pub training_rms_before: f64,
}

impl PolynomialCorrection {
    /// Least-squares fit (SVD) of `errors[i] ≈ p(inputs[i])`, one polynomial of total
    /// degree ≤ `degree` per component. Needs at least as many points as basis terms.
    pub fn fit(inputs: &[Vec<f64>], errors: &[Vector3<f64>], degree: usize) -> Result<Self> {
        let m = inputs.len();
        if m == 0 || m != errors.len() {
            return Err(Error::Input(format!(
                "polynomial correction: {m} inputs and {} errors (need equal, non-zero counts)",
                errors.len()
            )));
        }
        let k = inputs[0].len();
        if let Some(bad) = inputs.iter().position(|x| x.len() != k) {
            return Err(Error::Input(format!(
                "polynomial correction: input {bad} has {} variables, input 0 has {k}",
                inputs[bad].len()
            )));
        }
        let basis = PolynomialBasis::new(k, degree);
        let p = basis.len();
        if m < p {
            return Err(Error::Input(format!(
                "polynomial correction: {m} points for {p} terms (degree {degree}, {k} variables)"
            )));
        }
        let mut lower = vec![f64::INFINITY; k];
        let mut upper = vec![f64::NEG_INFINITY; k];
        for x in inputs {
            for i in 0..k {
                if !x[i].is_finite() {
                    return Err(Error::Input(
                        "polynomial correction: non-finite input".to_string(),
                    ));
                }
                lower[i] = lower[i].min(x[i]);
                upper[i] = upper[i].max(x[i]);
            }
        }
        let mut fit = PolynomialCorrection {
            basis,
            lower,
            upper,
            coefficients: DMatrix::zeros(p, 3),
            training_rms: 0.0,
            training_rms_before: 0.0,
        };
        let mut b = DMatrix::zeros(m, p);
        let mut e = DMatrix::zeros(m, 3);
        let mut eta = vec![0.0; k];
        let mut row = vec![0.0; p];
        for (r, (x, err)) in inputs.iter().zip(errors).enumerate() {
            fit.normalise_into(x, &mut eta);
            fit.basis.eval_into(&eta, &mut row);
            for (c, v) in row.iter().enumerate() {
                b[(r, c)] = *v;
            }
            for c in 0..3 {
                e[(r, c)] = err[c];
            }
        }
        let svd = b.svd(true, true);
        let tol = 1e-12 * svd.singular_values.max();
        fit.coefficients = svd
            .solve(&e, tol)
            .map_err(|msg| Error::Numerical(format!("polynomial correction: {msg}")))?;
        let (mut ss, mut ss0) = (0.0, 0.0);
        for (x, err) in inputs.iter().zip(errors) {
            ss += (err - fit.predict(x)).norm_squared();
            ss0 += err.norm_squared();
        }
        fit.training_rms = (ss / m as f64).sqrt();
        fit.training_rms_before = (ss0 / m as f64).sqrt();
        Ok(fit)
    }

    /// Maps `x` to [−1, 1] per variable using the training range (a constant variable maps
    /// to 0). Inputs outside the range extrapolate.
    pub fn normalise_into(&self, x: &[f64], eta: &mut [f64]) {
        for i in 0..self.lower.len() {
            let half = 0.5 * (self.upper[i] - self.lower[i]);
            let mid = 0.5 * (self.upper[i] + self.lower[i]);
            eta[i] = if half > 0.0 { (x[i] - mid) / half } else { 0.0 };
        }
    }

    /// Predicted error at input `x`.
    pub fn predict(&self, x: &[f64]) -> Vector3<f64> {
        assert_eq!(x.len(), self.basis.vars, "input size");
        let mut eta = vec![0.0; x.len()];
        self.normalise_into(x, &mut eta);
        let row = self.basis.eval(&eta);
        let mut out = Vector3::zeros();
        for (j, v) in row.iter().enumerate() {
            for c in 0..3 {
                out[c] += v * self.coefficients[(j, c)];
            }
        }
        out
    }
}

/// What a [`ResidualCorrection`] is a function of.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CorrectionInputs {
    /// The arm joints q1…q3 (default). The non-geometric errors a kinematic model leaves
    /// (joint compliance under gravity, gear and encoder errors) are functions of the
    /// configuration, and the arm joints set most of it; the same TCP position reached in
    /// another configuration has another error, so joints are the better-posed input, and
    /// three of them keep the basis small (20 terms at degree 3, against 84 for six).
    ArmJoints,
    /// Every joint (for errors that depend on the wrist too).
    Joints,
    /// The TCP position in the world frame (book §5.4's workspace interpolation): fitted at
    /// the measured point, applied at the tool point.
    Position,
}

impl CorrectionInputs {
    /// The input vector at joints `q` and world position `position`.
    pub fn values(self, q: &[f64], position: &Vector3<f64>) -> Vec<f64> {
        match self {
            CorrectionInputs::ArmJoints => q[..q.len().min(3)].to_vec(),
            CorrectionInputs::Joints => q.to_vec(),
            CorrectionInputs::Position => position.iter().copied().collect(),
        }
    }
}

/// The position error a parametric calibration leaves, `e = measured − calibrated-model
/// prediction` in the world frame, as a polynomial of [`CorrectionInputs`] (book §5.4).
/// Compensation asks the calibrated model to reach `t − ê` so that the real robot, which
/// lands at `FK_cal(q) + e(q)`, reaches `t`. The error is measured at the observed point
/// (reflector) and applied at the tool point: exact for the translational part of the
/// error, approximate by (rotation error × their distance) otherwise.
#[derive(Clone, Debug)]
pub struct ResidualCorrection {
    /// What the polynomial is a function of (arm joints, all joints or TCP position).
    pub inputs: CorrectionInputs,
    /// The fitted polynomial: inputs → world-frame position error `e` (mm).
    pub polynomial: PolynomialCorrection,
}

impl ResidualCorrection {
    /// Fits on the position (and pose) measurements of `data`: the residual of each,
    /// rotated from the instrument frame into the world frame with the calibrated
    /// instrument orientation, `e = R_I (m − m̂)`. Distance measurements carry no position
    /// and are skipped.
    pub fn fit(
        model: &Model,
        calibrated: &[f64],
        data: &Dataset,
        inputs: CorrectionInputs,
        degree: usize,
    ) -> Result<Self> {
        if inputs == CorrectionInputs::ArmJoints && model.dof() < 3 {
            return Err(Error::Input(format!(
                "nonparametric correction on q1…q3: model `{}` has {} joints",
                model.name,
                model.dof()
            )));
        }
        let payloads = data.model_payloads(model)?;
        let mut fk = Data::new(model);
        let (mut xs, mut es) = (Vec::new(), Vec::new());
        for m in &data.measurements {
            let measured = match &m.kind {
                MeasurementKind::Position { value, .. } => *value,
                MeasurementKind::Pose { value, .. } => value.trans,
                _ => continue,
            };
            let q = &data.configurations[m.config];
            fk.payload = payloads[m.config];
            forward_kinematics(model, &mut fk, calibrated, q);
            let predicted = observed_position(&fk, m.observed);
            let world = fk.instrument.transform_point(&predicted);
            xs.push(inputs.values(q, &world));
            es.push(fk.instrument.rot * (measured - predicted));
        }
        if xs.is_empty() {
            return Err(Error::Input(format!(
                "nonparametric correction: `{}` has no position measurements",
                data.source
            )));
        }
        Ok(ResidualCorrection {
            inputs,
            polynomial: PolynomialCorrection::fit(&xs, &es, degree)?,
        })
    }

    /// Predicted error (world, mm) at joints `q` with the tool at `position`.
    pub fn predict(&self, q: &[f64], position: &Vector3<f64>) -> Vector3<f64> {
        self.polynomial.predict(&self.inputs.values(q, position))
    }
}
