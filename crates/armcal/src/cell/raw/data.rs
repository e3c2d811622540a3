//! `[data]`: how the cell's data files are laid out — the joint columns and, for a vendor's
//! export, the delimiter, decimal notation and the mapped columns with their units and
//! orientation convention ([`crate::measure::format`]).

use super::*;
use crate::measure::angles::Orientation;
use crate::measure::format::{ColumnUnit, Columns, DataFormat, Decimal, OrientationColumns};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawData {
    joints: Vec<String>,
    joint_unit: Option<Spanned<String>>,
    delimiter: Option<Spanned<String>>,
    decimal: Option<Spanned<String>>,
    position: Option<Spanned<RawColumns>>,
    orientation: Option<Spanned<RawColumns>>,
    sigma_position: Option<Spanned<RawColumns>>,
    sigma_orientation: Option<Spanned<RawColumns>>,
    temperature: Option<Spanned<RawTemperature>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawColumns {
    columns: Vec<String>,
    unit: Option<String>,
    /// Orientation only: `rpy`, `xyz-intrinsic`, `quat-xyzw` or `quat-wxyz`.
    convention: Option<String>,
    /// σ only: a file may lack these columns.
    #[serde(default)]
    optional: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTemperature {
    column: String,
    unit: String,
}

/// A string field with its span.
fn text(v: &Option<Spanned<String>>) -> Option<(std::ops::Range<usize>, &str)> {
    v.as_ref().map(|s| (s.span(), s.get_ref().as_str()))
}

const UNITS: &str = "mm, m, in, um, deg or rad";

fn unit(
    ctx: &Ctx,
    span: std::ops::Range<usize>,
    field: &str,
    name: &str,
) -> Result<ColumnUnit, Error> {
    ColumnUnit::from_name(name)
        .ok_or_else(|| ctx.err(span, field, format!("unknown unit `{name}` (use {UNITS})")))
}

/// Three columns with a unit (`position`, `sigma_position`, `sigma_orientation`).
fn three(
    ctx: &Ctx,
    raw: Option<&Spanned<RawColumns>>,
    field: &str,
) -> Result<Option<Columns>, Error> {
    let Some(raw) = raw else { return Ok(None) };
    let (span, c) = (raw.span(), raw.get_ref());
    if c.convention.is_some() {
        return Err(ctx.err(span, field, "`convention` belongs to `orientation`"));
    }
    let columns: [String; 3] = c.columns.clone().try_into().map_err(|_| {
        ctx.err(
            span.clone(),
            field,
            format!("`columns` must name 3 columns, not {}", c.columns.len()),
        )
    })?;
    let name = c
        .unit
        .as_deref()
        .ok_or_else(|| ctx.err(span.clone(), field, format!("`unit` is required ({UNITS})")))?;
    if c.optional && field == "data.position" {
        return Err(ctx.err(span, field, "the position cannot be `optional`"));
    }
    Ok(Some(Columns {
        columns,
        unit: unit(ctx, span, field, name)?,
        optional: c.optional,
    }))
}

/// The `[data]` section as a [`DataFormat`] and the cell's [`DataColumns`].
pub(super) fn data_columns(
    ctx: &Ctx,
    data: Option<Spanned<RawData>>,
    model: &Model,
) -> Result<Option<DataColumns>, Error> {
    let Some(data) = data else { return Ok(None) };
    let span = data.span();
    let d = data.into_inner();
    if d.joints.len() != model.dof() {
        return Err(Error::File {
            file: ctx.file.to_string(),
            message: format!(
                "`data.joints` lists {} columns, the robot has {} joints",
                d.joints.len(),
                model.dof()
            ),
        });
    }
    let delimiter = match text(&d.delimiter) {
        None => ',',
        Some((s, v)) => {
            let mut chars = v.chars();
            match (chars.next(), chars.next()) {
                (Some(c), None) if c.is_ascii() && c != '"' && c != '\n' => c,
                _ => {
                    return Err(ctx.err(
                        s,
                        "data.delimiter",
                        format!("`{v}` is not one character (e.g. \";\")"),
                    ))
                }
            }
        }
    };
    let decimal = match text(&d.decimal) {
        None | Some((_, ".")) => Decimal::Point,
        Some((_, ",")) => Decimal::Comma,
        Some((s, v)) => {
            return Err(ctx.err(s, "data.decimal", format!("`{v}`: use \".\" or \",\"")))
        }
    };
    let joint_unit = match text(&d.joint_unit) {
        None => None,
        Some((s, v)) => Some(unit(ctx, s, "data.joint_unit", v)?),
    };
    let orientation = match &d.orientation {
        None => None,
        Some(raw) => {
            let (s, o) = (raw.span(), raw.get_ref());
            let field = "data.orientation";
            let name = o.convention.as_deref().ok_or_else(|| {
                ctx.err(s.clone(), field, "`convention` is required: rpy, xyz-intrinsic, quat-xyzw or quat-wxyz (there is no default)")
            })?;
            let convention = Orientation::from_name(name).ok_or_else(|| {
                ctx.err(s.clone(), field, format!("unknown convention `{name}` (use rpy, xyz-intrinsic, quat-xyzw or quat-wxyz)"))
            })?;
            if o.optional {
                return Err(ctx.err(s, field, "the orientation cannot be `optional`"));
            }
            let unit = match o.unit.as_deref() {
                None => None,
                Some(u) => Some(unit(ctx, s, field, u)?),
            };
            Some(OrientationColumns {
                columns: o.columns.clone(),
                unit,
                convention,
            })
        }
    };
    let temperature = match &d.temperature {
        None => None,
        Some(t) if t.get_ref().unit == "degC" => Some(t.get_ref().column.clone()),
        Some(t) => {
            return Err(ctx.err(
                t.span(),
                "data.temperature",
                format!("unit `{}`: use \"degC\"", t.get_ref().unit),
            ))
        }
    };
    let format = DataFormat {
        delimiter,
        decimal,
        joints: Some(d.joints.clone()),
        joint_unit,
        position: three(ctx, d.position.as_ref(), "data.position")?,
        orientation,
        sigma_position: three(ctx, d.sigma_position.as_ref(), "data.sigma_position")?,
        sigma_orientation: three(ctx, d.sigma_orientation.as_ref(), "data.sigma_orientation")?,
        temperature,
    };
    format.check(model).map_err(|m| ctx.err(span, "data", m))?;
    Ok(Some(DataColumns {
        joints: d.joints,
        format,
    }))
}
