//! The estimate record (`estimate.json`, what [`identify`](super::identify()) returns and
//! `armcal identify` writes): parameters with σ, solver report, uncertainty, residuals,
//! validation, and what the fit knows about itself — and the checks every consumer makes
//! before using one ([`Estimate::check_usable`], [`Estimate::check_model`]).

use super::uncertainty::{Chi2Outcome, Observability, ParameterUncertainty, TcpCovariance};
use super::verdicts::Verdicts;
use super::{Loss, Method, ModelFingerprint, Outlier};
use crate::accuracy::ErrorStats;
use crate::model::rank_deficit::RankDeficit;
use crate::model::{Model, ModelSpec};
use crate::solve::Status;
use crate::Error;
use nalgebra::Matrix3;
use serde::{Deserialize, Serialize};

/// One parameter in the estimate report (display units: mm, deg).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ParameterEstimate {
    /// Parameter name in the model's registry.
    pub name: String,
    /// Display unit: `mm` or `deg`.
    pub unit: String,
    /// Nominal value (display unit).
    pub nominal: f64,
    /// Value at the solution (display unit).
    pub estimate: f64,
    /// Standard deviation (display unit); `None` for fixed parameters.
    pub sigma: Option<f64>,
    /// Whether the parameter was estimated.
    pub free: bool,
}

/// Solver statistics.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SolverReport {
    /// Solver used.
    pub method: Method,
    /// Robust loss of an IRLS fit; `None` for plain least squares.
    pub robust: Option<Loss>,
    /// How the (last) solver run ended.
    pub status: Status,
    /// Iterations of the last solver run.
    pub iterations: usize,
    /// Wall-clock time of the last solver run (ms).
    pub time_ms: f64,
    /// Cost ½‖r‖² of the whitened residual after each iteration (index 0: the start).
    pub history: Vec<f64>,
}

/// Residual statistics per axis (mm) of the position-bearing measurements.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ResidualReport {
    /// x components of the position residuals (instrument frame, mm).
    pub x: ErrorStats,
    /// y components of the position residuals (instrument frame, mm).
    pub y: ErrorStats,
    /// z components of the position residuals (instrument frame, mm).
    pub z: ErrorStats,
    /// Euclidean position error per measurement (scalar error for distances and planes).
    pub norm: ErrorStats,
    /// Orientation error of the pose measurements (degrees): the angle of the rotation
    /// `R_model R_measᵀ` between predicted and measured orientation. `None` without pose
    /// measurements (and in files of an older armcal).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orientation: Option<ErrorStats>,
    /// Every measurement's residual, in data order (for the report's histograms and
    /// per-pose plot).
    #[serde(default)]
    pub per_measurement: Vec<MeasurementResidual>,
}

/// One measurement's residual, `model − measured` (mm; the robust weights undone).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MeasurementResidual {
    /// The configuration's number in the data file (1-based, in the file's order, also
    /// when part of the file was held out).
    pub pose: usize,
    /// The configuration's `pose_id` in the data file.
    pub pose_id: String,
    /// Position residual x, y, z (mm); `None` for distance and plane measurements.
    pub xyz: Option<[f64; 3]>,
    /// Euclidean position error (the scalar error for distances and planes, mm).
    pub norm: f64,
}

/// Held-out validation (position error on configurations not used in the fit, mm).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Validation {
    /// What the fit was validated on: a held-out fraction of the data file, or the user's
    /// test data file.
    #[serde(default)]
    pub test_data: String,
    /// Number of configurations fitted.
    pub train_configurations: usize,
    /// Number of configurations validated on.
    pub test_configurations: usize,
    /// The `pose_id`s of the fitted configurations (data file), in file order.
    #[serde(default)]
    pub train_ids: Vec<String>,
    /// The `pose_id`s of the validation configurations (data file, or the test file), in
    /// file order.
    #[serde(default)]
    pub test_ids: Vec<String>,
    /// Nominal model, nothing fitted.
    pub nominal: ErrorStats,
    /// Nominal robot with only the base, tool, instrument and target frames fitted (for a
    /// cell whose only free parameters are frames: the calibration itself).
    pub frames_only: ErrorStats,
    /// Full calibration.
    pub calibrated: ErrorStats,
    /// The same three models' errors per axis of the instrument frame (position
    /// measurements only); `None` in files of an older armcal.
    #[serde(default)]
    pub per_axis: Option<HeldOutAxes>,
    /// The same three models' orientation errors (degrees, the angle of `R_model R_measᵀ`)
    /// on the pose measurements; `None` without pose measurements.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orientation: Option<HeldOutOrientation>,
    /// The calibrated model's error at every validation measurement, with its station and
    /// temperature ([`super::held_out`]: grouped per station and per temperature bin).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub errors: Vec<super::held_out::HeldOutError>,
}

/// Held-out orientation error (degrees) before and after calibration
/// ([`Validation::orientation`]): the angle of the rotation between the measured and the
/// predicted orientation of every pose measurement.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct HeldOutOrientation {
    /// Nominal model, nothing fitted (deg).
    pub nominal: ErrorStats,
    /// Only the frames fitted (deg).
    pub frames_only: ErrorStats,
    /// Full calibration (deg).
    pub calibrated: ErrorStats,
}

/// Held-out error per axis before and after calibration ([`Validation::per_axis`]).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct HeldOutAxes {
    /// Nominal model, nothing fitted.
    pub nominal: AxisErrors,
    /// Only the frames fitted.
    pub frames_only: AxisErrors,
    /// Full calibration.
    pub calibrated: AxisErrors,
}

/// Statistics of the x, y and z components of position errors `model − measured` in the
/// instrument frame (mm).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct AxisErrors {
    /// x components (mm).
    pub x: ErrorStats,
    /// y components (mm).
    pub y: ErrorStats,
    /// z components (mm).
    pub z: ErrorStats,
}

impl AxisErrors {
    /// The statistics of each axis over the position errors `xyz`.
    pub fn of(xyz: &[[f64; 3]]) -> AxisErrors {
        let axis = |k: usize| ErrorStats::of(&xyz.iter().map(|v| v[k]).collect::<Vec<f64>>());
        AxisErrors {
            x: axis(0),
            y: axis(1),
            z: axis(2),
        }
    }
}

/// Everything an identification produced: what `estimate.json` holds.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Estimate {
    /// Name of the cell.
    pub cell: String,
    /// Where the fitted data came from ([`Dataset::source`](crate::Dataset::source)).
    pub data: String,
    /// The identified model (internal units: mm, rad), for predict / compensate / export.
    pub model: ModelSpec,
    /// Every model parameter, free or fixed, in registry order (display units).
    pub parameters: Vec<ParameterEstimate>,
    /// The payload states the fitted data carried (a payload's name, `none` for rows without
    /// one), in order of first appearance; empty: no row named a payload
    /// ([`Estimate::payload_for`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub payloads_measured: Vec<String>,
    /// The identifiability gate of the free non-geometric terms (compliance, periodic
    /// errors; `crate::identify::nongeometric_gate`); empty for a kinematic model.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub nongeometric: Vec<crate::identify::nongeometric_gate::TermVerdict>,
    /// The cross-validated choice of the non-geometric terms (`identify --nongeometric
    /// auto`, `crate::identify::nongeometric_choice`): every candidate's held-out score.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nongeometric_choice: Option<crate::identify::NonGeometricChoice>,
    /// Why each parameter not estimated was left out (identifiability analysis).
    pub fixed_reasons: Vec<(String, String)>,
    /// Why fewer parameters than the generic count were identified (at the fit, from these
    /// data), if so.
    #[serde(default)]
    pub rank_deficit: Option<RankDeficit>,
    /// Solver statistics of the fit.
    pub solver: SolverReport,
    /// C_p, σ's, correlations and the χ² test of the free parameters (internal units).
    pub uncertainty: ParameterUncertainty,
    /// Names of the free parameters, the order of C_p.
    pub free: Vec<String>,
    /// Pairs of free parameters with correlation |ρ| > 0.95, and ρ.
    pub strong_correlations: Vec<(String, String, f64)>,
    /// C_s = G C_p Gᵀ at each working configuration.
    pub tcp: Vec<TcpCovariance>,
    /// C_s by the constrained formulation (paper eq. 19), same order.
    pub tcp_constrained: Vec<Matrix3<f64>>,
    /// The model floor at the same working configurations: what the fixed parameters'
    /// stated uncertainty adds to C_s ([`crate::identify::model_floor`]); `None` for a frames refit (its robot is an earlier calibration's,
    /// held without that calibration's C_p) or in files of an older armcal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model_floor: Option<crate::identify::model_floor::ModelFloor>,
    /// Observability indices of the data rows of the whitened Jacobian at the solution
    /// (book §4.5.3, paper eqs. 8–10).
    pub observability: Observability,
    /// Residuals of the fitted data, `model − measured` (mm).
    pub residuals: ResidualReport,
    /// Measurements a robust fit left out (of the χ² test and C_p too).
    pub outliers: Vec<Outlier>,
    /// Free angles more than 90° from nominal that no equivalent parameter set brings
    /// closer (the estimate is reported in the equivalent set nearest the nominal).
    #[serde(default)]
    pub far_from_nominal: Vec<crate::model::branch::FarAngle>,
    /// Robust scale of the whitened residuals at the end of an IRLS fit (≈ 1 if σ is
    /// right); `None` for plain least squares.
    pub robust_scale: Option<f64>,
    /// Held-out validation; `None` without held-out or test data.
    pub validation: Option<Validation>,
    /// Number of measurements fitted (the training part).
    pub measurements: usize,
    /// Number of configurations fitted (the training part).
    pub configurations: usize,
    /// Solver, χ² and identifiability verdicts; `None` in files of an older armcal, which
    /// consumers treat as unverified ([`Estimate::check_usable`]).
    #[serde(default)]
    pub verdicts: Option<Verdicts>,
    /// The cell model the estimate was identified on; `None` in files of an older armcal
    /// (then only the parameter names are checked, [`Estimate::check_model`]).
    #[serde(default)]
    pub fingerprint: Option<ModelFingerprint>,
    /// The range of every joint over the configurations fitted on
    /// ([`super::fitted_ranges`]); empty in files of an older armcal.
    #[serde(default)]
    pub fitted_ranges: Vec<super::fitted_ranges::FittedRange>,
    /// Set when this estimate is a frames refit (`identify` with
    /// [`IdentifySettings::refit`](super::IdentifySettings::refit)): the estimate whose robot
    /// parameters it kept.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refit: Option<super::RefitRecord>,
}

/// Whether the caller accepts an estimate whose fit did not converge (or that records no
/// verdicts), and how its user would say so, in the caller's own words (the CLI: its
/// flags): [`Estimate::check_usable`] names them in the refusal and in the line every
/// output made with an accepted estimate carries.
#[derive(Clone, Copy, Debug)]
pub struct Acceptance<'a> {
    /// The user accepted the estimate as it is.
    pub accepted: bool,
    /// How the user accepts it (the CLI passes its flag's name).
    pub accept: &'a str,
    /// How the user raises the identification's iteration limit (the CLI passes its flag's
    /// name).
    pub raise_iterations: &'a str,
}

/// Whether an estimate may be used ([`Estimate::check_usable`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Usability {
    /// Set when the estimate is used only because the caller accepted an unconverged (or
    /// unverified) fit: every output written with it must carry this line.
    pub overridden: Option<String>,
    /// What else the user should know (χ² not consistent with the stated σ, fewer parameters
    /// than the generic count), one sentence each.
    pub notes: Vec<String>,
}

impl Estimate {
    /// The warning for the configurations `(id, q)` of `model` outside the joint ranges this
    /// estimate was fitted on ([`super::fitted_ranges::outside_warning`]); `None` when all
    /// are inside.
    pub fn outside_fitted_ranges(
        &self,
        model: &Model,
        configurations: &[(String, Vec<f64>)],
    ) -> Option<String> {
        super::fitted_ranges::outside_warning(&self.fitted_ranges, &model.joints, configurations)
    }

    /// Reads an `estimate.json`.
    pub fn from_file(path: &std::path::Path) -> Result<Estimate, Error> {
        let text =
            crate::input::read_capped(path, crate::input::TEXT_CAP).map_err(|e| Error::File {
                file: path.display().to_string(),
                message: e.to_string(),
            })?;
        serde_json::from_str(&text).map_err(|e| Error::File {
            file: path.display().to_string(),
            message: super::tree::tree_estimate_refusal(&text)
                .unwrap_or_else(|| format!("not an armcal estimate: {e}")),
        })
    }

    /// Whether the record hangs together where its consumers index it: C_p and the σ's
    /// sized by the free set (a damaged or edited file is an error, never a panic).
    pub fn check_consistent(&self) -> Result<(), Error> {
        let n = self.free.len();
        let u = &self.uncertainty;
        if u.covariance.shape() == (n, n) && u.sigma.len() == n {
            return Ok(());
        }
        Err(Error::Input(format!(
            "the estimate (cell `{}`) names {n} free parameters but holds a {}×{} C_p and {} σ's: the file is damaged or was edited; identify again",
            self.cell,
            u.covariance.nrows(),
            u.covariance.ncols(),
            u.sigma.len()
        )))
    }

    /// Whether the estimate may be used: an estimate whose fit did not converge — or that
    /// records no verdicts (written by an older armcal) — is an error naming the status,
    /// unless `acceptance.accepted`, when [`Usability::overridden`] says what every output
    /// must carry. Both say how the user accepts it, in the caller's words
    /// ([`Acceptance`]). The χ² and identifiability verdicts worth knowing come back as
    /// notes.
    pub fn check_usable(&self, acceptance: &Acceptance) -> Result<Usability, Error> {
        // no acceptance makes a damaged record usable
        self.check_consistent()?;
        let accept = acceptance.accept;
        let flag = format!("pass {accept} to use it anyway");
        let Some(v) = &self.verdicts else {
            if !acceptance.accepted {
                return Err(Error::Input(format!(
                    "the estimate (cell `{}`) was written by an older armcal: it records no solver, χ² or identifiability verdict and no model fingerprint; identify again, or {flag}",
                    self.cell
                )));
            }
            return Ok(Usability {
                overridden: Some(format!(
                    "armcal: estimate of cell `{}` unverified (no recorded verdicts), used with {accept}",
                    self.cell
                )),
                notes: Vec::new(),
            });
        };
        let mut usability = Usability::default();
        if !v.solver.is_converged() {
            if !acceptance.accepted {
                return Err(Error::Input(format!(
                    "the fit of this estimate (cell `{}`) did not converge: {} after {} iterations; its parameters are not a least-squares solution. Identify again (check the nominal model, the data's units and joint columns, or raise {}), or {flag}",
                    self.cell, v.solver, self.solver.iterations, acceptance.raise_iterations
                )));
            }
            usability.overridden = Some(format!(
                "armcal: estimate of cell `{}` did not converge ({}), used with {accept}",
                self.cell, v.solver
            ));
        }
        if v.fit.refuses() {
            let why = v.fit.reasons().join("; ");
            let line = match (&v.fit.accepted, acceptance.accepted) {
                (Some(how), _) => format!(
                    "armcal: estimate of cell `{}` does not fit its data, accepted with {how} when identified: {why}",
                    self.cell
                ),
                (None, true) => format!(
                    "armcal: estimate of cell `{}` does not fit its data, used with {accept}: {why}",
                    self.cell
                ),
                (None, false) => {
                    return Err(Error::Input(format!(
                        "the estimate (cell `{}`) does not fit its data: {why}. Identify again, or {flag}",
                        self.cell
                    )))
                }
            };
            usability.overridden = Some(match usability.overridden.take() {
                Some(o) => format!("{o}; {line}"),
                None => line,
            });
        }
        if v.chi2.outcome != Chi2Outcome::Consistent {
            usability.notes.push(format!("χ² test: {}", v.chi2.meaning));
        }
        if v.identifiability.is_short() {
            usability
                .notes
                .push(format!("identifiability: {}", v.identifiability.meaning));
        }
        Ok(usability)
    }

    /// Checks that this estimate belongs to `model`: the same parameter names and, for an
    /// estimate that carries a [`ModelFingerprint`], the same conventions, joints, nominal
    /// geometry, frames, targets and free set. The error names every difference.
    pub fn check_model(&self, model: &Model) -> Result<(), Error> {
        self.check_names(model)?;
        let Some(f) = &self.fingerprint else {
            return Ok(());
        };
        let differences = f.differences(model);
        if differences.is_empty() {
            return Ok(());
        }
        Err(Error::Input(format!(
            "the estimate (cell `{}`) was identified on another model than `{}`: {}; identify again with this cell, or use the cell the estimate was made for",
            self.cell,
            model.name,
            differences.join("; ")
        )))
    }

    /// The payload (an index into `model`'s payloads) at which this estimate can predict the
    /// robot carrying `name` (`none`: no payload), with a sentence on how; `name` `None`:
    /// the payload the calibration carried if it carried one only, else none. A rigid model
    /// predicts alike at every payload (said). With compliance, a payload state the
    /// calibration measured in is always honest (its deflection is in the fit, whether the
    /// payload terms were kept or absorbed); another needs every payload term
    /// (`<joint>.compliance.payload`) identified, else the error names them and what to do.
    pub fn payload_for(
        &self,
        model: &Model,
        name: Option<&str>,
    ) -> Result<(Option<usize>, String), Error> {
        let measured: Vec<&str> = if self.payloads_measured.is_empty() {
            vec!["none"]
        } else {
            self.payloads_measured.iter().map(String::as_str).collect()
        };
        let name = name.unwrap_or(if measured.len() == 1 {
            measured[0]
        } else {
            "none"
        });
        let index = model.payload_index(name).map_err(Error::Input)?;
        let label = match index {
            Some(k) => format!("payload `{name}` ({} kg)", model.payloads[k].mass_kg),
            None => "no payload".to_string(),
        };
        let Some(c) = &model.compliance else {
            return Ok((
                index,
                format!("{label}: the model is rigid, so the payload changes no prediction"),
            ));
        };
        if measured.contains(&name) {
            return Ok((index, format!("{label}, as in the calibration data")));
        }
        let unknown: Vec<&str> = c
            .terms
            .iter()
            .filter(|t| t.spec.is_payload())
            .map(|t| model.registry.get(t.param).name.as_str())
            .filter(|n| !self.parameters.iter().any(|p| p.name == *n && p.free))
            .collect();
        let terms = c.terms.iter().filter(|t| t.spec.is_payload()).count();
        if terms == 0 || !unknown.is_empty() {
            return Err(Error::Input(format!(
                "the estimate cannot predict the robot with {label}: its data carried {} only, and \
                 the joints' own compliance was not identified{}; calibrate with rows carrying \
                 different payloads (a `payload` column naming the cell's [[payload]] entries), \
                 or predict at {}",
                measured.join(", "),
                if unknown.is_empty() {
                    " (the cell declares no payload term)".to_string()
                } else {
                    format!(" ({})", unknown.join(", "))
                },
                measured.join(" or ")
            )));
        }
        Ok((
            index,
            format!(
                "{label}, with the identified joint compliances (the data carried {})",
                measured.join(", ")
            ),
        ))
    }

    /// The full parameter vector of `model` from this estimate (by parameter name), after
    /// [`Estimate::check_model`]. An estimate over several instrument stations gives a model
    /// without stations its first station's instrument pose (`Estimate::by_model_name`).
    pub fn params_for(&self, model: &Model) -> Result<Vec<f64>, Error> {
        self.check_model(model)?;
        let by_name = self.by_model_name(model);
        Ok(model
            .registry
            .iter()
            .map(|p| by_name[p.name.as_str()].estimate / p.unit.display_factor())
            .collect())
    }

    /// This estimate's parameters under the names `model` gives them
    /// ([`Estimate::model_name`]); the first of several with one name.
    fn by_model_name(
        &self,
        model: &Model,
    ) -> std::collections::HashMap<String, &ParameterEstimate> {
        let mut out = std::collections::HashMap::new();
        for p in &self.parameters {
            out.entry(Self::model_name(model, &p.name)).or_insert(p);
        }
        out
    }

    /// The name `model` gives this estimate's parameter `name`: the name itself, except that
    /// for a model without stations a station's instrument parameter `I@S.f`
    /// ([`crate::model::station`]) is `I.f` (the robot is the same at every station; each
    /// station's pose stays in [`Estimate::parameters`]).
    fn model_name(model: &Model, name: &str) -> String {
        let field = match (&model.instrument, model.stations.is_empty()) {
            (Some(l), true) => name
                .strip_prefix(l.spec.name.as_str())
                .and_then(|rest| rest.strip_prefix(crate::model::station::SEPARATOR))
                .and_then(|rest| rest.split_once('.'))
                .map(|(_, f)| format!("{}.{f}", l.spec.name)),
            _ => None,
        };
        field.unwrap_or_else(|| name.to_string())
    }

    /// An estimate of a different robot or cell (other parameter names) is an error that
    /// names the mismatch.
    fn check_names(&self, model: &Model) -> Result<(), Error> {
        let by_name = self.by_model_name(model);
        let missing: Vec<&str> = model
            .registry
            .iter()
            .filter(|p| !by_name.contains_key(p.name.as_str()))
            .map(|p| p.name.as_str())
            .collect();
        let extra: Vec<&str> = self
            .parameters
            .iter()
            .filter(|p| {
                model
                    .registry
                    .index_of(&Self::model_name(model, &p.name))
                    .is_none()
            })
            .map(|p| p.name.as_str())
            .collect();
        if !missing.is_empty() || !extra.is_empty() {
            return Err(Error::Input(format!(
                "the estimate (cell `{}`) does not belong to model `{}`: {}{}",
                self.cell,
                model.name,
                if missing.is_empty() {
                    String::new()
                } else {
                    format!("the estimate lacks {}", missing.join(", "))
                },
                if extra.is_empty() {
                    String::new()
                } else {
                    format!(
                        "{}the model has no {}",
                        if missing.is_empty() { "" } else { "; " },
                        extra.join(", ")
                    )
                },
            )));
        }
        Ok(())
    }
}
