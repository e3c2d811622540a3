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

#[cfg(test)]
mod tests {
    use crate::cell::Cell;
    use crate::measure::csv::read_configurations_format_str;
    use std::path::Path;

    fn cell(extra: &str) -> Result<Cell, String> {
        let text = format!("[robot]\nbuiltin = \"kr15\"\n{extra}");
        Cell::from_toml(&text, "c.toml", Path::new(".")).map_err(|e| e.to_string())
    }

    #[test]
    fn presets_and_per_joint_maps() {
        let c = cell("").unwrap();
        assert!(c.controller.is_identity() && c.controller.source.contains("KUKA"));
        let c =
            cell("[robot.controller]\npreset = \"kr15\"\nq2 = { sign = -1, offset_deg = -90 }\n")
                .unwrap();
        let m = c.controller.joints[1];
        assert_eq!(m.sign, -1.0);
        assert!((m.offset + std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        assert!(c.controller.source.contains("kr15") && c.controller.source.contains("q2"));
        let c = cell("[robot.controller]\nq3 = { offset_rad = 0.25 }\n").unwrap();
        assert_eq!(
            (c.controller.joints[2].sign, c.controller.joints[2].offset),
            (1.0, 0.25)
        );
    }

    #[test]
    fn bad_fields_name_the_line_and_field() {
        for (extra, want) in [
            (
                "\n[robot.controller]\nq2 = { sign = 2 }\n",
                "line 4: `robot.controller.q2`: `sign` must be 1 or -1",
            ),
            (
                "[robot.controller]\nq9 = { sign = -1 }\n",
                "`robot.controller.q9`: no joint of that name",
            ),
            (
                "[robot.controller]\nq2 = { offset_mm = 3 }\n",
                "unknown field `offset_mm`",
            ),
            (
                "[robot.controller]\nq2 = -1\n",
                "`robot.controller.q2`: give",
            ),
            (
                "[robot.controller]\npreset = \"puma560\"\n",
                "`robot.controller.preset`: `puma560`: no public source",
            ),
            ("[data]\nangles = \"vendor\"\n", "`data.angles`: `vendor`"),
        ] {
            let e = cell(extra).unwrap_err();
            assert!(e.contains("c.toml") && e.contains(want), "{e}");
        }
    }

    /// An exported cell carries the convention, joint by joint.
    #[test]
    fn an_exported_cell_keeps_the_convention() {
        let c =
            cell("[robot.controller]\nq2 = { sign = -1, offset_deg = -90 }\nq5 = { sign = -1 }\n")
                .unwrap();
        let text = crate::cell::export::to_cell_toml(&c, &c.model, &c.model.spec()).unwrap();
        let back = Cell::from_toml(&text, "exported.toml", Path::new(".")).unwrap();
        assert_eq!(back.controller.joints, c.controller.joints, "{text}");
    }

    /// A data file in controller angles reads as the model's joints, with armcal's column
    /// names and with the cell's; a file in armcal's own columns read through a `[data]
    /// joints` mapping is one armcal wrote (`import`): model angles.
    #[test]
    fn data_in_controller_angles_read_as_model_angles() {
        let csv = "pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\np1,10,20,30,40,50,60\n";
        let named = "pose_id,a1,a2,a3,a4,a5,a6\np1,10,20,30,40,50,60\n";
        let mapping =
            "joints = [\"a1\", \"a2\", \"a3\", \"a4\", \"a5\", \"a6\"]\njoint_unit = \"deg\"\n";
        for (data, csv) in [
            ("[data]\nangles = \"controller\"\n".to_string(), csv),
            (format!("[data]\nangles = \"controller\"\n{mapping}"), named),
        ] {
            let c = cell(&format!(
                "[robot.controller]\nq2 = {{ sign = -1, offset_deg = -90 }}\n{data}"
            ))
            .unwrap();
            let rows =
                read_configurations_format_str(csv, "d.csv", &c.model, &c.data_format()).unwrap();
            let deg: Vec<f64> = rows[0].1.iter().map(|q| q.to_degrees()).collect();
            assert!(
                (deg[1] + 110.0).abs() < 1e-9 && (deg[2] - 30.0).abs() < 1e-9,
                "{deg:?}"
            );
            assert!(c
                .data_format()
                .to_toml()
                .contains("angles = \"controller\""));
        }
        let c = cell(&format!(
            "[robot.controller]\nq2 = {{ sign = -1 }}\n[data]\nangles = \"controller\"\n{mapping}"
        ))
        .unwrap();
        let own = read_configurations_format_str(csv, "d.csv", &c.model, &c.data_format()).unwrap();
        assert!((own[0].1[1].to_degrees() - 20.0).abs() < 1e-9);
        let model_angles = cell("[data]\nangles = \"model\"\n").unwrap();
        let rows = read_configurations_format_str(
            csv,
            "d.csv",
            &model_angles.model,
            &model_angles.data_format(),
        )
        .unwrap();
        assert!((rows[0].1[1].to_degrees() - 20.0).abs() < 1e-9);
    }
}
