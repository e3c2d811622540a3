//! `[[working]]`: the configurations the robot works at (the KPI poses), with weights.

use super::fields::*;
use super::*;

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
    for (i, w) in tables.iter().enumerate() {
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
        let arr = match t.get(key) {
            None => return Err(ctx.err(
                w.span(),
                &field,
                "missing `joints_deg` (deg for revolute, mm for prismatic joints) or `joints_rad`",
            )),
            Some(v) => v.as_array().ok_or_else(|| {
                ctx.err(
                    w.span(),
                    &format!("{field}.{key}"),
                    format!(
                        "must be an array of {} numbers, e.g. `{key} = [{}]`; it is a {}",
                        model.dof(),
                        vec!["0"; model.dof()].join(", "),
                        v.type_str()
                    ),
                )
            })?,
        };
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
    Ok((working, warnings))
}
