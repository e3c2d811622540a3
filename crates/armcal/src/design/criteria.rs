//! Design criteria as functions of the information matrix M (C = M⁻¹), each with its
//! matrix gradient `Φ = ∂φ/∂M`, so that for any configuration variable x
//! `dφ/dx = tr(Φ dM/dx)` (paper §2.1–2.3; book §4.5 for the observability indices).
//!
//! All criteria are minimised:
//! * `A`: `tr(C)/n_p` on C_p in mm and rad, unscaled — the paper's φ_A(C_p) = tr(C_p)/27
//!   (the paper does not state a scaling; unscaled reproduces its numbers);
//!   `Φ = −C C/n_p`;
//! * `D`: `log det C / n_p`; `Φ = −C/n_p`;
//! * `E`: `λ_max(C) = 1/λ_min(M)`; `Φ = −v vᵀ/λ_min²`;
//! * `Kpi`: `Σ_w ω_w (1/3) tr(G_w C G_wᵀ) / Σ_w ω_w`, the TCP position variance at the
//!   working configurations (paper eq. 24, φ_A(C_s)); `Φ = −C HᵀH C` with `H` the stacked
//!   `√(ω_w/(3Σω)) G_w`; the working configurations are the `[[working]]` poses and every
//!   configuration of every `[[working_path]]` (a path's weight shared equally by its points);
//! * `KpiMax`: the largest TCP position variance over the same configurations (paper §6,
//!   "working path trajectories"), through the smooth maximum
//!   `φ = (Σ_k v_k^p)^{1/p}`, `v_k = (1/3) tr(G_k C G_kᵀ)`, p = [`SMOOTH_MAX_P`]
//!   (`max_k v_k ≤ φ ≤ K^{1/p} max_k v_k`; convex in M, since each v_k is and the p-norm of
//!   non-negative convex functions is); `Φ = −Σ_k (v_k/φ)^{p−1} C G_kᵀ G_k C / 3`. The
//!   weights ω do not enter a maximum;
//! * `O1`…`O5`: `−log O_k` of the observability indices (see
//!   [`crate::identify::Observability`]) written through the eigenvalues λ_i = σ_i² of M:
//!   O1 ∝ (Π λ_i)^{1/2n}, O2 = (λ_min/λ_max)^{1/2}, O3 = λ_min^{1/2},
//!   O4 = λ_min/λ_max^{1/2}, O5 = 1/Σ λ_i^{−1/2}; `Φ = Σ_i ∂φ/∂λ_i v_i v_iᵀ` (simple
//!   eigenvalues).

use crate::design::information::DesignModel;
use crate::Error;
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// A design criterion (minimised).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Criterion {
    /// `tr(C)/n_p`, C in mm and rad unscaled (paper's φ_A(C_p)).
    A,
    /// `log det C / n_p` (D-optimality).
    D,
    /// `λ_max(C) = 1/λ_min(M)` (E-optimality).
    E,
    /// Weighted mean TCP position variance at the working configurations (mm², paper eq. 24,
    /// φ_A(C_s)).
    Kpi,
    /// Largest TCP position variance over the working configurations and paths (mm², smooth
    /// maximum; paper §6).
    #[serde(rename = "kpi-max")]
    KpiMax,
    /// `−log O1`, O1 ∝ (Π σ_i)^{1/n} (Borm & Menq; book §4.5.3), σ_i = √λ_i(M).
    O1,
    /// `−log O2`, O2 = σ_min/σ_max, the inverse condition number (book §4.5.3).
    O2,
    /// `−log O3`, O3 = σ_min, the minimum singular value (book §4.5.3).
    O3,
    /// `−log O4`, O4 = σ_min²/σ_max, the noise amplification index (book §4.5.3).
    O4,
    /// `−log O5`, O5 = 1/Σ σ_i⁻¹ (book §4.5.3).
    O5,
}

impl Criterion {
    /// The criterion named `s` as [`Criterion::name`] writes it; `None` for any other name.
    pub fn from_name(s: &str) -> Option<Criterion> {
        Some(match s {
            "a" => Criterion::A,
            "d" => Criterion::D,
            "e" => Criterion::E,
            "kpi" => Criterion::Kpi,
            "kpi-max" => Criterion::KpiMax,
            "o1" => Criterion::O1,
            "o2" => Criterion::O2,
            "o3" => Criterion::O3,
            "o4" => Criterion::O4,
            "o5" => Criterion::O5,
            _ => return None,
        })
    }

    /// The criterion in words, for output: `A`, `D`, `E`, `KPI`, `O1` … `O5`.
    pub fn words(self) -> &'static str {
        match self {
            Criterion::A => "A",
            Criterion::D => "D",
            Criterion::E => "E",
            Criterion::Kpi => "KPI",
            Criterion::KpiMax => "KPI-max",
            Criterion::O1 => "O1",
            Criterion::O2 => "O2",
            Criterion::O3 => "O3",
            Criterion::O4 => "O4",
            Criterion::O5 => "O5",
        }
    }

    /// The name [`Criterion::from_name`] reads (and the files carry): `a`, `d`, `e`, `kpi`,
    /// `kpi-max`, `o1` … `o5`.
    pub fn name(self) -> &'static str {
        match self {
            Criterion::A => "a",
            Criterion::D => "d",
            Criterion::E => "e",
            Criterion::Kpi => "kpi",
            Criterion::KpiMax => "kpi-max",
            Criterion::O1 => "o1",
            Criterion::O2 => "o2",
            Criterion::O3 => "o3",
            Criterion::O4 => "o4",
            Criterion::O5 => "o5",
        }
    }

    /// Every criterion, in declaration order.
    pub const ALL: [Criterion; 10] = [
        Criterion::A,
        Criterion::D,
        Criterion::E,
        Criterion::Kpi,
        Criterion::KpiMax,
        Criterion::O1,
        Criterion::O2,
        Criterion::O3,
        Criterion::O4,
        Criterion::O5,
    ];
}

/// Value of a criterion and its gradient w.r.t. the information matrix.
#[derive(Clone, Debug)]
pub struct CriterionValue {
    /// φ(M), minimised (KPI in mm²; D and O1–O5 are logarithms).
    pub value: f64,
    /// `Φ = ∂φ/∂M` (symmetric).
    pub gradient: DMatrix<f64>,
    /// `F` with `Φ = −F Fᵀ`, when the criterion has that form with fewer columns than
    /// parameters (KPI: `F = C Hᵀ`, 3 columns per working configuration): the design
    /// gradient `∂φ/∂q = −2 ⟨J F, (∂J/∂q) F⟩` then costs O(rows · n_p · columns).
    pub factor: Option<DMatrix<f64>>,
}

/// Evaluates `criterion` for the information matrix `M = RᵀR`, given its triangular
/// factor `R` (from a QR decomposition of the stacked whitened Jacobian: C and the
/// eigenvalues of M then carry the accuracy of J, not of the squared M). Fails if M is
/// singular (the design does not identify every free parameter).
pub fn evaluate(
    criterion: Criterion,
    r: &DMatrix<f64>,
    d: &DesignModel,
) -> Result<CriterionValue, Error> {
    let n = r.nrows();
    let nf = n as f64;
    let singular = || {
        Error::Numerical("the design's information matrix is singular: it does not identify every free parameter".into())
    };
    let rmax = r.diagonal().iter().fold(0.0f64, |a, x| a.max(x.abs()));
    if r.diagonal().iter().any(|x| x.abs() <= 1e-13 * rmax) {
        return Err(singular());
    }
    match criterion {
        Criterion::Kpi => {
            // F = C Hᵀ = R⁻¹ (R⁻ᵀ Hᵀ) by two triangular solves with one right-hand side per
            // KPI row (3 per working configuration), without forming C; φ = tr(H C Hᵀ) =
            // ‖R⁻ᵀ Hᵀ‖²_F.
            let h = kpi_matrix(d)?;
            let y = r
                .tr_solve_upper_triangular(&h.transpose())
                .ok_or_else(singular)?;
            let f = r.solve_upper_triangular(&y).ok_or_else(singular)?;
            Ok(CriterionValue {
                value: y.norm_squared(),
                gradient: -(&f * f.transpose()),
                factor: (f.ncols() < n).then_some(f),
            })
        }
        Criterion::A | Criterion::D | Criterion::KpiMax => {
            // C = R⁻¹ R⁻ᵀ.
            let rinv = r
                .clone()
                .solve_upper_triangular(&DMatrix::identity(n, n))
                .ok_or_else(singular)?;
            let c = &rinv * rinv.transpose();
            Ok(match criterion {
                Criterion::A => CriterionValue {
                    value: c.trace() / nf,
                    gradient: -(&c * &c) / nf,
                    factor: None,
                },
                Criterion::D => {
                    let logdet: f64 = 2.0 * r.diagonal().iter().map(|x| x.abs().ln()).sum::<f64>();
                    CriterionValue {
                        value: -logdet / nf,
                        gradient: -c / nf,
                        factor: None,
                    }
                }
                _ => kpi_max(&c, d)?,
            })
        }
        _ => {
            // Eigenpairs of M from the SVD of R: λ_i = σ_i², v_i the right singular vectors.
            let svd = r.clone().svd(false, true);
            let vt = svd.v_t.ok_or_else(singular)?;
            let lam: Vec<f64> = svd.singular_values.iter().map(|s| s * s).collect();
            let (mut imin, mut imax) = (0, 0);
            for (i, l) in lam.iter().enumerate() {
                if *l < lam[imin] {
                    imin = i;
                }
                if *l > lam[imax] {
                    imax = i;
                }
            }
            let (lmin, lmax) = (lam[imin], lam[imax]);
            if lmin <= 1e-26 * lmax.max(1e-300) {
                return Err(singular());
            }
            // φ and ∂φ/∂λ_i.
            let mut dphi = vec![0.0; n];
            let value = match criterion {
                Criterion::E => {
                    dphi[imin] = -1.0 / (lmin * lmin);
                    1.0 / lmin
                }
                Criterion::O1 => {
                    for (g, l) in dphi.iter_mut().zip(&lam) {
                        *g = -0.5 / (nf * l);
                    }
                    -0.5 * lam.iter().map(|l| l.ln()).sum::<f64>() / nf
                }
                Criterion::O2 => {
                    dphi[imax] += 0.5 / lmax;
                    dphi[imin] -= 0.5 / lmin;
                    0.5 * (lmax.ln() - lmin.ln())
                }
                Criterion::O3 => {
                    dphi[imin] = -0.5 / lmin;
                    -0.5 * lmin.ln()
                }
                Criterion::O4 => {
                    dphi[imin] -= 1.0 / lmin;
                    dphi[imax] += 0.5 / lmax;
                    -lmin.ln() + 0.5 * lmax.ln()
                }
                Criterion::O5 => {
                    let s: f64 = lam.iter().map(|l| l.powf(-0.5)).sum();
                    for (g, l) in dphi.iter_mut().zip(&lam) {
                        *g = -0.5 * l.powf(-1.5) / s;
                    }
                    s.ln()
                }
                _ => unreachable!("handled above"),
            };
            let mut gradient = DMatrix::zeros(n, n);
            for (i, g) in dphi.iter().enumerate() {
                if *g != 0.0 {
                    let vi = vt.row(i).transpose();
                    gradient.ger(*g, &vi, &vi, 1.0);
                }
            }
            Ok(CriterionValue {
                value,
                gradient,
                factor: None,
            })
        }
    }
}

/// The exponent of [`Criterion::KpiMax`]'s smooth maximum: with K configurations the value
/// lies between the largest variance and `K^{1/p}` times it (1.15 for 100 points).
pub const SMOOTH_MAX_P: f64 = 32.0;

/// [`Criterion::KpiMax`] at `C`: the smooth maximum of the TCP variances `v_k` and its
/// matrix gradient (see the module notes). The variances are scaled by their largest before
/// the powers are taken, so that nothing underflows.
fn kpi_max(c: &DMatrix<f64>, d: &DesignModel) -> Result<CriterionValue, Error> {
    require_working(d)?;
    let g = &d.kpi_rows;
    let cg = c * g.transpose();
    let k = d.kpi_weights.len();
    let v: Vec<f64> = (0..k)
        .map(|w| {
            (0..3)
                .map(|r| g.row(3 * w + r).dot(&cg.column(3 * w + r).transpose()))
                .sum::<f64>()
                / 3.0
        })
        .collect();
    let vmax = v.iter().fold(0.0f64, |a, &x| a.max(x));
    let p = SMOOTH_MAX_P;
    let value = vmax
        * v.iter()
            .map(|x| (x / vmax).powf(p))
            .sum::<f64>()
            .powf(1.0 / p);
    let mut weighted = cg.clone();
    for (w, vw) in v.iter().enumerate() {
        let s = ((vw / value).powf(p - 1.0) / 3.0).sqrt();
        weighted.columns_mut(3 * w, 3).scale_mut(s);
    }
    Ok(CriterionValue {
        value,
        gradient: -(&weighted * weighted.transpose()),
        factor: (weighted.ncols() < c.nrows()).then_some(weighted),
    })
}

/// The KPI criteria need a working configuration.
fn require_working(d: &DesignModel) -> Result<(), Error> {
    if d.kpi_weights.is_empty() {
        return Err(Error::Input(
            "the KPI criteria need at least one [[working]] configuration or [[working_path]] in the cell".into(),
        ));
    }
    Ok(())
}

/// `H`: the KPI rows `√(ω_w / (3 Σω)) G_w` stacked.
pub(crate) fn kpi_matrix(d: &DesignModel) -> Result<DMatrix<f64>, Error> {
    require_working(d)?;
    let total: f64 = d.kpi_weights.iter().sum();
    let mut h = d.kpi_rows.clone();
    for (w, weight) in d.kpi_weights.iter().enumerate() {
        let s = (weight / (3.0 * total)).sqrt();
        h.rows_mut(3 * w, 3).scale_mut(s);
    }
    Ok(h)
}
