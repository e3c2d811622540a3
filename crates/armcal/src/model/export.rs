//! Exports of a (calibrated) model: a cell file with inline links in any convention (TOML,
//! mm and degrees — loadable as it is), a parameter table (CSV), JSON, and URDF.

use crate::model::chain::{LinkSpec, Model, ModelSpec};
use crate::model::complete::LinkForm;
use crate::model::compliance::ComplianceSpec;
use crate::model::convert;
use crate::model::kinematics::{forward_kinematics, Data};
use crate::model::link::{Convention, JointKind};
use crate::model::periodic::PeriodicSpec;
use crate::model::registry::{Segment, Unit};
use crate::table::Table;
use crate::toml_text;
use crate::Error;
use nalgebra::{Matrix3, Vector3};
use std::fmt::Write;

/// The unit suffix of a cell field in `u`'s display unit (`_mm`, `_deg`, …).
pub(crate) fn suffix(u: Unit) -> &'static str {
    match u {
        Unit::Mm => "_mm",
        Unit::Rad => "_deg",
        Unit::Unitless => "",
        Unit::RadPerMm => "_urad_per_m",
        Unit::RadPerNmm => "_urad_per_Nm",
        Unit::Arcsec => "_arcsec",
    }
}

fn display(u: Unit, v: f64) -> f64 {
    v * u.display_factor()
}

/// One link as a `[[table]]` entry of a cell file (name, convention, joint, axis, values in
/// display units); `extra` lines (a tree link's `parent`, `coupled`) close the entry.
pub(crate) fn link_toml_with(
    out: &mut String,
    table: &str,
    l: &LinkSpec,
    with_convention: bool,
    extra: &str,
) {
    let kind = l.joint.as_ref().map(|j| j.kind);
    let _ = writeln!(out, "[[{table}]]\nname = {}", toml_text::string(&l.name));
    if with_convention {
        let _ = writeln!(out, "convention = \"{}\"", l.geometry.convention.name());
    }
    if let Some(j) = &l.joint {
        let f = j.kind.unit().display_factor();
        let _ = writeln!(
            out,
            "joint = \"{}\"\njoint_name = {}\nlimits = [{:?}, {:?}]",
            if j.kind == JointKind::Revolute {
                "revolute"
            } else {
                "prismatic"
            },
            toml_text::string(&j.name),
            j.lower * f,
            j.upper * f
        );
    }
    if let Some(a) = l.geometry.axis {
        let _ = writeln!(out, "axis = [{:?}, {:?}, {:?}]", a[0], a[1], a[2]);
    }
    for ((field, unit), v) in l
        .geometry
        .convention
        .fields(kind)
        .iter()
        .zip(&l.geometry.values)
    {
        let _ = writeln!(out, "{field}{} = {:?}", suffix(*unit), display(*unit, *v));
    }
    out.push_str(extra);
    out.push('\n');
}

fn link_toml(out: &mut String, table: &str, l: &LinkSpec, with_convention: bool) {
    link_toml_with(out, table, l, with_convention, "");
}

/// The `[instrument]` section of a cell for the instrument frame `i` (its name and frame
/// fields; what follows them is the caller's): an error unless it is a `frame6`.
pub(crate) fn instrument_section(i: &LinkSpec) -> Result<String, Error> {
    if i.geometry.convention != Convention::Frame6 {
        return Err(Error::Conversion(format!(
            "instrument `{}` is not a frame6 and cannot be written to a cell",
            i.name
        )));
    }
    Ok(format!(
        "[instrument]\nname = {}\n{}",
        toml_text::string(&i.name),
        frame_fields(&i.geometry.values)
    ))
}

/// `xyz_mm` and `rpy_deg` lines of a frame6 (x, y, z in mm, rx, ry, rz in rad).
pub(crate) fn frame_fields(v: &[f64]) -> String {
    format!(
        "xyz_mm = [{:?}, {:?}, {:?}]\nrpy_deg = [{:?}, {:?}, {:?}]\n",
        v[0],
        v[1],
        v[2],
        v[3].to_degrees(),
        v[4].to_degrees(),
        v[5].to_degrees()
    )
}

/// What a cell file holds besides the model (see `cell::export`), as TOML lines for each
/// place of the file; empty: a cell of the model alone.
#[derive(Clone, Debug, Default)]
pub struct CellSections {
    /// The cell's name (default: the model's).
    pub name: Option<String>,
    /// Tables that belong to `[robot]` after its links (`[[robot.capsules]]`).
    pub robot: String,
    /// Lines of `[instrument]` after its frame (kind, noise, incidence limit).
    pub instrument: String,
    /// The body of `[parameters]` (default `free = "all"`).
    pub parameters: Option<String>,
    /// Tables at the end (working poses, obstacles, data columns).
    pub tail: String,
}

/// A cell file holding the model as inline links (every convention the cell format reads),
/// the instrument frame and the targets. Values are written with full precision.
pub fn to_cell_toml(spec: &ModelSpec) -> Result<String, Error> {
    to_cell_toml_with(spec, &CellSections::default())
}

/// [`to_cell_toml`] with the rest of a cell in its places.
pub fn to_cell_toml_with(spec: &ModelSpec, sections: &CellSections) -> Result<String, Error> {
    let name = sections.name.as_deref().unwrap_or(&spec.name);
    let mut out = format!(
        "# armcal model export: {}\nname = {}\n\n[robot]\nname = {}\n",
        toml_text::string(&spec.name),
        toml_text::string(name),
        toml_text::string(&spec.name)
    );
    if let Some(c) = &spec.compliance {
        let g = c.gravity;
        let _ = writeln!(out, "gravity = [{:?}, {:?}, {:?}]", g[0], g[1], g[2]);
    }
    out.push('\n');
    for l in &spec.links {
        link_toml(&mut out, "robot.links", l, true);
    }
    out.push_str(&sections.robot);
    if let Some(i) = &spec.instrument {
        let _ = writeln!(out, "{}{}", instrument_section(i)?, sections.instrument);
    }
    for t in &spec.targets {
        let v = &t.geometry.values;
        match t.geometry.convention {
            Convention::Point => {
                let _ = writeln!(
                    out,
                    "[[targets]]\nname = {}\nxyz_mm = [{:?}, {:?}, {:?}]\n",
                    toml_text::string(&t.name),
                    v[0],
                    v[1],
                    v[2]
                );
            }
            Convention::Frame6 => {
                let _ = writeln!(
                    out,
                    "[[targets]]\nname = {}\n{}",
                    toml_text::string(&t.name),
                    frame_fields(v)
                );
            }
            c => {
                return Err(Error::Conversion(format!(
                    "target `{}` ({c}) has no cell-file form",
                    t.name
                )))
            }
        }
    }
    out.push_str("[parameters]\n");
    out.push_str(sections.parameters.as_deref().unwrap_or("free = \"all\"\n"));
    out.push_str(&joint_corrections_toml(spec)?);
    out.push_str(&sections.tail);
    for p in &spec.payloads {
        let _ = writeln!(
            out,
            "\n[[payload]]\nname = {}\nmass_kg = {:?}\ncom_mm = {:?}",
            toml_text::string(&p.name),
            p.mass_kg,
            p.com_mm
        );
    }
    Ok(out)
}

/// The `[parameters]` lines of `spec`'s joint corrections as the cell reader takes them: the
/// compliant joints, the periodic joints and harmonics, and every non-zero term's `values`
/// (µrad/m, arcsec). A compliance whose terms are not the default lumped terms of its joints
/// at the written geometry ([`ComplianceSpec::lumped`]) has no cell form: the error says so.
fn joint_corrections_toml(spec: &ModelSpec) -> Result<String, Error> {
    let mut out = String::new();
    let mut values = Vec::new();
    let quoted = |names: Vec<String>| -> String {
        let q: Vec<String> = joints_once(&names)
            .iter()
            .map(|n| toml_text::string(n))
            .collect();
        q.join(", ")
    };
    if let Some(c) = &spec.compliance {
        let joints: Vec<String> = c.terms.iter().map(|t| t.joint.clone()).collect();
        let rigid = Model::from_spec(&ModelSpec {
            compliance: None,
            periodic: None,
            ..spec.clone()
        })?;
        let names = |terms: &[crate::model::compliance::ComplianceTerm]| -> Vec<String> {
            terms.iter().map(ComplianceSpec::parameter_name).collect()
        };
        let mut read_back = ComplianceSpec::lumped(&rigid, &joints_once(&joints), c.gravity)
            .map(|r| names(&r.terms))
            .unwrap_or_default();
        read_back.sort();
        let mut own = names(&c.terms);
        own.sort();
        if read_back != own {
            return Err(Error::Conversion(format!(
                "the compliance terms {} are not the lumped terms a cell makes of joints {} \
                 ({}); export to json to keep them",
                own.join(", "),
                joints_once(&joints).join(", "),
                read_back.join(", ")
            )));
        }
        let _ = writeln!(out, "compliance = [{}]", quoted(joints));
        for t in &c.terms {
            values.push((ComplianceSpec::parameter_name(t), t.unit(), t.value));
        }
    }
    if let Some(p) = &spec.periodic {
        let mut harmonics: Vec<u32> = p.terms.iter().map(|t| t.harmonic).collect();
        harmonics.sort_unstable();
        harmonics.dedup();
        let _ = writeln!(
            out,
            "periodic = {{ joints = [{}], harmonics = {harmonics:?} }}",
            quoted(p.terms.iter().map(|t| t.joint.clone()).collect())
        );
        for t in &p.terms {
            values.push((PeriodicSpec::parameter_name(t), Unit::Arcsec, t.value));
        }
    }
    let set: Vec<String> = values
        .iter()
        .filter(|v| v.2 != 0.0)
        .map(|(name, unit, v)| {
            format!(
                "{} = {{ value{} = {:?} }}",
                toml_text::string(name),
                suffix(*unit),
                display(*unit, *v)
            )
        })
        .collect();
    if !set.is_empty() {
        let _ = writeln!(out, "values = {{ {} }}", set.join(", "));
    }
    Ok(out)
}

/// `names` with repeats removed, first occurrence kept.
fn joints_once(names: &[String]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for n in names {
        if !out.contains(n) {
            out.push(n.clone());
        }
    }
    out
}

/// A parameter table: one row per link with its convention and fields (mm, deg).
pub fn to_table_csv(spec: &ModelSpec) -> String {
    let mut out = Table::new(["link", "convention", "joint", "field", "value", "unit"]);
    let links = spec
        .instrument
        .iter()
        .chain(&spec.links)
        .chain(&spec.targets);
    for l in links {
        let kind = l.joint.as_ref().map(|j| j.kind);
        let joint = l.joint.as_ref().map(|j| j.name.as_str()).unwrap_or("");
        for ((field, unit), v) in l
            .geometry
            .convention
            .fields(kind)
            .iter()
            .zip(&l.geometry.values)
        {
            out.row([
                l.name.as_str(),
                l.geometry.convention.name(),
                joint,
                field,
                &format!("{:?}", display(*unit, *v)),
                unit.display_name(),
            ]);
        }
    }
    out.into_string()
}

/// `spec` in the link form of an export, forward kinematics unchanged: `Zrp` the
/// zero-reference model; `Dh` DH links by the common normals, Hayati links where `spec` has
/// them (book §6.3.4); `Mdh` Craig's modified DH of that DH form, with β where it has a
/// Hayati link ([`convert::dh_to_mdh`]); anything else `spec` as it is.
///
/// The joint corrections (compliance, periodic errors) are not link geometry and ride along:
/// the same joints, terms and values. A converted compliance takes the converted links as its
/// levers, as a cell file does when it is read ([`ComplianceSpec::lumped`]), where `spec` may
/// keep the nominal ones: the deflection then changes by the lever change, a share of it of
/// the order of the calibrated angles' change (0.2 % for 0.1°; test
/// `model::export_reload::a_nongeometric_calibration_exported_as_a_cell_keeps_its_terms_and_its_deflection`).
/// Its gravity keeps its direction in the world, re-expressed in the new base frame.
pub fn export_form(spec: &ModelSpec, form: LinkForm) -> Result<ModelSpec, Error> {
    let model = Model::from_spec(spec)?;
    let zrp = || convert::to_zrp(&model, &model.nominal());
    let mut out = match form {
        LinkForm::Zrp => zrp(),
        LinkForm::Dh => convert::zrp_to_dh(&zrp(), Some(spec))?,
        // The DH form with Hayati links regroups with β; where it cannot (a book Type 3
        // last link), the pure DH form.
        LinkForm::Mdh => convert::dh_to_mdh(&convert::zrp_to_dh(&zrp(), Some(spec))?)
            .or_else(|_| convert::dh_to_mdh(&convert::zrp_to_dh(&zrp(), None)?))?,
        LinkForm::Auto | LinkForm::AsGiven => return Ok(spec.clone()),
    };
    if let Some(c) = &spec.compliance {
        let mut at = c.levers.clone();
        at.extend_from_slice(&model.nominal()[c.levers.len()..]);
        let world = base_rotation(&model, &at) * Vector3::from(c.gravity);
        let links = Model::from_spec(&out)?;
        let levers = links.nominal();
        let g = base_rotation(&links, &levers).transpose() * world;
        out.compliance = Some(ComplianceSpec {
            gravity: g.into(),
            levers,
            terms: c.terms.clone(),
            bending: c.bending.clone(),
        });
    }
    out.periodic = spec.periodic.clone();
    out.payloads = spec.payloads.clone();
    Ok(out)
}

/// The world rotation of `model`'s base frame (the chain's first frame) at `params`.
fn base_rotation(model: &Model, params: &[f64]) -> Matrix3<f64> {
    let mut data = Data::<f64>::without_corrections(model);
    forward_kinematics(model, &mut data, params, &vec![0.0; model.dof()]);
    data.frames[0].rot
}

/// Exported values a user should look at before loading the cell: lengths beyond twice the
/// robot's size (the sum of its nominal link lengths and offsets, mm), and angles more than
/// 45° (modulo whole turns) from the same link's in `reference`, the cell's nominal model in
/// the same form (a general frame's rotation compared as a whole). Each as a sentence.
pub fn suspicious_values(reference: &Model, spec: &ModelSpec) -> Result<Vec<String>, Error> {
    let exported = Model::from_spec(spec)?;
    let size: f64 = reference
        .registry
        .iter()
        .filter(|p| p.unit == Unit::Mm && matches!(p.segment, Segment::Chain))
        .map(|p| p.nominal.abs())
        .sum();
    let mut out = Vec::new();
    for p in exported.registry.iter() {
        if p.unit == Unit::Mm
            && matches!(p.segment, Segment::Chain)
            && p.nominal.abs() > 2.0 * size.max(1.0)
        {
            out.push(format!(
                "`{}` = {:.1} mm is more than twice the robot's size ({size:.0} mm): the \
                 convention is ill-conditioned here (e.g. plain DH across nearly parallel \
                 axes); prefer another format",
                p.name, p.nominal
            ));
        }
    }
    // Angles: a general frame's rotation as a whole (its Euler angles are arbitrary near
    // ±90° pitch), every other angle field by field, modulo whole turns.
    let links = |m: &ModelSpec| -> Vec<LinkSpec> {
        m.instrument
            .iter()
            .chain(&m.links)
            .chain(&m.targets)
            .cloned()
            .collect()
    };
    let reference_links = links(&reference.spec());
    for l in links(spec) {
        let Some(r) = reference_links.iter().find(|r| r.name == l.name) else {
            continue;
        };
        let g = &l.geometry;
        if g.convention != r.geometry.convention {
            continue;
        }
        let kind = l.joint.as_ref().map(|j| j.kind);
        if matches!(
            g.convention,
            Convention::Frame6 | Convention::Urdf | Convention::BookType3
        ) {
            let d = convert::link_pose(g, kind)?
                .rotation_angle_to(&convert::link_pose(&r.geometry, kind)?)
                .to_degrees();
            if d > 45.0 {
                out.push(format!(
                    "the rotation of `{}` is {d:.1}° from the nominal's",
                    l.name
                ));
            }
            continue;
        }
        for (((field, unit), v), nominal) in g
            .convention
            .fields(kind)
            .iter()
            .zip(&g.values)
            .zip(&r.geometry.values)
        {
            let d = convert::wrap(v - nominal).to_degrees();
            if *unit == Unit::Rad && d.abs() > 45.0 {
                out.push(format!(
                    "`{}.{field}` = {:.3}° is {d:.1}° from the nominal {:.3}°",
                    l.name,
                    v.to_degrees(),
                    nominal.to_degrees()
                ));
            }
        }
    }
    Ok(out)
}
