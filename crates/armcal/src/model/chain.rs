//! The kinematic model: instrument frame, base, links with joints, tool, and targets, with
//! one parameter registry. A [`Model`] is immutable once built and can be shared across
//! threads; buffers for one evaluation live in [`crate::model::Data`].

use crate::model::compliance::{Compliance, ComplianceSpec, Payload};
use crate::model::link::{Convention, Joint, JointKind, LinkGeometry, Motion};
use crate::model::periodic::{CompiledPeriodic, PeriodicSpec};
use crate::model::registry::{ParameterStatus, Registry, Segment, Unit};
use crate::Error;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// A link as a user describes it: a name (the prefix of its parameter names), a geometry,
/// and the joint that drives it (none for fixed links and frames).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LinkSpec {
    /// Link name; parameters are named `<name>.<field>` (e.g. `l2.alpha`).
    pub name: String,
    /// Convention and nominal parameter values (mm, rad).
    pub geometry: LinkGeometry,
    /// Joint driving the link; `None` for fixed links, frames and targets.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joint: Option<Joint>,
}

impl LinkSpec {
    /// Every value of the link and its joint limits finite and within the range a model
    /// holds ([`Unit::max_abs`]); the error names the value, its unit and the range.
    pub fn check_values(&self) -> Result<(), String> {
        let kind = self.joint.as_ref().map(|j| j.kind);
        let fields = self.geometry.convention.fields(kind);
        let outside = |what: String, v: f64, unit: Unit| {
            format!(
                "{what} = {:e} {} is outside the range armcal accepts ({})",
                v * unit.display_factor(),
                unit.display_name(),
                unit.range_text()
            )
        };
        for ((field, unit), &v) in fields.iter().zip(&self.geometry.values) {
            if !unit.holds(v) {
                return Err(outside(format!("`{}.{field}`", self.name), v, *unit));
            }
        }
        if let Some(j) = &self.joint {
            let unit = match j.kind {
                JointKind::Revolute => Unit::Rad,
                JointKind::Prismatic => Unit::Mm,
            };
            for (end, v) in [("lower", j.lower), ("upper", j.upper)] {
                if !unit.holds(v) {
                    return Err(outside(
                        format!("the {end} limit of joint `{}`", j.name),
                        v,
                        unit,
                    ));
                }
            }
        }
        Ok(())
    }
}

/// Everything needed to build a [`Model`]; also what exports and estimate files store.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelSpec {
    /// Robot name (cell file `[robot] name`, URDF `<robot name>`).
    pub name: String,
    /// Frame of the measuring instrument in the world (e.g. a laser tracker). Measurements
    /// are expressed in it (paper eq. 3). `None`: measurements are in the world frame.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub instrument: Option<LinkSpec>,
    /// Base frame, then the links from base to flange, then the tool frame.
    pub links: Vec<LinkSpec>,
    /// Points or frames attached to the last chain link (the tool): reflectors, SMRs,
    /// tooling balls, or a full end-effector frame.
    #[serde(default)]
    pub targets: Vec<LinkSpec>,
    /// Joint compliance under gravity ([`crate::model::compliance`]); `None`: rigid joints.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compliance: Option<ComplianceSpec>,
    /// Periodic joint errors ([`crate::model::periodic`]); `None`: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub periodic: Option<PeriodicSpec>,
    /// Payloads the robot may carry (a cell's `[[payload]]`): what a measurement's
    /// `payload` names; with compliance, their gravity torque deflects the joints.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub payloads: Vec<Payload>,
}

/// A compiled link: its spec plus where its parameters live in the registry.
#[derive(Clone, Debug)]
pub struct Link {
    /// The link as described, with its nominal values.
    pub spec: LinkSpec,
    /// Index of the joint variable in `q`, if the link has a joint.
    pub joint: Option<usize>,
    /// Index of the link's first parameter; its fields follow contiguously.
    pub first_param: usize,
}

impl Link {
    /// Number of parameters of this link.
    pub fn param_count(&self) -> usize {
        self.spec.geometry.values.len()
    }

    /// The link's geometry with values taken from a parameter vector.
    pub fn geometry_at(&self, params: &[f64]) -> LinkGeometry {
        let mut g = self.spec.geometry.clone();
        let n = g.values.len();
        g.values
            .copy_from_slice(&params[self.first_param..self.first_param + n]);
        g
    }
}

/// One elementary factor of the kinematic chain, after compilation.
#[derive(Clone, Debug)]
pub(crate) enum Step {
    /// Rotation about / translation along a local axis by `params[param] (+ q[joint])`.
    Elementary {
        motion: Motion,
        param: usize,
        joint: Option<usize>,
        /// Fixed unit axis for `RotAxis` / `TransAxis`.
        axis: Vector3<f64>,
    },
    /// Zero-reference screw motion; parameters `first..first+7` are ux, uy, uz, px, py, pz,
    /// offset.
    Screw {
        first: usize,
        joint: Option<usize>,
        prismatic: bool,
    },
}

/// Immutable kinematic model with its parameter registry.
#[derive(Clone, Debug)]
pub struct Model {
    /// Robot name, from [`ModelSpec::name`].
    pub name: String,
    /// Every link parameter with its nominal value, unit and status, in link order.
    pub registry: Registry,
    /// Joints in chain order; `q[i]` drives `joints[i]` (rad or mm).
    pub joints: Vec<Joint>,
    /// Instrument frame in the world (paper eq. 3); `None`: measurements in the world frame.
    /// With stations, its spec is the cell's instrument and its parameters the first
    /// station's.
    pub instrument: Option<Link>,
    /// The instrument's frame at each station the data name, in station order (frames
    /// `<instrument>@<station>`, `crate::model::station`); empty: one instrument pose.
    pub stations: Vec<Link>,
    /// Base frame, links, tool frame, in chain order.
    pub links: Vec<Link>,
    /// Points or frames attached to the tool, measured by the instrument.
    pub targets: Vec<Link>,
    /// Joint compliance, compiled; its κ follow the link parameters in the registry.
    pub compliance: Option<Compliance>,
    /// Periodic joint errors, compiled; their amplitudes are the registry's last parameters.
    pub periodic: Vec<CompiledPeriodic>,
    /// Payloads the robot may carry ([`ModelSpec::payloads`], checked); a measurement's
    /// payload is an index into them ([`crate::model::Data::payload`]).
    pub payloads: Vec<Payload>,
    pub(crate) instrument_steps: Vec<Step>,
    /// The instrument steps of each station (empty without stations).
    pub(crate) station_steps: Vec<Vec<Step>>,
    pub(crate) chain_steps: Vec<Step>,
    /// `chain_step_end[i]`: number of chain steps after which link `i` is complete.
    pub(crate) chain_step_end: Vec<usize>,
    pub(crate) target_steps: Vec<Vec<Step>>,
}

/// How far past a nominal joint limit a measured joint value may lie and still be read as a
/// measurement (with a warning): a real robot's software limits are not its datasheet's, and
/// datasheets round. Further than this, a value more likely has the wrong unit or column.
#[derive(Clone, Copy, Debug)]
pub struct LimitTolerance {
    /// Revolute joints (rad).
    pub revolute: f64,
    /// Prismatic joints (mm).
    pub prismatic: f64,
}

impl LimitTolerance {
    /// The tolerance of a joint of `kind` (rad or mm).
    pub fn of(&self, kind: JointKind) -> f64 {
        match kind {
            JointKind::Revolute => self.revolute,
            JointKind::Prismatic => self.prismatic,
        }
    }
}

/// 5° and 5 mm ([`LimitTolerance`]).
pub const MEASURED_LIMIT_TOLERANCE: LimitTolerance = LimitTolerance {
    revolute: 5.0 * std::f64::consts::PI / 180.0,
    prismatic: 5.0,
};

impl Model {
    /// Builds a model from its spec. Checks field counts, unique names, conventions that
    /// need or forbid a joint, non-zero ZRP axes and joint limits.
    pub fn from_spec(spec: &ModelSpec) -> Result<Model, Error> {
        Model::compile(spec, &[])
    }

    /// As [`Model::from_spec`], with the instrument's frame repeated once per station
    /// (`stations` non-empty: [`crate::model::station`]).
    pub(crate) fn compile(spec: &ModelSpec, stations: &[String]) -> Result<Model, Error> {
        let mut registry = Registry::new();
        let mut joints = Vec::new();
        let mut names = std::collections::HashSet::new();
        let mut compile = |ls: &LinkSpec,
                           segment: Segment,
                           registry: &mut Registry,
                           joints: &mut Vec<Joint>|
         -> Result<(Link, Vec<Step>), Error> {
            if !names.insert(ls.name.clone()) {
                return Err(Error::Model(format!(
                    "frame name `{}` is used twice",
                    ls.name
                )));
            }
            if ls.name.is_empty() || ls.name.contains('.') || ls.name.contains('*') {
                return Err(Error::Model(format!(
                    "frame name `{}` must be non-empty and contain no `.` or `*`",
                    ls.name
                )));
            }
            let g = &ls.geometry;
            let kind = ls.joint.as_ref().map(|j| j.kind);
            let fields = g.convention.fields(kind);
            if fields.len() != g.values.len() {
                return Err(Error::Model(format!(
                    "link `{}` ({}) needs {} values ({}), got {}",
                    ls.name,
                    g.convention,
                    fields.len(),
                    fields.iter().map(|f| f.0).collect::<Vec<_>>().join(", "),
                    g.values.len()
                )));
            }
            if let Some(v) = g.values.iter().find(|v| !v.is_finite()) {
                return Err(Error::Model(format!(
                    "link `{}` has a non-finite value {v}",
                    ls.name
                )));
            }
            ls.check_values().map_err(Error::Model)?;
            let joint = match &ls.joint {
                Some(j) => {
                    if g.convention.joint_field(j.kind).is_none() {
                        return Err(Error::Model(format!(
                            "link `{}`: convention {} takes no joint",
                            ls.name, g.convention
                        )));
                    }
                    if j.lower.is_nan() || j.upper.is_nan() || j.lower > j.upper {
                        return Err(Error::Model(format!(
                            "joint `{}`: lower limit {} is above upper limit {}",
                            j.name, j.lower, j.upper
                        )));
                    }
                    joints.push(j.clone());
                    Some(joints.len() - 1)
                }
                None => None,
            };
            let first_param = registry.len();
            for ((field, unit), &v) in fields.iter().zip(&g.values) {
                registry.add(format!("{}.{}", ls.name, field), *unit, v, segment)?;
            }
            let joint_field = ls
                .joint
                .as_ref()
                .and_then(|j| g.convention.joint_field(j.kind));
            let mut steps = Vec::new();
            match g.convention.motions(kind) {
                Some(motions) => {
                    let axis = g.axis_vector();
                    if matches!(g.convention, Convention::Urdf)
                        && !axis.iter().all(|x| x.is_finite())
                    {
                        return Err(Error::Model(format!(
                            "link `{}`: joint axis must be a non-zero vector",
                            ls.name
                        )));
                    }
                    for &(motion, field) in motions {
                        steps.push(Step::Elementary {
                            motion,
                            param: first_param + field,
                            joint: if Some(field) == joint_field {
                                joint
                            } else {
                                None
                            },
                            axis,
                        });
                    }
                }
                None => {
                    let u = Vector3::new(g.values[0], g.values[1], g.values[2]);
                    if u.norm() < 1e-9 {
                        return Err(Error::Model(format!(
                            "link `{}`: zero-reference axis u must be non-zero",
                            ls.name
                        )));
                    }
                    steps.push(Step::Screw {
                        first: first_param,
                        joint,
                        prismatic: kind == Some(JointKind::Prismatic),
                    });
                }
            }
            Ok((
                Link {
                    spec: ls.clone(),
                    joint,
                    first_param,
                },
                steps,
            ))
        };

        let mut station_links = Vec::new();
        let mut station_steps = Vec::new();
        let (instrument, instrument_steps) = match &spec.instrument {
            Some(ls) => {
                if ls.joint.is_some() {
                    return Err(Error::Model(
                        "the instrument frame cannot have a joint".into(),
                    ));
                }
                for station in stations {
                    let at = LinkSpec {
                        name: crate::model::station::frame_name(&ls.name, station),
                        ..ls.clone()
                    };
                    let (l, s) = compile(&at, Segment::Instrument, &mut registry, &mut joints)?;
                    station_links.push(l);
                    station_steps.push(s);
                }
                match (station_links.first(), station_steps.first()) {
                    (Some(first), Some(steps)) => {
                        let template = Link {
                            spec: ls.clone(),
                            ..first.clone()
                        };
                        (Some(template), steps.clone())
                    }
                    _ => {
                        let (l, s) = compile(ls, Segment::Instrument, &mut registry, &mut joints)?;
                        (Some(l), s)
                    }
                }
            }
            None if !stations.is_empty() => {
                return Err(Error::Model(format!(
                    "model `{}` has no instrument whose pose stations could set",
                    spec.name
                )))
            }
            None => (None, Vec::new()),
        };
        let mut links = Vec::new();
        let mut chain_steps = Vec::new();
        let mut chain_step_end = Vec::new();
        for ls in &spec.links {
            let (l, s) = compile(ls, Segment::Chain, &mut registry, &mut joints)?;
            chain_steps.extend(s);
            chain_step_end.push(chain_steps.len());
            links.push(l);
        }
        if links.is_empty() {
            return Err(Error::Model(format!("model `{}` has no links", spec.name)));
        }
        let mut targets = Vec::new();
        let mut target_steps = Vec::new();
        for (k, ls) in spec.targets.iter().enumerate() {
            if ls.joint.is_some() {
                return Err(Error::Model(format!(
                    "target `{}` cannot have a joint",
                    ls.name
                )));
            }
            let (l, s) = compile(ls, Segment::Target(k), &mut registry, &mut joints)?;
            targets.push(l);
            target_steps.push(s);
        }
        for (k, p) in spec.payloads.iter().enumerate() {
            p.check().map_err(Error::Model)?;
            if spec.payloads[..k].iter().any(|o| o.name == p.name) {
                return Err(Error::Model(format!("payload `{}` is named twice", p.name)));
            }
        }
        let link_params = registry.len();
        let mut compliance = match &spec.compliance {
            Some(c) => Some(c.compile(&joints, &spec.payloads, link_params, &mut registry)?),
            None => None,
        };
        let periodic = match &spec.periodic {
            Some(p) => p.compile(&joints, &mut registry)?,
            None => Vec::new(),
        };
        if let Some(c) = &mut compliance {
            c.levers.resize(registry.len(), 0.0);
        }
        Ok(Model {
            name: spec.name.clone(),
            registry,
            joints,
            instrument,
            stations: station_links,
            links,
            targets,
            compliance,
            periodic,
            payloads: spec.payloads.clone(),
            instrument_steps,
            station_steps,
            chain_steps,
            chain_step_end,
            target_steps,
        })
    }

    /// The spec of this model with every value taken from `params` (e.g. an estimate).
    pub fn spec_at(&self, params: &[f64]) -> ModelSpec {
        let re = |l: &Link| LinkSpec {
            geometry: l.geometry_at(params),
            ..l.spec.clone()
        };
        ModelSpec {
            name: self.name.clone(),
            instrument: self.instrument.as_ref().map(re),
            links: self.links.iter().map(re).collect(),
            targets: self.targets.iter().map(re).collect(),
            compliance: self.compliance.as_ref().map(|c| ComplianceSpec {
                gravity: c.gravity.into(),
                levers: c.levers[..c.link_params()].to_vec(),
                terms: c
                    .terms
                    .iter()
                    .map(|t| crate::model::compliance::ComplianceTerm {
                        value: params[t.param],
                        ..t.spec.clone()
                    })
                    .collect(),
                bending: Vec::new(),
            }),
            periodic: (!self.periodic.is_empty()).then(|| PeriodicSpec {
                terms: self
                    .periodic
                    .iter()
                    .map(|t| crate::model::periodic::PeriodicTerm {
                        value: params[t.param],
                        ..t.spec.clone()
                    })
                    .collect(),
            }),
            payloads: self.payloads.clone(),
        }
    }

    /// The joint-space correction terms (`crate::model::joint_correction`) in registry
    /// order, each as (registry index, index of the joint it turns): the compliance terms,
    /// then the periodic terms.
    pub fn joint_corrections(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        let compliance = self.compliance.iter().flat_map(|c| &c.terms);
        compliance
            .map(|t| (t.param, t.joint))
            .chain(self.periodic.iter().map(|t| (t.param, t.joint)))
    }

    /// Whether registry parameter `i` is a joint-space correction (a non-geometric term).
    pub fn is_joint_correction(&self, i: usize) -> bool {
        self.joint_corrections().any(|(p, _)| p == i)
    }

    /// The spec with nominal values.
    pub fn spec(&self) -> ModelSpec {
        self.spec_at(&self.registry.nominal())
    }

    /// Number of joint variables (length of `q`).
    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    /// Number of link parameters in the registry (length of a parameter vector).
    pub fn param_count(&self) -> usize {
        self.registry.len()
    }

    /// Nominal parameter vector in registry order (mm, rad).
    pub fn nominal(&self) -> Vec<f64> {
        self.registry.nominal()
    }

    /// Index of a chain link by name.
    pub fn link_index(&self, name: &str) -> Option<usize> {
        self.links.iter().position(|l| l.spec.name == name)
    }

    /// Index of a target by name.
    pub fn target_index(&self, name: &str) -> Option<usize> {
        self.targets.iter().position(|l| l.spec.name == name)
    }

    /// Whether a target measures a full frame (orientation too) or only a point.
    pub fn target_is_frame(&self, k: usize) -> bool {
        self.targets[k].spec.geometry.convention != Convention::Point
    }

    /// Sets the status of every parameter matching `pattern` (see [`Registry::matching`]).
    pub fn set_status(&mut self, pattern: &str, status: ParameterStatus) -> Result<(), Error> {
        for i in self.registry.matching(pattern)? {
            self.registry.set_status(i, status);
        }
        Ok(())
    }

    /// Checks a joint vector's length and limits; the error names the joint and its range.
    pub fn check_joints(&self, q: &[f64]) -> Result<(), Error> {
        self.check_joints_within(q, |_| 1e-9)
    }

    /// As [`Model::check_joints`] for measured joint values, which may lie up to
    /// [`MEASURED_LIMIT_TOLERANCE`] past a limit (a real robot's limits differ from its
    /// nominal ones; the data reader warns about them).
    pub fn check_measured_joints(&self, q: &[f64]) -> Result<(), Error> {
        self.check_joints_within(q, |kind| MEASURED_LIMIT_TOLERANCE.of(kind) + 1e-9)
    }

    fn check_joints_within(&self, q: &[f64], tol: impl Fn(JointKind) -> f64) -> Result<(), Error> {
        if q.len() != self.dof() {
            return Err(Error::Input(format!(
                "model `{}` has {} joints, got {} values",
                self.name,
                self.dof(),
                q.len()
            )));
        }
        for (j, (v, joint)) in q.iter().zip(&self.joints).enumerate() {
            if !v.is_finite() {
                return Err(Error::Input(format!(
                    "joint {} (`{}`) is not finite",
                    j + 1,
                    joint.name
                )));
            }
            let tol = tol(joint.kind);
            if *v < joint.lower - tol || *v > joint.upper + tol {
                let f = joint.kind.unit().display_factor();
                return Err(Error::Input(format!(
                    "joint `{}` = {:.4} {} is outside its limits [{:.4}, {:.4}]",
                    joint.name,
                    v * f,
                    joint.kind.unit().display_name(),
                    joint.lower * f,
                    joint.upper * f
                )));
            }
        }
        Ok(())
    }

    /// The joint furthest past its limits in `q` (finite values, one per joint) and by how
    /// much (rad or mm); `None` if every joint is within its limits.
    pub fn joints_past_limits(&self, q: &[f64]) -> Option<(usize, f64)> {
        q.iter()
            .zip(&self.joints)
            .map(|(v, j)| (j.lower - v).max(v - j.upper))
            .enumerate()
            .filter(|(_, excess)| *excess > 1e-9)
            .max_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// Joint limits as (lower, upper) vectors.
    pub fn joint_limits(&self) -> (Vec<f64>, Vec<f64>) {
        (
            self.joints.iter().map(|j| j.lower).collect(),
            self.joints.iter().map(|j| j.upper).collect(),
        )
    }
}
