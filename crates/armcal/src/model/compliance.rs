//! Joint compliance under gravity (elastostatic deflection), identified with the geometry:
//! the book's level-3 calibration (Mooring, Roth & Driels 1991, §1.3 and ch. 2's
//! non-kinematic errors) and the outlook of Jost et al. 2017, §6 ("non-geometric errors like
//! joint elasticities").
//!
//! # Model
//! A compliant joint `i` deflects under the gravity torque of everything beyond it,
//! `Δq_i = c_i τ_i(q)`, and forward kinematics runs at `q + Δq` (a joint-space correction:
//! every other parameter, Jacobian and derivative is unchanged but evaluated there).
//!
//! # The identifiable combinations
//! Let joint `i` have the unit world twist `ξ_i = (ω_i, v_i)` (axis direction and moment) and
//! let a point mass `m` sit at `x` on a link beyond it. Gravity is `F = m g ĝ`, `ĝ` the unit
//! direction of `[robot] gravity` (the chain's first frame, default `[0, 0, −1]`) and
//! `g = 9.81 m/s²`. By virtual work the torque about joint `i` is the force times the
//! velocity of `x` under a unit rotation of joint `i`:
//!
//! `τ_i = F · (ω_i × x + v_i) = m g ℓ_i(x, q)`, with the lever `ℓ_i = ĝ · ∂x/∂q_i` (mm).
//!
//! Link masses and stiffnesses are unknown, so `c_i` and `m` never appear alone: the data see
//! only the products `κ_{i,m} = c_i m g`, and `Δq_i = Σ_m κ_{i,m} ℓ_i(x_m, q)`. Every lever is
//! taken from the nominal kinematics (kept with the model as [`ComplianceSpec::levers`]), so
//! `Δq` is a known function of `q` times the unknown `κ`: the model stays linear in `κ` and
//! its derivatives stay exact. A general link mass (mass and first moment, four numbers per
//! link) makes `τ_i` a combination of the levers of the link's origin and of its three axes;
//! armcal starts from point masses at chosen frames instead (the form that worked on real
//! tracker data, issue 14) and drops what cannot be told apart:
//!
//! * **no torque**: `ℓ_i ≡ 0` when `ω_i ∥ ĝ` (a vertical first joint: `ĝ · (ω_i × r) = 0`) or
//!   when the mass lies on the axis of joint `i` (`r ∥ ω_i`) or before it in the chain;
//! * **a constant torque**: `ℓ_i` constant over the joint range is the joint offset's
//!   column (`Δq_i` constant), already identified;
//! * **the same function twice**: a lever that is a linear combination of the joint's other
//!   kept levers and the constant (a mass on the segment between two kept masses on one
//!   link: `ℓ` is linear in `x`).
//!
//! The three tests run on the levers sampled over the joint limits
//! ([`ComplianceSpec::lumped`]); a compliant joint with no term left is an error. What is
//! left can still be indistinguishable from the geometry on a given data set (a small arm, a
//! narrow joint range): the identification's gate reports for every term its σ, its largest
//! correlation with the geometric parameters and the share of its effect the geometric
//! columns cannot absorb (`crate::identify::compliance_gate`).
//!
//! # Default masses
//! For compliant joints `i₁ < i₂ < …` two point masses: the **elbow**, the point where the
//! chain reaches the axis of the joint after `i₁` (for a 6R arm with parallel shoulder and
//! elbow: the elbow axis), and the **wrist**, the point of the second-to-last joint's axis
//! (the wrist centre of a spherical wrist). A joint `i₁ = 2, i₂ = 3` arm gets
//! `j2 × elbow`, `j2 × wrist`, `j3 × wrist` (`j3 × elbow` has no torque: the elbow lies on
//! the axis of `j3`). The terms are named `<joint>.compliance.<mass>`.
//!
//! # A known payload
//! A payload of known mass `m_p` with its centre of mass at `x_p` (in the tool frame, the
//! chain's end; [`Payload`]) adds `c_i m_p g ℓ_i(x_p, q)` to `Δq_i`. Here the joint's
//! compliance `c_i` itself appears, not a product with an unknown mass: a model whose robot
//! may carry payloads (a cell's `[[payload]]`) has one more term per compliant joint,
//! `<joint>.compliance.payload` = `c_i` in **µrad/(N·m)** (stored in rad per N·mm), whose
//! basis is the payload's torque `m_p g ℓ_i(x_p)` (N·mm) for a measurement that carried one
//! ([`crate::model::Data::payload`]) and 0 for one that did not. Over measurements with and
//! without the payload (or with two payloads) `c_i` is separate from the lumped `κ` and the
//! geometry, so the deflection can be predicted at any payload; over measurements that all
//! carried the same payload its torque is nearly the wrist mass's lever and the gate finds it
//! inseparable (the same point mass seen twice). With no measurement carrying a payload its
//! column is zero and identification leaves it out, saying so. Joints whose levers are zero
//! at the payload (a vertical first joint) get no payload term.
//!
//! # Units
//! `κ` is stored in rad per mm of lever and shown in **µrad/m** (`1 rad/mm = 10⁹ µrad/m`): a
//! deflection of `κ` µrad for every metre of horizontal lever arm. For `c = 10⁻⁶ rad/(N·m)`
//! and 20 kg beyond the joint, `κ ≈ 196 µrad/m`. A physical compliance is `κ ≥ 0` (the arm
//! sags: the potential `−F·x` falls by `κ ℓ² ≥ 0`); a negative estimate is flagged.

use crate::model::chain::Model;
use crate::model::joint_correction::revolute_joints;
use crate::model::kinematics::{forward_kinematics, Data};
use crate::model::link::{Joint, JointKind};
use crate::model::pose::{Pose, Twist};
use crate::model::registry::{Registry, Segment, Unit};
use crate::Error;
use nalgebra::{convert, RealField, Vector3};
use serde::{Deserialize, Serialize};

/// Largest |κ| a model holds (rad/mm; 10⁶ µrad/m).
pub const MAX_COMPLIANCE: f64 = 1e-3;

/// Largest |c| of a payload term (rad per N·mm; 10⁶ µrad/(N·m) = 1 rad/(N·m)).
pub const MAX_JOINT_COMPLIANCE: f64 = 1e-3;

/// Standard gravity (m/s²): a payload's weight is `m_p g` newtons.
pub const STANDARD_GRAVITY: f64 = 9.80665;

/// Largest payload mass a model holds (kg).
pub const MAX_PAYLOAD_KG: f64 = 1e5;

/// The mass label of a payload term (`j2.compliance.payload`).
pub const PAYLOAD_TERM: &str = "payload";

/// Configurations the lever tests of [`ComplianceSpec::lumped`] sample.
const LEVER_SAMPLES: usize = 200;

/// A lever whose part outside the span of the constant and the kept levers is below this
/// share of its norm is dropped (it is the same function).
const LEVER_DEPENDENCE: f64 = 1e-6;

/// One lumped compliance term `κ_{i,m} = c_i m g` (see the module notes).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ComplianceTerm {
    /// Name of the compliant joint `i`.
    pub joint: String,
    /// The mass's label in the parameter name (`elbow`, `wrist`).
    pub mass: String,
    /// The joint on whose axis the point mass sits (where the chain reaches that axis);
    /// `None` for a payload term (mass [`PAYLOAD_TERM`]), whose point is the carried
    /// payload's centre of mass.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at: Option<String>,
    /// κ in rad per mm of lever (shown in µrad/m); a payload term's `c` in rad per N·mm
    /// (shown in µrad/(N·m)).
    pub value: f64,
}

impl ComplianceTerm {
    /// Whether this is a payload term (`c_i`, loaded by the known payload).
    pub fn is_payload(&self) -> bool {
        self.at.is_none()
    }

    /// The unit of the term's value: µrad/m for a lumped κ, µrad/(N·m) for a payload term.
    pub fn unit(&self) -> Unit {
        if self.is_payload() {
            Unit::RadPerNmm
        } else {
            Unit::RadPerMm
        }
    }
}

/// A payload the robot may carry: a cell's `[[payload]]` (`name`, `mass_kg`, `com_mm`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Payload {
    /// The name a data file's `payload` column and `--payload` give.
    pub name: String,
    /// Mass in kg (> 0).
    pub mass_kg: f64,
    /// Centre of mass in the tool frame (the chain's end frame), mm.
    pub com_mm: [f64; 3],
}

impl Payload {
    /// Checks the name (as a station name: it becomes part of file rows and records), the
    /// mass (0 < m ≤ [`MAX_PAYLOAD_KG`]) and the centre of mass (finite, within the model's
    /// length range); the error says which and why.
    pub fn check(&self) -> Result<(), String> {
        crate::model::station::check_name(&self.name)
            .map_err(|e| e.replace("station", "payload"))?;
        if self.name == "none" {
            return Err("`none` means no payload in a data file; choose another name".into());
        }
        if !(self.mass_kg > 0.0 && self.mass_kg <= MAX_PAYLOAD_KG) {
            return Err(format!(
                "payload `{}`: mass_kg = {} must be > 0 and ≤ {MAX_PAYLOAD_KG} kg",
                self.name, self.mass_kg
            ));
        }
        if let Some(x) = self.com_mm.iter().find(|x| !Unit::Mm.holds(**x)) {
            return Err(format!(
                "payload `{}`: com_mm has {x}, outside {}",
                self.name,
                Unit::Mm.range_text()
            ));
        }
        Ok(())
    }
}

/// Joint compliance of a model: gravity, the lever geometry and the lumped terms.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ComplianceSpec {
    /// Unit gravity direction in the chain's first (base) frame.
    pub gravity: [f64; 3],
    /// The link parameter values (registry order, mm and rad) the levers are computed with:
    /// the nominal geometry, kept so that a model rebuilt from an estimate deflects alike.
    pub levers: Vec<f64>,
    /// The lumped terms (then, with payloads, one payload term per compliant joint).
    pub terms: Vec<ComplianceTerm>,
    /// The lateral (bending) terms of a tree's joints ([`crate::model::tree::bending`]):
    /// each names its joint and the joint on whose axis its mass sits. A serial chain takes
    /// none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub bending: Vec<ComplianceTerm>,
}

/// A term compiled against a model.
#[derive(Clone, Debug)]
pub struct CompiledTerm {
    /// Index of the compliant joint in `q`.
    pub joint: usize,
    /// Index of the joint whose axis point carries the mass; `None`: a payload term.
    pub at: Option<usize>,
    /// Index of κ in the registry.
    pub param: usize,
    /// The term as specified (its value is the nominal).
    pub spec: ComplianceTerm,
}

/// [`ComplianceSpec`] compiled against a model ([`Model::compliance`]).
#[derive(Clone, Debug)]
pub struct Compliance {
    /// Unit gravity in the base frame.
    pub gravity: Vector3<f64>,
    /// Lever parameter vector (a full parameter vector; non-geometric entries unused).
    pub levers: Vec<f64>,
    /// The terms, in registry order.
    pub terms: Vec<CompiledTerm>,
    /// Per model payload ([`crate::model::Model::payloads`]): its weight `m_p g` (N) and
    /// centre of mass in the tool frame (mm).
    pub payloads: Vec<(f64, Vector3<f64>)>,
    /// Number of link parameters (the registry before the κ).
    link_params: usize,
}

impl Compliance {
    /// Number of link parameters (the registry before the κ).
    pub fn link_params(&self) -> usize {
        self.link_params
    }
}

/// The compliance's lever pass (`crate::model::joint_correction::CorrectionData`).
#[derive(Clone, Debug)]
pub struct ComplianceData<T: RealField + Copy> {
    /// The model at the lever parameters and the commanded `q`.
    pub levers: Data<T>,
}

impl<T: RealField + Copy> ComplianceData<T> {
    /// Buffers for `model` (which has compliance).
    pub(crate) fn new(model: &Model, _c: &Compliance) -> Self {
        ComplianceData {
            levers: Data::without_corrections(model),
        }
    }

    /// The levers `ℓ_t` (into `lever`) and their q-derivatives (into `lever_rate`, row-major
    /// `term · dof + k`) at `q`.
    ///
    /// `∂ℓ_i/∂q_k` with `c = ω_i × x + v_i` (the velocity of the mass point under joint i):
    /// for `k ≤ i` joint k turns axis i and the point rigidly, `ċ = ω_k × c`; for `k > i`
    /// the axis stays and the point moves if joint k comes before it in the chain,
    /// `ċ = ω_i × (ω_k × x + v_k)`, else nothing moves. `ℓ̇ = ĝ · ċ` (ĝ fixed in the world).
    /// A payload term's basis is the torque `m_p g ℓ_i(x_p)` of `payload` (an index into
    /// [`Compliance::payloads`]; its point is beyond every joint), and 0 without one.
    pub(crate) fn evaluate(
        &mut self,
        model: &Model,
        c: &Compliance,
        q: &[T],
        payload: Option<usize>,
        lever: &mut [T],
        lever_rate: &mut [T],
    ) {
        forward_kinematics(model, &mut self.levers, &c.levers, q);
        let dof = model.dof();
        let g: Vector3<T> = self.levers.frames[0].rot * c.gravity.map(convert::<f64, T>);
        let carried = payload
            .and_then(|p| c.payloads.get(p))
            .map(|(weight, com)| {
                let x = self
                    .levers
                    .tool()
                    .transform_point(&com.map(convert::<f64, T>));
                (convert::<f64, T>(*weight), x)
            });
        for (t, term) in c.terms.iter().enumerate() {
            let rates = &mut lever_rate[t * dof..(t + 1) * dof];
            let (scale, x, at) = match (term.at, carried) {
                (Some(at), _) => (T::one(), self.levers.joint_points[at], at),
                (None, Some((weight, x))) => (weight, x, dof),
                (None, None) => {
                    lever[t] = T::zero();
                    rates.fill(T::zero());
                    continue;
                }
            };
            let twists = &self.levers.joint_twists;
            let axis = twists[term.joint];
            let vel = axis.point_velocity(&x);
            lever[t] = g.dot(&vel) * scale;
            for (k, tw) in twists.iter().enumerate() {
                rates[k] = scale
                    * if k <= term.joint {
                        g.dot(&tw.w.cross(&vel))
                    } else if k < at {
                        g.dot(&axis.w.cross(&tw.point_velocity(&x)))
                    } else {
                        T::zero()
                    };
            }
        }
    }
}

impl ComplianceSpec {
    /// The lumped terms for compliant `joints` with the default masses (elbow and wrist, see
    /// the module notes), after dropping the terms with no torque, a constant torque or a
    /// lever another term already has, sampled over the joint limits. `model` has no
    /// compliance yet; its nominal parameters become the levers. The error names the joint
    /// and what to do (unknown, prismatic, no gravity torque, given twice).
    pub fn lumped(model: &Model, joints: &[String], gravity: [f64; 3]) -> Result<Self, String> {
        let g = gravity_direction(gravity)?;
        let names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
        let index = revolute_joints(&model.joints, joints, "compliance is")?;
        let dof = model.dof();
        let Some(&first) = index.first() else {
            return Err("give at least one joint, e.g. [\"j2\", \"j3\"]".into());
        };
        let mut masses: Vec<(&str, usize)> = Vec::new();
        if first + 1 < dof {
            masses.push(("elbow", first + 1));
        }
        if dof >= 2 && masses.iter().all(|m| m.1 != dof - 2) {
            masses.push(("wrist", dof - 2));
        }
        let levers = model.nominal();
        let samples = lever_samples(model, &levers, g);
        let mut terms = Vec::new();
        for &i in &index {
            // columns: the constant, then the kept levers of joint i
            let mut basis: Vec<Vec<f64>> = vec![vec![1.0; samples.len()]];
            orthonormalise(&mut basis[0]);
            for &(label, at) in &masses {
                if at <= i {
                    continue;
                }
                let mut l: Vec<f64> = samples.iter().map(|s| s.lever(i, at)).collect();
                let norm = l.iter().map(|x| x * x).sum::<f64>().sqrt();
                for b in &basis {
                    let d: f64 = b.iter().zip(&l).map(|(x, y)| x * y).sum();
                    l.iter_mut().zip(b).for_each(|(y, x)| *y -= d * x);
                }
                let rest = l.iter().map(|x| x * x).sum::<f64>().sqrt();
                // 1e-9 mm: no torque at all
                if norm < 1e-9 * samples.len() as f64 || rest < LEVER_DEPENDENCE * norm {
                    continue;
                }
                orthonormalise(&mut l);
                basis.push(l);
                terms.push(ComplianceTerm {
                    joint: names[i].to_string(),
                    mass: label.to_string(),
                    at: Some(names[at].to_string()),
                    value: 0.0,
                });
            }
            if basis.len() == 1 {
                return Err(format!(
                    "joint `{}` carries no gravity torque that a joint offset does not absorb \
                     (its axis is along gravity, or the elbow and wrist lie on it or before \
                     it); remove it from the list",
                    names[i]
                ));
            }
        }
        // one payload term per compliant joint that a payload's weight turns
        for &i in &index {
            let turns = model.payloads.iter().any(|p| {
                let com = Vector3::from(p.com_mm);
                samples
                    .iter()
                    .any(|s| s.payload_lever(i, &com).abs() > 1e-9)
            });
            if turns {
                terms.push(ComplianceTerm {
                    joint: names[i].to_string(),
                    mass: PAYLOAD_TERM.to_string(),
                    at: None,
                    value: 0.0,
                });
            }
        }
        Ok(ComplianceSpec {
            gravity: [g.x, g.y, g.z],
            levers,
            terms,
            bending: Vec::new(),
        })
    }

    /// Checks a [`ComplianceSpec`] against the chain and adds its κ to the registry (unit
    /// µrad/m, segment chain, free).
    pub(crate) fn compile(
        &self,
        joints: &[Joint],
        payloads: &[Payload],
        link_params: usize,
        registry: &mut Registry,
    ) -> Result<Compliance, Error> {
        let c = self;
        let g =
            gravity_direction(c.gravity).map_err(|e| Error::Model(format!("compliance: {e}")))?;
        if let Some(t) = c.bending.first() {
            return Err(Error::Model(format!(
                "compliance: the bending term `{}` is for a kinematic tree; a serial chain \
                 takes none (describe the robot as a tree cell, links naming a `parent`)",
                Self::bending_name(t)
            )));
        }
        if c.levers.len() != link_params || !c.levers.iter().all(|x| x.is_finite()) {
            return Err(Error::Model(format!(
                "compliance: the lever geometry has {} values, the chain {link_params}",
                c.levers.len()
            )));
        }
        let joint = |name: &str| {
            joints
                .iter()
                .position(|j| j.name == name)
                .ok_or_else(|| Error::Model(format!("compliance: no joint `{name}`")))
        };
        let mut terms = Vec::new();
        for t in &c.terms {
            let i = joint(&t.joint)?;
            let at = t.at.as_deref().map(joint).transpose()?;
            if joints[i].kind != JointKind::Revolute || at.is_some_and(|at| at <= i) {
                return Err(Error::Model(format!(
                    "compliance term `{}`: joint `{}` must be revolute and the mass joint `{}` \
                     beyond it",
                    Self::parameter_name(t),
                    t.joint,
                    t.at.as_deref().unwrap_or(PAYLOAD_TERM)
                )));
            }
            if t.is_payload() != (t.mass == PAYLOAD_TERM) {
                return Err(Error::Model(format!(
                    "compliance term `{}`: a term without a mass joint is the payload term \
                     `{PAYLOAD_TERM}`, and only it",
                    Self::parameter_name(t)
                )));
            }
            let unit = t.unit();
            if !unit.holds(t.value) {
                return Err(Error::Model(format!(
                    "compliance term `{}` = {:e} {} is outside {}",
                    Self::parameter_name(t),
                    t.value * unit.display_factor(),
                    unit.display_name(),
                    unit.range_text()
                )));
            }
            let param = registry.add(Self::parameter_name(t), unit, t.value, Segment::Chain)?;
            terms.push(CompiledTerm {
                joint: i,
                at,
                param,
                spec: t.clone(),
            });
        }
        // the levers grow to the full registry once every term is in it (Model::from_spec)
        Ok(Compliance {
            gravity: g,
            levers: c.levers.clone(),
            terms,
            payloads: payloads
                .iter()
                .map(|p| (p.mass_kg * STANDARD_GRAVITY, Vector3::from(p.com_mm)))
                .collect(),
            link_params,
        })
    }

    /// Name of term `t`'s parameter: `<joint>.compliance.<mass>`.
    pub fn parameter_name(term: &ComplianceTerm) -> String {
        format!("{}.compliance.{}", term.joint, term.mass)
    }

    /// Name of bending term `t`'s parameter: `<joint>.bending.<mass>`.
    pub(crate) fn bending_name(term: &ComplianceTerm) -> String {
        format!("{}.bending.{}", term.joint, term.mass)
    }
}

impl Model {
    /// The index of payload `name` in [`Model::payloads`]; `None` (no payload) for `none`
    /// or an empty name; an unknown name is an error that lists the model's payloads.
    pub fn payload_index(&self, name: &str) -> Result<Option<usize>, String> {
        if name.is_empty() || name == "none" {
            return Ok(None);
        }
        match self.payloads.iter().position(|p| p.name == name) {
            Some(k) => Ok(Some(k)),
            None if self.payloads.is_empty() => Err(format!(
                "payload `{name}`: the cell declares no payload (add a [[payload]] with its \
                 name, mass_kg and com_mm)"
            )),
            None => Err(format!(
                "payload `{name}` is not one of the cell's payloads ({}; or `none`)",
                self.payloads
                    .iter()
                    .map(|p| p.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
        }
    }
}

/// The unit direction of `gravity` (any length), or an error for a zero or non-finite one.
pub fn gravity_direction(gravity: [f64; 3]) -> Result<Vector3<f64>, String> {
    let g = Vector3::from(gravity);
    if g.iter().all(|x| x.is_finite()) && g.norm() > 1e-9 {
        Ok(g.normalize())
    } else {
        Err(format!(
            "gravity {gravity:?} must be a non-zero direction in the base frame"
        ))
    }
}

/// One sampled configuration of the lever tests: joint twists and joint points at the
/// lever parameters, and world gravity.
struct LeverSample {
    twists: Vec<Twist<f64>>,
    points: Vec<Vector3<f64>>,
    tool: Pose<f64>,
    gravity: Vector3<f64>,
}

impl LeverSample {
    fn lever(&self, i: usize, at: usize) -> f64 {
        self.gravity
            .dot(&self.twists[i].point_velocity(&self.points[at]))
    }

    /// The lever of a payload with centre of mass `com` (tool frame) about joint `i`.
    fn payload_lever(&self, i: usize, com: &Vector3<f64>) -> f64 {
        let x = self.tool.transform_point(com);
        self.gravity.dot(&self.twists[i].point_velocity(&x))
    }
}

fn lever_samples(model: &Model, levers: &[f64], g: Vector3<f64>) -> Vec<LeverSample> {
    let qs = crate::model::random_configurations(model, LEVER_SAMPLES, 14);
    let mut data = Data::without_corrections(model);
    qs.iter()
        .map(|q| {
            forward_kinematics(model, &mut data, levers, q);
            LeverSample {
                twists: data.joint_twists.clone(),
                points: data.joint_points.clone(),
                tool: *data.tool(),
                gravity: data.frames[0].rot * g,
            }
        })
        .collect()
}

fn orthonormalise(v: &mut [f64]) {
    let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    v.iter_mut().for_each(|x| *x /= n);
}
