//! The settings of an identification ([`crate::identify()`]): the solver, the robust loss,
//! the held-out split, the frames refit, the warm start, the non-geometric terms kept, and how
//! a refused fit is accepted.

use super::{FramesRefit, LmSettings, Loss, NonGeometric};
use crate::measure::Dataset;
use serde::{Deserialize, Serialize};

/// Which solver.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Levenberg–Marquardt ([`levenberg_marquardt`](super::levenberg_marquardt), book §4.3).
    Lm,
    /// Damped Gauss–Newton ([`gauss_newton()`](super::gauss_newton()), book eqs. 4.22–4.27).
    GaussNewton,
    /// Iterated Kalman filter ([`kalman_filter`](super::kalman_filter), book §4.3.3, §4.5.4).
    Kalman,
}

impl Method {
    /// The method in words, for output: `Levenberg–Marquardt`, `Gauss–Newton`, `recursive
    /// (Kalman filter)`.
    pub fn words(self) -> &'static str {
        match self {
            Method::Lm => "Levenberg–Marquardt",
            Method::GaussNewton => "Gauss–Newton",
            Method::Kalman => "recursive (Kalman filter)",
        }
    }

    /// The method named `lm`, `gn` / `gauss-newton` or `kalman`; `None` for another name.
    pub fn from_name(s: &str) -> Option<Method> {
        match s {
            "lm" => Some(Method::Lm),
            "gn" | "gauss-newton" => Some(Method::GaussNewton),
            "kalman" => Some(Method::Kalman),
            _ => None,
        }
    }
}

/// Settings of [`identify`](crate::identify()).
#[derive(Clone, Debug)]
pub struct IdentifySettings {
    /// Solver of the fit.
    pub method: Method,
    /// Robust loss for an IRLS fit ([`robust_fit`](super::robust_fit), always with Levenberg–Marquardt);
    /// `None`: plain least squares.
    pub robust: Option<Loss>,
    /// Fraction of configurations held out for validation, in [0, 1) (0: none).
    pub holdout: f64,
    /// Validation data of the same cell (the user's own held-out file): the whole `data`
    /// is fitted and validated on these configurations. Excludes `holdout`.
    pub test: Option<Dataset>,
    /// Seed of the random choice of held-out configurations.
    pub seed: u64,
    /// Settings of Levenberg–Marquardt (also inside a robust fit); Gauss–Newton stops by
    /// its tolerances.
    pub lm: LmSettings,
    /// A frames refit (`refit`): keep the robot of this estimate and fit only the
    /// instrument, base, tool and target frames. `None`: a full calibration.
    pub refit: Option<FramesRefit>,
    /// Warm start: every parameter of the cell's model (internal units), e.g. a previous
    /// estimate of the same cell on part of these data ([`Estimate::params_for`](crate::Estimate::params_for)); the fit
    /// starts there instead of at the frames-first start ([`frames_first_start`](super::frames_first_start)), and the
    /// free set is decided there. `None`: the frames-first start.
    pub start: Option<Vec<f64>>,
    /// Which of the cell's non-geometric terms (compliance, periodic errors) the fit keeps,
    /// or a choice by cross-validation (`nongeometric_choice`).
    pub nongeometric: NonGeometric,
    /// Run the joint sign and zero diagnosis (`sign_diagnosis`) even without a gross
    /// misfit (it always runs on an unexplained one).
    pub diagnose_signs: bool,
    /// How the caller accepts a fit the checks refuse (`fit_checks`: a gross misfit or a
    /// unit mistake), in its own words (the CLI: its flag); recorded in the estimate, whose
    /// every later use then says so. `None`: not accepted.
    pub accept_misfit: Option<String>,
}

impl Default for IdentifySettings {
    fn default() -> Self {
        IdentifySettings {
            method: Method::Lm,
            robust: None,
            holdout: 0.0,
            test: None,
            seed: 1,
            lm: LmSettings::default(),
            refit: None,
            start: None,
            nongeometric: NonGeometric::AsCell,
            diagnose_signs: false,
            accept_misfit: None,
        }
    }
}
