//! Exports of a (calibrated) model: a cell file with inline links in any convention (TOML,
//! mm and degrees — loadable as it is), a parameter table (CSV), JSON, and URDF.

use crate::model::chain::{LinkSpec, Model, ModelSpec};
use crate::model::complete::LinkForm;
use crate::model::convert;
use crate::model::link::{Convention, JointKind};
use crate::model::registry::{Segment, Unit};
use crate::table::Table;
use crate::toml_text;
use crate::Error;
use std::fmt::Write;

fn suffix(u: Unit) -> &'static str {
    match u {
        Unit::Mm => "_mm",
        Unit::Rad => "_deg",
        Unit::Unitless => "",
        Unit::RadPerMm => "_urad_per_m",
        Unit::Arcsec => "_arcsec",
    }
}

fn display(u: Unit, v: f64) -> f64 {
    v * u.display_factor()
}

fn link_toml(out: &mut String, table: &str, l: &LinkSpec, with_convention: bool) {
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
    out.push('\n');
}

/// `xyz_mm` and `rpy_deg` lines of a frame6 (x, y, z in mm, rx, ry, rz in rad).
fn frame_fields(v: &[f64]) -> String {
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
        "# armcal model export: {}\nname = {}\n\n[robot]\nname = {}\n\n",
        toml_text::string(&spec.name),
        toml_text::string(name),
        toml_text::string(&spec.name)
    );
    for l in &spec.links {
        link_toml(&mut out, "robot.links", l, true);
    }
    out.push_str(&sections.robot);
    if let Some(i) = &spec.instrument {
        if i.geometry.convention != Convention::Frame6 {
            return Err(Error::Conversion(format!(
                "instrument `{}` is not a frame6 and cannot be written to a cell",
                i.name
            )));
        }
        let _ = writeln!(
            out,
            "[instrument]\nname = {}\n{}{}",
            toml_text::string(&i.name),
            frame_fields(&i.geometry.values),
            sections.instrument
        );
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
    out.push_str(&sections.tail);
    Ok(out)
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
pub fn export_form(spec: &ModelSpec, form: LinkForm) -> Result<ModelSpec, Error> {
    let model = Model::from_spec(spec)?;
    let zrp = || convert::to_zrp(&model, &model.nominal());
    Ok(match form {
        LinkForm::Zrp => zrp(),
        LinkForm::Dh => convert::zrp_to_dh(&zrp(), Some(spec))?,
        // The DH form with Hayati links regroups with β; where it cannot (a book Type 3
        // last link), the pure DH form.
        LinkForm::Mdh => convert::dh_to_mdh(&convert::zrp_to_dh(&zrp(), Some(spec))?)
            .or_else(|_| convert::dh_to_mdh(&convert::zrp_to_dh(&zrp(), None)?))?,
        LinkForm::Auto | LinkForm::AsGiven => spec.clone(),
    })
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
