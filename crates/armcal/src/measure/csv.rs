//! Data files: CSV with a header, one measurement per row.
//!
//! Columns (unit suffixes in the names; defaults in brackets):
//! * `pose_id` — configuration id; rows with the same id share a configuration [row number];
//! * one column per joint: `q1_deg`, `q2_rad`, `q3_mm`, … [deg for revolute, mm for
//!   prismatic joints], or the names a cell lists in `[data] joints` (e.g. `s1_rad`);
//! * `target` — name of the measured target [the cell's only target];
//! * `x`, `y`, `z` — position in the instrument frame [`_mm`; also `_m`, `_in`];
//! * `roll`, `pitch`, `yaw` — orientation (pose measurements) [`_deg`; also `_rad`];
//! * `sigma_x` … `sigma_z` or `u_x` … `u_z` — stated σ per axis [`_mm`; also `_m`, `_in`],
//!   and `sigma_roll` … for pose rows.
//!
//! Other columns are ignored and listed in [`ReadReport::ignored`]; a known column with an
//! unknown unit suffix is an error.

use crate::measure::{Dataset, Measurement, MeasurementKind};
use crate::model::{Joint, JointKind, Model, Observed, Pose};
use crate::Error;
use nalgebra::Vector3;
use std::collections::HashMap;
use std::path::Path;

/// What the reader found besides the data.
#[derive(Clone, Debug, Default)]
pub struct ReadReport {
    /// Header names of the columns the reader did not use.
    pub ignored: Vec<String>,
}

/// Unit factor to internal units for a length suffix.
fn length_factor(suffix: &str) -> Option<f64> {
    match suffix {
        "" | "mm" => Some(1.0),
        "m" => Some(1000.0),
        "in" => Some(25.4),
        "um" => Some(1e-3),
        _ => None,
    }
}

fn angle_factor(suffix: &str) -> Option<f64> {
    match suffix {
        "" | "deg" => Some(std::f64::consts::PI / 180.0),
        "rad" => Some(1.0),
        _ => None,
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

struct Column {
    index: usize,
    factor: f64,
}

fn err(file: &str, msg: String) -> Error {
    Error::File {
        file: file.to_string(),
        message: msg,
    }
}

/// The column of every joint, with its unit factor; marks the columns used.
fn joint_layout(
    header: &[String],
    model: &Model,
    joint_columns: Option<&[String]>,
    file: &str,
    used: &mut [bool],
) -> Result<Vec<Column>, Error> {
    let find = |name: &str| header.iter().position(|h| h == name);
    let mut joints = Vec::new();
    for (j, joint) in model.joints.iter().enumerate() {
        let col = match joint_columns {
            Some(names) => {
                let name = &names[j];
                let i = find(name).ok_or_else(|| err(file, format!("header: no column `{name}` for joint `{}` (named in the cell's [data] joints)", joint.name)))?;
                let (_, suffix) = split_unit(name);
                (i, suffix.to_string())
            }
            None => {
                let candidates: Vec<usize> = header
                    .iter()
                    .enumerate()
                    .filter(|(_, h)| split_unit(h).0 == joint.name || h.as_str() == joint.name)
                    .map(|(i, _)| i)
                    .collect();
                match candidates.as_slice() {
                    [i] => (*i, split_unit(&header[*i]).1.to_string()),
                    [] => {
                        return Err(err(
                            file,
                            format!(
                                "header: no column for joint `{}` (expected e.g. `{}`)",
                                joint.name,
                                joint_column(joint)
                            ),
                        ))
                    }
                    _ => {
                        return Err(err(
                            file,
                            format!("header: joint `{}` has several columns", joint.name),
                        ))
                    }
                }
            }
        };
        let factor = match joint.kind {
            JointKind::Revolute => angle_factor(&col.1),
            JointKind::Prismatic => length_factor(&col.1),
        }
        .ok_or_else(|| err(file, format!("column `{}`: unknown unit suffix `{}` for joint `{}` (use deg or rad for revolute, mm, m or in for prismatic joints)", header[col.0], col.1, joint.name)))?;
        used[col.0] = true;
        joints.push(Column {
            index: col.0,
            factor,
        });
    }

    Ok(joints)
}

/// A CSV reader, the header, and the file line of the header and of every record after it.
type Table<'t> = (csv::Reader<&'t [u8]>, Vec<String>, Vec<usize>);

/// A trimming CSV reader over `text`, its header, and the file line (1-based) of the header
/// and of every record after it. Lines that start with `#` are comments (armcal writes one
/// when an output was made with an accepted unconverged estimate); they and
/// empty lines are skipped but counted.
fn reader<'t>(text: &'t str, file: &str) -> Result<Table<'t>, Error> {
    let lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'))
        .map(|(i, _)| i + 1)
        .collect();
    let mut rdr = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(text.as_bytes());
    let header = rdr
        .headers()
        .map_err(|e| err(file, format!("header: {e}")))?
        .iter()
        .map(str::to_string)
        .collect();
    Ok((rdr, header, lines))
}

/// Parses the joint values of one record (internal units), with line and column in errors.
fn record_joints(
    record: &csv::StringRecord,
    joints: &[Column],
    header: &[String],
    model: &Model,
    file: &str,
    line: usize,
) -> Result<Vec<f64>, Error> {
    joints
        .iter()
        .zip(&model.joints)
        .map(|(c, j)| cell_value(record, c, header, file, line, &j.name))
        .collect()
}

/// One numeric field: missing, unparsable and non-finite values are errors naming line
/// and column.
fn cell_value(
    record: &csv::StringRecord,
    c: &Column,
    header: &[String],
    file: &str,
    line: usize,
    what: &str,
) -> Result<f64, Error> {
    let s = record.get(c.index).unwrap_or("");
    if s.is_empty() {
        return Err(err(
            file,
            format!("line {line}: `{}` ({what}) is missing", header[c.index]),
        ));
    }
    let v: f64 = s.parse().map_err(|_| {
        err(
            file,
            format!("line {line}: `{}` = `{s}` is not a number", header[c.index]),
        )
    })?;
    if !v.is_finite() {
        return Err(err(
            file,
            format!("line {line}: `{}` = `{s}` is not finite", header[c.index]),
        ));
    }
    Ok(v * c.factor)
}

/// Reads joint configurations (a pose list or a joint program): `pose_id` (optional) and
/// one column per joint as in data files; other columns are ignored.
pub fn read_configurations(
    path: &Path,
    model: &Model,
    joint_columns: Option<&[String]>,
) -> Result<Vec<(String, Vec<f64>)>, Error> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| err(&file, e.to_string()))?;
    read_configurations_str(&text, &file, model, joint_columns)
}

/// As [`read_configurations`], from text.
pub fn read_configurations_str(
    text: &str,
    file: &str,
    model: &Model,
    joint_columns: Option<&[String]>,
) -> Result<Vec<(String, Vec<f64>)>, Error> {
    let (mut rdr, header, lines) = reader(text, file)?;
    let mut used = vec![false; header.len()];
    let joints = joint_layout(&header, model, joint_columns, file, &mut used)?;
    let id_col = header.iter().position(|h| h == "pose_id");
    let mut out = Vec::new();
    for (r, record) in rdr.records().enumerate() {
        let line = lines.get(r + 1).copied().unwrap_or(r + 2);
        let record = record.map_err(|e| err(file, format!("line {line}: {e}")))?;
        let q = record_joints(&record, &joints, &header, model, file, line)?;
        let id = id_col
            .and_then(|c| record.get(c))
            .map(str::to_string)
            .unwrap_or_else(|| format!("{}", r + 1));
        out.push((id, q));
    }
    if out.is_empty() {
        return Err(err(file, "no rows".into()));
    }
    Ok(out)
}

/// Reads a data file for `model`. `joint_columns`: the column names feeding the joints
/// (from the cell), or `None` for `q1…qn` with unit suffixes.
pub fn read(
    path: &Path,
    model: &Model,
    joint_columns: Option<&[String]>,
) -> Result<(Dataset, ReadReport), Error> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| err(&path.display().to_string(), e.to_string()))?;
    read_str(&text, &path.display().to_string(), model, joint_columns)
}

/// As [`read`], from text; `file` names it in errors.
pub fn read_str(
    text: &str,
    file: &str,
    model: &Model,
    joint_columns: Option<&[String]>,
) -> Result<(Dataset, ReadReport), Error> {
    let (mut rdr, header, lines) = reader(text, file)?;
    let find = |name: &str| header.iter().position(|h| h == name);
    let mut used = vec![false; header.len()];

    let joints = joint_layout(&header, model, joint_columns, file, &mut used)?;

    // Named value columns with unit checks.
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
    let pose_col = find("pose_id");
    let target_col = find("target");
    for c in [pose_col, target_col].into_iter().flatten() {
        used[c] = true;
    }
    let ignored: Vec<String> = header
        .iter()
        .zip(&used)
        .filter(|(_, u)| !**u)
        .map(|(h, _)| h.clone())
        .collect();

    let mut data = Dataset {
        source: file.to_string(),
        ..Default::default()
    };
    let mut config_of: HashMap<String, usize> = HashMap::new();
    let targets: Vec<&str> = model.targets.iter().map(|t| t.spec.name.as_str()).collect();
    for (r, record) in rdr.records().enumerate() {
        let line = lines.get(r + 1).copied().unwrap_or(r + 2);
        let record = record.map_err(|e| err(file, format!("line {line}: {e}")))?;
        let value = |c: &Column, what: &str| cell_value(&record, c, &header, file, line, what);
        let q = record_joints(&record, &joints, &header, model, file, line)?;
        let id = pose_col
            .and_then(|c| record.get(c))
            .map(str::to_string)
            .unwrap_or_else(|| format!("{}", r + 1));
        let config = match config_of.get(&id) {
            Some(&c) => {
                if data.configurations[c]
                    .iter()
                    .zip(&q)
                    .any(|(a, b)| (a - b).abs() > 1e-9)
                {
                    return Err(err(
                        file,
                        format!("line {line}: pose_id `{id}` appears with different joint values"),
                    ));
                }
                c
            }
            None => {
                let c = data.push_configuration(id.clone(), q);
                config_of.insert(id, c);
                c
            }
        };
        let observed = match target_col.and_then(|c| record.get(c)) {
            Some(name) if !name.is_empty() => {
                let k = targets.iter().position(|t| *t == name).ok_or_else(|| {
                    err(
                        file,
                        format!(
                            "line {line}: unknown target `{name}` (the cell has: {})",
                            targets.join(", ")
                        ),
                    )
                })?;
                Observed::Target(k)
            }
            _ => match targets.len() {
                0 => Observed::Tool,
                1 => Observed::Target(0),
                _ => {
                    return Err(err(
                        file,
                        format!(
                            "line {line}: the cell has several targets ({}); add a `target` column",
                            targets.join(", ")
                        ),
                    ))
                }
            },
        };
        let v3 = |cols: &[Option<Column>; 3], what: &str| -> Result<Vector3<f64>, Error> {
            Ok(Vector3::new(
                value(cols[0].as_ref().expect("checked"), what)?,
                value(cols[1].as_ref().expect("checked"), what)?,
                value(cols[2].as_ref().expect("checked"), what)?,
            ))
        };
        let position = v3(&xyz, "position")?;
        let filled = |cols: &[Option<Column>; 3]| {
            cols.iter()
                .flatten()
                .any(|c| !record.get(c.index).unwrap_or("").is_empty())
        };
        let sigma = if filled(&sxyz) {
            Some(v3(&sxyz, "σ")?)
        } else {
            None
        };
        let kind = if filled(&rpy) {
            let a = v3(&rpy, "orientation")?;
            let pose = Pose::from_xyz_rpy(position.into(), a.into());
            let sr = if filled(&srpy) {
                Some(v3(&srpy, "σ")?)
            } else {
                None
            };
            let sigma = match (sigma, sr) {
                (Some(s), Some(r)) => Some([s[0], s[1], s[2], r[0], r[1], r[2]]),
                (None, None) => None,
                _ => return Err(err(file, format!("line {line}: pose rows need σ for both position and orientation, or neither"))),
            };
            MeasurementKind::Pose { value: pose, sigma }
        } else {
            MeasurementKind::Position {
                value: position,
                sigma,
            }
        };
        data.measurements.push(Measurement {
            config,
            observed,
            kind,
            line,
        });
    }
    if data.measurements.is_empty() {
        return Err(err(file, "no data rows".into()));
    }
    Ok((data, ReadReport { ignored }))
}

/// Writes a dataset in armcal's format: `pose_id`, `q<i>_deg` (or `_mm`), `target`, `x_mm`,
/// `y_mm`, `z_mm`, then `roll_deg`, `pitch_deg`, `yaw_deg` for pose rows and σ columns if
/// any measurement has them. Only position and pose measurements have a CSV form.
pub fn write_string(data: &Dataset, model: &Model) -> Result<String, Error> {
    let any_pose = data
        .measurements
        .iter()
        .any(|m| matches!(m.kind, MeasurementKind::Pose { .. }));
    let any_sigma = data.measurements.iter().any(|m| match &m.kind {
        MeasurementKind::Position { sigma, .. } => sigma.is_some(),
        MeasurementKind::Pose { sigma, .. } => sigma.is_some(),
        _ => false,
    });
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header = vec!["pose_id".to_string()];
    header.extend(model.joints.iter().map(joint_column));
    header.extend(["target", "x_mm", "y_mm", "z_mm"].map(String::from));
    if any_pose {
        header.extend(["roll_deg", "pitch_deg", "yaw_deg"].map(String::from));
    }
    if any_sigma {
        header.extend(["sigma_x_mm", "sigma_y_mm", "sigma_z_mm"].map(String::from));
        if any_pose {
            header.extend(["sigma_roll_deg", "sigma_pitch_deg", "sigma_yaw_deg"].map(String::from));
        }
    }
    w.write_record(&header)
        .map_err(|e| Error::Output(e.to_string()))?;
    let f = |x: f64| format!("{x:.9}");
    for m in &data.measurements {
        let mut row = vec![data.config_ids[m.config].clone()];
        for (v, j) in data.configurations[m.config].iter().zip(&model.joints) {
            row.push(f(if j.kind == JointKind::Revolute {
                v.to_degrees()
            } else {
                *v
            }));
        }
        row.push(match m.observed {
            Observed::Target(k) => model.targets[k].spec.name.clone(),
            Observed::Tool => String::new(),
        });
        let (p, rpy, s) = match &m.kind {
            MeasurementKind::Position { value, sigma } => (
                *value,
                None,
                sigma.map(|s| [s[0], s[1], s[2], 0.0, 0.0, 0.0]),
            ),
            MeasurementKind::Pose { value, sigma } => {
                (value.trans, Some(value.to_xyz_rpy().1), *sigma)
            }
            other => {
                return Err(Error::Input(format!(
                    "a {} measurement has no CSV form; save the dataset as JSON",
                    other.name()
                )))
            }
        };
        row.extend([f(p[0]), f(p[1]), f(p[2])]);
        if any_pose {
            match rpy {
                Some(a) => row.extend(a.map(|x| f(x.to_degrees()))),
                None => row.extend(["", "", ""].map(String::from)),
            }
        }
        if any_sigma {
            let blank = || ["", "", ""].map(String::from);
            match s {
                Some(s) => row.extend([f(s[0]), f(s[1]), f(s[2])]),
                None => row.extend(blank()),
            }
            if any_pose {
                match (s, rpy) {
                    (Some(s), Some(_)) => row.extend([3, 4, 5].map(|k| f(s[k].to_degrees()))),
                    _ => row.extend(blank()),
                }
            }
        }
        w.write_record(&row)
            .map_err(|e| Error::Output(e.to_string()))?;
    }
    let bytes = w.into_inner().map_err(|e| Error::Output(e.to_string()))?;
    String::from_utf8(bytes).map_err(|e| Error::Output(e.to_string()))
}

/// The column name of a joint in the data files armcal writes: its name with the unit of
/// its display values, `q1_deg` (revolute) or `q7_mm` (prismatic).
pub fn joint_column(joint: &Joint) -> String {
    format!("{}_{}", joint.name, joint.kind.unit().display_name())
}

/// Writes joint configurations (a pose list, design or joint program): `pose_id` 1, 2, …
/// and one column per joint, `_deg` for revolute and `_mm` for prismatic joints — the format
/// [`read_configurations`] reads.
pub fn write_configurations(model: &Model, qs: &[Vec<f64>]) -> String {
    let mut s = String::from("pose_id");
    for j in &model.joints {
        s.push(',');
        s.push_str(&joint_column(j));
    }
    s.push('\n');
    for (i, q) in qs.iter().enumerate() {
        s.push_str(&format!("{}", i + 1));
        for (v, j) in q.iter().zip(&model.joints) {
            s.push_str(&format!(
                ",{:.6}",
                if j.kind == JointKind::Revolute {
                    v.to_degrees()
                } else {
                    *v
                }
            ));
        }
        s.push('\n');
    }
    s
}
