//! The parameter registry: every scalar of a model has a stable name (`j2.beta`, `base.rz`,
//! `tracker.x`, `smr1.y`), a unit, a nominal value and a status. Parameter vectors are
//! indexed through the registry. Internal units are millimetres and radians.

use crate::model::prior::CorrelatedPrior;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::fmt;

/// Physical unit of a parameter. Internal values are in mm or rad; user-facing values of
/// angles are shown in degrees.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Unit {
    /// Length, stored in millimetres.
    Mm,
    /// Angle, stored in radians (shown in degrees).
    Rad,
    /// Dimensionless (components of a unit axis vector).
    Unitless,
    /// Lumped joint compliance κ = c·m·g ([`crate::model::compliance`]), stored in rad per
    /// mm of lever, shown in µrad/m.
    #[serde(rename = "urad_per_m")]
    RadPerMm,
    /// A joint's own compliance `c` (the payload term of [`crate::model::compliance`]),
    /// stored in rad per N·mm of gravity torque, shown in µrad/(N·m).
    #[serde(rename = "urad_per_Nm")]
    RadPerNmm,
    /// A small joint angle: a periodic joint error's amplitude
    /// ([`crate::model::periodic`]), stored in radians, shown in arcseconds.
    Arcsec,
}

impl Unit {
    /// Factor from the internal unit to the display unit (mm, deg, 1).
    pub fn display_factor(self) -> f64 {
        match self {
            Unit::Rad => 180.0 / std::f64::consts::PI,
            Unit::RadPerMm | Unit::RadPerNmm => 1e9,
            Unit::Arcsec => 648_000.0 / std::f64::consts::PI,
            _ => 1.0,
        }
    }

    /// The largest magnitude a model value of this unit may have, in internal units: lengths
    /// 10⁶ mm (1 km), angles 3600° (ten turns, 20π rad), dimensionless 10⁶, compliance 10⁶ µrad/m and 10⁶ µrad/(N·m), periodic amplitudes 0.1 rad. Beyond these the
    /// kinematics and the conversions between conventions lose every digit (and overflow), so
    /// a model refuses them ([`crate::model::LinkSpec::check_values`]).
    pub fn max_abs(self) -> f64 {
        match self {
            Unit::Mm | Unit::Unitless => 1e6,
            Unit::Rad => 20.0 * std::f64::consts::PI,
            Unit::RadPerMm => crate::model::compliance::MAX_COMPLIANCE,
            Unit::RadPerNmm => crate::model::compliance::MAX_JOINT_COMPLIANCE,
            Unit::Arcsec => crate::model::periodic::MAX_AMPLITUDE,
        }
    }

    /// Whether `v` (internal units) is within [`Unit::max_abs`]; false for NaN and ±∞.
    pub fn holds(self, v: f64) -> bool {
        v.abs() <= self.max_abs()
    }

    /// The range of [`Unit::max_abs`] in display units, for an error message: `|x| ≤ 1e6 mm`.
    pub fn range_text(self) -> String {
        format!(
            "|x| ≤ {} {}",
            self.max_abs() * self.display_factor(),
            self.display_name()
        )
    }

    /// Name of the display unit.
    pub fn display_name(self) -> &'static str {
        match self {
            Unit::Mm => "mm",
            Unit::Rad => "deg",
            Unit::Unitless => "1",
            Unit::RadPerMm => "µrad/m",
            Unit::RadPerNmm => "µrad/(N·m)",
            Unit::Arcsec => "arcsec",
        }
    }
}

/// Whether a parameter is estimated.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase", tag = "status")]
pub enum ParameterStatus {
    /// Estimated from the data.
    Free,
    /// Held at its nominal value.
    Fixed,
    /// Estimated, with a Gaussian prior centred on the nominal value (σ in internal units).
    Prior {
        /// Standard deviation of the prior (mm or rad, the parameter's internal unit).
        sigma: f64,
    },
}

impl ParameterStatus {
    /// True unless [`ParameterStatus::Fixed`]: free and prior parameters are both estimated.
    pub fn is_free(&self) -> bool {
        !matches!(self, ParameterStatus::Fixed)
    }
}

/// Which part of the measurement chain a parameter belongs to. It decides which targets a
/// parameter moves and with which sign (instrument parameters enter inverted, paper eq. 3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Segment {
    /// The instrument frame (e.g. the laser tracker pose in the world).
    Instrument,
    /// Base frame, links and tool: moves every target.
    Chain,
    /// The offset of one target (reflector, SMR, tool frame) from the tool frame.
    Target(usize),
}

/// One named scalar of a model: a link, frame or target field.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Parameter {
    /// Stable name, `<frame>.<field>`.
    pub name: String,
    /// Unit of `nominal` (mm, rad or unitless).
    pub unit: Unit,
    /// Nominal value in internal units (mm, rad).
    pub nominal: f64,
    /// Whether the identification estimates it, holds it, or estimates it with a prior.
    pub status: ParameterStatus,
    /// Instrument, chain or target: which targets it moves.
    pub segment: Segment,
}

impl Parameter {
    /// The part of the name before the dot (`j2` of `j2.beta`).
    pub fn frame(&self) -> &str {
        self.name.split('.').next().unwrap_or(&self.name)
    }
}

/// Ordered set of named parameters.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Registry {
    params: Vec<Parameter>,
    #[serde(skip)]
    index: HashMap<String, usize>,
    /// A correlated Gaussian prior over some of the parameters
    /// ([`crate::model::prior`]); `None`: the per-parameter priors alone.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    correlated: Option<CorrelatedPrior>,
}

impl Registry {
    /// Registry with no parameters.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a parameter and returns its index. Names must be unique.
    pub fn add(
        &mut self,
        name: String,
        unit: Unit,
        nominal: f64,
        segment: Segment,
    ) -> Result<usize, crate::Error> {
        if self.index.contains_key(&name) {
            return Err(crate::Error::Model(format!(
                "parameter name `{name}` is used twice; frame names must be unique"
            )));
        }
        let i = self.params.len();
        self.index.insert(name.clone(), i);
        self.params.push(Parameter {
            name,
            unit,
            nominal,
            status: ParameterStatus::Free,
            segment,
        });
        Ok(i)
    }

    /// Number of parameters (length of a parameter vector).
    pub fn len(&self) -> usize {
        self.params.len()
    }

    /// True if the registry has no parameters.
    pub fn is_empty(&self) -> bool {
        self.params.is_empty()
    }

    /// Parameter at index `i`; panics if out of range.
    pub fn get(&self, i: usize) -> &Parameter {
        &self.params[i]
    }

    /// Parameters in index order.
    pub fn iter(&self) -> impl Iterator<Item = &Parameter> {
        self.params.iter()
    }

    /// Index of the parameter with this exact name, if any.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.index.get(name).copied()
    }

    /// Index of a parameter, or an error that lists similar names.
    pub fn require(&self, name: &str) -> Result<usize, crate::Error> {
        self.index_of(name).ok_or_else(|| {
            let frame = name.split('.').next().unwrap_or(name);
            let similar: Vec<&str> = self
                .params
                .iter()
                .filter(|p| p.frame() == frame)
                .map(|p| p.name.as_str())
                .collect();
            let hint = if similar.is_empty() {
                let frames: Vec<&str> = self.frames();
                format!("known frames: {}", frames.join(", "))
            } else {
                format!("parameters of `{frame}`: {}", similar.join(", "))
            };
            crate::Error::Model(format!("unknown parameter `{name}` ({hint})"))
        })
    }

    /// Frame names in order of first appearance.
    pub fn frames(&self) -> Vec<&str> {
        let mut out: Vec<&str> = Vec::new();
        for p in &self.params {
            if out.last() != Some(&p.frame()) && !out.contains(&p.frame()) {
                out.push(p.frame());
            }
        }
        out
    }

    /// Indices of parameters whose name matches a pattern: an exact name, a whole frame
    /// (`j6` or `j6.*`), or a field across frames (`*.theta`).
    pub fn matching(&self, pattern: &str) -> Result<Vec<usize>, crate::Error> {
        let (frame, field) = match pattern.split_once('.') {
            Some((f, g)) => (f, g),
            None => (pattern, "*"),
        };
        let out: Vec<usize> = self
            .params
            .iter()
            .enumerate()
            .filter(|(_, p)| {
                let (pf, pg) = p.name.split_once('.').unwrap_or((&p.name, ""));
                (frame == "*" || frame == pf) && (field == "*" || field == pg)
            })
            .map(|(i, _)| i)
            .collect();
        if out.is_empty() {
            // Produce the helpful error for the exact-name case.
            self.require(pattern)?;
        }
        Ok(out)
    }

    /// Sets whether parameter `i` is free, fixed or has a prior.
    pub fn set_status(&mut self, i: usize, status: ParameterStatus) {
        self.params[i].status = status;
    }

    /// Sets the nominal value of parameter `i` (internal units): e.g. to an estimate's, so
    /// that a design is planned where the frame is now believed to be.
    pub fn set_nominal(&mut self, i: usize, value: f64) {
        self.params[i].nominal = value;
    }

    /// The correlated prior, if any (`crate::model::prior`).
    pub fn correlated_prior(&self) -> Option<&CorrelatedPrior> {
        self.correlated.as_ref()
    }

    /// Sets (or with `None` removes) the correlated prior, after checking it
    /// (`CorrelatedPrior::check`); its parameters keep their statuses (a fit estimates the
    /// free ones with it).
    pub fn set_correlated_prior(
        &mut self,
        prior: Option<CorrelatedPrior>,
    ) -> Result<(), crate::Error> {
        if let Some(p) = &prior {
            p.check()?;
        }
        self.correlated = prior;
        Ok(())
    }

    /// Nominal parameter vector.
    pub fn nominal(&self) -> Vec<f64> {
        self.params.iter().map(|p| p.nominal).collect()
    }

    /// Indices of the parameters whose status is free or prior.
    pub fn free(&self) -> Vec<usize> {
        (0..self.len())
            .filter(|&i| self.params[i].status.is_free())
            .collect()
    }
}

impl fmt::Display for Parameter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} = {:.6} {}",
            self.name,
            self.nominal * self.unit.display_factor(),
            self.unit.display_name()
        )
    }
}
