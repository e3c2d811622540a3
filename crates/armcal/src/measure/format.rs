//! The column mapping of a data file: one mechanism for armcal's own CSV and any vendor's
//! export. A [`DataFormat`] says how fields are separated, how decimals are written, and which
//! columns hold the joints, the position, the orientation (with its named
//! [`Orientation`] convention), their σ and the temperature, each with its unit. A cell gives
//! it in its `[data]` section; without one, [`DataFormat::armcal`] reads armcal's own files
//! (columns found by name, units from name suffixes, see [`crate::measure::csv`]).
//!
//! ```toml
//! [data]
//! delimiter = ";"          # default ","
//! decimal = ","            # default "."; per field, also in exponent form (`2,78E-17`)
//! joints = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
//!           "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"]
//! joint_unit = "rad"       # the unit of every joint column: no unit suffix is looked for
//! position = { columns = ["measurement_x", "measurement_y", "measurement_z"], unit = "mm" }
//! orientation = { columns = ["measurement_rx", "measurement_ry", "measurement_rz"],
//!                 unit = "deg", convention = "xyz-intrinsic" }   # convention required
//! sigma_position = { columns = ["measurement_std_x", "measurement_std_y", "measurement_std_z"], unit = "mm" }
//! sigma_orientation = { columns = ["measurement_std_rx", "measurement_std_ry", "measurement_std_rz"], unit = "deg" }
//! temperature = { column = "measurement_temperature", unit = "degC" }
//! ```
//!
//! Every field is trimmed of white space and NUL bytes; CRLF and LF line ends both read. The
//! σ of mapped orientation angles are σ of the angles: they become σ of the pose residual's
//! rotation rows through the convention's rate Jacobian ([`Orientation::rotation_sigma`]);
//! in armcal's own files (`sigma_roll_deg` …) they are already σ of the rotation rows.

use crate::measure::angles::Orientation;
use crate::model::controller::ControllerConvention;
use crate::model::{JointKind, Model};
use crate::toml_text;
use serde::{Deserialize, Serialize};

/// How decimals are written in a file's numbers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Decimal {
    /// `0.365141`
    Point,
    /// `0,365141`, `2,78E-17`
    Comma,
}

/// The unit of a mapped column (or of a name suffix in armcal's own files).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ColumnUnit {
    /// Millimetre.
    Mm,
    /// Metre.
    M,
    /// Inch.
    In,
    /// Micrometre.
    Um,
    /// Degree.
    Deg,
    /// Radian.
    Rad,
}

impl ColumnUnit {
    /// The unit of a name (`mm`, `m`, `in`, `um`, `deg`, `rad`).
    pub fn from_name(name: &str) -> Option<ColumnUnit> {
        Some(match name {
            "mm" => ColumnUnit::Mm,
            "m" => ColumnUnit::M,
            "in" => ColumnUnit::In,
            "um" => ColumnUnit::Um,
            "deg" => ColumnUnit::Deg,
            "rad" => ColumnUnit::Rad,
            _ => return None,
        })
    }

    /// The name a cell file uses.
    pub fn name(self) -> &'static str {
        match self {
            ColumnUnit::Mm => "mm",
            ColumnUnit::M => "m",
            ColumnUnit::In => "in",
            ColumnUnit::Um => "um",
            ColumnUnit::Deg => "deg",
            ColumnUnit::Rad => "rad",
        }
    }

    /// Whether this is a length (else an angle).
    pub fn is_length(self) -> bool {
        !matches!(self, ColumnUnit::Deg | ColumnUnit::Rad)
    }

    /// The factor to internal units (mm, rad).
    pub fn factor(self) -> f64 {
        match self {
            ColumnUnit::Mm => 1.0,
            ColumnUnit::M => 1000.0,
            ColumnUnit::In => 25.4,
            ColumnUnit::Um => 1e-3,
            ColumnUnit::Deg => std::f64::consts::PI / 180.0,
            ColumnUnit::Rad => 1.0,
        }
    }
}

/// Unit factor of a length suffix (none: mm).
pub(crate) fn length_factor(suffix: &str) -> Option<f64> {
    suffix_unit(suffix, ColumnUnit::Mm)
        .filter(|u| u.is_length())
        .map(ColumnUnit::factor)
}

/// Unit factor of an angle suffix (none: deg).
pub(crate) fn angle_factor(suffix: &str) -> Option<f64> {
    suffix_unit(suffix, ColumnUnit::Deg)
        .filter(|u| !u.is_length())
        .map(ColumnUnit::factor)
}

fn suffix_unit(suffix: &str, default: ColumnUnit) -> Option<ColumnUnit> {
    if suffix.is_empty() {
        Some(default)
    } else {
        ColumnUnit::from_name(suffix)
    }
}

/// Three named columns in one unit (a position or its σ, or the angles' σ).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Columns {
    /// The column names, x, y, z (or the angles' order).
    pub columns: [String; 3],
    /// Their unit.
    pub unit: ColumnUnit,
    /// A file without these columns reads without them (e.g. σ that one series lacks).
    pub optional: bool,
}

/// The orientation columns: names, unit (angles only) and convention.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OrientationColumns {
    /// The column names in the convention's order (3 angles or 4 quaternion components).
    pub columns: Vec<String>,
    /// The angles' unit (`None` for quaternions).
    pub unit: Option<ColumnUnit>,
    /// What the columns mean.
    pub convention: Orientation,
}

/// How a data file is laid out: see the module documentation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DataFormat {
    /// The field separator.
    pub delimiter: char,
    /// How decimals are written.
    pub decimal: Decimal,
    /// One column per model joint (`None`: `q1_deg` … by the joints' names).
    pub joints: Option<Vec<String>>,
    /// The unit of every joint column (`None`: from the name's suffix, e.g. `s1_rad`).
    pub joint_unit: Option<ColumnUnit>,
    /// The position columns (`None`: `x`, `y`, `z` with unit suffixes).
    pub position: Option<Columns>,
    /// The orientation columns (`None`: `roll`, `pitch`, `yaw` as `rpy`, if present).
    pub orientation: Option<OrientationColumns>,
    /// σ of the position (`None`: `sigma_x` … or `u_x` …, if present).
    pub sigma_position: Option<Columns>,
    /// σ of the orientation angles (`None`: `sigma_roll` …, σ of the rotation rows).
    pub sigma_orientation: Option<Columns>,
    /// The air temperature column, °C (`None`: `temperature_c`, if present).
    pub temperature: Option<String>,
    /// `[data] angles = "controller"`: the joint columns hold the controller's axis values,
    /// mapped to the model's joints by this convention on reading (`None`: model angles).
    #[serde(default)]
    pub controller: Option<ControllerConvention>,
    /// The cell's controller convention, for the `<joint>_controller_<unit>` columns of
    /// armcal's own files (`None`: the cell's convention is the identity, or unknown; such
    /// columns are then ignored beside the model's and an error alone).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub controller_columns: Option<ControllerConvention>,
}

impl Default for DataFormat {
    fn default() -> Self {
        DataFormat::armcal()
    }
}

impl DataFormat {
    /// armcal's own CSV: comma-separated, decimal point, columns found by name.
    pub fn armcal() -> DataFormat {
        DataFormat {
            delimiter: ',',
            decimal: Decimal::Point,
            joints: None,
            joint_unit: None,
            position: None,
            orientation: None,
            sigma_position: None,
            sigma_orientation: None,
            temperature: None,
            controller: None,
            controller_columns: None,
        }
    }

    /// A row's joint values as read (the columns' values in internal units) as the model's
    /// joint variables: through the controller convention if the columns hold controller
    /// angles.
    pub fn model_joints(&self, q: Vec<f64>) -> Vec<f64> {
        match &self.controller {
            Some(c) => c.to_model(&q),
            None => q,
        }
    }

    /// armcal's own CSV for a cell whose controller convention is `convention`: its
    /// `<joint>_controller_<unit>` columns are read through it.
    pub fn armcal_for(convention: &ControllerConvention) -> DataFormat {
        DataFormat {
            controller_columns: (!convention.is_identity()).then(|| convention.clone()),
            ..DataFormat::armcal()
        }
    }

    /// armcal's own CSV with the joints read from `joints` (a cell's `[data] joints`).
    pub fn armcal_with_joints(joints: Option<&[String]>) -> DataFormat {
        DataFormat {
            joints: joints.map(<[String]>::to_vec),
            ..DataFormat::armcal()
        }
    }

    /// The body of a cell's `[data]` section that reads as this format (the joints line
    /// alone for armcal's own files with named joint columns).
    pub fn to_toml(&self) -> String {
        let mut out = Vec::new();
        if self.delimiter != ',' {
            out.push(format!(
                "delimiter = {}",
                toml_text::string(&self.delimiter.to_string())
            ));
        }
        if self.decimal == Decimal::Comma {
            out.push("decimal = \",\"".into());
        }
        if let Some(j) = &self.joints {
            out.push(format!("joints = {}", toml_text::strings(j)));
        }
        if let Some(u) = self.joint_unit {
            out.push(format!("joint_unit = {:?}", u.name()));
        }
        if self.controller.is_some() {
            out.push("angles = \"controller\"".into());
        }
        let three = |field: &str, c: &Option<Columns>| {
            c.as_ref().map(|c| {
                let optional = if c.optional { ", optional = true" } else { "" };
                format!(
                    "{field} = {{ columns = {}, unit = {:?}{optional} }}",
                    toml_text::strings(&c.columns),
                    c.unit.name()
                )
            })
        };
        out.extend(three("position", &self.position));
        if let Some(o) = &self.orientation {
            let unit = o
                .unit
                .map(|u| format!(", unit = {:?}", u.name()))
                .unwrap_or_default();
            out.push(format!(
                "orientation = {{ columns = {}{unit}, convention = {:?} }}",
                toml_text::strings(&o.columns),
                o.convention.name()
            ));
        }
        out.extend(three("sigma_position", &self.sigma_position));
        out.extend(three("sigma_orientation", &self.sigma_orientation));
        if let Some(t) = &self.temperature {
            out.push(format!(
                "temperature = {{ column = {}, unit = \"degC\" }}",
                toml_text::string(t)
            ));
        }
        out.join("\n")
    }

    /// Checks the format against itself and the model; the message names the field.
    pub fn check(&self, model: &Model) -> Result<(), String> {
        if self.decimal == Decimal::Comma && self.delimiter == ',' {
            return Err("`decimal = \",\"` needs another `delimiter` (e.g. \";\")".into());
        }
        if self.controller.is_some() && self.joints.is_none() {
            return Err(
                "`angles = \"controller\"` says which angles the columns named in \
                        `joints` hold: add `joints = [...]`. (armcal's own columns need no \
                        setting: `q2_deg` is the model's joint, `q2_controller_deg` the \
                        controller's axis, read through [robot.controller].)"
                    .into(),
            );
        }
        if let Some(j) = &self.joints {
            if j.len() != model.dof() {
                return Err(format!(
                    "`joints` lists {} columns, the robot has {} joints",
                    j.len(),
                    model.dof()
                ));
            }
        }
        if let Some(u) = self.joint_unit {
            let kind = if u.is_length() {
                JointKind::Prismatic
            } else {
                JointKind::Revolute
            };
            if let Some(j) = model.joints.iter().find(|j| j.kind != kind) {
                return Err(format!(
                    "`joint_unit` is a unit of {} joints; joint `{}` is not one",
                    if u.is_length() {
                        "prismatic"
                    } else {
                        "revolute"
                    },
                    j.name
                ));
            }
        }
        let mapped = self.orientation.is_some()
            || self.sigma_position.is_some()
            || self.sigma_orientation.is_some();
        if mapped && self.position.is_none() {
            return Err("mapped orientation or σ columns need `position` mapped too".into());
        }
        let length = |c: &Option<Columns>, field: &str, want_length: bool| match c {
            Some(c) if c.unit.is_length() != want_length => Err(format!(
                "`{field}.unit` must be {}",
                if want_length {
                    "a length (mm, m, in, um)"
                } else {
                    "an angle (deg, rad)"
                }
            )),
            _ => Ok(()),
        };
        length(&self.position, "position", true)?;
        length(&self.sigma_position, "sigma_position", true)?;
        length(&self.sigma_orientation, "sigma_orientation", false)?;
        if let Some(o) = &self.orientation {
            if o.columns.len() != o.convention.columns() {
                return Err(format!(
                    "`orientation.columns`: `{}` takes {} columns, {} given",
                    o.convention.name(),
                    o.convention.columns(),
                    o.columns.len()
                ));
            }
            match (o.convention.is_angles(), o.unit) {
                (true, None) => {
                    return Err("`orientation.unit` is needed for angles (deg or rad)".into())
                }
                (true, Some(u)) if u.is_length() => {
                    return Err("`orientation.unit` must be deg or rad".into())
                }
                (false, Some(_)) => {
                    return Err("quaternion columns have no `orientation.unit`".into())
                }
                _ => {}
            }
        }
        if let Some(s) = &self.sigma_orientation {
            let angles = self
                .orientation
                .as_ref()
                .is_some_and(|o| o.convention.is_angles());
            if !angles {
                return Err(format!(
                    "`sigma_orientation` ({}) needs an angle `orientation` (σ of quaternion components are not read)",
                    s.columns.join(", ")
                ));
            }
        }
        Ok(())
    }
}

/// A field as read: white space and NUL bytes trimmed.
pub(crate) fn clean(field: &str) -> &str {
    field.trim_matches(|c: char| c.is_whitespace() || c == '\0')
}

/// A number in `decimal` notation, `None` if it is none.
pub(crate) fn number(field: &str, decimal: Decimal) -> Option<f64> {
    match decimal {
        Decimal::Point => field.parse().ok(),
        Decimal::Comma if field.contains('.') => None,
        Decimal::Comma => field.replacen(',', ".", 1).parse().ok(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_trimmed_and_read_in_their_decimal_notation() {
        assert_eq!(clean(" 0,25\0"), "0,25");
        assert_eq!(clean("\t x \r"), "x");
        assert_eq!(number("2,78E-17", Decimal::Comma), Some(2.78e-17));
        assert_eq!(
            number("4,7313030354655597e-05", Decimal::Comma),
            Some(4.7313030354655597e-05)
        );
        assert_eq!(number("-0,365141", Decimal::Comma), Some(-0.365141));
        assert_eq!(number("1,2,3", Decimal::Comma), None);
        assert_eq!(number("0.5", Decimal::Comma), None);
        assert_eq!(number("0,5", Decimal::Point), None);
        assert_eq!(number("1e3", Decimal::Point), Some(1000.0));
        assert_eq!(length_factor(""), Some(1.0));
        assert_eq!(length_factor("m"), Some(1000.0));
        assert_eq!(length_factor("deg"), None);
        assert_eq!(angle_factor("rad"), Some(1.0));
        assert_eq!(angle_factor("joint"), None);
    }
}
