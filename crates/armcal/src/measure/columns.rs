//! A [`DataFormat`] resolved against a file's header: which column index feeds each joint, the
//! position, the orientation, their σ and the temperature, with the factor to internal units.
//! armcal's own files are resolved by name with unit suffixes (`x_mm`, `q1_deg`, `u_x_m`, see
//! [`crate::measure::csv`]); a cell's mapped columns by their exact names.

use crate::measure::angles::Orientation;
use crate::measure::format::{angle_factor, length_factor, ColumnUnit, Columns, DataFormat};
use crate::model::controller::ControllerConvention;
use crate::model::{Joint, JointKind, Model};
use crate::Error;

/// A resolved column: its index in the header and the factor to internal units.
pub(crate) struct Column {
    pub index: usize,
    pub factor: f64,
}

/// The joint columns of a file: the model's joint variables, the controller's axis values
/// with the convention that maps them, or both ([`DataFormat::joint_layout`]).
pub(crate) struct JointColumns {
    /// One column per model joint (`q2_deg`); `None`: the joints are read from `controller`.
    pub model: Option<Vec<Column>>,
    /// One column per joint in the controller's angles (`q2_controller_deg`) and the
    /// convention that maps them to the model's.
    pub controller: Option<(Vec<Column>, ControllerConvention)>,
}

/// The name, without its unit suffix, of joint `joint`'s controller column in armcal's own
/// files: `q2` → `q2_controller` (written `q2_controller_deg`).
pub(crate) fn controller_base(joint: &str) -> String {
    format!("{joint}_controller")
}

/// What the σ columns of an orientation are σ of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SigmaOf {
    /// σ of the pose residual's rotation rows (armcal's own files).
    RotationRows,
    /// σ of the mapped convention's angles.
    Angles,
}

/// A format resolved against a file's header.
pub(crate) struct Layout {
    pub joints: JointColumns,
    pub position: [Column; 3],
    pub orientation: Option<(Vec<Column>, Orientation)>,
    pub sigma_position: Option<[Column; 3]>,
    pub sigma_orientation: Option<([Column; 3], SigmaOf)>,
    pub temperature: Option<Column>,
    pub pose_id: Option<usize>,
    pub target: Option<usize>,
    /// The `station` column ([`crate::model::station`]).
    pub station: Option<usize>,
    /// The `payload` column (a cell's `[[payload]]`, [`crate::model::compliance`]).
    pub payload: Option<usize>,
    /// Header names no column of the layout uses.
    pub ignored: Vec<String>,
}

fn err(file: &str, msg: String) -> Error {
    Error::File {
        file: file.to_string(),
        message: msg,
    }
}

/// `e` (an error resolving `header`) with what a user needs to fix the header: the columns the
/// reader found, and, when the header's first line (`header_line`) splits into more columns
/// with another delimiter (`;`, tab or `,`) than with the format's `delimiter`, that
/// delimiter and the `[data]` line that sets it. Errors not about the header pass unchanged.
pub(crate) fn explain_header(
    e: Error,
    header: &[String],
    header_line: &str,
    delimiter: char,
) -> Error {
    const SHOWN: usize = 30;
    let Error::File { file, message } = e else {
        return e;
    };
    if !message.starts_with("header:") {
        return Error::File { file, message };
    }
    let mut found: Vec<String> = header
        .iter()
        .take(SHOWN)
        .map(|h| format!("`{h}`"))
        .collect();
    if header.len() > SHOWN {
        found.push(format!("… ({} more)", header.len() - SHOWN));
    }
    let columns = |n: usize| if n == 1 { "column" } else { "columns" };
    let mut message = format!(
        "{message}; the header has {} {} with delimiter {}: {}",
        header.len(),
        columns(header.len()),
        delimiter_text(delimiter).0,
        found.join(", ")
    );
    let guess = [';', '\t', ',']
        .into_iter()
        .filter(|&d| d != delimiter)
        .map(|d| (header_line.split(d).count(), d))
        .max_by_key(|(n, _)| *n)
        .filter(|(n, _)| *n > header.len().max(1));
    if let Some((n, d)) = guess {
        let (name, toml) = delimiter_text(d);
        message.push_str(&format!(
            "; the header splits into {n} columns with {name} — set `[data] delimiter = \"{toml}\"`"
        ));
    }
    Error::File { file, message }
}

/// A delimiter as a message names it (`;`, tab) and as a TOML string holds it.
fn delimiter_text(d: char) -> (String, String) {
    match d {
        '\t' => ("tab".into(), "\\t".into()),
        d => (format!("`{d}`"), d.to_string()),
    }
}

/// Splits `x_mm` into (`x`, `mm`), `sigma_x_m` into (`sigma_x`, `m`).
fn split_unit(name: &str) -> (&str, &str) {
    for suffix in ["_mm", "_m", "_in", "_um", "_deg", "_rad"] {
        if let Some(base) = name.strip_suffix(suffix) {
            return (base, &suffix[1..]);
        }
    }
    match name.rsplit_once('_') {
        Some((b, s)) if !s.is_empty() && s.chars().all(|c| c.is_ascii_alphabetic()) => (b, s),
        _ => (name, ""),
    }
}

impl DataFormat {
    /// The column of every joint, with its unit factor; marks the columns used.
    ///
    /// In armcal's own naming (no `[data] joints`), `q2_deg` is the model's joint variable
    /// and `q2_controller_deg` the controller's axis value (the cell's `[robot.controller]`,
    /// [`crate::model::controller`]). A file may carry either set or both; with both, each
    /// row's controller values are checked against its model values.
    pub(crate) fn joint_layout(
        &self,
        header: &[String],
        model: &Model,
        file: &str,
        used: &mut [bool],
    ) -> Result<JointColumns, Error> {
        if let Some(names) = &self.joints {
            let columns = model
                .joints
                .iter()
                .zip(names)
                .map(|(joint, name)| {
                    let i = header.iter().position(|h| h == name).ok_or_else(|| err(file, format!("header: no column `{name}` for joint `{}` (named in the cell's [data] joints)", joint.name)))?;
                    self.joint_column(header, i, joint, file, used)
                })
                .collect::<Result<_, Error>>()?;
            return Ok(JointColumns {
                model: Some(columns),
                controller: None,
            });
        }
        // the one column whose name without its unit suffix is `base` (or `base` itself)
        let unique = |base: &str, joint: &str| -> Result<Option<usize>, Error> {
            let mut found = header
                .iter()
                .enumerate()
                .filter(|(_, h)| split_unit(h).0 == base || h.as_str() == base)
                .map(|(i, _)| i);
            match (found.next(), found.next()) {
                (Some(_), Some(_)) => Err(err(
                    file,
                    format!("header: joint `{joint}` has several columns"),
                )),
                (i, _) => Ok(i),
            }
        };
        let mut own = Vec::new();
        let mut controller = Vec::new();
        for joint in &model.joints {
            own.push(unique(&joint.name, &joint.name)?);
            controller.push(unique(&controller_base(&joint.name), &joint.name)?);
        }
        let all = |c: &[Option<usize>]| c.iter().all(Option::is_some);
        let resolve = |c: &[Option<usize>], used: &mut [bool]| -> Result<Vec<Column>, Error> {
            c.iter()
                .zip(&model.joints)
                .map(|(i, joint)| self.joint_column(header, i.expect("all"), joint, file, used))
                .collect()
        };
        let controller = match (all(&controller), &self.controller_columns) {
            (true, Some(c)) => Some((resolve(&controller, used)?, c.clone())),
            (true, None) if all(&own) => {
                // a file written for a cell with a controller convention, read without it:
                // the model's columns hold the same configuration
                controller.iter().flatten().for_each(|&i| used[i] = true);
                None
            }
            (true, None) => {
                return Err(err(
                    file,
                    format!(
                        "header: the joints have controller columns (`{}`) but no model \
                         columns, and the cell has no [robot.controller] that maps them: \
                         add the section to the cell, or give the model's columns (`{}`)",
                        header[controller[0].expect("all")],
                        super::csv::joint_column(&model.joints[0])
                    ),
                ))
            }
            (false, _) => None,
        };
        let own = if all(&own) {
            Some(resolve(&own, used)?)
        } else if controller.is_some() && own.iter().all(Option::is_none) {
            None
        } else {
            let (joint, _) = model
                .joints
                .iter()
                .zip(&own)
                .find(|(_, i)| i.is_none())
                .expect("a joint without a column");
            return Err(err(
                file,
                format!(
                    "header: no column for joint `{}` (expected e.g. `{}`)",
                    joint.name,
                    super::csv::joint_column(joint)
                ),
            ));
        };
        Ok(JointColumns {
            model: own,
            controller,
        })
    }

    /// Joint `joint`'s column `i` with the factor of its unit (the format's `joint_unit`, or
    /// the name's suffix); marks it used.
    fn joint_column(
        &self,
        header: &[String],
        i: usize,
        joint: &Joint,
        file: &str,
        used: &mut [bool],
    ) -> Result<Column, Error> {
        let suffix = split_unit(&header[i]).1;
        let factor = match (self.joint_unit, joint.kind) {
            (Some(u), _) => Some(u.factor()),
            (None, JointKind::Revolute) => angle_factor(suffix),
            (None, JointKind::Prismatic) => length_factor(suffix),
        }
        .ok_or_else(|| err(file, format!("column `{}`: unknown unit suffix `{suffix}` for joint `{}` (use deg or rad for revolute, mm, m or in for prismatic joints)", header[i], joint.name)))?;
        used[i] = true;
        Ok(Column { index: i, factor })
    }

    /// Resolves the format against a file's header (`file` names it in errors).
    pub(crate) fn layout(
        &self,
        header: &[String],
        model: &Model,
        file: &str,
    ) -> Result<Layout, Error> {
        let mut used = vec![false; header.len()];
        let joints = self.joint_layout(header, model, file, &mut used)?;
        let (position, orientation, sigma_position, sigma_orientation, temperature) =
            match &self.position {
                Some(_) => self.mapped(header, file, &mut used)?,
                None => armcal_columns(header, file, &mut used)?,
            };
        let find = |name: &str| header.iter().position(|h| h == name);
        let pose_id = find("pose_id");
        let target = find("target");
        let station = find("station");
        let payload = find("payload");
        for c in [pose_id, target, station, payload].into_iter().flatten() {
            used[c] = true;
        }
        let ignored = header
            .iter()
            .zip(&used)
            .filter(|(_, u)| !**u)
            .map(|(h, _)| h.clone())
            .collect();
        Ok(Layout {
            joints,
            position,
            orientation,
            sigma_position,
            sigma_orientation,
            temperature,
            pose_id,
            target,
            station,
            payload,
            ignored,
        })
    }

    /// The columns a cell maps by name.
    fn mapped(&self, header: &[String], file: &str, used: &mut [bool]) -> Result<Groups, Error> {
        let mut find = |name: &str, field: &str, factor: f64| -> Result<Column, Error> {
            let index = header.iter().position(|h| h == name).ok_or_else(|| {
                err(
                    file,
                    format!("header: no column `{name}` (the cell's [data] {field})"),
                )
            })?;
            used[index] = true;
            Ok(Column { index, factor })
        };
        let mut three = |c: &Columns, field: &str| -> Result<Option<[Column; 3]>, Error> {
            if c.optional && !c.columns.iter().any(|n| header.contains(n)) {
                return Ok(None);
            }
            let f = c.unit.factor();
            Ok(Some([
                find(&c.columns[0], field, f)?,
                find(&c.columns[1], field, f)?,
                find(&c.columns[2], field, f)?,
            ]))
        };
        let position = three(self.position.as_ref().expect("mapped"), "position")?
            .ok_or_else(|| err(file, "header: no position columns".into()))?;
        let sigma_position = match &self.sigma_position {
            Some(c) => three(c, "sigma_position")?,
            None => None,
        };
        let sigma_orientation = match &self.sigma_orientation {
            Some(c) => three(c, "sigma_orientation")?.map(|c| (c, SigmaOf::Angles)),
            None => None,
        };
        let orientation = match &self.orientation {
            Some(o) => {
                let f = o.unit.map_or(1.0, ColumnUnit::factor);
                let cols = o
                    .columns
                    .iter()
                    .map(|n| find(n, "orientation", f))
                    .collect::<Result<Vec<_>, _>>()?;
                Some((cols, o.convention))
            }
            None => None,
        };
        let temperature = self
            .temperature
            .as_ref()
            .map(|n| find(n, "temperature", 1.0))
            .transpose()?;
        Ok((
            position,
            orientation,
            sigma_position,
            sigma_orientation,
            temperature,
        ))
    }
}

/// Position, orientation, their σ and the temperature, as resolved.
type Groups = (
    [Column; 3],
    Option<(Vec<Column>, Orientation)>,
    Option<[Column; 3]>,
    Option<([Column; 3], SigmaOf)>,
    Option<Column>,
);

/// armcal's own columns, found by name with unit suffixes (see [`crate::measure::csv`]).
fn armcal_columns(header: &[String], file: &str, used: &mut [bool]) -> Result<Groups, Error> {
    let mut named = |base: &str, length: bool, aliases: &[&str]| -> Result<Option<Column>, Error> {
        for (i, h) in header.iter().enumerate() {
            let (b, suffix) = split_unit(h);
            if b == base || aliases.contains(&b) {
                let f = if length {
                    length_factor(suffix)
                } else {
                    angle_factor(suffix)
                };
                let f = f.ok_or_else(|| {
                    err(
                        file,
                        format!(
                            "column `{h}`: unknown unit suffix `{suffix}` (use {})",
                            if length {
                                "mm, m, in or um"
                            } else {
                                "deg or rad"
                            }
                        ),
                    )
                })?;
                used[i] = true;
                return Ok(Some(Column {
                    index: i,
                    factor: f,
                }));
            }
        }
        Ok(None)
    };
    let xyz = [
        named("x", true, &[])?,
        named("y", true, &[])?,
        named("z", true, &[])?,
    ];
    let rpy = [
        named("roll", false, &[])?,
        named("pitch", false, &[])?,
        named("yaw", false, &[])?,
    ];
    let sxyz = [
        named("sigma_x", true, &["u_x"])?,
        named("sigma_y", true, &["u_y"])?,
        named("sigma_z", true, &["u_z"])?,
    ];
    let srpy = [
        named("sigma_roll", false, &[])?,
        named("sigma_pitch", false, &[])?,
        named("sigma_yaw", false, &[])?,
    ];
    let present = |c: &[Option<Column>; 3]| c.iter().filter(|x| x.is_some()).count();
    if present(&xyz) != 3 {
        return Err(err(
            file,
            "header: need the position columns x, y, z (e.g. x_mm, y_mm, z_mm)".into(),
        ));
    }
    for (group, name) in [
        (&rpy, "roll, pitch, yaw"),
        (&sxyz, "sigma_x, sigma_y, sigma_z"),
        (&srpy, "sigma_roll, sigma_pitch, sigma_yaw"),
    ] {
        let k = present(group);
        if k != 0 && k != 3 {
            return Err(err(file, format!("header: give all of {name} or none")));
        }
    }
    let all = |c: [Option<Column>; 3]| -> Option<[Column; 3]> {
        let [a, b, c] = c;
        Some([a?, b?, c?])
    };
    let temperature = header
        .iter()
        .position(|h| h == "temperature_c")
        .map(|index| {
            used[index] = true;
            Column { index, factor: 1.0 }
        });
    Ok((
        all(xyz).expect("checked"),
        all(rpy).map(|c| (c.into_iter().collect(), Orientation::Rpy)),
        all(sxyz),
        all(srpy).map(|c| (c, SigmaOf::RotationRows)),
        temperature,
    ))
}
