//! Periodic joint errors (gear transmission, encoder eccentricity), identified with the
//! geometry: the non-kinematic joint errors of the book's level-3 calibration (Mooring, Roth
//! & Driels 1991, §1.3, ch. 2) that repeat with the joint angle, issue 14 item 2.
//!
//! # Model
//! A joint `i` with periodic errors turns by
//!
//! `Δq_i = Σ_k a_ik sin(k q_i) + b_ik cos(k q_i)`
//!
//! for the chosen harmonics `k ≥ 1` (`q_i` the commanded angle), and forward kinematics runs
//! at `q + Δq` with the joint compliance's deflection (`crate::model::joint_correction`).
//! The constant term (`k = 0`) is the joint offset, already a parameter of every link form,
//! so it is never a periodic term. The model is linear in the amplitudes: a unit change of
//! `a_ik` turns joint `i` by `sin(k q_i)`, so its identification column is `sin(k q_i)` times
//! joint `i`'s column, and `∂/∂q_i` of the basis is `k cos(k q_i)` (`−k sin(k q_i)` for
//! `b_ik`).
//!
//! A periodic term can be the same function as another over the measured poses: the first
//! harmonic of a shoulder joint and the compliance of that joint under an elbow mass (whose
//! lever is `a cos(q_i + φ)`), or any harmonic of a joint that moves over a small range. The
//! identification's gate (`crate::identify::nongeometric_gate`) reports such a term as
//! not separable and the fit drops it.
//!
//! # Names and units
//! `<joint>.periodic.sin<k>` and `<joint>.periodic.cos<k>`, stored in rad and shown in
//! **arcsec** (a strain-wave gear's transmission error is of the order of 10–60 arcsec).

use crate::model::joint_correction::revolute_joints;
use crate::model::link::{Joint, JointKind};
use crate::model::registry::{Registry, Segment, Unit};
use crate::Error;
use nalgebra::{convert, RealField};
use serde::{Deserialize, Serialize};

/// Largest |amplitude| a model holds (rad; about 5.7°).
pub const MAX_AMPLITUDE: f64 = 0.1;

/// Highest harmonic a cell may ask for.
pub const MAX_HARMONIC: u32 = 64;

/// Which function of `k q_i` a term multiplies.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Phase {
    /// `sin(k q_i)`.
    Sin,
    /// `cos(k q_i)`.
    Cos,
}

/// One periodic term: joint, harmonic, phase and its amplitude.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PeriodicTerm {
    /// Name of the joint.
    pub joint: String,
    /// The harmonic `k ≥ 1`.
    pub harmonic: u32,
    /// `sin` or `cos`.
    pub phase: Phase,
    /// The amplitude (rad; shown in arcsec).
    pub value: f64,
}

/// The periodic joint errors of a model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PeriodicSpec {
    /// The terms, in registry order.
    pub terms: Vec<PeriodicTerm>,
}

/// A term compiled against a model.
#[derive(Clone, Debug)]
pub struct CompiledPeriodic {
    /// Index of the joint in `q`.
    pub joint: usize,
    /// Index of the amplitude in the registry.
    pub param: usize,
    /// The term as specified (its value is the nominal).
    pub spec: PeriodicTerm,
}

impl PeriodicSpec {
    /// The terms of `joints` × `harmonics` (sin then cos for each harmonic, joints in chain
    /// order), all zero. The error names what is wrong (unknown or prismatic joint, a
    /// harmonic out of 1…[`MAX_HARMONIC`], a joint or harmonic given twice, an empty list).
    pub fn new(joints: &[Joint], names: &[String], harmonics: &[u32]) -> Result<Self, String> {
        let index = revolute_joints(joints, names, "periodic errors are")?;
        if index.is_empty() || harmonics.is_empty() {
            return Err(
                "give at least one joint and one harmonic, e.g. joints = [\"j1\"], \
                        harmonics = [1, 2]"
                    .into(),
            );
        }
        let mut ks: Vec<u32> = Vec::new();
        for &k in harmonics {
            if !(1..=MAX_HARMONIC).contains(&k) {
                return Err(format!(
                    "harmonic {k} is outside 1…{MAX_HARMONIC} (the constant term is the joint \
                     offset)"
                ));
            }
            if ks.contains(&k) {
                return Err(format!("harmonic {k} is listed twice"));
            }
            ks.push(k);
        }
        ks.sort_unstable();
        let terms = index
            .iter()
            .flat_map(|&i| {
                ks.iter().flat_map(move |&k| {
                    [Phase::Sin, Phase::Cos].map(|phase| PeriodicTerm {
                        joint: joints[i].name.clone(),
                        harmonic: k,
                        phase,
                        value: 0.0,
                    })
                })
            })
            .collect();
        Ok(PeriodicSpec { terms })
    }

    /// Name of a term's parameter: `<joint>.periodic.sin<k>` or `….cos<k>`.
    pub fn parameter_name(term: &PeriodicTerm) -> String {
        let phase = match term.phase {
            Phase::Sin => "sin",
            Phase::Cos => "cos",
        };
        format!("{}.periodic.{phase}{}", term.joint, term.harmonic)
    }

    /// Checks the spec against the chain's joints and adds the amplitudes to the registry
    /// (unit arcsec, segment chain, free).
    pub(crate) fn compile(
        &self,
        joints: &[Joint],
        registry: &mut Registry,
    ) -> Result<Vec<CompiledPeriodic>, Error> {
        self.terms
            .iter()
            .map(|t| {
                let name = Self::parameter_name(t);
                let joint = joints
                    .iter()
                    .position(|j| j.name == t.joint && j.kind == JointKind::Revolute)
                    .ok_or_else(|| {
                        Error::Model(format!(
                            "periodic term `{name}`: no revolute joint `{}`",
                            t.joint
                        ))
                    })?;
                if !(1..=MAX_HARMONIC).contains(&t.harmonic) || !Unit::Arcsec.holds(t.value) {
                    return Err(Error::Model(format!(
                        "periodic term `{name}`: harmonic 1…{MAX_HARMONIC} and amplitude {}",
                        Unit::Arcsec.range_text()
                    )));
                }
                let param = registry.add(name, Unit::Arcsec, t.value, Segment::Chain)?;
                Ok(CompiledPeriodic {
                    joint,
                    param,
                    spec: t.clone(),
                })
            })
            .collect()
    }
}

impl CompiledPeriodic {
    /// The basis function `f(q_i)` (`sin(k q_i)` or `cos(k q_i)`) and `df/dq_i`.
    pub fn basis<T: RealField + Copy>(&self, q: &[T]) -> (T, T) {
        let k: T = convert(f64::from(self.spec.harmonic));
        let (s, c) = (k * q[self.joint]).sin_cos();
        match self.spec.phase {
            Phase::Sin => (s, k * c),
            Phase::Cos => (c, -k * s),
        }
    }
}
