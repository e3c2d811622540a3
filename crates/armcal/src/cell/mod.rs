//! The cell file (TOML): robot, instrument, targets, which parameters are free, working
//! configurations (the KPI poses), obstacles, and how data-file columns map to joints.
//! User files are in mm and degrees unless a field's suffix says otherwise (`_m`, `_rad`).
//! Every error names the file, the line and the field.

pub mod builtin;
mod data_files;
pub(crate) mod export;
pub(crate) mod loaded;
pub(crate) mod model_analysis;
mod raw;
pub(crate) mod tree;

use crate::measure::NoiseModel;
use crate::model::complete::{self, FormChange, Formed, LinkForm};
use crate::model::identifiability::{self, IdentifiabilitySettings, Measurement};
use crate::model::rank_deficit::{rank_deficit, RankDeficit};
use crate::model::{LinkGeometry, LinkSpec, Model, ModelSpec, ParameterStatus};
use crate::robots::{self, Capsule, Robot};
use crate::Error;
pub use export::{export_against_nominal, to_cell_toml, NominalReference};
pub(crate) use loaded::Cell;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The measuring instrument.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Instrument {
    /// Instrument type from `[instrument] kind` (default `laser-tracker`; one of the kinds the
    /// cell parser accepts).
    pub kind: String,
    /// Measurement noise of the instrument (`[instrument.noise]`).
    pub noise: NoiseModel,
    /// Largest angle between the target's z axis and the beam to the instrument (rad;
    /// paper eq. 4), if the targets are reflectors with a limited acceptance angle.
    pub max_incidence: Option<f64>,
    /// Whether the cell places the instrument (`[instrument] xyz_mm`). Without a position the
    /// instrument stands where a fit will put it (its frame starts at the world origin, inside
    /// the robot's base): the line of sight and the incidence cannot be evaluated, and
    /// [`crate::design::cell_constraints::ConstraintSet`] leaves them out.
    #[serde(default = "placed_by_default")]
    pub placed: bool,
}

/// Records written before [`Instrument::placed`] existed evaluated every instrument as placed.
fn placed_by_default() -> bool {
    true
}

/// A configuration at which the robot works; the pose-design KPI is the TCP there.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WorkingPose {
    /// Name from `[[working]] name`, used in reports.
    pub name: String,
    /// Joint values, internal units (rad, mm).
    pub q: Vec<f64>,
    /// Relative weight (> 0) of this configuration's TCP error in the pose-design KPI.
    pub weight: f64,
}

/// A path the robot works along (`[[working_path]]`: a welding seam, a measuring path); the
/// pose-design KPIs take the TCP at each of its configurations (paper §6, "working path
/// trajectories").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WorkingPath {
    /// Name from `[[working_path]] name`, used in reports.
    pub name: String,
    /// Its configurations in order, internal units (rad, mm).
    pub q: Vec<Vec<f64>>,
    /// Relative weight (> 0) of the whole path in the mean KPI, shared equally by its
    /// configurations (a working pose of the same weight counts as much as the path).
    pub weight: f64,
}

/// An obstacle in the world frame (mm).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Obstacle {
    /// The points within `radius` of the segment `a`–`b`.
    Capsule {
        /// Obstacle name, used in messages.
        name: String,
        /// First end of the axis segment (mm, world frame).
        a: [f64; 3],
        /// Second end of the axis segment (mm, world frame).
        b: [f64; 3],
        /// Radius around the segment (mm).
        radius: f64,
    },
    /// A box (a table, a fixture, a fence): the points within `size / 2` of `center` along
    /// each of its edges, the edges along the axes of `Rz(rpy₃) Ry(rpy₂) Rx(rpy₁)` (fixed-axis
    /// roll, pitch, yaw, as every rpy of a cell).
    Box {
        /// Obstacle name, used in messages.
        name: String,
        /// Centre (mm, world frame).
        center: [f64; 3],
        /// Full edge lengths along the box's x, y and z (mm, > 0).
        size: [f64; 3],
        /// Orientation: roll, pitch, yaw (rad).
        rpy: [f64; 3],
    },
    /// The free side is `normal · x ≥ offset` (normal of unit length).
    HalfSpace {
        /// Obstacle name, used in messages.
        name: String,
        /// Normal pointing to the free side, as given (see [`half_space_unit_normal`]).
        normal: [f64; 3],
        /// Distance of the boundary plane from the world origin along the normal (mm).
        offset: f64,
    },
}

impl Obstacle {
    /// The obstacle's name.
    pub fn name(&self) -> &str {
        match self {
            Obstacle::Capsule { name, .. }
            | Obstacle::Box { name, .. }
            | Obstacle::HalfSpace { name, .. } => name,
        }
    }
}

/// A box obstacle as the geometry's [`Cuboid`](crate::geometry::Cuboid) (world frame, mm).
pub fn box_cuboid(center: &[f64; 3], size: &[f64; 3], rpy: &[f64; 3]) -> crate::geometry::Cuboid {
    let pose = crate::model::Pose::from_xyz_rpy(*center, *rpy);
    crate::geometry::Cuboid {
        center: pose.trans,
        rotation: pose.rot,
        half: nalgebra::Vector3::from(*size) * 0.5,
    }
}

/// The unit normal of the half-space `name` with the (possibly unnormalised) `normal`; an
/// error when the normal is zero or not finite.
pub fn half_space_unit_normal(
    name: &str,
    normal: &[f64; 3],
) -> Result<nalgebra::Vector3<f64>, Error> {
    let n = nalgebra::Vector3::from(*normal);
    let norm = n.norm();
    if !(norm > 0.0 && norm.is_finite()) {
        return Err(Error::Model(format!(
            "half-space `{name}` has no valid normal"
        )));
    }
    Ok(n / norm)
}

/// The safety margins a planned pose keeps (`[design]` of the cell file): every distance
/// constraint of the design (robot capsule to robot capsule, to an obstacle or half-space)
/// at least `clearance`, the laser beam at least `line_of_sight_margin` from robot and
/// obstacle capsules, the reflector's incidence angle at least `incidence_margin` below the
/// instrument's limit, every revolute joint at least `joint_margin` inside its limits.
///
/// **Defaults: 5 mm, 1°, 2° and 20 mm.** A design is planned on the *nominal* model, and the
/// real robot is not where the nominal model puts it: with armcal's default simulated robot
/// (lengths off by σ = 0.5 mm, angles by σ = 0.1°, the size of an uncalibrated industrial
/// robot's geometric error) the nominal model misses the paper robot's reflector by 2.8 mm
/// RMS and 4.4 mm at most once the tracker is placed (README, held-out validation "nominal +
/// frames fitted"). A robot point nearer the base moves less than the reflector, so 5 mm — the
/// RMS error plus about 2 mm, above the largest miss — keeps a capsule that the nominal model
/// puts at the clearance off the obstacle. It does not cover obstacles placed wrongly in the
/// cell: draw their capsules generously, or raise the clearance. 1° keeps a pose off the
/// hard stops that a controller's soft limits (typically a degree or so inside the data-sheet
/// limits) would refuse. Prismatic joints get no margin.
///
/// The instrument is not where the cell says either: a tracker set up by tape measure and
/// eye is some centimetres off. Its orientation does not matter to the incidence or the
/// beam, its position does: moved by `D` at a distance `L` from the reflector, the beam turns
/// by up to `asin(D/L)` — 1.43° for 50 mm at 2 m, the near end of a laser tracker's working
/// range — and the flange's own orientation error (σ = 0.1° per angle over six joints) adds
/// a few tenths: 2° of incidence margin keeps a planned pose measurable with the tracker 50 mm
/// off at 2 m or more. A beam point a fraction `s` of the way from the reflector to the
/// tracker moves by `s·D`: the robot capsules a beam passes are near the reflector (`s` below
/// about 0.4 in a cell whose tracker stands 2 m or more away), so 20 mm covers 50 mm of
/// tracker error there; an obstacle near the tracker needs more. `armcal evaluate
/// --tracker-shift-mm D` checks a design exactly against a tracker `D` mm off in any
/// direction (`crate::design::cell_constraints::tracker_shift`).
///
/// The paper's cells set all four to 0: the paper's constraints (eq. 4, eq. 24b) have no
/// margin, and its Tables 6–8 are reproduced with none.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DesignClearance {
    /// Least distance (mm) of every robot and obstacle distance constraint;
    /// `[design] clearance_mm`.
    pub clearance: f64,
    /// Least distance (rad) of every revolute joint from its limits;
    /// `[design] joint_margin_deg`.
    pub joint_margin: f64,
    /// Least angle (rad) between the reflector's incidence angle and the instrument's
    /// `max_incidence`; `[design] incidence_margin_deg`.
    #[serde(default = "default_incidence_margin")]
    pub incidence_margin: f64,
    /// Least distance (mm) of the laser beam (a capsule of the beam radius) from every robot
    /// and obstacle capsule it is checked against; `[design] line_of_sight_margin_mm`.
    #[serde(default = "default_line_of_sight_margin")]
    pub line_of_sight_margin: f64,
}

fn default_incidence_margin() -> f64 {
    2f64.to_radians()
}

fn default_line_of_sight_margin() -> f64 {
    20.0
}

impl Default for DesignClearance {
    fn default() -> Self {
        DesignClearance {
            clearance: 5.0,
            joint_margin: 1f64.to_radians(),
            incidence_margin: default_incidence_margin(),
            line_of_sight_margin: default_line_of_sight_margin(),
        }
    }
}

/// Which columns of a data file feed which joints, and the unit of each.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DataColumns {
    /// One column name per model joint, in joint order.
    pub joints: Vec<String>,
    /// The whole layout of the data files (`[data]`), these joint columns included.
    pub format: crate::measure::format::DataFormat,
}

/// Builds the model of a cell: robot links with the cell's base/tool overrides, the
/// instrument frame and the targets; then applies parameter statuses.
pub(crate) fn assemble_spec(
    robot: &Robot,
    instrument: Option<LinkGeometry>,
    instrument_name: &str,
    base: Option<LinkGeometry>,
    tool: Option<LinkGeometry>,
    targets: Vec<LinkSpec>,
) -> ModelSpec {
    let mut links = robot.spec.links.clone();
    if let Some(b) = base {
        links[0].geometry = b;
    }
    if let Some(t) = tool {
        let last = links.len() - 1;
        links[last].geometry = t;
    }
    ModelSpec {
        compliance: None,
        periodic: None,
        payloads: Vec::new(),
        name: robot.spec.name.clone(),
        instrument: instrument.map(|g| LinkSpec {
            name: instrument_name.into(),
            geometry: g,
            joint: None,
        }),
        links,
        targets,
    }
}

/// Puts the cell's assembled chain `spec` (robot, base and tool overrides, instrument,
/// targets; `given` is its model) into the link `form`, and re-expresses the robot's and
/// the tool's capsules in the new frames; `robot` then holds the formed chain.
pub(crate) fn shape_robot(
    robot: &mut Robot,
    given: &Model,
    spec: ModelSpec,
    form: LinkForm,
    tool_capsules: &mut Vec<Capsule>,
) -> Result<Formed, Error> {
    let formed = complete::in_form(&spec, form)?;
    let model = Model::from_spec(&formed.spec)?;
    robot.capsules = robots::transfer_capsules(given, &model, &robot.capsules)?;
    *tool_capsules = robots::transfer_capsules(given, &model, tool_capsules)?;
    robot.spec.links = formed.spec.links.clone();
    Ok(formed)
}

/// Applies `fixed` patterns, then `free` patterns (which win), then priors.
pub(crate) fn apply_statuses(
    model: &mut Model,
    fixed: &[String],
    free: &[String],
    priors: &[(String, f64)],
) -> Result<(), Error> {
    for p in fixed {
        model.set_status(p, ParameterStatus::Fixed)?;
    }
    for p in free {
        model.set_status(p, ParameterStatus::Free)?;
    }
    for (p, sigma) in priors {
        model.set_status(p, ParameterStatus::Prior { sigma: *sigma })?;
    }
    Ok(())
}
