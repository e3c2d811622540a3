//! Exports of a (calibrated) model: a cell file with inline links in any convention (TOML,
//! mm and degrees — loadable as it is), a parameter table (CSV), JSON, and URDF.

use crate::model::chain::{LinkSpec, ModelSpec};
use crate::model::link::{Convention, JointKind};
use crate::model::registry::Unit;
use crate::Error;
use std::fmt::Write;

fn suffix(u: Unit) -> &'static str {
    match u {
        Unit::Mm => "_mm",
        Unit::Rad => "_deg",
        Unit::Unitless => "",
    }
}

fn display(u: Unit, v: f64) -> f64 {
    v * u.display_factor()
}

fn link_toml(out: &mut String, table: &str, l: &LinkSpec, with_convention: bool) {
    let kind = l.joint.as_ref().map(|j| j.kind);
    let _ = writeln!(out, "[[{table}]]\nname = \"{}\"", l.name);
    if with_convention {
        let _ = writeln!(out, "convention = \"{}\"", l.geometry.convention.name());
    }
    if let Some(j) = &l.joint {
        let f = j.kind.unit().display_factor();
        let _ = writeln!(
            out,
            "joint = \"{}\"\njoint_name = \"{}\"\nlimits = [{:?}, {:?}]",
            if j.kind == JointKind::Revolute {
                "revolute"
            } else {
                "prismatic"
            },
            j.name,
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

/// A cell file holding the model as inline links (every convention the cell format reads),
/// the instrument frame and the targets. Values are written with full precision.
pub fn to_cell_toml(spec: &ModelSpec) -> Result<String, Error> {
    let mut out = format!(
        "# armcal model export: {}\nname = \"{}\"\n\n[robot]\nname = \"{}\"\n\n",
        spec.name, spec.name, spec.name
    );
    for l in &spec.links {
        link_toml(&mut out, "robot.links", l, true);
    }
    if let Some(i) = &spec.instrument {
        if i.geometry.convention != Convention::Frame6 {
            return Err(Error::Conversion(format!(
                "instrument `{}` is not a frame6 and cannot be written to a cell",
                i.name
            )));
        }
        let _ = writeln!(
            out,
            "[instrument]\nname = \"{}\"\n{}",
            i.name,
            frame_fields(&i.geometry.values)
        );
    }
    for t in &spec.targets {
        let v = &t.geometry.values;
        match t.geometry.convention {
            Convention::Point => {
                let _ = writeln!(
                    out,
                    "[[targets]]\nname = \"{}\"\nxyz_mm = [{:?}, {:?}, {:?}]\n",
                    t.name, v[0], v[1], v[2]
                );
            }
            Convention::Frame6 => {
                let _ = writeln!(
                    out,
                    "[[targets]]\nname = \"{}\"\n{}",
                    t.name,
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
    out.push_str("[parameters]\nfree = \"all\"\n");
    Ok(out)
}

/// A parameter table: one row per link with its convention and fields (mm, deg).
pub fn to_table_csv(spec: &ModelSpec) -> String {
    let mut out = String::from("link,convention,joint,field,value,unit\n");
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
            let _ = writeln!(
                out,
                "{},{},{},{},{:?},{}",
                l.name,
                l.geometry.convention.name(),
                joint,
                field,
                display(*unit, *v),
                unit.display_name()
            );
        }
    }
    out
}
