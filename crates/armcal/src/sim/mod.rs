//! Simulation: a virtual robot whose true parameters are the nominal ones perturbed by a
//! seeded amount per parameter kind, measured by a virtual instrument with its noise.
//! The same seed gives the same truth and the same measurements.

use crate::measure::{Dataset, Measurement, MeasurementKind, NoiseModel};
use crate::model::identifiability::Measurement as Measured;
use crate::model::pose::rot_axis;
use crate::model::prior::{
    FixedPrior, FIXED_ANGLE_SIGMA_DEG, FIXED_LENGTH_SIGMA_MM, FIXED_UNITLESS_SIGMA,
};
use crate::model::{forward_kinematics, observed_pose, Data, Model, Observed, Pose, Segment, Unit};
use crate::Error;
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};

pub(crate) mod tree;

/// Standard deviations of the truth perturbation per parameter kind (internal units).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Perturbation {
    /// Lengths (mm); e.g. 0.5.
    pub length: f64,
    /// Angles (rad); e.g. 0.1° = 0.001745.
    pub angle: f64,
    /// Dimensionless parameters (zero-reference axis components).
    pub unitless: f64,
    /// Lumped joint compliances κ ([`crate::model::compliance`], rad per mm of lever): the
    /// truth draws `κ = nominal + σ |z|`, a sagging arm (κ ≥ 0 is the physical sign).
    /// Default 2·10⁻⁷ rad/mm = 200 µrad/m (e.g. 10⁻⁶ rad/(N·m) with 20 kg beyond the joint).
    #[serde(default = "default_compliance")]
    pub compliance: f64,
    /// Periodic joint error amplitudes ([`crate::model::periodic`], rad): the truth draws
    /// `nominal + σ z`. Default 20 arcsec (9.7·10⁻⁵ rad), a gear's transmission error.
    #[serde(default = "default_periodic")]
    pub periodic: f64,
    /// A joint's own compliance `c` (the payload term of [`crate::model::compliance`], rad
    /// per N·mm): the truth draws `c = nominal + σ |z|`. Default 5·10⁻⁹ rad/(N·mm) =
    /// 5 µrad/(N·m) (a joint stiffness of 2·10⁵ N·m/rad).
    #[serde(default = "default_joint_compliance")]
    pub joint_compliance: f64,
    /// Lengths of the instrument frame (mm: where the tracker stands); `None` (the default)
    /// draws them with `length` like every other length. A tracker set up by tape measure
    /// and eye stands centimetres, not tenths of a millimetre, from where its cell puts it:
    /// `campaign simulate --instrument-offset-mm` (default 20 mm per axis) places the virtual
    /// instrument so.
    #[serde(default)]
    pub instrument_length: Option<f64>,
    /// Perturb every parameter (`true`) or only the free ones (`false`, the default: the
    /// truth then lies in the identifiable set and identification can recover it exactly).
    pub all: bool,
    /// Perturb the parameters the model holds fixed by their stated prior instead
    /// (`nominal + σ z`, σ of the cell's `FixedPrior`, 0 for an exact one; overrides
    /// `all` for them): the robot a fit's model floor ([`crate::identify::model_floor`])
    /// describes. `None` (the default): as `all` says.
    #[serde(default)]
    pub fixed: Option<FixedPrior>,
}

impl Default for Perturbation {
    fn default() -> Self {
        Perturbation {
            length: FIXED_LENGTH_SIGMA_MM,
            angle: FIXED_ANGLE_SIGMA_DEG.to_radians(),
            unitless: FIXED_UNITLESS_SIGMA,
            compliance: default_compliance(),
            periodic: default_periodic(),
            joint_compliance: default_joint_compliance(),
            instrument_length: None,
            all: false,
            fixed: None,
        }
    }
}

fn default_compliance() -> f64 {
    2e-7
}

fn default_joint_compliance() -> f64 {
    5e-9
}

fn default_periodic() -> f64 {
    20.0 / Unit::Arcsec.display_factor()
}

/// The true parameters: nominal + N(0, σ_kind²) per parameter (free ones unless `all`; the
/// instrument frame's lengths with [`Perturbation::instrument_length`] if given); a fixed
/// one nominal + N(0, σ²) of its stated prior if `p.fixed` is given (the same draw z per
/// parameter whatever the statuses, so a seed's free parameters do not change).
pub fn perturbed_truth(model: &Model, p: &Perturbation, seed: u64) -> Vec<f64> {
    perturbed_registry(&model.registry, p, seed)
}

/// [`perturbed_truth`] of the parameters of `registry` (a serial model's or a tree's).
pub(crate) fn perturbed_registry(
    registry: &crate::model::Registry,
    p: &Perturbation,
    seed: u64,
) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let unit_normal = Normal::new(0.0, 1.0).expect("valid normal");
    registry
        .iter()
        .map(|par| {
            // Draw for every parameter so the sequence does not depend on the statuses.
            let z: f64 = unit_normal.sample(&mut rng);
            if let (Some(prior), false) = (&p.fixed, par.status.is_free()) {
                return par.nominal + prior.sigma(par) * z;
            }
            if !(p.all || par.status.is_free()) {
                return par.nominal;
            }
            let s = match par.unit {
                Unit::Mm if par.segment == Segment::Instrument => {
                    p.instrument_length.unwrap_or(p.length)
                }
                Unit::Mm => p.length,
                Unit::Rad => p.angle,
                Unit::Unitless => p.unitless,
                Unit::RadPerMm => return par.nominal + p.compliance * z.abs(),
                Unit::RadPerNmm => return par.nominal + p.joint_compliance * z.abs(),
                Unit::Arcsec => p.periodic,
            };
            par.nominal + s * z
        })
        .collect()
}

/// Measures `configurations` on the robot with parameters `truth`: the position of every
/// point target (or of the tool origin if the model has no targets) and the pose of every
/// frame target, with noise drawn from `noise` (seeded). Noise-free if `noise` is `None`.
/// Configuration ids are 1, 2, ….
///
/// ```
/// use armcal::{simulate, Cell};
/// use armcal::model::random_configurations;
///
/// # fn main() -> armcal::Result<()> {
/// let cell = armcal::cell::builtin::paper_cell()?;
/// let model = &cell.model;
/// let poses = random_configurations(model, 10, 1);
/// // Noise-free measurements of the nominal robot; then the same with the tracker's noise.
/// let exact = simulate(model, &model.nominal(), &poses, None, 1)?;
/// let noisy = simulate(model, &model.nominal(), &poses, Some(&cell.noise()), 1)?;
/// assert_eq!(exact.measurements.len(), 10); // one reflector per pose
/// assert_eq!(exact.measurements[0].observed, noisy.measurements[0].observed);
/// assert_ne!(exact.measurements[0].kind, noisy.measurements[0].kind);
/// # Ok(())
/// # }
/// ```
pub fn simulate(
    model: &Model,
    truth: &[f64],
    configurations: &[Vec<f64>],
    noise: Option<&NoiseModel>,
    seed: u64,
) -> Result<Dataset, Error> {
    simulate_carrying(model, truth, configurations, &[], noise, seed)
}

/// As [`simulate`], configuration `c` carrying payload `payloads[c]` (an index into
/// [`Model::payloads`]; a missing entry or `None`: none), which the data record.
pub fn simulate_carrying(
    model: &Model,
    truth: &[f64],
    configurations: &[Vec<f64>],
    payloads: &[Option<usize>],
    noise: Option<&NoiseModel>,
    seed: u64,
) -> Result<Dataset, Error> {
    // What the targets measure: a frame target its pose, a point its position; the tool
    // origin's position without targets.
    let any_frame = (0..model.targets.len()).any(|k| model.target_is_frame(k));
    let measured = if any_frame {
        Measured::Pose
    } else {
        Measured::Position
    };
    simulate_measuring(
        model,
        truth,
        configurations,
        payloads,
        measured,
        noise,
        seed,
    )
}

/// As [`simulate_carrying`], measuring what `measured` (a cell's `measurement`) says of a
/// model without targets: the tool frame's full pose for [`Measured::Pose`] (a full-pose
/// cell, paper eq. 3 with the orientation), else the tool origin's position. Point targets
/// are measured in position; frame targets in pose, unless `measured` is
/// [`Measured::Position`] (a position-measuring cell: `measurement_at`).
pub fn simulate_measuring(
    model: &Model,
    truth: &[f64],
    configurations: &[Vec<f64>],
    payloads: &[Option<usize>],
    measured: Measured,
    noise: Option<&NoiseModel>,
    seed: u64,
) -> Result<Dataset, Error> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let unit_normal = Normal::new(0.0, 1.0).expect("valid normal");
    let mut data = Dataset {
        source: format!("simulation (seed {seed})"),
        ..Default::default()
    };
    let observed = observed_frames(model);
    let mut fk = Data::new(model);
    for (c, q) in configurations.iter().enumerate() {
        model
            .check_joints(q)
            .map_err(|e| Error::Input(format!("configuration {}: {e}", c + 1)))?;
        fk.payload = payloads.get(c).copied().flatten();
        forward_kinematics(model, &mut fk, truth, q);
        let config = data.push_configuration(format!("{}", c + 1), q.clone());
        data.set_payload(config, fk.payload.map(|k| model.payloads[k].name.as_str()));
        for &obs in &observed {
            let mut m = measurement_at(model, &fk, config, obs, measured);
            if let Some(noise) = noise {
                add_noise(&mut m, noise, &mut || unit_normal.sample(&mut rng))?;
            }
            data.measurements.push(m);
        }
    }
    Ok(data)
}

/// Adds the instrument's noise to a simulated position or pose measurement, drawing each
/// standard normal from `z`: `σ z` per position row, and a rotation by the vector `σ z` of
/// the rotation rows on the left (the residual's `log(R_model R_measᵀ)` convention).
pub(crate) fn add_noise(
    m: &mut Measurement,
    noise: &NoiseModel,
    z: &mut dyn FnMut() -> f64,
) -> Result<(), Error> {
    let s = noise.row_sigmas(m)?;
    match &mut m.kind {
        MeasurementKind::Position { value, .. } => {
            *value += Vector3::new(s[0] * z(), s[1] * z(), s[2] * z());
        }
        MeasurementKind::Pose { value, .. } => {
            let dp = Vector3::new(s[0] * z(), s[1] * z(), s[2] * z());
            let dr = Vector3::new(s[3] * z(), s[4] * z(), s[5] * z());
            let angle = dr.norm();
            let rot = if angle > 0.0 {
                rot_axis(&(dr / angle), angle)
            } else {
                nalgebra::Matrix3::identity()
            };
            *value = Pose {
                rot: rot * value.rot,
                trans: value.trans + dp,
            };
        }
        _ => unreachable!("simulation makes position and pose measurements"),
    }
    Ok(())
}

/// The frames a configuration's measurements observe: every target of `model`, or the tool
/// frame if it has none.
pub fn observed_frames(model: &Model) -> Vec<Observed> {
    if model.targets.is_empty() {
        vec![Observed::Tool]
    } else {
        (0..model.targets.len()).map(Observed::Target).collect()
    }
}

/// The noise-free measurement of `obs` at the kinematics `fk` (configuration `config`): the
/// pose of a frame target (unless `measured` is [`Measured::Position`]), the pose of the tool
/// frame if `measured` is [`Measured::Pose`], else the position. What [`simulate`] and [`predict`] write, and so
/// the rows and σ's an identification of such data has; the pose design builds its rows
/// from it ([`crate::design::DesignModel::from_cell`]).
pub fn measurement_at(
    model: &Model,
    fk: &Data<f64>,
    config: usize,
    obs: Observed,
    measured: Measured,
) -> Measurement {
    // A frame target of a position-measuring cell is measured as a point: its orientation
    // only says where the reflector faces (incidence), as the model analysis assumes.
    let is_frame = match obs {
        Observed::Target(k) => model.target_is_frame(k) && measured != Measured::Position,
        Observed::Tool => measured == Measured::Pose,
    };
    Measurement::simulated(config, obs, observed_pose(fk, obs), is_frame)
}

/// One parameter of a simulated robot, display units (mm, deg).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrueParameter {
    /// The parameter's name.
    pub name: String,
    /// Its display unit.
    pub unit: String,
    /// Its nominal value.
    pub nominal: f64,
    /// Its true value.
    pub truth: f64,
}

/// The true parameters of a simulation (`armcal simulate --truth-out`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TruthRecord {
    /// The cell's name.
    pub cell: String,
    /// The seed of the perturbation and of the noise.
    pub seed: u64,
    /// Every parameter of the model, nominal and true.
    pub parameters: Vec<TrueParameter>,
}

impl TruthRecord {
    /// The record of `truth` (internal units) for `model` of the cell `cell`.
    pub fn new(cell: &str, model: &Model, truth: &[f64], seed: u64) -> TruthRecord {
        TruthRecord::of_registry(cell, &model.registry, truth, seed)
    }

    /// [`TruthRecord::new`] of the parameters of `registry` (a serial model's or a tree's).
    pub(crate) fn of_registry(
        cell: &str,
        registry: &crate::model::Registry,
        truth: &[f64],
        seed: u64,
    ) -> TruthRecord {
        TruthRecord {
            cell: cell.to_string(),
            seed,
            parameters: registry
                .iter()
                .zip(truth)
                .map(|(p, v)| TrueParameter {
                    name: p.name.clone(),
                    unit: p.unit.display_name().to_string(),
                    nominal: p.nominal * p.unit.display_factor(),
                    truth: v * p.unit.display_factor(),
                })
                .collect(),
        }
    }

    /// The record as JSON (keys in alphabetical order, see `crate::json`).
    pub fn to_json(&self) -> Result<String, Error> {
        crate::json::sorted_pretty(self)
    }
}

/// A simulated campaign: the data measured and the robot that was measured.
#[derive(Clone, Debug)]
pub struct Simulation {
    /// The data measured.
    pub data: Dataset,
    /// The true parameters.
    pub truth: TruthRecord,
}

/// Measures the poses `(id, q)` on a robot perturbed from `model` ([`perturbed_truth`] with
/// `seed`), with the instrument's `noise` (seed `seed + 0x5eed`; noise-free if `None`);
/// configurations keep their ids, and every one carries `payload` (an index into
/// [`Model::payloads`]; `None`: none). `measured`: what the cell's instrument measures (a
/// full-pose cell without targets measures the tool frame's pose). `cell` names the model in
/// the truth record.
#[allow(clippy::too_many_arguments)]
pub fn simulate_poses(
    cell: &str,
    model: &Model,
    poses: &[(String, Vec<f64>)],
    payload: Option<usize>,
    measured: Measured,
    perturbation: &Perturbation,
    noise: Option<&NoiseModel>,
    seed: u64,
) -> Result<Simulation, Error> {
    let truth = perturbed_truth(model, perturbation, seed);
    let data = simulate_with_ids(
        model,
        &truth,
        poses,
        (payload, measured),
        noise,
        seed.wrapping_add(0x5eed),
    )?;
    Ok(Simulation {
        data,
        truth: TruthRecord::new(cell, model, &truth, seed),
    })
}

/// What the instrument measures at the poses `(id, q)` according to the model with
/// parameters `params` with the robot carrying `payload` (an index into [`Model::payloads`];
/// `None`: none), without noise; `measured` as in [`simulate_poses`]; the data's source is
/// "prediction".
///
/// ```
/// use armcal::Measurement;
/// use armcal::model::random_configurations;
/// use armcal::{predict, simulate};
///
/// # fn main() -> armcal::Result<()> {
/// let cell = armcal::cell::builtin::paper_cell()?;
/// let model = &cell.model;
/// let poses: Vec<(String, Vec<f64>)> = random_configurations(model, 3, 1)
///     .into_iter()
///     .enumerate()
///     .map(|(i, q)| (format!("p{i}"), q))
///     .collect();
/// // What the tracker would see of the nominal robot: noise-free simulation.
/// let seen = predict(model, &model.nominal(), &poses, None, Measurement::Position)?;
/// let qs: Vec<Vec<f64>> = poses.iter().map(|(_, q)| q.clone()).collect();
/// let simulated = simulate(model, &model.nominal(), &qs, None, 0)?;
/// assert_eq!(seen.config_ids, ["p0", "p1", "p2"]);
/// assert_eq!(seen.measurements[1].kind, simulated.measurements[1].kind);
/// # Ok(())
/// # }
/// ```
pub fn predict(
    model: &Model,
    params: &[f64],
    poses: &[(String, Vec<f64>)],
    payload: Option<usize>,
    measured: Measured,
) -> Result<Dataset, Error> {
    let mut data = simulate_with_ids(model, params, poses, (payload, measured), None, 0)?;
    data.source = "prediction".into();
    Ok(data)
}

/// [`simulate_measuring`] at the configurations of `poses`, which keep their ids, each
/// carrying the payload of `(payload, measured)` and measuring what it says.
fn simulate_with_ids(
    model: &Model,
    params: &[f64],
    poses: &[(String, Vec<f64>)],
    (payload, measured): (Option<usize>, Measured),
    noise: Option<&NoiseModel>,
    seed: u64,
) -> Result<Dataset, Error> {
    let qs: Vec<Vec<f64>> = poses.iter().map(|(_, q)| q.clone()).collect();
    let payloads = vec![payload; qs.len()];
    let mut data = simulate_measuring(model, params, &qs, &payloads, measured, noise, seed)?;
    for (k, (id, _)) in poses.iter().enumerate() {
        data.config_ids[k] = id.clone();
    }
    Ok(data)
}
