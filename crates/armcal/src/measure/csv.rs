//! Data files: CSV with a header, one measurement per row.
//!
//! (Over 600 lines: the reader, the checks of its rows and the writer of one format stay in
//! one file, so that the format is defined in one place.)
//!
//! Columns (unit suffixes in the names; defaults in brackets):
//! * `pose_id` — configuration id; rows with the same id share a configuration [row number];
//! * one column per joint: `q1_deg`, `q2_rad`, `q3_mm`, … [deg for revolute, mm for
//!   prismatic joints], or the names a cell lists in `[data] joints` (e.g. `s1_rad`);
//! * `target` — name of the measured target [the cell's only target];
//! * `x`, `y`, `z` — position in the instrument frame [`_mm`; also `_m`, `_in`];
//! * `roll`, `pitch`, `yaw` — orientation (pose measurements) [`_deg`; also `_rad`];
//! * `sigma_x` … `sigma_z` or `u_x` … `u_z` — stated σ per axis [`_mm`; also `_m`, `_in`],
//!   and `sigma_roll` … for pose rows (σ of the residual's rotation rows);
//! * `temperature_c` — air temperature at the measurement, °C (a covariate);
//! * `station` — the instrument station the row was measured from
//!   (`crate::model::station`); with it, a configuration is a (station, `pose_id`) pair;
//! * `payload` — the payload the robot carried (a cell's `[[payload]]` name; empty or
//!   `none`: no payload; [`crate::model::compliance`]); with it, a configuration is a
//!   (station, payload, `pose_id`) triple, so one pose list measured with two payloads
//!   gives two configurations per pose.
//!
//! That is [`DataFormat::armcal`]; a cell's `[data]` section maps any other layout
//! ([`crate::measure::format`]: delimiter, decimal comma, column names, units, orientation
//! convention), read by [`read_with`] and converted to this format by [`import`].
//!
//! Other columns are ignored and listed in [`ReadReport::ignored`](crate::ReadReport::ignored); a known column with an
//! unknown unit suffix is an error.

use crate::measure::columns::{controller_base, explain_header, Column, JointColumns, SigmaOf};
use crate::measure::format::{clean, number, DataFormat, Decimal};
use crate::measure::read_report::ReadReport;
use crate::measure::{Covariates, Dataset, Measurement, MeasurementKind};
use crate::model::controller::ControllerConvention;
use crate::model::{Joint, JointKind, Model, Observed, Pose};
use crate::table;
use crate::Error;
use nalgebra::Vector3;
use std::collections::HashMap;
use std::path::Path;

fn err(file: &str, msg: String) -> Error {
    Error::File {
        file: file.to_string(),
        message: msg,
    }
}

/// A CSV reader, the header, and the file line of the header and of every record after it.
type Table<'t> = (csv::Reader<&'t [u8]>, Vec<String>, Vec<usize>);

/// A trimming CSV reader over `text` with the format's delimiter, its header, and the file
/// line (1-based) of the header and of every record after it. Lines that start with `#` are
/// comments (armcal writes one when an output was made with an accepted unconverged
/// estimate); they and empty lines are skipped but counted. CRLF and LF both end a line.
fn reader<'t>(text: &'t str, file: &str, format: &DataFormat) -> Result<Table<'t>, Error> {
    let lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'))
        .map(|(i, _)| i + 1)
        .collect();
    let delimiter = u8::try_from(format.delimiter).map_err(|_| {
        err(
            file,
            format!("delimiter `{}` is not one byte", format.delimiter),
        )
    })?;
    let mut rdr = csv::ReaderBuilder::new()
        .delimiter(delimiter)
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(text.as_bytes());
    let header = rdr
        .headers()
        .map_err(|e| err(file, format!("header: {e}")))?
        .iter()
        .map(|h| clean(h).to_string())
        .collect();
    Ok((rdr, header, lines))
}

/// The header line of `text`: its first line that is neither empty nor a comment.
fn header_line(text: &str) -> &str {
    text.lines()
        .find(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .unwrap_or("")
}

/// The fields of one record, read with the file's header and decimal notation.
struct Row<'a> {
    record: &'a csv::StringRecord,
    header: &'a [String],
    file: &'a str,
    line: usize,
    decimal: Decimal,
}

impl Row<'_> {
    /// A field, trimmed ([`clean`]); empty if absent.
    fn text(&self, index: usize) -> &str {
        clean(self.record.get(index).unwrap_or(""))
    }

    /// Whether any of the columns has a value.
    fn filled(&self, cols: &[Column]) -> bool {
        cols.iter().any(|c| !self.text(c.index).is_empty())
    }

    /// One numeric field in internal units: missing, unparsable and non-finite values are
    /// errors naming line and column.
    fn value(&self, c: &Column, what: &str) -> Result<f64, Error> {
        let (line, name) = (self.line, &self.header[c.index]);
        let s = self.text(c.index);
        if s.is_empty() {
            return Err(err(
                self.file,
                format!("line {line}: `{name}` ({what}) is missing"),
            ));
        }
        let v = number(s, self.decimal).ok_or_else(|| {
            err(
                self.file,
                format!("line {line}: `{name}` = `{s}` is not a number"),
            )
        })?;
        if !v.is_finite() {
            return Err(err(
                self.file,
                format!("line {line}: `{name}` = `{s}` is not finite"),
            ));
        }
        Ok(v * c.factor)
    }

    /// Several fields as a vector.
    fn values(&self, cols: &[Column], what: &str) -> Result<Vec<f64>, Error> {
        cols.iter().map(|c| self.value(c, what)).collect()
    }

    fn v3(&self, cols: &[Column; 3], what: &str) -> Result<Vector3<f64>, Error> {
        Ok(Vector3::from_iterator(self.values(cols, what)?))
    }

    /// Three standard deviations: none may be negative. A σ of 0 is read (instruments
    /// state it for an axis they do not resolve, e.g. the Motoman set's `u_y_m`); the
    /// per-measurement noise model raises it to its floor.
    fn sigmas(&self, cols: &[Column; 3]) -> Result<Vector3<f64>, Error> {
        let s = self.v3(cols, "σ")?;
        if let Some((c, v)) = cols.iter().zip(s.iter()).find(|(_, v)| **v < 0.0) {
            return Err(err(
                self.file,
                format!(
                    "line {}: `{}` = {} is not a standard deviation: a σ cannot be negative \
                     (leave the σ columns of a row empty to use the cell's noise model)",
                    self.line,
                    self.header[c.index],
                    v / c.factor
                ),
            ));
        }
        Ok(s)
    }

    /// Checks measured joint values against the model's limits: within them, `None`; past a
    /// limit by at most [`crate::model::MEASURED_LIMIT_TOLERANCE`] (a real robot's limits are
    /// not its datasheet's), a warning; further, an error naming the file, line and joint.
    fn limit_check(&self, q: &[f64], model: &Model) -> Result<Option<String>, Error> {
        let Some((j, excess)) = model.joints_past_limits(q) else {
            return Ok(None);
        };
        let joint = &model.joints[j];
        let unit = joint.kind.unit();
        let f = unit.display_factor();
        let says = format!(
            "line {}: joint `{}` = {:.4} {u} is {:.4} {u} past its limits [{:.4}, {:.4}] {u}",
            self.line,
            joint.name,
            q[j] * f,
            excess * f,
            joint.lower * f,
            joint.upper * f,
            u = unit.display_name(),
        );
        if excess <= crate::model::MEASURED_LIMIT_TOLERANCE.of(joint.kind) {
            return Ok(Some(format!(
                "{}: {says}; read, since a real robot's limits differ from its nominal ones",
                self.file
            )));
        }
        Err(err(
            self.file,
            format!(
                "{says}: check the column's unit (the header's `_deg` / `_rad` / `_mm` suffix or \
                 the cell's `[data]` joint_unit), or widen the cell's `[robot] limits` if the \
                 robot reaches there"
            ),
        ))
    }

    /// The row's station name: checked ([`crate::model::station::check_name`]), and only
    /// for a model with an instrument whose pose a station sets.
    fn station(&self, c: usize, model: &Model) -> Result<&str, Error> {
        let s = self.text(c);
        let fail = |why: String| {
            err(
                self.file,
                format!("line {}: `station` = `{s}`: {why}", self.line),
            )
        };
        crate::model::station::check_name(s).map_err(fail)?;
        if model.instrument.is_none() {
            return Err(fail(
                "the cell has no [instrument] whose pose a station could set".into(),
            ));
        }
        Ok(s)
    }

    /// The row's payload: `None` for an empty cell or `none`, else one of the model's
    /// payloads (the error lists them).
    fn payload(&self, c: usize, model: &Model) -> Result<Option<&str>, Error> {
        let p = self.text(c);
        model
            .payload_index(p)
            .map(|k| k.map(|_| p))
            .map_err(|why| err(self.file, format!("line {}: `payload`: {why}", self.line)))
    }

    /// The joint values (internal units).
    fn joints(&self, joints: &[Column], model: &Model) -> Result<Vec<f64>, Error> {
        joints
            .iter()
            .zip(&model.joints)
            .map(|(c, j)| self.value(c, &j.name))
            .collect()
    }

    /// The row's configuration as the model's joint variables: from the model's columns
    /// (through the format's convention if they hold controller angles), or from armcal's
    /// controller columns through the cell's convention. With both, every controller value
    /// must give the model's to [`CONTROLLER_COLUMN_TOLERANCE`]: a user who edited one set
    /// and not the other gets an error naming the line and column, not either set silently.
    fn model_joints(
        &self,
        columns: &JointColumns,
        format: &DataFormat,
        model: &Model,
    ) -> Result<Vec<f64>, Error> {
        let controller = match &columns.controller {
            Some((cols, convention)) => {
                Some((cols, convention.to_model(&self.joints(cols, model)?)))
            }
            None => None,
        };
        let Some(own) = &columns.model else {
            return Ok(controller
                .expect("a joint layout has model or controller columns")
                .1);
        };
        let q = format.model_joints(self.joints(own, model)?);
        if let Some((cols, from_controller)) = controller {
            for (k, joint) in model.joints.iter().enumerate() {
                let tolerance = CONTROLLER_COLUMN_TOLERANCE.of(joint.kind);
                if (from_controller[k] - q[k]).abs() > tolerance {
                    let f = joint.kind.unit().display_factor();
                    return Err(err(
                        self.file,
                        format!(
                            "line {}: `{}` gives joint `{}` = {:.6} {u} through the cell's \
                             [robot.controller], but `{}` says {:.6} {u}: the two sets of \
                             joint columns disagree; correct one, or delete one set",
                            self.line,
                            self.header[cols[k].index],
                            joint.name,
                            from_controller[k] * f,
                            self.header[own[k].index],
                            q[k] * f,
                            u = joint.kind.unit().display_name(),
                        ),
                    ));
                }
            }
        }
        Ok(q)
    }
}

/// The column names of an armcal CSV file's text (its first line that is not a comment),
/// read as CSV: a quoted name with a comma is one column.
pub fn header_str(text: &str, file: &str) -> Result<Vec<String>, Error> {
    reader(text, file, &DataFormat::armcal()).map(|(_, header, _)| header)
}

/// Reads joint configurations (a pose list or a joint program): `pose_id` (optional) and
/// one column per joint as in data files; other columns are ignored.
pub fn read_configurations(
    path: &Path,
    model: &Model,
    joint_columns: Option<&[String]>,
) -> Result<Vec<(String, Vec<f64>)>, Error> {
    read_configurations_with(path, model, &DataFormat::armcal_with_joints(joint_columns))
}

/// As [`read_configurations`], from text.
pub fn read_configurations_str(
    text: &str,
    file: &str,
    model: &Model,
    joint_columns: Option<&[String]>,
) -> Result<Vec<(String, Vec<f64>)>, Error> {
    read_configurations_format_str(
        text,
        file,
        model,
        &DataFormat::armcal_with_joints(joint_columns),
    )
}

/// A data file's name (for errors) and its text, read with the data-file size cap.
fn read_data_file(path: &Path) -> Result<(String, String), Error> {
    let file = path.display().to_string();
    let text = crate::input::read_capped(path, crate::input::DATA_CAP)
        .map_err(|e| err(&file, e.to_string()))?;
    Ok((file, text))
}

/// Joint configurations from a file laid out as `format` says (its delimiter, decimal
/// notation, joint columns and unit; the other mapped columns are not needed).
pub fn read_configurations_with(
    path: &Path,
    model: &Model,
    format: &DataFormat,
) -> Result<Vec<(String, Vec<f64>)>, Error> {
    let (file, text) = read_data_file(path)?;
    read_configurations_format_str(&text, &file, model, format)
}

/// As [`read_configurations_with`], from text; `file` names it in errors.
pub fn read_configurations_format_str(
    text: &str,
    file: &str,
    model: &Model,
    format: &DataFormat,
) -> Result<Vec<(String, Vec<f64>)>, Error> {
    mapped_or_own(format, |f| {
        configurations(text, file, model, f, Limits::Unchecked)
    })
    .map(|(rows, _)| rows)
}

/// As [`read_configurations`] (armcal's joint columns), for poses the robot must take (a
/// pose list to measure): a row with a joint outside its limits is an error naming the
/// file, line, pose and joint.
/// `controller`: the cell's convention, for controller joint columns (`q1_controller_deg`).
pub fn read_reachable_configurations(
    path: &Path,
    model: &Model,
    controller: &ControllerConvention,
) -> Result<Vec<(String, Vec<f64>)>, Error> {
    let (file, text) = read_data_file(path)?;
    let format = DataFormat::armcal_for(controller);
    configurations(&text, &file, model, &format, Limits::Checked)
}

/// The rows of a joint-configuration file; with [`Limits::Checked`] every row within the
/// joint limits.
fn configurations(
    text: &str,
    file: &str,
    model: &Model,
    format: &DataFormat,
    limits: Limits,
) -> Result<Vec<(String, Vec<f64>)>, Error> {
    let (mut rdr, header, lines) = reader(text, file, format)?;
    let mut used = vec![false; header.len()];
    let joints = format
        .joint_layout(&header, model, file, &mut used)
        .map_err(|e| explain_header(e, &header, header_line(text), format.delimiter))?;
    let id_col = header.iter().position(|h| h == "pose_id");
    let mut out = Vec::new();
    for (r, record) in rdr.records().enumerate() {
        let line = lines.get(r + 1).copied().unwrap_or(r + 2);
        let record = record.map_err(|e| err(file, format!("line {line}: {e}")))?;
        let row = Row {
            record: &record,
            header: &header,
            file,
            line,
            decimal: format.decimal,
        };
        let q = row.model_joints(&joints, format, model)?;
        let id = id_col
            .map(|c| row.text(c).to_string())
            .unwrap_or_else(|| format!("{}", r + 1));
        if limits == Limits::Checked {
            model
                .check_joints(&q)
                .map_err(|e| err(file, format!("line {line} (pose `{id}`): {e}")))?;
        }
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
    read_with(path, model, &DataFormat::armcal_with_joints(joint_columns))
}

/// As [`read`], from text; `file` names it in errors.
pub fn read_str(
    text: &str,
    file: &str,
    model: &Model,
    joint_columns: Option<&[String]>,
) -> Result<(Dataset, ReadReport), Error> {
    read_format_str(
        text,
        file,
        model,
        &DataFormat::armcal_with_joints(joint_columns),
    )
}

/// Reads a data file laid out as `format` says (a cell's `[data]`, [`crate::cell::Cell::data_format`]).
pub fn read_with(
    path: &Path,
    model: &Model,
    format: &DataFormat,
) -> Result<(Dataset, ReadReport), Error> {
    let (file, text) = read_data_file(path)?;
    read_format_str(&text, &file, model, format)
}

/// As [`read_with`], from text; `file` names it in errors.
pub fn read_format_str(
    text: &str,
    file: &str,
    model: &Model,
    format: &DataFormat,
) -> Result<(Dataset, ReadReport), Error> {
    let (read, own) = mapped_or_own(format, |f| read_rows(text, file, model, f, Limits::Checked))?;
    let (data, mut report) = read;
    if own {
        report.warnings.insert(0, format!(
            "{file}: the header has armcal's own columns (as `import`, `simulate` and `predict` write them), not the cell's [data] mapping; read as armcal's CSV"
        ));
    }
    Ok((data, report))
}

/// `read` with `format`; when that fails on the header and `format` is a cell's mapping, the
/// file may be armcal's own CSV (what `armcal import` made of the cell's files, or what
/// `simulate`, `predict` and `plan` write), which every cell reads: then `read` with
/// [`DataFormat::armcal`], and `true`. When that fails too, the error is the mapping's.
fn mapped_or_own<T>(
    format: &DataFormat,
    read: impl Fn(&DataFormat) -> Result<T, Error>,
) -> Result<(T, bool), Error> {
    // armcal's own columns: a file armcal wrote (`import`), in model angles (and the
    // controller's in their own columns).
    let own = DataFormat {
        controller_columns: format.controller_columns.clone(),
        ..DataFormat::armcal()
    };
    match read(format) {
        Err(Error::File { file, message }) if message.starts_with("header:") && *format != own => {
            match read(&own) {
                Ok(t) => Ok((t, true)),
                Err(_) => Err(Error::File { file, message }),
            }
        }
        r => r.map(|t| (t, false)),
    }
}

/// Cartesian targets in armcal's data format (a program of tool poses): the joint columns
/// are IK seeds, not measured joint values, so they are not checked against the limits.
/// `controller`: the cell's convention, for controller joint columns (`q1_controller_deg`).
pub fn read_targets_str(
    text: &str,
    file: &str,
    model: &Model,
    controller: Option<&ControllerConvention>,
) -> Result<Dataset, Error> {
    let format = DataFormat {
        controller_columns: controller.cloned(),
        ..DataFormat::armcal()
    };
    read_rows(text, file, model, &format, Limits::Unchecked).map(|(d, _)| d)
}

/// Whether the joint values of a file are checked against the model's limits (measured joints
/// with a tolerance and a warning, see `read_rows`; poses to take exactly).
#[derive(Clone, Copy, PartialEq)]
enum Limits {
    Checked,
    Unchecked,
}

fn read_rows(
    text: &str,
    file: &str,
    model: &Model,
    format: &DataFormat,
    limits: Limits,
) -> Result<(Dataset, ReadReport), Error> {
    let (mut rdr, header, lines) = reader(text, file, format)?;
    let layout = format
        .layout(&header, model, file)
        .map_err(|e| explain_header(e, &header, header_line(text), format.delimiter))?;
    let mut data = Dataset {
        source: file.to_string(),
        ..Default::default()
    };
    let mut config_of: HashMap<(usize, Option<String>, String), usize> = HashMap::new();
    let mut warnings = Vec::new();
    let targets: Vec<&str> = model.targets.iter().map(|t| t.spec.name.as_str()).collect();
    for (r, record) in rdr.records().enumerate() {
        let line = lines.get(r + 1).copied().unwrap_or(r + 2);
        let record = record.map_err(|e| err(file, format!("line {line}: {e}")))?;
        let row = Row {
            record: &record,
            header: &header,
            file,
            line,
            decimal: format.decimal,
        };
        let q = row.model_joints(&layout.joints, format, model)?;
        if limits == Limits::Checked {
            warnings.extend(row.limit_check(&q, model)?);
        }
        let id = layout
            .pose_id
            .map(|c| row.text(c).to_string())
            .unwrap_or_else(|| format!("{}", r + 1));
        let station = match layout.station {
            Some(c) => Some(row.station(c, model)?),
            None => None,
        };
        let payload = match layout.payload {
            Some(c) => row.payload(c, model)?,
            None => None,
        };
        let key = (
            station.map_or(0, |s| data.station_index(s)),
            payload.map(str::to_string),
            id.clone(),
        );
        let config = match config_of.get(&key) {
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
                let c = data.push_configuration(id, q);
                if let Some(s) = data.config_stations.last_mut() {
                    *s = key.0;
                }
                data.set_payload(c, payload);
                config_of.insert(key, c);
                c
            }
        };
        let observed = match layout.target.map(|c| row.text(c)) {
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
        let position = row.v3(&layout.position, "position")?;
        let sigma = match &layout.sigma_position {
            Some(c) if row.filled(c) => Some(row.sigmas(c)?),
            _ => None,
        };
        let kind = match &layout.orientation {
            Some((cols, convention)) if row.filled(cols) => {
                let values = row.values(cols, "orientation")?;
                let pose = Pose {
                    rot: convention.to_rot(&values),
                    trans: position,
                };
                let sr = match &layout.sigma_orientation {
                    Some((c, of)) if row.filled(c) => {
                        let s = row.sigmas(c)?;
                        Some(match of {
                            SigmaOf::RotationRows => s,
                            SigmaOf::Angles => {
                                let angles = [values[0], values[1], values[2]];
                                Vector3::from(
                                    convention
                                        .rotation_sigma(&angles, &s.into())
                                        .expect("checked: an angle convention"),
                                )
                            }
                        })
                    }
                    _ => None,
                };
                let sigma = match (sigma, sr) {
                    (Some(s), Some(r)) => Some([s[0], s[1], s[2], r[0], r[1], r[2]]),
                    (None, None) => None,
                    _ => return Err(err(file, format!("line {line}: pose rows need σ for both position and orientation, or neither"))),
                };
                MeasurementKind::Pose { value: pose, sigma }
            }
            _ => MeasurementKind::Position {
                value: position,
                sigma,
            },
        };
        let covariates = Covariates {
            temperature_c: match &layout.temperature {
                Some(c) if row.filled(std::slice::from_ref(c)) => {
                    Some(row.value(c, "temperature")?)
                }
                _ => None,
            },
        };
        data.measurements.push(Measurement {
            config,
            observed,
            kind,
            line,
            covariates,
        });
    }
    if data.measurements.is_empty() {
        return Err(err(file, "no data rows".into()));
    }
    Ok((
        data,
        ReadReport {
            ignored: layout.ignored,
            warnings,
        },
    ))
}

/// A data file read through a format and written in armcal's own CSV ([`import`]).
#[derive(Clone, Debug)]
pub struct Import {
    /// What was read.
    pub data: Dataset,
    /// The columns the format did not use.
    pub report: ReadReport,
    /// `data` in armcal's CSV ([`write_string`]).
    pub csv: String,
}

/// Reads `path` laid out as `format` and writes it in armcal's own CSV, so a user can see
/// what armcal read: joints in degrees, positions in mm, orientations as `rpy` in degrees
/// (converted through the rotation matrix), σ of the residual rows, `temperature_c`.
pub fn import(path: &Path, model: &Model, format: &DataFormat) -> Result<Import, Error> {
    let (data, report) = read_with(path, model, format)?;
    let csv = write_string(&data, model)?;
    Ok(Import { data, report, csv })
}

/// Writes a dataset in armcal's format: `pose_id`, `station` if the data name stations,
/// `payload` if any configuration carried one or the model has payloads,
/// `q<i>_deg` (or `_mm`), `target`, `x_mm`,
/// `y_mm`, `z_mm`, then `roll_deg`, `pitch_deg`, `yaw_deg` for pose rows and σ columns if
/// any measurement has them, and `temperature_c` if any measurement recorded one. Only
/// position and pose measurements have a CSV form.
pub fn write_string(data: &Dataset, model: &Model) -> Result<String, Error> {
    write_string_with(data, model, &[], &[])
}

/// [`write_string`] with the columns `extra` (header) appended, `rows[k]` their values in
/// measurement `k`'s row (a reader of data files ignores them).
pub fn write_string_with(
    data: &Dataset,
    model: &Model,
    extra: &[&str],
    rows: &[Vec<String>],
) -> Result<String, Error> {
    let any_pose = data
        .measurements
        .iter()
        .any(|m| matches!(m.kind, MeasurementKind::Pose { .. }));
    let any_sigma = data.measurements.iter().any(|m| match &m.kind {
        MeasurementKind::Position { sigma, .. } => sigma.is_some(),
        MeasurementKind::Pose { sigma, .. } => sigma.is_some(),
        _ => false,
    });
    let any_temperature = data
        .measurements
        .iter()
        .any(|m| m.covariates.temperature_c.is_some());
    let mut header = vec!["pose_id".to_string()];
    let stations = !data.stations.is_empty();
    if stations {
        header.push("station".into());
    }
    // a cell with payloads writes the column always, so that its files share one header
    let payloads = data.carries_payloads() || !model.payloads.is_empty();
    if payloads {
        header.push("payload".into());
    }
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
    if any_temperature {
        header.push("temperature_c".into());
    }
    header.extend(extra.iter().map(|c| c.to_string()));
    let mut w = table::Table::new(&header);
    let f = |x: f64| format!("{x:.9}");
    for (k, m) in data.measurements.iter().enumerate() {
        let mut row = vec![data.config_ids[m.config].clone()];
        if stations {
            row.push(data.stations[data.station_of(m.config)].clone());
        }
        if payloads {
            row.push(data.payload_of(m.config).unwrap_or("none").to_string());
        }
        for (v, j) in data.configurations[m.config].iter().zip(&model.joints) {
            row.push(f(joint_display(j, *v)));
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
        if any_temperature {
            row.push(m.covariates.temperature_c.map(f).unwrap_or_default());
        }
        if let Some(more) = rows.get(k) {
            row.extend(more.iter().cloned());
        }
        w.row(&row);
    }
    Ok(w.into_string())
}

/// How far a row's controller columns may be from its model columns (1e-5° / 1e-5 mm: above
/// the rounding of the six decimals armcal writes, far below any real error).
pub(crate) const CONTROLLER_COLUMN_TOLERANCE: crate::model::LimitTolerance =
    crate::model::LimitTolerance {
        revolute: 1e-5 * std::f64::consts::PI / 180.0,
        prismatic: 1e-5,
    };

/// armcal's joint CSV `text` (a pose list, design, data file or compensated program, with
/// the model's joint columns `q1_deg` …) with each joint's controller column
/// (`q1_controller_deg` …: the controller's axis value under `convention`, the cell's
/// `[robot.controller]`) inserted after the last model joint column, each value to as many
/// decimals as its model value. The text is returned unchanged when `convention` is the
/// identity. Leading comment lines (`#`) are kept; every other field is kept as read.
/// `file` names the text in errors (a file armcal wrote itself has none).
pub fn with_controller_columns(
    text: &str,
    file: &str,
    model: &Model,
    convention: &ControllerConvention,
) -> Result<String, Error> {
    if convention.is_identity() {
        return Ok(text.to_string());
    }
    let body_start = text
        .split_inclusive('\n')
        .take_while(|l| l.starts_with('#'))
        .map(str::len)
        .sum::<usize>();
    let (comments, body) = text.split_at(body_start);
    let mut rdr = ::csv::ReaderBuilder::new().from_reader(body.as_bytes());
    let header: Vec<String> = rdr
        .headers()
        .map_err(|e| err(file, format!("header: {e}")))?
        .iter()
        .map(str::to_string)
        .collect();
    let columns = model
        .joints
        .iter()
        .map(|j| {
            let name = joint_column(j);
            header.iter().position(|h| *h == name).ok_or_else(|| {
                err(
                    file,
                    format!("header: no column `{name}` to map to the controller's axes"),
                )
            })
        })
        .collect::<Result<Vec<usize>, Error>>()?;
    let at = columns.iter().max().map_or(header.len(), |&i| i + 1);
    let insert = |fields: &mut Vec<String>, new: Vec<String>| {
        let tail = fields.split_off(at);
        fields.extend(new);
        fields.extend(tail);
    };
    let mut h = header.clone();
    insert(
        &mut h,
        model
            .joints
            .iter()
            .map(|j| {
                let unit = j.kind.unit().display_name();
                format!("{}_{unit}", controller_base(&j.name))
            })
            .collect(),
    );
    let mut t = table::Table::new(&h);
    for (r, record) in rdr.records().enumerate() {
        let line = r + 2 + comments.lines().count();
        let record = record.map_err(|e| err(file, format!("line {line}: {e}")))?;
        let mut fields: Vec<String> = record.iter().map(str::to_string).collect();
        let shown: Vec<&str> = columns
            .iter()
            .map(|&c| record.get(c).unwrap_or(""))
            .collect();
        let q = shown
            .iter()
            .zip(&model.joints)
            .map(|(v, j)| {
                v.parse::<f64>()
                    .map(|v| v / joint_display(j, 1.0))
                    .map_err(|_| {
                        err(
                            file,
                            format!("line {line}: `{}` = `{v}` is not a number", joint_column(j)),
                        )
                    })
            })
            .collect::<Result<Vec<f64>, Error>>()?;
        let controller = convention.to_controller(&q);
        let values = controller
            .iter()
            .zip(&model.joints)
            .zip(&shown)
            .map(|((c, j), v)| {
                let decimals = v.split_once('.').map_or(0, |(_, d)| d.len());
                format!("{:.decimals$}", joint_display(j, *c))
            })
            .collect();
        insert(&mut fields, values);
        t.row(&fields);
    }
    Ok(format!("{comments}{}", t.into_string()))
}

/// The column name of a joint in the data files armcal writes: its name with the unit of
/// its display values, `q1_deg` (revolute) or `q7_mm` (prismatic).
pub fn joint_column(joint: &Joint) -> String {
    format!("{}_{}", joint.name, joint.kind.unit().display_name())
}

/// A joint value in the unit of its column ([`joint_column`]): degrees for a revolute
/// joint, millimetres for a prismatic one.
pub fn joint_display(joint: &Joint, q: f64) -> f64 {
    if joint.kind == JointKind::Revolute {
        q.to_degrees()
    } else {
        q
    }
}

/// Writes joint configurations (a pose list, design or joint program): `pose_id` 1, 2, …
/// and one column per joint, `_deg` for revolute and `_mm` for prismatic joints — the format
/// [`read_configurations`] reads.
pub fn write_configurations(model: &Model, qs: &[Vec<f64>]) -> String {
    let numbered: Vec<(String, &[f64])> = qs
        .iter()
        .enumerate()
        .map(|(i, q)| ((i + 1).to_string(), q.as_slice()))
        .collect();
    write_poses(model, &numbered)
}

/// Writes joint configurations with their own `pose_id`s, in the format of
/// [`write_configurations`].
pub fn write_poses(model: &Model, poses: &[(String, &[f64])]) -> String {
    let mut t = table::Table::new(
        std::iter::once("pose_id".to_string()).chain(model.joints.iter().map(joint_column)),
    );
    for (id, q) in poses {
        let values = q.iter().zip(&model.joints);
        t.row(
            std::iter::once(id.clone())
                .chain(values.map(|(v, j)| format!("{:.6}", joint_display(j, *v)))),
        );
    }
    t.into_string()
}
