//! The TOML layer of the cell file: raw structures with spans, unit suffixes, and errors
//! that give file, line and field.

use super::*;
use crate::model::complete::LinkForm;
use crate::model::identifiability::Measurement;
use crate::model::{Convention, Joint, JointKind, LinkGeometry, LinkSpec, Unit};
use serde::Deserialize;
use std::collections::BTreeMap;
use toml::Spanned;

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
    obstacles: Vec<Spanned<toml::Table>>,
    #[serde(default)]
    tool_capsules: Vec<Spanned<toml::Table>>,
    data: Option<RawData>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRobot {
    builtin: Option<String>,
    urdf: Option<String>,
    tip: Option<String>,
    name: Option<String>,
    #[serde(default)]
    links: Vec<Spanned<toml::Table>>,
    /// Per-joint limit overrides, `q1 = [-82, 82]` (deg; mm for prismatic joints).
    limits: Option<BTreeMap<String, [f64; 2]>>,
    #[serde(default)]
    capsules: Vec<Spanned<toml::Table>>,
    /// `auto` (default), `as-given`, `dh`, `mdh` or `zrp` ([`LinkForm`]).
    convention: Option<String>,
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
    measurement: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawData {
    joints: Vec<String>,
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

/// The field `<key><suffix>` of a table with the suffixes a unit allows (`_mm` / `_m` for
/// lengths, `_deg` / `_rad` for angles, none for dimensionless), its value and the factor to
/// internal units. Giving the same key with two units is an error.
fn find_with_unit<'t>(
    t: &'t toml::Table,
    key: &str,
    unit: Unit,
    used: &mut Vec<String>,
) -> Result<Option<(String, &'t toml::Value, f64)>, String> {
    let options: &[(&str, f64)] = match unit {
        Unit::Mm => &[("_mm", 1.0), ("_m", 1000.0)],
        Unit::Rad => &[("_deg", std::f64::consts::PI / 180.0), ("_rad", 1.0)],
        Unit::Unitless => &[("", 1.0)],
    };
    let mut found = None;
    for (suffix, factor) in options {
        let k = format!("{key}{suffix}");
        if let Some(v) = t.get(&k) {
            if found.is_some() {
                return Err(format!("`{key}` is given twice with different units"));
            }
            used.push(k.clone());
            found = Some((k, v, *factor));
        }
    }
    Ok(found)
}

fn number(v: &toml::Value) -> Option<f64> {
    v.as_float()
        .or_else(|| v.as_integer().map(|i| i as f64))
        .filter(|x| x.is_finite())
}

/// A number with a unit suffix (see [`find_with_unit`]), in internal units.
fn unit_value(
    t: &toml::Table,
    key: &str,
    unit: Unit,
    used: &mut Vec<String>,
) -> Result<Option<f64>, String> {
    match find_with_unit(t, key, unit, used)? {
        None => Ok(None),
        Some((k, v, f)) => number(v)
            .map(|x| Some(x * f))
            .ok_or_else(|| format!("`{k}` must be a finite number")),
    }
}

/// Three numbers with a unit suffix (see [`find_with_unit`]), in internal units.
fn unit_triple(
    t: &toml::Table,
    key: &str,
    unit: Unit,
    used: &mut Vec<String>,
) -> Result<Option<[f64; 3]>, String> {
    match find_with_unit(t, key, unit, used)? {
        None => Ok(None),
        Some((k, v, f)) => {
            let bad = || format!("`{k}` must be an array of 3 finite numbers");
            let arr = v.as_array().filter(|a| a.len() == 3).ok_or_else(bad)?;
            let mut out = [0.0; 3];
            for (o, x) in out.iter_mut().zip(arr) {
                *o = number(x).ok_or_else(bad)? * f;
            }
            Ok(Some(out))
        }
    }
}

/// Every key of `t` must be one the parser read (`used`) or one of `allowed`. The error for
/// an unknown key lists what is valid there: `valid` (the fields with their unit suffixes,
/// e.g. `theta_deg|theta_rad`) and `allowed`.
fn check_unused(
    t: &toml::Table,
    used: &[String],
    allowed: &[&str],
    valid: &[String],
) -> Result<(), String> {
    for k in t.keys() {
        if !used.iter().any(|u| u == k) && !allowed.contains(&k.as_str()) {
            let fields: Vec<String> = valid
                .iter()
                .cloned()
                .chain(allowed.iter().map(|a| a.to_string()))
                .collect();
            return Err(format!(
                "unknown field `{k}`; valid here: {} (mind the unit suffix: _mm, _m, _deg, _rad)",
                fields.join(", ")
            ));
        }
    }
    Ok(())
}

/// The spellings of a field with its unit suffixes: `theta_deg|theta_rad`.
fn unit_spellings(field: &str, unit: Unit) -> String {
    match unit {
        Unit::Mm => format!("{field}_mm|{field}_m"),
        Unit::Rad => format!("{field}_deg|{field}_rad"),
        Unit::Unitless => field.to_string(),
    }
}

/// A frame table `{ xyz_mm = [...], rpy_deg = [...] }` (both optional, zero by default).
fn frame(t: &toml::Table, allowed: &[&str]) -> Result<LinkGeometry, String> {
    let mut used = Vec::new();
    let xyz = unit_triple(t, "xyz", Unit::Mm, &mut used)?.unwrap_or([0.0; 3]);
    let rpy = unit_triple(t, "rpy", Unit::Rad, &mut used)?.unwrap_or([0.0; 3]);
    let valid = [
        unit_spellings("xyz", Unit::Mm),
        unit_spellings("rpy", Unit::Rad),
    ];
    check_unused(t, &used, allowed, &valid)?;
    Ok(LinkGeometry::frame6(xyz, rpy))
}

fn string_field<'a>(t: &'a toml::Table, key: &str) -> Result<Option<&'a str>, String> {
    match t.get(key) {
        None => Ok(None),
        Some(v) => v
            .as_str()
            .map(Some)
            .ok_or_else(|| format!("`{key}` must be a string")),
    }
}

/// An inline link: `name`, `convention`, the convention's fields with unit suffixes,
/// optional `joint = "revolute" | "prismatic"`, `limits = [lo, hi]` (deg or mm),
/// `axis = [x, y, z]` for URDF-convention links.
fn inline_link(t: &toml::Table, index: usize) -> Result<LinkSpec, String> {
    let name = string_field(t, "name")?
        .map(str::to_string)
        .unwrap_or_else(|| format!("j{index}"));
    let conv_name = string_field(t, "convention")?.ok_or("missing `convention`")?;
    let mut convention = Convention::from_name(conv_name).ok_or_else(|| {
        format!(
            "unknown convention `{conv_name}`; known: {}",
            Convention::ALL.map(|c| c.name()).join(", ")
        )
    })?;
    // A modified-DH link with β (book §2.6) is written `convention = "mdh"` + `beta_deg`.
    if convention == Convention::Mdh && (t.contains_key("beta_deg") || t.contains_key("beta_rad")) {
        convention = Convention::MdhBeta;
    }
    let kind = match string_field(t, "joint")? {
        None | Some("fixed") => None,
        Some("revolute") => Some(JointKind::Revolute),
        Some("prismatic") => Some(JointKind::Prismatic),
        Some(other) => {
            return Err(format!(
                "`joint` is `{other}`; use revolute, prismatic or fixed"
            ))
        }
    };
    let mut used = Vec::new();
    let mut values = Vec::new();
    for (field, unit) in convention.fields(kind) {
        let v = unit_value(t, field, *unit, &mut used)?;
        let default_zero = *field == "offset";
        values.push(match v {
            Some(v) => v,
            None if default_zero => 0.0,
            None => {
                let hint = match unit {
                    Unit::Mm => "_mm",
                    Unit::Rad => "_deg",
                    Unit::Unitless => "",
                };
                return Err(format!(
                    "missing `{field}{hint}` for convention {convention}"
                ));
            }
        });
    }
    let mut geometry = LinkGeometry::new(convention, values);
    if let Some(a) = t.get("axis") {
        let arr: Vec<f64> = a
            .as_array()
            .map(|v| v.iter().filter_map(number).collect())
            .unwrap_or_default();
        if arr.len() != 3 || arr.iter().all(|x| *x == 0.0) {
            return Err("`axis` must be a non-zero array of 3 numbers".into());
        }
        geometry.axis = Some([arr[0], arr[1], arr[2]]);
    }
    let joint = match kind {
        None => None,
        Some(k) => {
            let lim = t
                .get("limits")
                .and_then(|v| v.as_array())
                .filter(|a| a.len() == 2)
                .ok_or(
                    "a jointed link needs `limits = [lower, upper]` (deg, or mm for prismatic)",
                )?;
            let f = match k {
                JointKind::Revolute => std::f64::consts::PI / 180.0,
                JointKind::Prismatic => 1.0,
            };
            let num = |v: &toml::Value| number(v).ok_or("`limits` must hold finite numbers");
            let jname = string_field(t, "joint_name")?
                .map(str::to_string)
                .unwrap_or_else(|| format!("q{index}"));
            Some(Joint {
                name: jname,
                kind: k,
                lower: num(&lim[0])? * f,
                upper: num(&lim[1])? * f,
            })
        }
    };
    let mut valid: Vec<String> = convention
        .fields(kind)
        .iter()
        .map(|(f, u)| unit_spellings(f, *u))
        .collect();
    if convention == Convention::Mdh {
        valid.push(unit_spellings("beta", Unit::Rad));
    }
    check_unused(
        t,
        &used,
        &[
            "name",
            "convention",
            "joint",
            "limits",
            "axis",
            "joint_name",
        ],
        &valid,
    )?;
    Ok(LinkSpec {
        name,
        geometry,
        joint,
    })
}

fn capsule(t: &toml::Table, frame_required: bool) -> Result<Capsule, String> {
    let mut used = Vec::new();
    let a = unit_triple(t, "a", Unit::Mm, &mut used)?.ok_or("missing `a_mm`")?;
    let b = unit_triple(t, "b", Unit::Mm, &mut used)?.ok_or("missing `b_mm`")?;
    let radius = unit_value(t, "radius", Unit::Mm, &mut used)?.ok_or("missing `radius_mm`")?;
    if radius < 0.0 {
        return Err("`radius_mm` must be ≥ 0".into());
    }
    let frame = string_field(t, "frame")?;
    if frame_required && frame.is_none() {
        return Err("missing `frame` (the chain frame the capsule moves with)".into());
    }
    let valid = ["a", "b", "radius"].map(|k| unit_spellings(k, Unit::Mm));
    check_unused(t, &used, &["frame", "name", "kind"], &valid)?;
    Ok(Capsule {
        frame: frame.unwrap_or("tool").to_string(),
        a,
        b,
        radius,
    })
}

fn obstacle(t: &toml::Table, i: usize) -> Result<Obstacle, String> {
    let name = string_field(t, "name")?
        .map(str::to_string)
        .unwrap_or_else(|| format!("obstacle{}", i + 1));
    match string_field(t, "kind")? {
        Some("capsule") => {
            let c = capsule(t, false)?;
            if t.contains_key("frame") {
                return Err("obstacles are in the world frame; `frame` is not allowed".into());
            }
            Ok(Obstacle::Capsule {
                name,
                a: c.a,
                b: c.b,
                radius: c.radius,
            })
        }
        Some("half-space") => {
            let mut used = Vec::new();
            let n = unit_triple(t, "normal", Unit::Unitless, &mut used)?
                .ok_or("missing `normal = [x, y, z]`")?;
            let offset =
                unit_value(t, "offset", Unit::Mm, &mut used)?.ok_or("missing `offset_mm`")?;
            let norm = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if norm < 1e-12 {
                return Err("`normal` must be non-zero".into());
            }
            let valid = ["normal".to_string(), unit_spellings("offset", Unit::Mm)];
            check_unused(t, &used, &["kind", "name"], &valid)?;
            Ok(Obstacle::HalfSpace {
                name,
                normal: n.map(|x| x / norm),
                offset,
            })
        }
        Some(k) => Err(format!(
            "unknown obstacle kind `{k}`; use capsule or half-space"
        )),
        None => Err("missing `kind` (capsule or half-space)".into()),
    }
}

fn noise(t: &toml::Table) -> Result<NoiseModel, String> {
    let mut used = vec!["model".to_string()];
    let valid: Vec<String> = match string_field(t, "model")? {
        Some("constant") => vec![
            unit_spellings("sigma", Unit::Mm),
            unit_spellings("sigma_angle", Unit::Rad),
        ],
        Some("range") => vec![unit_spellings("a", Unit::Mm), "b_um_per_m".into()],
        Some("per-measurement") => vec![unit_spellings("floor", Unit::Mm)],
        _ => Vec::new(),
    };
    let n = match string_field(t, "model")? {
        Some("constant") => {
            let is_array = ["sigma_mm", "sigma_m"]
                .iter()
                .any(|k| t.get(*k).map(|v| v.is_array()).unwrap_or(false));
            let s = if is_array {
                unit_triple(t, "sigma", Unit::Mm, &mut used)?.ok_or("missing `sigma_mm`")?
            } else {
                [unit_value(t, "sigma", Unit::Mm, &mut used)?
                    .ok_or("missing `sigma_mm` (a number or 3 numbers)")?; 3]
            };
            if s.iter().any(|x| *x <= 0.0) {
                return Err("`sigma_mm` must be positive".into());
            }
            let sigma_angle = unit_value(t, "sigma_angle", Unit::Rad, &mut used)?.unwrap_or(1e-3);
            if sigma_angle <= 0.0 {
                return Err("`sigma_angle_deg` must be positive".into());
            }
            NoiseModel::Constant {
                sigma: s,
                sigma_angle,
            }
        }
        Some("range") => {
            let a = unit_value(t, "a", Unit::Mm, &mut used)?.ok_or("missing `a_mm`")?;
            let b = t
                .get("b_um_per_m")
                .and_then(number)
                .ok_or("missing `b_um_per_m` (µm per metre of range)")?;
            used.push("b_um_per_m".into());
            if a <= 0.0 || b < 0.0 {
                return Err("need `a_mm` > 0 and `b_um_per_m` ≥ 0".into());
            }
            NoiseModel::Range {
                a,
                b_per_m: b / 1000.0,
            }
        }
        Some("per-measurement") => {
            let floor = unit_value(t, "floor", Unit::Mm, &mut used)?.unwrap_or(1e-3);
            if floor <= 0.0 {
                return Err("`floor_mm` must be positive".into());
            }
            NoiseModel::PerMeasurement { floor }
        }
        Some(m) => {
            return Err(format!(
                "unknown noise model `{m}`; use constant, range or per-measurement"
            ))
        }
        None => return Err("missing `model` (constant, range or per-measurement)".into()),
    };
    check_unused(t, &used, &[], &valid)?;
    Ok(n)
}

pub(super) fn parse(text: &str, file: &str, dir: &Path) -> Result<Cell, Error> {
    let ctx = Ctx { file, text };
    let raw: RawCell = toml::from_str(text).map_err(|e| Error::File {
        file: file.to_string(),
        message: e.to_string(),
    })?;
    let rspan = raw.robot.span();
    let rr = raw.robot.into_inner();

    // Robot.
    let sources = rr.builtin.is_some() as usize
        + rr.urdf.is_some() as usize
        + (!rr.links.is_empty()) as usize;
    if sources != 1 {
        return Err(ctx.err(
            rspan,
            "robot",
            "give exactly one of `builtin`, `urdf` or `[[robot.links]]`",
        ));
    }
    let mut robot = if let Some(b) = &rr.builtin {
        robots::robot(b).map_err(|e| ctx.err(rspan.clone(), "robot.builtin", e))?
    } else if let Some(u) = &rr.urdf {
        let path = dir.join(u);
        let spec = crate::model::urdf::read_urdf(&path, rr.tip.as_deref())
            .map_err(|e| ctx.err(rspan.clone(), "robot.urdf", e))?;
        Robot {
            name: rr.name.clone().unwrap_or_else(|| spec.name.clone()),
            summary: format!("imported from {u}"),
            source: format!("URDF file {}", path.display()),
            spec,
            capsules: Vec::new(),
        }
    } else {
        let mut links = Vec::new();
        let mut joint_index = 0;
        for (i, l) in rr.links.iter().enumerate() {
            let has_joint = matches!(
                l.get_ref().get("joint").and_then(|v| v.as_str()),
                Some("revolute") | Some("prismatic")
            );
            if has_joint {
                joint_index += 1;
            }
            let spec = inline_link(l.get_ref(), joint_index)
                .map_err(|e| ctx.err(l.span(), &format!("robot.links[{i}]"), e))?;
            links.push(spec);
        }
        // Every chain starts with a base frame and ends with a tool frame.
        if links.first().map(|l| l.name.as_str()) != Some("base") {
            links.insert(0, crate::robots::frame_link("base", [0.0; 3], [0.0; 3]));
        }
        if links.last().map(|l| l.name.as_str()) != Some("tool") {
            links.push(crate::robots::frame_link("tool", [0.0; 3], [0.0; 3]));
        }
        let name = rr.name.clone().unwrap_or_else(|| "inline".into());
        Robot {
            name: name.clone(),
            summary: "inline robot from the cell file".into(),
            source: format!("cell file {file}"),
            spec: ModelSpec {
                name,
                instrument: None,
                links,
                targets: vec![],
            },
            capsules: Vec::new(),
        }
    };
    if let Some(limits) = &rr.limits {
        for (jname, [lo, hi]) in limits {
            let link = robot
                .spec
                .links
                .iter_mut()
                .find(|l| l.joint.as_ref().map(|j| j.name == *jname).unwrap_or(false))
                .ok_or_else(|| {
                    ctx.err(
                        rspan.clone(),
                        &format!("robot.limits.{jname}"),
                        "no joint of that name",
                    )
                })?;
            let j = link.joint.as_mut().expect("found by joint");
            let f = match j.kind {
                JointKind::Revolute => std::f64::consts::PI / 180.0,
                JointKind::Prismatic => 1.0,
            };
            j.lower = lo * f;
            j.upper = hi * f;
        }
    }
    for (i, c) in rr.capsules.iter().enumerate() {
        let cap = capsule(c.get_ref(), true)
            .map_err(|e| ctx.err(c.span(), &format!("robot.capsules[{i}]"), e))?;
        robot.capsules.push(cap);
    }

    // Instrument.
    let (instrument, instrument_geometry, instrument_name) = match raw.instrument {
        None => (None, None, "instrument".to_string()),
        Some(ri) => {
            let span = ri.span();
            let ri = ri.into_inner();
            let xyz = match (ri.xyz_mm, ri.xyz_m) {
                (Some(v), None) => v,
                (None, Some(v)) => v.map(|x| x * 1000.0),
                (None, None) => [0.0; 3],
                _ => return Err(ctx.err(span, "instrument", "give `xyz_mm` or `xyz_m`, not both")),
            };
            let rpy = match (ri.rpy_deg, ri.rpy_rad) {
                (Some(v), None) => v.map(f64::to_radians),
                (None, Some(v)) => v,
                (None, None) => [0.0; 3],
                _ => {
                    return Err(ctx.err(
                        span,
                        "instrument",
                        "give `rpy_deg` or `rpy_rad`, not both",
                    ))
                }
            };
            let noise = match &ri.noise {
                Some(t) => noise(t).map_err(|e| ctx.err(span.clone(), "instrument.noise", e))?,
                None => NoiseModel::default(),
            };
            if let Some(a) = ri.max_incidence_deg {
                if !(0.0..=180.0).contains(&a) {
                    return Err(ctx.err(
                        span,
                        "instrument.max_incidence_deg",
                        "must be in [0, 180]",
                    ));
                }
            }
            (
                Some(Instrument {
                    kind: ri.kind.unwrap_or_else(|| "laser-tracker".into()),
                    noise,
                    max_incidence: ri.max_incidence_deg.map(f64::to_radians),
                }),
                Some(LinkGeometry::frame6(xyz, rpy)),
                ri.name.unwrap_or_else(|| "tracker".into()),
            )
        }
    };
    let base = match &raw.base {
        Some(t) => Some(frame(t.get_ref(), &[]).map_err(|e| ctx.err(t.span(), "base", e))?),
        None => None,
    };
    let tool = match &raw.tool {
        Some(t) => Some(frame(t.get_ref(), &[]).map_err(|e| ctx.err(t.span(), "tool", e))?),
        None => None,
    };
    let mut targets = Vec::new();
    for (i, t) in raw.targets.iter().enumerate() {
        let tt = t.get_ref();
        let field = format!("targets[{i}]");
        let name = string_field(tt, "name")
            .map_err(|e| ctx.err(t.span(), &field, e))?
            .map(str::to_string)
            .unwrap_or_else(|| format!("smr{}", i + 1));
        let is_frame = tt.keys().any(|k| k.starts_with("rpy"));
        let geometry = if is_frame {
            frame(tt, &["name"]).map_err(|e| ctx.err(t.span(), &field, e))?
        } else {
            let mut used = vec!["name".to_string()];
            let xyz = unit_triple(tt, "xyz", Unit::Mm, &mut used)
                .and_then(|v| v.ok_or_else(|| "missing `xyz_mm`".to_string()))
                .map_err(|e| ctx.err(t.span(), &field, e))?;
            check_unused(tt, &used, &[], &[unit_spellings("xyz", Unit::Mm)])
                .map_err(|e| ctx.err(t.span(), &field, e))?;
            LinkGeometry::point(xyz)
        };
        targets.push(LinkSpec {
            name,
            geometry,
            joint: None,
        });
    }
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
    let mut tool_capsules = Vec::new();
    for (i, c) in raw.tool_capsules.iter().enumerate() {
        tool_capsules.push(
            capsule(c.get_ref(), false)
                .map_err(|e| ctx.err(c.span(), &format!("tool_capsules[{i}]"), e))?,
        );
    }
    let form = match &rr.convention {
        None => LinkForm::Auto,
        Some(c) => LinkForm::from_name(c).ok_or_else(|| {
            ctx.err(
                rspan.clone(),
                "robot.convention",
                format!(
                    "`{c}`; use {}",
                    LinkForm::ALL.map(LinkForm::name).join(", ")
                ),
            )
        })?,
    };
    let given = Model::from_spec(&spec).map_err(model_error)?;
    let shaped = shape_robot(&mut robot, &given, spec, form, &mut tool_capsules)
        .map_err(|e| ctx.err(rspan.clone(), "robot.convention", e))?;
    let mut model = Model::from_spec(&shaped.spec).map_err(model_error)?;

    // Parameters.
    let all_frames = (0..model.targets.len()).all(|k| model.target_is_frame(k));
    let mut measurement = if all_frames {
        // No targets (the tool frame is measured) or only frame targets.
        Measurement::Pose
    } else {
        Measurement::Position
    };
    let mut auto_free = true;
    if let Some(p) = &raw.parameters {
        let span = p.span();
        let p = p.get_ref();
        let free: Vec<String> = match &p.free {
            None => Vec::new(),
            Some(toml::Value::String(s)) if s == "auto" => Vec::new(),
            Some(toml::Value::String(s)) if s == "all" => {
                auto_free = false;
                Vec::new()
            }
            Some(toml::Value::Array(a)) => {
                auto_free = false;
                a.iter()
                    .map(|v| v.as_str().map(str::to_string))
                    .collect::<Option<Vec<_>>>()
                    .ok_or_else(|| {
                        ctx.err(
                            span.clone(),
                            "parameters.free",
                            "must be \"auto\", \"all\" or a list of parameter patterns",
                        )
                    })?
            }
            Some(_) => {
                return Err(ctx.err(
                    span,
                    "parameters.free",
                    "must be \"auto\", \"all\" or a list of parameter patterns",
                ))
            }
        };
        let mut priors = Vec::new();
        for (name, t) in &p.priors {
            let i = model
                .registry
                .matching(name)
                .map_err(|e| ctx.err(span.clone(), &format!("parameters.priors.{name}"), e))?;
            let unit = model.registry.get(i[0]).unit;
            let mut used = Vec::new();
            let s = unit_value(t, "sigma", unit, &mut used)
                .and_then(|v| v.ok_or_else(|| "missing `sigma_deg` / `sigma_mm`".into()))
                .and_then(|v| {
                    check_unused(t, &used, &[], &[unit_spellings("sigma", unit)]).map(|_| v)
                })
                .map_err(|e| ctx.err(span.clone(), &format!("parameters.priors.{name}"), e))?;
            if s <= 0.0 {
                return Err(ctx.err(
                    span,
                    &format!("parameters.priors.{name}"),
                    "sigma must be positive",
                ));
            }
            priors.push((name.clone(), s));
        }
        if !free.is_empty() {
            // An explicit free list: everything else is fixed.
            model
                .set_status("*", Status::Fixed)
                .expect("every model has parameters");
        }
        apply_statuses(&mut model, &p.fixed, &free, &priors)
            .map_err(|e| ctx.err(span.clone(), "parameters", e))?;
        if let Some(m) = &p.measurement {
            measurement = Measurement::from_name(m).ok_or_else(|| {
                ctx.err(
                    span.clone(),
                    "parameters.measurement",
                    format!("`{m}`: use pose, position or distance"),
                )
            })?;
        }
    }

    // Working configurations.
    let mut warnings = Vec::new();
    let mut working = Vec::new();
    for (i, w) in raw.working.iter().enumerate() {
        let field = format!("working[{i}]");
        let t = w.get_ref();
        let name = string_field(t, "name")
            .map_err(|e| ctx.err(w.span(), &field, e))?
            .map(str::to_string)
            .unwrap_or_else(|| format!("work{}", i + 1));
        let (key, f) = if t.contains_key("joints_deg") {
            ("joints_deg", std::f64::consts::PI / 180.0)
        } else {
            ("joints_rad", 1.0)
        };
        let arr = t.get(key).and_then(|v| v.as_array()).ok_or_else(|| {
            ctx.err(
                w.span(),
                &field,
                "missing `joints_deg` (deg for revolute, mm for prismatic joints) or `joints_rad`",
            )
        })?;
        let q: Vec<f64> = arr
            .iter()
            .zip(&model.joints)
            .map(|(v, j)| {
                let x = number(v).unwrap_or(f64::NAN);
                if j.kind == JointKind::Prismatic {
                    x
                } else {
                    x * f
                }
            })
            .collect();
        if arr.len() != model.dof() {
            return Err(ctx.err(
                w.span(),
                &format!("{field}.{key}"),
                format!(
                    "has {} values, the robot has {} joints",
                    arr.len(),
                    model.dof()
                ),
            ));
        }
        if q.iter().any(|x| !x.is_finite()) {
            return Err(ctx.err(
                w.span(),
                &format!("{field}.{key}"),
                "values must be numbers",
            ));
        }
        if let Err(e) = model.check_joints(&q) {
            warnings.push(format!(
                "{file}: line {}: `{field}` ({name}): {e}; kept, since the KPI only needs the model there, but the robot cannot reach it",
                ctx.line(w.span())
            ));
        }
        let weight = t
            .get("weight")
            .map(|v| number(v).unwrap_or(f64::NAN))
            .unwrap_or(1.0);
        if !(weight > 0.0 && weight.is_finite()) {
            return Err(ctx.err(
                w.span(),
                &format!("{field}.weight"),
                "must be a positive number",
            ));
        }
        let used: Vec<String> = vec![key.into()];
        check_unused(
            t,
            &used,
            &["name", "weight"],
            &["joints_deg|joints_rad".into()],
        )
        .map_err(|e| ctx.err(w.span(), &field, e))?;
        working.push(WorkingPose { name, q, weight });
    }

    let mut obstacles = Vec::new();
    for (i, o) in raw.obstacles.iter().enumerate() {
        obstacles.push(
            obstacle(o.get_ref(), i)
                .map_err(|e| ctx.err(o.span(), &format!("obstacles[{i}]"), e))?,
        );
    }
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
    let data_columns = match raw.data {
        Some(d) => {
            if d.joints.len() != model.dof() {
                return Err(Error::File {
                    file: file.to_string(),
                    message: format!(
                        "`data.joints` lists {} columns, the robot has {} joints",
                        d.joints.len(),
                        model.dof()
                    ),
                });
            }
            Some(DataColumns { joints: d.joints })
        }
        None => None,
    };
    let mut cell = Cell {
        name: raw.name.unwrap_or_else(|| robot.name.clone()),
        origin: file.to_string(),
        robot,
        model,
        instrument,
        working,
        obstacles,
        capsules,
        measurement,
        auto_free,
        declared_free: Vec::new(),
        data_columns,
        warnings,
        form,
        form_changes: shaped.changes,
        form_incomplete: shaped.incomplete,
    };
    cell.declared_free = cell.model.registry.free();
    if cell.auto_free {
        let report = cell.identifiability(&cell.identifiability_settings())?;
        report.apply(&mut cell.model)?;
    }
    Ok(cell)
}
