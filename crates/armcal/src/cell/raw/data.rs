//! `[data]`: how the cell's data files are laid out — the joint columns and, for a vendor's
//! export, the delimiter, decimal notation and the mapped columns with their units and
//! orientation convention ([`crate::measure::format`]).

use super::*;
use crate::measure::angles::Orientation;
use crate::measure::format::{ColumnUnit, Columns, DataFormat, Decimal, OrientationColumns};
use crate::model::controller::ControllerConvention;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawData {
    /// The joint columns (default: armcal's `q1_deg` … by the joints' names).
    #[serde(default)]
    joints: Vec<String>,
    /// `model` (default) or `controller`: which angles the joint columns hold.
    angles: Option<Spanned<String>>,
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
    convention: &ControllerConvention,
) -> Result<Option<DataColumns>, Error> {
    let Some(data) = data else { return Ok(None) };
    let span = data.span();
    let d = data.into_inner();
    if !d.joints.is_empty() && d.joints.len() != model.dof() {
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
    let controller = match text(&d.angles) {
        None | Some((_, "model")) => None,
        Some((_, "controller")) => Some(convention.clone()),
        Some((s, v)) => {
            return Err(ctx.err(
                s,
                "data.angles",
                format!("`{v}`: use \"model\" or \"controller\" (the cell's [robot.controller])"),
            ))
        }
    };
    let format = DataFormat {
        delimiter,
        decimal,
        joints: (!d.joints.is_empty()).then(|| d.joints.clone()),
        joint_unit,
        position: three(ctx, d.position.as_ref(), "data.position")?,
        orientation,
        sigma_position: three(ctx, d.sigma_position.as_ref(), "data.sigma_position")?,
        sigma_orientation: three(ctx, d.sigma_orientation.as_ref(), "data.sigma_orientation")?,
        temperature,
        controller,
        controller_columns: DataFormat::armcal_for(convention).controller_columns,
    };
    format.check(model).map_err(|m| ctx.err(span, "data", m))?;
    Ok(Some(DataColumns {
        joints: d.joints,
        format,
    }))
}

#[cfg(test)]
mod tests {
    use crate::cell::Cell;
    use crate::measure::csv::read_format_str;
    use crate::measure::MeasurementKind;
    use std::path::Path;

    const HEAD: &str = "[robot]\nbuiltin = \"ur10\"\n[data]\njoints = [\"a\", \"b\", \"c\", \"d\", \"e\", \"f\"]\n";

    fn cell(data: &str) -> Result<Cell, String> {
        Cell::from_toml(&format!("{HEAD}{data}"), "c.toml", Path::new("."))
            .map_err(|e| e.to_string())
    }

    #[test]
    fn a_mapping_names_its_units_and_convention_or_fails_with_line_and_field() {
        let pos = "position = { columns = [\"x\", \"y\", \"z\"], unit = \"mm\" }\n";
        let e = cell(&format!(
            "{pos}orientation = {{ columns = [\"r\", \"p\", \"w\"], unit = \"deg\" }}\n"
        ))
        .unwrap_err();
        assert!(
            e.contains("line 6") && e.contains("`data.orientation`") && e.contains("no default"),
            "{e}"
        );
        let e = cell(&format!("{pos}orientation = {{ columns = [\"r\", \"p\", \"w\"], unit = \"deg\", convention = \"zyx\" }}\n")).unwrap_err();
        assert!(e.contains("unknown convention `zyx`"), "{e}");
        let e = cell(&format!("{pos}orientation = {{ columns = [\"r\", \"p\", \"w\"], convention = \"quat-xyzw\" }}\n")).unwrap_err();
        assert!(e.contains("takes 4 columns"), "{e}");
        let e = cell(&format!(
            "{pos}orientation = {{ columns = [\"r\", \"p\", \"w\"], convention = \"rpy\" }}\n"
        ))
        .unwrap_err();
        assert!(e.contains("`orientation.unit` is needed"), "{e}");
        let e =
            cell("position = { columns = [\"x\", \"y\", \"z\"], unit = \"feet\" }\n").unwrap_err();
        assert!(
            e.contains("line 5")
                && e.contains("`data.position`")
                && e.contains("unknown unit `feet`"),
            "{e}"
        );
        let e =
            cell("position = { columns = [\"x\", \"y\", \"z\"], unit = \"deg\" }\n").unwrap_err();
        assert!(e.contains("must be a length"), "{e}");
        let e = cell(&format!("decimal = \",\"\n{pos}")).unwrap_err();
        assert!(e.contains("another `delimiter`"), "{e}");
        let e = cell("joint_unit = \"mm\"\n").unwrap_err();
        assert!(e.contains("joint `q1` is not one"), "{e}");
        let e = cell(&format!(
            "{pos}temperature = {{ column = \"t\", unit = \"K\" }}\n"
        ))
        .unwrap_err();
        assert!(
            e.contains("`data.temperature`") && e.contains("degC"),
            "{e}"
        );
        let e = cell("sigma_position = { columns = [\"x\", \"y\", \"z\"], unit = \"mm\" }\n")
            .unwrap_err();
        assert!(e.contains("need `position` mapped"), "{e}");
    }

    #[test]
    fn a_vendor_file_reads_per_field_with_crlf_lf_and_nul() {
        let c = cell(
            "delimiter = \";\"\ndecimal = \",\"\njoint_unit = \"rad\"\n\
             position = { columns = [\"x\", \"y\", \"z\"], unit = \"m\" }\n\
             orientation = { columns = [\"qx\", \"qy\", \"qz\", \"qw\"], convention = \"quat-xyzw\" }\n\
             temperature = { column = \"t\", unit = \"degC\" }\n",
        )
        .unwrap();
        let f = c.data_format();
        let text = "a;b;c;d;e;f;x;y;z;qx;qy;qz;qw;t\r\n\
                    0;0;0;0;0;0;1,5;2,78E-3;0;0;0;0;1;20,5\r\n\
                    0,1;0;0;0;0;0; -1 ;0;0;0;0;0,7071067811865476;0,7071067811865476;21\0\n";
        let (data, report) = read_format_str(text, "v.csv", &c.model, &f).unwrap();
        assert!(report.ignored.is_empty());
        assert_eq!(data.measurements.len(), 2);
        assert_eq!(data.configurations[1][0], 0.1);
        assert_eq!(data.measurements[1].covariates.temperature_c, Some(21.0));
        let MeasurementKind::Pose { value, sigma: None } = &data.measurements[0].kind else {
            panic!("a pose without σ")
        };
        assert_eq!(value.trans[0], 1500.0);
        assert!((value.trans[1] - 2.78).abs() < 1e-12);
        let MeasurementKind::Pose { value, .. } = &data.measurements[1].kind else {
            panic!()
        };
        assert_eq!(value.trans[0], -1000.0);
        assert!((value.rot[(1, 0)] - 1.0).abs() < 1e-12, "90° about z");
        // A missing mapped column names the column and the [data] field.
        let e = read_format_str("a;b;c;d;e;f;x;y\n0;0;0;0;0;0;1;2\n", "v.csv", &c.model, &f)
            .unwrap_err();
        assert!(
            e.to_string()
                .contains("no column `z` (the cell's [data] position)"),
            "{e}"
        );
        // A point in a decimal-comma file is not a number.
        let bad = "a;b;c;d;e;f;x;y;z;qx;qy;qz;qw;t\n0;0;0;0;0;0;1.5;0;0;0;0;0;1;20\n";
        let e = read_format_str(bad, "v.csv", &c.model, &f).unwrap_err();
        assert!(
            e.to_string()
                .contains("line 2: `x` = `1.5` is not a number"),
            "{e}"
        );
    }
}
