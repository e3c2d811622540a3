//! The TOML layer of the cell file: raw structures with spans, unit suffixes, and errors
//! that give file, line and field. [`parse`] reads the file section by section, one module
//! per section: [`robot`] (`[robot]`, `[[tool_capsules]]`), [`instrument`], [`frames`]
//! (`[base]`, `[tool]`, `[[targets]]`), [`payloads`], [`parameters`], [`working`], [`obstacles`],
//! [`design`] and [`data`]; [`fields`] holds the field readers they share.

use super::*;
use crate::model::complete::LinkForm;
use crate::model::identifiability::Measurement;
use crate::model::{Convention, Joint, JointKind, LinkGeometry, LinkSpec, Unit};
use serde::Deserialize;
use std::collections::BTreeMap;
use toml::Spanned;

mod controller;
mod data;
mod design;
mod fields;
mod frames;
mod instrument;
mod obstacles;
mod parameters;
mod payloads;
mod robot;
mod tree;
mod working;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCell {
    name: Option<String>,
    robot: Spanned<RawRobot>,
    instrument: Option<Spanned<RawInstrument>>,
    base: Option<Spanned<toml::Table>>,
    tool: Option<Spanned<toml::Table>>,
    #[serde(default)]
    targets: Vec<Spanned<toml::Table>>,
    parameters: Option<Spanned<RawParameters>>,
    #[serde(default)]
    working: Vec<Spanned<toml::Table>>,
    #[serde(default)]
    working_path: Vec<Spanned<toml::Table>>,
    #[serde(default)]
    obstacles: Vec<Spanned<toml::Table>>,
    #[serde(default)]
    tool_capsules: Vec<Spanned<toml::Table>>,
    #[serde(default)]
    payload: Vec<Spanned<toml::Table>>,
    design: Option<Spanned<toml::Table>>,
    data: Option<Spanned<data::RawData>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRobot {
    builtin: Option<String>,
    urdf: Option<String>,
    /// A Universal Robots kinematics YAML ([`crate::model::ur_kinematics`]), relative to the
    /// cell file: the robot's factory calibration as its nominal model.
    ur_kinematics: Option<String>,
    tip: Option<String>,
    name: Option<String>,
    #[serde(default)]
    links: Vec<Spanned<toml::Table>>,
    /// Per-joint limit overrides, `q1 = [-82, 82]` (deg; mm for prismatic joints).
    limits: Option<BTreeMap<String, [f64; 2]>>,
    #[serde(default)]
    capsules: Vec<Spanned<toml::Table>>,
    /// Radius (mm) of every skeleton capsule ([`crate::robots::skeleton`]) of a robot from
    /// `urdf` or `[[robot.links]]` without `[[robot.capsules]]`; default
    /// [`crate::robots::skeleton::default_link_radius`].
    link_radius_mm: Option<f64>,
    /// Per-frame skeleton radii, `{ j2 = 80 }` (mm), over `link_radius_mm`.
    link_radii_mm: Option<BTreeMap<String, f64>>,
    /// `auto` (default), `as-given`, `dh`, `mdh` or `zrp` ([`LinkForm`]).
    convention: Option<String>,
    /// Direction of gravity in the base frame (any length), default `[0, 0, -1]`.
    gravity: Option<[f64; 3]>,
    /// `[robot.controller]`: the controller's joint convention ([`controller`]).
    controller: Option<Spanned<toml::Table>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawInstrument {
    name: Option<String>,
    kind: Option<String>,
    xyz_mm: Option<[f64; 3]>,
    xyz_m: Option<[f64; 3]>,
    rpy_deg: Option<[f64; 3]>,
    rpy_rad: Option<[f64; 3]>,
    noise: Option<toml::Table>,
    max_incidence_deg: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawParameters {
    /// `"auto"`: reduce to the minimal identifiable set; or a list of patterns.
    free: Option<toml::Value>,
    #[serde(default)]
    fixed: Vec<String>,
    #[serde(default)]
    priors: BTreeMap<String, toml::Table>,
    /// σ of the fixed parameters per kind, `{ length_mm = 0.5, angle_deg = 0.1, unitless =
    /// 0.001 }` ([`crate::model::prior::FixedPrior`]).
    fixed_prior: Option<toml::Table>,
    /// σ of fixed parameters by pattern, `{ "tool.z" = { sigma_mm = 0.2 } }`.
    #[serde(default)]
    fixed_priors: BTreeMap<String, toml::Table>,
    measurement: Option<String>,
    /// Compliant joints, `["j2", "j3"]` ([`crate::model::compliance`]).
    compliance: Option<Vec<String>>,
    /// Joints whose structure bends laterally, `["torso"]` (a tree cell only,
    /// [`crate::model::tree::bending`]).
    bending: Option<Vec<String>>,
    /// Periodic joint errors ([`crate::model::periodic`]).
    periodic: Option<RawPeriodic>,
    /// Values of the compliance and periodic terms, `{ "j2.compliance.elbow" = {
    /// value_urad_per_m = 120 } }` (an exported calibration); default 0.
    #[serde(default)]
    values: BTreeMap<String, toml::Table>,
}

/// `periodic = { joints = ["j1", "j2"], harmonics = [1, 2] }`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPeriodic {
    joints: Vec<String>,
    harmonics: Vec<u32>,
}

/// Error helper: file, line of a span, field path.
struct Ctx<'a> {
    file: &'a str,
    text: &'a str,
}

impl Ctx<'_> {
    fn line(&self, span: std::ops::Range<usize>) -> usize {
        self.text[..span.start.min(self.text.len())]
            .chars()
            .filter(|&c| c == '\n')
            .count()
            + 1
    }

    fn err(&self, span: std::ops::Range<usize>, field: &str, msg: impl std::fmt::Display) -> Error {
        Error::File {
            file: self.file.to_string(),
            message: format!("line {}: `{field}`: {msg}", self.line(span)),
        }
    }
}

pub(super) use tree::parse_tree;

/// The TOML of a cell file (serial or tree) read into its raw sections, with the context
/// its errors name (file, line, field).
fn parse_raw<'a>(text: &'a str, file: &'a str) -> Result<(Ctx<'a>, RawCell), Error> {
    let raw: RawCell = toml::from_str(text).map_err(|e| Error::File {
        file: file.to_string(),
        message: e.to_string(),
    })?;
    Ok((Ctx { file, text }, raw))
}

/// Parses a cell file section by section (in the order errors are reported).
pub(super) fn parse(text: &str, file: &str, dir: &Path) -> Result<Cell, Error> {
    let (ctx, raw) = parse_raw(text, file)?;
    let rspan = raw.robot.span();
    let rr = raw.robot.into_inner();
    if let Some((span, field)) = tree::tree_field(&rr.links, &raw.targets) {
        return Err(ctx.err(
            span,
            &field,
            "this cell describes a kinematic tree (or a coupled joint): `armcal model`, \
             `simulate` and `identify` take it; the other commands take a serial chain for \
             now (issue 32)",
        ));
    }

    let (mut robot, shapes) = robot::robot(&ctx, &rr, rspan.clone(), dir)?;
    let (instrument, instrument_geometry, instrument_name) =
        instrument::instrument(&ctx, raw.instrument)?;
    let (base, tool) = frames::base_and_tool(&ctx, &raw.base, &raw.tool)?;
    let targets = frames::targets(&ctx, &raw.targets)?
        .into_iter()
        .map(|(t, _)| t)
        .collect();
    let spec = assemble_spec(
        &robot,
        instrument_geometry,
        &instrument_name,
        base,
        tool,
        targets,
    );
    let model_error = |e: Error| Error::File {
        file: file.to_string(),
        message: e.to_string(),
    };
    let mut tool_capsules = robot::tool_capsules(&ctx, &raw.tool_capsules)?;
    let form = robot::link_form(&ctx, &rr, rspan.clone())?;
    let given = Model::from_spec(&spec).map_err(model_error)?;
    let collision_warnings = robot::collision_model(
        &ctx,
        &rr,
        rspan.clone(),
        &mut robot,
        &given,
        &tool_capsules,
        &shapes,
    )?;
    let shaped = shape_robot(&mut robot, &given, spec, form, &mut tool_capsules)
        .map_err(|e| ctx.err(rspan.clone(), "robot.convention", e))?;
    let mut spec = shaped.spec;
    spec.payloads = payloads::payloads(&ctx, &raw.payload)?;
    let mut model = Model::from_spec(&spec).map_err(model_error)?;
    parameters::joint_corrections(&ctx, raw.parameters.as_ref(), rr.gravity, &mut model)?;

    let (measurement, auto_free) =
        parameters::parameters(&ctx, raw.parameters.as_ref(), &mut model)?;
    let fixed_prior = parameters::fixed_prior(
        &ctx,
        raw.parameters.as_ref(),
        &model,
        [("base", raw.base.is_some()), ("tool", raw.tool.is_some())],
    )?;
    let (working, mut warnings) = working::working(&ctx, &raw.working, &model)?;
    let (working_paths, path_warnings) =
        working::working_paths(&ctx, &raw.working_path, &model, dir)?;
    warnings.extend(path_warnings);
    warnings.extend(collision_warnings);
    let obstacles = obstacles::obstacles(&ctx, &raw.obstacles)?;
    let design = design::design(&ctx, raw.design.as_ref())?;
    design::check_joint_margin(&ctx, raw.design.as_ref(), &design, &model)?;
    design::check_incidence_margin(
        &ctx,
        raw.design.as_ref(),
        &design,
        instrument.as_ref().and_then(|i| i.max_incidence),
    )?;
    let mut capsules = robot.capsules.clone();
    capsules.extend(tool_capsules);
    for (i, c) in capsules.iter().enumerate() {
        if model.link_index(&c.frame).is_none() {
            return Err(Error::File {
                file: file.to_string(),
                message: format!(
                    "capsule {i} names frame `{}`, which the robot does not have",
                    c.frame
                ),
            });
        }
    }
    let controller =
        controller::controller(&ctx, rr.controller.as_ref(), rr.builtin.as_deref(), &model)?;
    let data_columns = data::data_columns(&ctx, raw.data, &model, &controller)?;
    let mut cell = Cell {
        name: raw.name.unwrap_or_else(|| robot.name.clone()),
        origin: file.to_string(),
        robot,
        model,
        instrument,
        working,
        working_paths,
        obstacles,
        capsules,
        design,
        measurement,
        auto_free,
        declared_free: Vec::new(),
        data_columns,
        controller,
        warnings,
        form,
        form_changes: shaped.changes,
        form_incomplete: shaped.incomplete,
        fixed_prior,
    };
    cell.declared_free = cell.model.registry.free();
    if cell.auto_free {
        let report = cell.identifiability(&cell.identifiability_settings())?;
        report.apply(&mut cell.model)?;
    }
    Ok(cell)
}
