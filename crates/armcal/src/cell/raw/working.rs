//! `[[working]]`: the configurations the robot works at (the KPI poses), with weights; and
//! `[[working_path]]`: paths it works along (a welding seam, a measuring path), each a list of
//! configurations with one weight (paper §6: KPIs along "working path trajectories").

use super::fields::*;
use super::*;
use crate::cell::WorkingPath;

/// The working poses, and a warning for each outside the joint limits (kept: the KPI only
/// needs the model there).
pub(super) fn working(
    ctx: &Ctx,
    tables: &[Spanned<toml::Table>],
    model: &Model,
) -> Result<(Vec<WorkingPose>, Vec<String>), Error> {
    let file = ctx.file;
    let mut warnings = Vec::new();
    let mut working = Vec::new();
    let mut seen = Vec::new();
    for (i, w) in tables.iter().enumerate() {
        let field = format!("working[{i}]");
        let t = w.get_ref();
        let name = name_field(ctx, w, &field, &mut seen, "working pose", || {
            format!("work{}", i + 1)
        })?;
        let (key, f) = joints_key(t);
        let arr = match t.get(key) {
            None => return Err(ctx.err(
                w.span(),
                &field,
                "missing `joints_deg` (deg for revolute, mm for prismatic joints) or `joints_rad`",
            )),
            Some(v) => v
                .as_array()
                .ok_or_else(|| not_an_array(ctx, w, &format!("{field}.{key}"), v, model))?,
        };
        let q = joint_values(ctx, w, &format!("{field}.{key}"), arr, f, model)?;
        if let Err(e) = model.check_joints(&q) {
            warnings.push(format!(
                "{file}: line {}: `{field}` ({name}): {e}; kept, since the KPI only needs the model there, but the robot cannot reach it",
                ctx.line(w.span())
            ));
        }
        let weight = weight_field(ctx, w, &field)?;
        check_unused(
            t,
            &[key.into()],
            &["name", "weight"],
            &["joints_deg|joints_rad".into()],
        )
        .map_err(|e| ctx.err(w.span(), &field, e))?;
        working.push(WorkingPose { name, q, weight });
    }
    Ok((working, warnings))
}

/// The working paths: each `[[working_path]]` gives its configurations inline
/// (`joints_deg = [[…], […]]` or `joints_rad`) or as a joint-configuration CSV (`file`,
/// relative to the cell file; armcal's joint columns, deg for revolute joints), and a warning
/// for a path with points outside the joint limits.
pub(super) fn working_paths(
    ctx: &Ctx,
    tables: &[Spanned<toml::Table>],
    model: &Model,
    dir: &Path,
) -> Result<(Vec<WorkingPath>, Vec<String>), Error> {
    let mut warnings = Vec::new();
    let mut paths = Vec::new();
    let mut seen = Vec::new();
    for (i, w) in tables.iter().enumerate() {
        let field = format!("working_path[{i}]");
        let t = w.get_ref();
        let name = name_field(ctx, w, &field, &mut seen, "working path", || {
            format!("path{}", i + 1)
        })?;
        let (key, f) = joints_key(t);
        let (used, points) = match (t.get("file"), t.get(key)) {
            (Some(_), Some(_)) => {
                return Err(ctx.err(
                    w.span(),
                    &field,
                    format!("give either `file` or `{key}`, not both"),
                ))
            }
            (None, None) => {
                return Err(ctx.err(
                    w.span(),
                    &field,
                    "missing `file` (a CSV of joint configurations, armcal's joint columns) or \
                     `joints_deg = [[…], […]]` (deg for revolute, mm for prismatic joints)",
                ))
            }
            (Some(v), None) => {
                let rel = v.as_str().ok_or_else(|| {
                    ctx.err(
                        w.span(),
                        &format!("{field}.file"),
                        "must be a string (a path)",
                    )
                })?;
                let rows = crate::measure::csv::read_configurations(&dir.join(rel), model, None)
                    .map_err(|e| ctx.err(w.span(), &format!("{field}.file"), e))?;
                ("file", rows.into_iter().map(|(_, q)| q).collect())
            }
            (None, Some(v)) => {
                let rows = v
                    .as_array()
                    .ok_or_else(|| not_an_array(ctx, w, &format!("{field}.{key}"), v, model))?;
                let mut points = Vec::with_capacity(rows.len());
                for (k, row) in rows.iter().enumerate() {
                    let rfield = format!("{field}.{key}[{k}]");
                    let arr = row
                        .as_array()
                        .ok_or_else(|| not_an_array(ctx, w, &rfield, row, model))?;
                    points.push(joint_values(ctx, w, &rfield, arr, f, model)?);
                }
                (key, points)
            }
        };
        if points.is_empty() {
            return Err(ctx.err(w.span(), &field, "the path has no configurations"));
        }
        let outside = points
            .iter()
            .filter(|q| model.check_joints(q).is_err())
            .count();
        if outside > 0 {
            warnings.push(format!(
                "{}: line {}: `{field}` ({name}): {outside} of its {} configurations lie outside the joint limits; kept, since the KPI only needs the model there",
                ctx.file,
                ctx.line(w.span()),
                points.len()
            ));
        }
        let weight = weight_field(ctx, w, &field)?;
        check_unused(
            t,
            &[used.into()],
            &["name", "weight"],
            &["file|joints_deg|joints_rad".into()],
        )
        .map_err(|e| ctx.err(w.span(), &field, e))?;
        paths.push(WorkingPath {
            name,
            q: points,
            weight,
        });
    }
    Ok((paths, warnings))
}

/// `name`, or `default()` when the table has none; an error when an earlier `what` of the
/// section (in `seen`) has the same name.
fn name_field(
    ctx: &Ctx,
    w: &Spanned<toml::Table>,
    field: &str,
    seen: &mut Vec<(String, usize)>,
    what: &str,
    default: impl FnOnce() -> String,
) -> Result<String, Error> {
    let name = string_field(w.get_ref(), "name")
        .map_err(|e| ctx.err(w.span(), field, e))?
        .map(str::to_string)
        .unwrap_or_else(default);
    unique_name(seen, &name, ctx.line(w.span()), what).map_err(|e| ctx.err(w.span(), field, e))?;
    Ok(name)
}

/// The joint key the table uses and its factor to radians (revolute joints).
fn joints_key(t: &toml::Table) -> (&'static str, f64) {
    if t.contains_key("joints_deg") {
        ("joints_deg", std::f64::consts::PI / 180.0)
    } else {
        ("joints_rad", 1.0)
    }
}

/// `weight` (default 1), a positive number.
fn weight_field(ctx: &Ctx, w: &Spanned<toml::Table>, field: &str) -> Result<f64, Error> {
    let weight = w
        .get_ref()
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
    Ok(weight)
}

/// The error for a joint list that is not an array.
fn not_an_array(
    ctx: &Ctx,
    w: &Spanned<toml::Table>,
    field: &str,
    v: &toml::Value,
    model: &Model,
) -> Error {
    ctx.err(
        w.span(),
        field,
        format!(
            "must be an array of {} numbers, e.g. `[{}]`; it is a {}",
            model.dof(),
            vec!["0"; model.dof()].join(", "),
            v.type_str()
        ),
    )
}

/// One configuration in internal units (revolute values times `f`, prismatic in mm), one
/// finite number per joint.
fn joint_values(
    ctx: &Ctx,
    w: &Spanned<toml::Table>,
    field: &str,
    arr: &[toml::Value],
    f: f64,
    model: &Model,
) -> Result<Vec<f64>, Error> {
    if arr.len() != model.dof() {
        return Err(ctx.err(
            w.span(),
            field,
            format!(
                "has {} values, the robot has {} joints",
                arr.len(),
                model.dof()
            ),
        ));
    }
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
    if q.iter().any(|x| !x.is_finite()) {
        return Err(ctx.err(w.span(), field, "values must be numbers"));
    }
    Ok(q)
}
