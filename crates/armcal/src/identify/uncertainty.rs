//! Uncertainty of an estimate: parameter covariance C_p, correlations, the a-posteriori
//! variance factor with its χ² test, and the TCP covariance C_s at working configurations —
//! by the constrained formulation (paper eq. 19) and by `C_s = G C_p Gᵀ` (paper appendix).

use crate::linalg::unit_diagonal;
use crate::model::{
    forward_kinematics, identification_jacobian, Data, Model, Observed, Rows, Segment, Unit,
};
use crate::Error;
use nalgebra::{DMatrix, DMatrixView, DVector, Matrix3};
use serde::{Deserialize, Serialize};
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// Parameter covariance and what follows from it.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ParameterUncertainty {
    /// `C_p = (F₁ᵀF₁)⁻¹` with the whitened Jacobian F₁ (paper §1.1): the covariance implied by
    /// the stated measurement σ (internal units: mm, rad).
    pub covariance: DMatrix<f64>,
    /// √diag(C_p).
    pub sigma: Vec<f64>,
    /// Correlation matrix `ρ_ab = C_p[a,b] / (σ_a σ_b)`.
    pub correlation: DMatrix<f64>,
    /// Pairs of free-parameter columns with |ρ| > 0.95, and ρ.
    pub strong_correlations: Vec<(usize, usize, f64)>,
    /// A-posteriori variance factor σ̂₀² = rᵀr / (m − n); ≈ 1 if σ and the model are right.
    /// NaN (`null` in the file) without degrees of freedom.
    #[serde(deserialize_with = "crate::json::nan_from_null")]
    pub variance_factor: f64,
    /// Degrees of freedom m − n.
    pub dof: usize,
    /// rᵀr, χ²(m − n)-distributed under the model.
    pub chi2: f64,
    /// P(χ² ≥ rᵀr); NaN (`null` in the file) without degrees of freedom.
    #[serde(deserialize_with = "crate::json::nan_from_null")]
    pub p_value: f64,
    /// Two-sided test at 5 %: "consistent", "residuals too large", "residuals too small".
    pub verdict: String,
}

/// The two-sided χ² test at 5 % of the a-posteriori variance factor: under the model (right
/// σ, right kinematics, no outliers) `rᵀr ~ χ²(m − n)`, so `P(χ² ≥ rᵀr) < 0.025` says the
/// residuals are too large for the stated σ and `> 0.975` too small (the global
/// test of a least-squares adjustment).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Chi2Outcome {
    /// `0.025 ≤ P(χ² ≥ rᵀr) ≤ 0.975`: the residuals agree with the stated σ.
    Consistent,
    /// Residuals too large: the stated σ is too small (or model error, or outliers).
    SigmaTooSmall,
    /// Residuals too small: the stated σ is too large.
    SigmaTooLarge,
    /// No redundancy (m = n): nothing to test.
    Untestable,
}

impl Chi2Outcome {
    /// The outcome for `dof` degrees of freedom and p-value `P(χ² ≥ rᵀr)`.
    pub fn of(dof: usize, p_value: f64) -> Chi2Outcome {
        if dof == 0 || p_value.is_nan() {
            Chi2Outcome::Untestable
        } else if p_value < 0.025 {
            Chi2Outcome::SigmaTooSmall
        } else if p_value > 0.975 {
            Chi2Outcome::SigmaTooLarge
        } else {
            Chi2Outcome::Consistent
        }
    }

    /// One phrase for the outcome (the text of [`ParameterUncertainty::verdict`]).
    pub fn describe(self) -> &'static str {
        match self {
            Chi2Outcome::Consistent => "consistent with the stated σ",
            Chi2Outcome::SigmaTooSmall => {
                "residuals too large for the stated σ (σ too small, model error, or outliers)"
            }
            Chi2Outcome::SigmaTooLarge => "residuals too small for the stated σ (σ too large)",
            Chi2Outcome::Untestable => "no redundancy (m = n): cannot test",
        }
    }
}

/// Covariance and tests from the whitened Jacobian `j` and residual `r` at a solution.
/// Fails, naming the columns, if `jᵀj` is singular.
pub fn parameter_uncertainty(
    j: &DMatrix<f64>,
    r: &DVector<f64>,
    names: &[String],
) -> Result<ParameterUncertainty, Error> {
    let n = j.ncols();
    let info = crate::linalg::gram(j.as_view());
    let cov = information_inverse(&info, names)?;
    let sigma: Vec<f64> = (0..n).map(|k| cov[(k, k)].max(0.0).sqrt()).collect();
    let correlation =
        DMatrix::from_fn(n, n, |a, b| cov[(a, b)] / (sigma[a] * sigma[b]).max(1e-300));
    let mut strong = Vec::new();
    for a in 0..n {
        for b in a + 1..n {
            if correlation[(a, b)].abs() > 0.95 {
                strong.push((a, b, correlation[(a, b)]));
            }
        }
    }
    let m = j.nrows();
    let dof = m.saturating_sub(n);
    let chi2 = r.norm_squared();
    let p_value = if dof == 0 {
        f64::NAN
    } else {
        let d = ChiSquared::new(dof as f64).map_err(|e| Error::Numerical(e.to_string()))?;
        1.0 - d.cdf(chi2)
    };
    let verdict = Chi2Outcome::of(dof, p_value).describe().to_string();
    Ok(ParameterUncertainty {
        covariance: cov,
        sigma,
        correlation,
        strong_correlations: strong,
        variance_factor: if dof > 0 { chi2 / dof as f64 } else { f64::NAN },
        dof,
        chi2,
        p_value,
        verdict,
    })
}

/// `(JᵀJ)⁻¹` by Cholesky; if singular, an error naming the parameters in the null space.
pub fn information_inverse(info: &DMatrix<f64>, names: &[String]) -> Result<DMatrix<f64>, Error> {
    let n = info.nrows();
    // Scale to unit diagonal so the test for singularity is unit-free.
    let (scaled, d) = unit_diagonal(info).map_err(|k| {
        Error::Input(format!(
            "parameter `{}` has no effect on the measurements: it cannot be identified (fix it)",
            names[k]
        ))
    })?;
    let eig = scaled.clone().symmetric_eigen();
    let min = eig.eigenvalues.min();
    let max = eig.eigenvalues.max();
    if min <= 1e-14 * max {
        let k = eig.eigenvalues.imin();
        let v = eig.eigenvectors.column(k);
        let mut involved: Vec<(usize, f64)> = (0..n)
            .map(|i| (i, v[i].abs()))
            .filter(|x| x.1 > 0.05)
            .collect();
        involved.sort_by(|a, b| b.1.total_cmp(&a.1));
        let list: Vec<String> = involved
            .iter()
            .map(|(i, _)| format!("`{}`", names[*i]))
            .collect();
        return Err(Error::Input(format!(
            "the parameters are not all identifiable from these measurements: {} move the measurements in the same way (rank deficient; fix one of them or measure more varied poses)",
            list.join(", ")
        )));
    }
    let inv = scaled
        .cholesky()
        .ok_or_else(|| Error::Numerical("the information matrix is not positive definite".into()))?
        .inverse();
    Ok(DMatrix::from_fn(n, n, |a, b| inv[(a, b)] / (d[a] * d[b])))
}

/// Covariance of the TCP position (tool origin in the instrument frame) at one working
/// configuration.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TcpCovariance {
    /// Name of the working configuration.
    pub name: String,
    /// `C_s = G C_p Gᵀ` (mm²), G = ∂TCP/∂p.
    pub covariance: Matrix3<f64>,
    /// (1/3) tr(C_s) (mm²): the paper's KPI criterion φ_A(C_s).
    pub kpi: f64,
    /// The covariance of the TCP position in the robot base (world) frame, `G_w C_p G_wᵀ`
    /// (`tcp_jacobian_world`): where the robot's TCP is, without the uncertainty of the
    /// instrument's own pose that the instrument-frame C_s includes; `None` in files of an
    /// older armcal.
    #[serde(default)]
    pub covariance_base: Option<Matrix3<f64>>,
    /// (1/3) tr of the covariance of the TCP orientation (the tool frame's small rotation
    /// vector in the instrument frame, `G_ω C_p G_ωᵀ` with `tcp_orientation_jacobian`),
    /// deg²: the orientation's KPI beside the position's, for a design whose instrument
    /// measures orientations (`with_orientation`); `None` otherwise (a position-only
    /// design holds the tool's orientation parameters fixed, so it would state them exact).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orientation_kpi_deg2: Option<f64>,
}

/// `G_w` rows (3 per working configuration) of the TCP position in the world (robot base)
/// frame w.r.t. the free parameters: a chain parameter moves the tool origin p by its world
/// twist's point velocity `ω × p + v`; the instrument's and the targets' parameters do not
/// move it.
pub fn tcp_jacobian_world(
    model: &Model,
    params: &[f64],
    free: &[usize],
    working: &[Vec<f64>],
) -> DMatrix<f64> {
    tcp_rows(model, params, free, working, |data, g, row| {
        let p = data.tool().trans;
        for (c, &j) in free.iter().enumerate() {
            if model.registry.get(j).segment == Segment::Chain {
                let v = data.param_twists[j].point_velocity(&p);
                g.view_mut((row, c), (3, 1)).copy_from(&v);
            }
        }
    })
}

/// The `3·working × free` matrix whose rows `fill(data, g, 3i)` writes from the forward
/// kinematics at working configuration `i`.
fn tcp_rows(
    model: &Model,
    params: &[f64],
    free: &[usize],
    working: &[Vec<f64>],
    mut fill: impl FnMut(&Data<f64>, &mut DMatrix<f64>, usize),
) -> DMatrix<f64> {
    let mut g = DMatrix::zeros(3 * working.len(), free.len());
    let mut data = Data::new(model);
    for (i, q) in working.iter().enumerate() {
        forward_kinematics(model, &mut data, params, q);
        fill(&data, &mut g, 3 * i);
    }
    g
}

/// `cs` with their base-frame covariances `G_w C_p G_wᵀ` set (`g_world` from
/// [`tcp_jacobian_world`], same working configurations and columns as `cp`).
pub fn with_base_frame(
    mut cs: Vec<TcpCovariance>,
    g_world: &DMatrix<f64>,
    cp: &DMatrix<f64>,
) -> Vec<TcpCovariance> {
    let cw = g_world * cp * g_world.transpose();
    for (i, c) in cs.iter_mut().enumerate() {
        c.covariance_base = Some(cw.fixed_view::<3, 3>(3 * i, 3 * i).into_owned());
    }
    cs
}

/// `cs` with their orientation KPIs `(1/3) tr G_ω C_p G_ωᵀ` (deg²) set (`g_orientation`
/// from [`tcp_orientation_jacobian`], same working configurations and columns as `cp`).
pub fn with_orientation(
    mut cs: Vec<TcpCovariance>,
    g_orientation: &DMatrix<f64>,
    cp: &DMatrix<f64>,
) -> Vec<TcpCovariance> {
    let deg2 = Unit::Rad.display_factor().powi(2);
    for (i, c) in cs.iter_mut().enumerate() {
        let g = g_orientation.rows(3 * i, 3);
        c.orientation_kpi_deg2 = Some((g * cp).component_mul(&g).sum() / 3.0 * deg2);
    }
    cs
}

/// `G_ω` rows (3 per working configuration) of the TCP orientation w.r.t. the free
/// parameters: the rotation rows of the tool frame's identification Jacobian, the small
/// rotation vector in the instrument frame (book eqs. 4.14–4.20, as a pose measurement's).
pub fn tcp_orientation_jacobian(
    model: &Model,
    params: &[f64],
    free: &[usize],
    working: &[Vec<f64>],
) -> DMatrix<f64> {
    let mut pose = DMatrix::zeros(6, free.len());
    tcp_rows(model, params, free, working, |data, g, row| {
        identification_jacobian(model, data, Observed::Tool, Rows::Pose, free, &mut pose, 0);
        g.rows_mut(row, 3).copy_from(&pose.rows(3, 3));
    })
}

/// `G` rows (3 per working configuration) of the TCP position w.r.t. the free parameters.
pub fn tcp_jacobian(
    model: &Model,
    params: &[f64],
    free: &[usize],
    working: &[Vec<f64>],
) -> DMatrix<f64> {
    tcp_rows(model, params, free, working, |data, g, row| {
        identification_jacobian(model, data, Observed::Tool, Rows::Position, free, g, row);
    })
}

/// `C_s = G C_p Gᵀ` per working configuration (paper appendix).
pub fn tcp_covariance(g: &DMatrix<f64>, cp: &DMatrix<f64>, names: &[String]) -> Vec<TcpCovariance> {
    let cs = g * cp * g.transpose();
    names
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let c: Matrix3<f64> = cs.fixed_view::<3, 3>(3 * i, 3 * i).into_owned();
            TcpCovariance {
                name: name.clone(),
                kpi: c.trace() / 3.0,
                covariance: c,
                covariance_base: None,
                orientation_kpi_deg2: None,
            }
        })
        .collect()
}

/// The covariance of v = (p, s) by the constrained least-squares formulation of paper
/// eq. 19: `C_v = [I 0] [[F₁ᵀF₁, F₂ᵀ], [F₂, 0]]⁻¹ [I; 0]` with `F₁ = [J, 0]` and
/// `F₂ = [G, −I]` (the KPI constraint `TCP(p, q_work) − s = 0`). Returns the `s` block.
pub fn tcp_covariance_constrained(
    j: &DMatrix<f64>,
    g: &DMatrix<f64>,
) -> Result<DMatrix<f64>, Error> {
    let (np, ns) = (j.ncols(), g.nrows());
    let nv = np + ns;
    let mut kkt = DMatrix::zeros(nv + ns, nv + ns);
    kkt.view_mut((0, 0), (np, np))
        .copy_from(&crate::linalg::gram(j.as_view()));
    kkt.view_mut((nv, 0), (ns, np)).copy_from(g);
    kkt.view_mut((0, nv), (np, ns)).copy_from(&g.transpose());
    for k in 0..ns {
        kkt[(nv + k, np + k)] = -1.0;
        kkt[(np + k, nv + k)] = -1.0;
    }
    let inv = kkt
        .lu()
        .try_inverse()
        .ok_or_else(|| Error::Numerical("the KKT matrix of paper eq. 19 is singular".into()))?;
    Ok(inv.view((np, np), (ns, ns)).into_owned())
}

/// Observability indices of a (whitened) identification Jacobian with singular values
/// σ₁ ≥ … ≥ σₙ and m rows (book §4.5.3, paper eqs. 8–10; Sun & Hollerbach 2008 numbering):
/// O1 = (σ₁⋯σₙ)^{1/n}/√m (Borm & Menq), O2 = σₙ/σ₁ (inverse condition number),
/// O3 = σₙ (minimum singular value), O4 = σₙ²/σ₁ (noise amplification index),
/// O5 = 1/Σ(1/σᵢ). Larger is better for all five. `condition_number` = σ₁/σₙ of the
/// column-normalised Jacobian (unit-free; book eq. 4.174 corrected: κ of J, not of JᵀJ).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Observability {
    /// O1 = (σ₁⋯σₙ)^{1/n}/√m (Borm & Menq).
    pub o1: f64,
    /// O2 = σₙ/σ₁, the inverse condition number.
    pub o2: f64,
    /// O3 = σₙ, the minimum singular value.
    pub o3: f64,
    /// O4 = σₙ²/σ₁, the noise amplification index.
    pub o4: f64,
    /// O5 = 1/Σ(1/σᵢ).
    pub o5: f64,
    /// σ₁/σₙ of the column-normalised Jacobian (unit-free; book eq. 4.174 corrected).
    pub condition_number: f64,
    /// Singular values σ₁ ≥ … ≥ σₙ of the Jacobian as given (not column-normalised).
    pub singular_values: Vec<f64>,
}

/// The observability indices of the whitened identification Jacobian `j` ([`Observability`]).
/// Singular values and column norms are those of `j`'s triangular factor
/// (`crate::linalg`), so a Jacobian of many rows is neither copied nor decomposed whole.
pub fn observability(j: DMatrixView<f64>) -> Observability {
    let m = j.nrows() as f64;
    let r = crate::linalg::r_factor(j);
    let s = crate::linalg::singular_values_of_factor(&r, j.nrows());
    let n = s.len() as f64;
    let (smax, smin) = (s[0], *s.last().unwrap_or(&0.0));
    let geo = (s.iter().map(|x| x.max(1e-300).ln()).sum::<f64>() / n).exp();
    let mut scaled = r;
    for c in 0..scaled.ncols() {
        let nn = scaled.column(c).norm();
        if nn > 0.0 {
            scaled.column_mut(c).unscale_mut(nn);
        }
    }
    let ss = scaled.svd(false, false).singular_values;
    Observability {
        o1: geo / m.sqrt(),
        o2: smin / smax,
        o3: smin,
        o4: smin * smin / smax,
        o5: 1.0 / s.iter().map(|x| 1.0 / x.max(1e-300)).sum::<f64>(),
        condition_number: ss.max() / ss.min().max(1e-300),
        singular_values: s,
    }
}
