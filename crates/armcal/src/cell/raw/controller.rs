//! `[robot.controller]`: how the controller's axis values map to the model's joint variables
//! ([`crate::model::controller`]) — a built-in robot's vendor convention by name
//! (`preset = "kr15"`), then per joint `q2 = { sign = -1, offset_deg = -90 }` (`offset_mm`
//! for a prismatic joint; `q_model = sign · q_controller + offset`). Without the section a
//! built-in robot whose vendor convention is public carries it, any other robot reads and
//! writes model angles.

use super::fields::*;
use super::*;
use crate::model::controller::{ControllerConvention, JointMap};

/// The cell's controller convention for `model` (the robot of `[robot]`, `builtin` its
/// built-in name if any).
pub(super) fn controller(
    ctx: &Ctx,
    raw: Option<&Spanned<toml::Table>>,
    builtin: Option<&str>,
    model: &Model,
) -> Result<ControllerConvention, Error> {
    let dof = model.dof();
    let Some(raw) = raw else {
        return Ok(builtin
            .and_then(|b| crate::robots::controller::vendor_convention(b, dof).ok())
            .unwrap_or_else(|| ControllerConvention::model_angles(dof)));
    };
    let (span, t) = (raw.span(), raw.get_ref());
    let fail = |field: &str, e: String| ctx.err(span.clone(), field, e);
    let mut convention = match string_field(t, "preset").map_err(|e| fail("robot.controller", e))? {
        Some(name) => crate::robots::controller::vendor_convention(name, dof)
            .map_err(|e| fail("robot.controller.preset", e))?,
        None => ControllerConvention {
            source: "the cell's [robot.controller]".into(),
            ..ControllerConvention::model_angles(dof)
        },
    };
    let mut overridden = Vec::new();
    for (key, value) in t {
        if key == "preset" {
            continue;
        }
        let field = format!("robot.controller.{key}");
        let k = model
            .joints
            .iter()
            .position(|j| j.name == *key)
            .ok_or_else(|| {
                let names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
                fail(
                    &field,
                    format!(
                        "no joint of that name (joints: {}; or `preset`)",
                        names.join(", ")
                    ),
                )
            })?;
        let jt = value.as_table().ok_or_else(|| {
            fail(
                &field,
                "give `{ sign = -1, offset_deg = -90 }` (sign ±1; offset_deg, offset_rad or \
                 offset_mm, default 0)"
                    .into(),
            )
        })?;
        let mut used = vec!["sign".to_string()];
        let sign = match jt.get("sign") {
            None => 1.0,
            Some(v) => match number(v) {
                Some(s) if s == 1.0 || s == -1.0 => s,
                _ => return Err(fail(&field, "`sign` must be 1 or -1".into())),
            },
        };
        let unit = model.joints[k].kind.unit();
        let offset = unit_value(jt, "offset", unit, &mut used)
            .map_err(|e| fail(&field, e))?
            .unwrap_or(0.0);
        check_unused(jt, &used, &["sign"], &[unit_spellings("offset", unit)])
            .map_err(|e| fail(&field, e))?;
        convention.joints[k] = JointMap { sign, offset };
        overridden.push(key.clone());
    }
    if !overridden.is_empty() && t.contains_key("preset") {
        convention.source = format!(
            "{}, with [robot.controller] {}",
            convention.source,
            overridden.join(", ")
        );
    }
    convention
        .check(model)
        .map_err(|e| fail("robot.controller", e))?;
    Ok(convention)
}
