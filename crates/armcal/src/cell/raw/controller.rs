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

    /// A data file in controller angles reads as the model's joints, in armcal's controller
    /// columns (`q2_controller_deg`, no setting needed) and in the cell's mapped columns
    /// (`angles = "controller"`); armcal's model columns (`q2_deg`) are model angles always,
    /// also when read through a mapping (a file armcal wrote, e.g. by `import`).
    #[test]
    fn data_in_controller_angles_read_as_model_angles() {
        let own = "pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\np1,10,20,30,40,50,60\n";
        let controller = own.replace("_deg", "_controller_deg");
        let named = "pose_id,a1,a2,a3,a4,a5,a6\np1,10,20,30,40,50,60\n";
        let mapping =
            "joints = [\"a1\", \"a2\", \"a3\", \"a4\", \"a5\", \"a6\"]\njoint_unit = \"deg\"\n";
        let convention = "[robot.controller]\nq2 = { sign = -1, offset_deg = -90 }\n";
        for (data, csv) in [
            (String::new(), controller.as_str()),
            (format!("[data]\nangles = \"controller\"\n{mapping}"), named),
        ] {
            let c = cell(&format!("{convention}{data}")).unwrap();
            let rows =
                read_configurations_format_str(csv, "d.csv", &c.model, &c.data_format()).unwrap();
            let deg: Vec<f64> = rows[0].1.iter().map(|q| q.to_degrees()).collect();
            assert!(
                (deg[1] + 110.0).abs() < 1e-9 && (deg[2] - 30.0).abs() < 1e-9,
                "{deg:?}"
            );
        }
        let c = cell(&format!(
            "{convention}[data]\nangles = \"controller\"\n{mapping}"
        ))
        .unwrap();
        assert!(c
            .data_format()
            .to_toml()
            .contains("angles = \"controller\""));
        let rows =
            read_configurations_format_str(own, "d.csv", &c.model, &c.data_format()).unwrap();
        assert!((rows[0].1[1].to_degrees() - 20.0).abs() < 1e-9);
        // without a convention, controller columns alone cannot be read
        let plain = cell("").unwrap();
        let e = read_configurations_format_str(
            &controller,
            "d.csv",
            &plain.model,
            &plain.data_format(),
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("no [robot.controller]") && e.contains("q1_controller_deg"),
            "{e}"
        );
    }

    /// `angles = "controller"` names which columns hold controller angles: without
    /// `joints` it would make armcal's own `q2_deg` (model angles) ambiguous.
    #[test]
    fn controller_angles_need_named_columns() {
        let e = cell("[robot.controller]\nq2 = { sign = -1 }\n[data]\nangles = \"controller\"\n")
            .unwrap_err();
        assert!(
            e.contains("add `joints = [...]`") && e.contains("q2_controller_deg"),
            "{e}"
        );
    }

    /// What armcal writes for a cell with a convention carries the controller's columns
    /// beside the model's; either set reads back as the same configurations, and a row whose
    /// two sets disagree is an error naming the line and both columns.
    #[test]
    fn written_controller_columns_read_back() {
        use crate::measure::csv::{read_configurations_format_str as read, write_poses};
        let c = cell(
            "[robot.controller]\nq2 = { sign = -1, offset_deg = -90 }\nq3 = { offset_deg = 90 }\n\
             q5 = { sign = -1 }\n",
        )
        .unwrap();
        let qs: Vec<Vec<f64>> = (0..5)
            .map(|k| {
                (0..6)
                    .map(|j| 0.1 * (k + 1) as f64 - 0.07 * j as f64)
                    .collect()
            })
            .collect();
        let poses: Vec<(String, &[f64])> = qs
            .iter()
            .enumerate()
            .map(|(k, q)| (format!("p{k}"), q.as_slice()))
            .collect();
        let written = c
            .with_controller_columns(write_poses(&c.model, &poses))
            .unwrap();
        let header = written.lines().next().unwrap();
        assert!(
            header.starts_with(
                "pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg,q1_controller_deg,"
            ),
            "{header}"
        );
        // the controller's q2 of the first row: −(q2 − (−90°))
        let row: Vec<f64> = written
            .lines()
            .nth(1)
            .unwrap()
            .split(',')
            .skip(1)
            .map(|v| v.parse().unwrap())
            .collect();
        assert!((row[7] + (row[1] + 90.0)).abs() < 2e-6, "{row:?}");
        let format = c.data_format();
        let both = read(&written, "w.csv", &c.model, &format).unwrap();
        // the controller's set alone: drop the model columns
        let controller_only: String = written
            .lines()
            .map(|l| {
                l.split(',')
                    .enumerate()
                    .filter(|(i, _)| !(1..=6).contains(i))
                    .map(|(_, f)| f)
                    .collect::<Vec<_>>()
                    .join(",")
                    + "\n"
            })
            .collect();
        let alone = read(&controller_only, "c.csv", &c.model, &format).unwrap();
        for ((a, b), q) in both.iter().zip(&alone).zip(&qs) {
            for ((x, y), v) in a.1.iter().zip(&b.1).zip(q) {
                assert!((x - v).abs() < 1e-7 && (y - v).abs() < 1e-7);
            }
        }
        // a user edits q5 in the controller's columns only
        let mut lines: Vec<String> = written.lines().map(str::to_string).collect();
        let mut fields: Vec<String> = lines[2].split(',').map(str::to_string).collect();
        fields[11] = format!("{:.6}", fields[11].parse::<f64>().unwrap() + 0.5);
        lines[2] = fields.join(",");
        let e = read(&(lines.join("\n") + "\n"), "e.csv", &c.model, &format)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("e.csv")
                && e.contains("line 3")
                && e.contains("`q5_controller_deg`")
                && e.contains("`q5_deg`"),
            "{e}"
        );
    }
}
