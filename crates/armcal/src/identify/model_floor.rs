//! The model floor of the TCP covariance: what the parameters a fit holds fixed add to the
//! TCP error, given their stated prior uncertainty (`FixedPrior`).
//!
//! C_s (paper eq. 19) treats a fixed parameter as exact. A real one is off by `Δp_f` (a link
//! length along the flange axis, a tool frame from CAD), and the fit absorbs what of it the
//! data see into the free parameters. Linearised at the solution, with the whitened data
//! Jacobians `F` (free columns, prior rows included) and `F_f` (fixed columns, zero prior
//! rows), the estimate moves by `Δp̂ = Δp_true + A (F_f Δp_f + e)`, `A = C_p Fᵀ`,
//! `C_p = (FᵀF)⁻¹`; the predicted TCP minus the true one is then
//!
//! ```text
//! ΔTCP = G A e − K Δp_f,   K = G_f − G C_p Fᵀ F_f
//! ```
//!
//! (`G`, `G_f` = ∂TCP/∂p over the free and the fixed columns, tool origin in the instrument
//! frame as C_s). The first term is C_s; the second, with `Δp_f ~ N(0, Σ_f)` independent
//! of the noise, the model floor
//!
//! ```text
//! C_floor = K Σ_f Kᵀ,   C_total = C_s + C_floor.
//! ```
//!
//! A fixed parameter whose effect the free ones reproduce at the measured targets *and* at
//! the TCP gives K = 0 (`j1.d` under a free tracker pose); one they reproduce at the targets
//! only gives the full `G_f` (`j6.d` under a free reflector offset: the reflector's offset
//! absorbs it, the TCP, which does not hang from the reflector, keeps it).
//! For a parameter fixed because the data cannot separate it (`F_f` in the span of `F`),
//! `C_p Fᵀ F_f` is the design-independent combination that stands in for it, so its floor
//! does not depend on the design and does not shrink as poses are added; for a parameter
//! fixed although the data see it, the absorbed part depends on the design. Checked against a Monte Carlo of full
//! nonlinear fits on robots perturbed by the prior (`tests/suite/identify/model_floor.rs`).

use crate::cell::WorkingPose;
use crate::identify::robust::{kept_rows, Outlier};
use crate::identify::uncertainty::tcp_jacobian;
use crate::identify::Problem;
use crate::model::prior::FixedPrior;
use nalgebra::{DMatrix, DVector, Matrix3};
use serde::{Deserialize, Serialize};

/// One fixed parameter and the σ the floor gives it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FixedSigma {
    /// The parameter's name.
    pub name: String,
    /// Its display unit.
    pub unit: String,
    /// Its stated σ (display units); 0: exact (a definition).
    pub sigma: f64,
}

/// The model floor at one working configuration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TcpFloor {
    /// Name of the working configuration.
    pub name: String,
    /// `C_floor = K Σ_f Kᵀ` (mm², instrument frame, as C_s).
    pub covariance: Matrix3<f64>,
    /// (1/3) tr C_floor (mm²), the floor's part of the KPI.
    pub kpi: f64,
    /// Each fixed parameter's part of (1/3) tr C_floor (mm²), largest first; only those above
    /// 10⁻⁹ of the total (the rest is rounding of a part the free parameters absorb).
    pub contributions: Vec<(String, f64)>,
}

/// The model floor of an estimate or a design: what it assumed and what it gives.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelFloor {
    /// Every parameter the fit held fixed, with its stated σ.
    pub fixed: Vec<FixedSigma>,
    /// The floor at every working configuration, in the order of the cell's.
    pub tcp: Vec<TcpFloor>,
    /// What the fit absorbs of the fixed parameters' errors: the floor at any other
    /// configuration follows from it ([`Absorbed`]); `None` in files of an older armcal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub absorbed: Option<Absorbed>,
}

/// `A = C_p Fᵀ F_f` (module notes), the free parameters' response to the fixed ones'
/// errors, with the fixed parameters of non-zero prior σ it maps: the floor of any point the
/// model predicts at any configuration is `K Σ_f Kᵀ` with `K = G_f − G A`, `G`, `G_f` that
/// point's Jacobians (`crate::identify::prediction_sigma`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Absorbed {
    /// The fixed parameters with a non-zero prior σ, the columns of `map`.
    pub fixed: Vec<String>,
    /// Their prior σ (internal units: mm, rad).
    pub sigma: Vec<f64>,
    /// `A` (rows: the free parameters in the order of C_p; columns: `fixed`).
    pub map: DMatrix<f64>,
}

impl ModelFloor {
    /// The floor at the working configuration `name`, if any.
    pub fn at(&self, name: &str) -> Option<&TcpFloor> {
        self.tcp.iter().find(|t| t.name == name)
    }
}

/// The model floor of the fit `problem` at `params`, with `jacobian` its whitened Jacobian
/// (data and prior rows, free columns) and `cp` = C_p, at the working configurations
/// `working`, the fixed parameters distributed as `prior` (module notes).
pub fn model_floor(
    problem: &Problem,
    params: &[f64],
    jacobian: &DMatrix<f64>,
    cp: &DMatrix<f64>,
    working: &[WorkingPose],
    prior: &FixedPrior,
    outliers: &[Outlier],
) -> ModelFloor {
    let model = problem.model;
    let fixed_all: Vec<usize> = (0..model.param_count())
        .filter(|i| !problem.free.contains(i))
        .collect();
    let fixed_record = fixed_all
        .iter()
        .map(|&i| {
            let p = model.registry.get(i);
            FixedSigma {
                name: p.name.clone(),
                unit: p.unit.display_name().to_string(),
                sigma: prior.sigma(p) * p.unit.display_factor(),
            }
        })
        .collect();
    let fixed: Vec<usize> = fixed_all
        .into_iter()
        .filter(|&i| prior.sigma(model.registry.get(i)) > 0.0)
        .collect();
    let qs: Vec<Vec<f64>> = working.iter().map(|w| w.q.clone()).collect();
    let absorbed = absorbed_map(problem, params, jacobian, cp, &fixed, outliers);
    let k = tcp_jacobian(model, params, &fixed, &qs)
        - tcp_jacobian(model, params, &problem.free, &qs) * &absorbed;
    let sigma = DVector::from_iterator(
        fixed.len(),
        fixed.iter().map(|&i| prior.sigma(model.registry.get(i))),
    );
    let tcp = working
        .iter()
        .enumerate()
        .map(|(w, pose)| {
            let kw = k.rows(3 * w, 3);
            let scaled = DMatrix::from_fn(3, fixed.len(), |r, c| kw[(r, c)] * sigma[c]);
            let covariance: Matrix3<f64> = (&scaled * scaled.transpose())
                .fixed_view::<3, 3>(0, 0)
                .into_owned();
            let kpi = covariance.trace() / 3.0;
            // A parameter the free ones absorb at the TCP leaves rounding (≈ 1e-13 of the
            // total); what is below 1e-9 of it counts as nothing.
            let mut contributions: Vec<(String, f64)> = fixed
                .iter()
                .enumerate()
                .map(|(c, &i)| {
                    let part = scaled.column(c).norm_squared() / 3.0;
                    (model.registry.get(i).name.clone(), part)
                })
                .filter(|(_, part)| *part > 1e-9 * kpi)
                .collect();
            // Largest first, in steps of 1e-9 of the total and then by name: two lengths the
            // TCP feels alike (equal but for rounding) keep one order between builds.
            let step = 1e-9 * kpi;
            contributions.sort_by_cached_key(|(name, part)| {
                (
                    std::cmp::Reverse((part / step).round() as i64),
                    name.clone(),
                )
            });
            TcpFloor {
                name: pose.name.clone(),
                kpi,
                covariance,
                contributions,
            }
        })
        .collect();
    ModelFloor {
        fixed: fixed_record,
        tcp,
        absorbed: Some(Absorbed {
            fixed: fixed
                .iter()
                .map(|&i| model.registry.get(i).name.clone())
                .collect(),
            sigma: sigma.iter().copied().collect(),
            map: absorbed,
        }),
    }
}

/// `A = C_p Fᵀ F_f` (module notes), one column per parameter of `fixed` (registry
/// indices). `jacobian` is the fit's (its data rows those of the measurements a robust fit
/// kept, with weight 1, then its prior rows); `F_f` is taken over the same data rows.
pub fn absorbed_map(
    problem: &Problem,
    params: &[f64],
    jacobian: &DMatrix<f64>,
    cp: &DMatrix<f64>,
    fixed: &[usize],
    outliers: &[Outlier],
) -> DMatrix<f64> {
    // The data rows' Jacobian over the fixed columns: the same problem with those columns
    // free and no prior rows (a fixed parameter has none), over the rows the fit's Jacobian
    // holds (the kept measurements, weight 1), so the whitening is the fit's.
    let mut at_fixed = problem.clone();
    at_fixed.free = fixed.to_vec();
    at_fixed.prior_rows = DMatrix::zeros(0, fixed.len());
    at_fixed.prior_offset = DVector::zeros(0);
    let (_, f_fixed) = kept_rows(&mut at_fixed, params, outliers);
    let data_rows = f_fixed.nrows();
    cp * (jacobian.rows(0, data_rows).transpose() * f_fixed.rows(0, data_rows))
}
