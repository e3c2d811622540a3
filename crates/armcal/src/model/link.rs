//! Link conventions (book ch. 2, paper eq. 1 and Table 2). Every convention except the
//! zero-reference model is a product of elementary motions, each driven by one named
//! parameter (plus the joint variable for the motion the joint acts on). That single
//! representation gives forward kinematics and exact parameter derivatives for all of them.

use crate::model::registry::Unit;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::fmt;

/// Revolute or prismatic joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum JointKind {
    /// Rotates by the joint variable q (rad) about the joint axis.
    Revolute,
    /// Translates by the joint variable q (mm) along the joint axis.
    Prismatic,
}

impl JointKind {
    /// Unit of the joint variable (rad or mm).
    pub fn unit(self) -> Unit {
        match self {
            JointKind::Revolute => Unit::Rad,
            JointKind::Prismatic => Unit::Mm,
        }
    }
}

/// A joint variable with its limits, in internal units (rad or mm).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Joint {
    /// Joint name, as in the cell file or URDF.
    pub name: String,
    /// Whether q is an angle (rad) or a length (mm).
    pub kind: JointKind,
    /// Lower limit of q (rad or mm).
    pub lower: f64,
    /// Upper limit of q (rad or mm).
    pub upper: f64,
}

/// The link parameterisations armcal knows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Convention {
    /// Standard Denavit–Hartenberg `Rz(θ+q) Tz(d) Tx(a) Rx(α)` (book eq. 2.20, paper eq. 1,
    /// book Type 1 = `Harden`). Prismatic: `Tz(d+q)`.
    Dh,
    /// Hayati / modified DH for near-parallel axes `Rz(θ+q) Tx(a) Rx(α) Ry(β)` (book §2.6,
    /// Type 2 = `Modden`, paper Table 2 joint 2). Prismatic: `Rz(θ) Tz(d+q) Tx(a) Rx(α) Ry(β)`.
    Hayati,
    /// Craig's modified DH `Rx(α) Tx(a) Rz(θ+q) Tz(d)`.
    Mdh,
    /// Craig's modified DH with Hayati's β for a link whose axis is (nearly) parallel to the
    /// previous one: `Rx(α) Tx(a) Ry(β) Rz(θ+q) Tz(d)` (book §2.6). `Rx(α)` and `Ry(β)` tilt
    /// the axis about two perpendicular directions, so a small tilt of a parallel axis never
    /// moves a common normal far away; the previous link's `d` and this link's `d` then move
    /// the same frame along the common direction, and the identifiability analysis keeps one.
    /// `β = 0` is exactly [`Convention::Mdh`]. In cell files: `convention = "mdh"` with
    /// `beta_deg`.
    MdhBeta,
    /// Stone's S-model `Rz(β+q) Tz(r) Tx(l) Rx(α) Rz(γ) Tz(b)` (book eq. 4.304 with the
    /// `Tz(b)` the OCR lost, errata 8). Prismatic: `Tz(r+q)`.
    SModel,
    /// General frame `T(x,y,z) Rz(rz) Ry(ry) Rx(rx)` (URDF origin order); no joint.
    Frame6,
    /// The book's Type 3 transform `Rz(θz+q) Ry(θy) Rx(θx) T(dx,dy,dz)` (book eq. 6.4,
    /// `Trans`); the joint adds to θz (prismatic: to dz).
    BookType3,
    /// URDF joint: origin `T(x,y,z) Rz(yaw) Ry(pitch) Rx(roll)`, then a rotation about (or
    /// translation along) the fixed unit `axis` by `q + offset`.
    Urdf,
    /// Zero-reference-position model / product of exponentials (book §2.8.2, Tables 2.1 and
    /// 6.2): joint axis direction `u` and a point `p` on it, in the world frame at q = 0;
    /// the link transform is `T(p) Rot(u/|u|, q+offset) T(−p)` (prismatic: `T(u (q+offset))`).
    Zrp,
    /// A target point `T(x,y,z)` (reflector, SMR, tooling ball); no joint.
    Point,
}

/// One elementary motion of a link.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Motion {
    /// Rotation about the current x axis by the parameter (rad).
    Rx,
    /// Rotation about the current y axis by the parameter (rad).
    Ry,
    /// Rotation about the current z axis by the parameter (rad).
    Rz,
    /// Translation along the current x axis by the parameter (mm).
    Tx,
    /// Translation along the current y axis by the parameter (mm).
    Ty,
    /// Translation along the current z axis by the parameter (mm).
    Tz,
    /// Rotation about the link's fixed unit axis (URDF).
    RotAxis,
    /// Translation along the link's fixed unit axis (URDF).
    TransAxis,
}

impl Convention {
    /// Every convention, in declaration order (lists valid names in cell-file errors).
    pub const ALL: [Convention; 10] = [
        Convention::Dh,
        Convention::Hayati,
        Convention::Mdh,
        Convention::MdhBeta,
        Convention::SModel,
        Convention::Frame6,
        Convention::BookType3,
        Convention::Urdf,
        Convention::Zrp,
        Convention::Point,
    ];

    /// Snake-case name used in cell files and serialised models (`"dh"`, `"mdh_beta"`, …).
    pub fn name(self) -> &'static str {
        match self {
            Convention::Dh => "dh",
            Convention::Hayati => "hayati",
            Convention::Mdh => "mdh",
            Convention::MdhBeta => "mdh_beta",
            Convention::SModel => "s_model",
            Convention::Frame6 => "frame6",
            Convention::BookType3 => "book_type3",
            Convention::Urdf => "urdf",
            Convention::Zrp => "zrp",
            Convention::Point => "point",
        }
    }

    /// Inverse of [`Convention::name`]; `None` for an unknown name.
    pub fn from_name(s: &str) -> Option<Convention> {
        Convention::ALL.iter().copied().find(|c| c.name() == s)
    }

    /// Field names and units of the link's parameters, in storage order.
    pub fn fields(self, joint: Option<JointKind>) -> &'static [(&'static str, Unit)] {
        use Unit::*;
        let prismatic = joint == Some(JointKind::Prismatic);
        match self {
            Convention::Dh => &[("theta", Rad), ("d", Mm), ("a", Mm), ("alpha", Rad)],
            Convention::Hayati if prismatic => &[
                ("theta", Rad),
                ("d", Mm),
                ("a", Mm),
                ("alpha", Rad),
                ("beta", Rad),
            ],
            Convention::Hayati => &[("theta", Rad), ("a", Mm), ("alpha", Rad), ("beta", Rad)],
            Convention::Mdh => &[("alpha", Rad), ("a", Mm), ("theta", Rad), ("d", Mm)],
            Convention::MdhBeta => &[
                ("alpha", Rad),
                ("a", Mm),
                ("beta", Rad),
                ("theta", Rad),
                ("d", Mm),
            ],
            Convention::SModel => &[
                ("beta", Rad),
                ("r", Mm),
                ("l", Mm),
                ("alpha", Rad),
                ("gamma", Rad),
                ("b", Mm),
            ],
            Convention::Frame6 => &[
                ("x", Mm),
                ("y", Mm),
                ("z", Mm),
                ("rx", Rad),
                ("ry", Rad),
                ("rz", Rad),
            ],
            Convention::BookType3 => &[
                ("dx", Mm),
                ("dy", Mm),
                ("dz", Mm),
                ("tx", Rad),
                ("ty", Rad),
                ("tz", Rad),
            ],
            Convention::Urdf if prismatic => &[
                ("x", Mm),
                ("y", Mm),
                ("z", Mm),
                ("roll", Rad),
                ("pitch", Rad),
                ("yaw", Rad),
                ("offset", Mm),
            ],
            Convention::Urdf => &[
                ("x", Mm),
                ("y", Mm),
                ("z", Mm),
                ("roll", Rad),
                ("pitch", Rad),
                ("yaw", Rad),
                ("offset", Rad),
            ],
            Convention::Zrp if prismatic => &[
                ("ux", Unitless),
                ("uy", Unitless),
                ("uz", Unitless),
                ("px", Mm),
                ("py", Mm),
                ("pz", Mm),
                ("offset", Mm),
            ],
            Convention::Zrp => &[
                ("ux", Unitless),
                ("uy", Unitless),
                ("uz", Unitless),
                ("px", Mm),
                ("py", Mm),
                ("pz", Mm),
                ("offset", Rad),
            ],
            Convention::Point => &[("x", Mm), ("y", Mm), ("z", Mm)],
        }
    }

    /// The elementary motions as (motion, field index), in the order they are multiplied.
    /// `None` for the zero-reference model, which is a screw motion.
    pub fn motions(self, joint: Option<JointKind>) -> Option<&'static [(Motion, usize)]> {
        use Motion::*;
        let prismatic = joint == Some(JointKind::Prismatic);
        Some(match self {
            Convention::Dh => &[(Rz, 0), (Tz, 1), (Tx, 2), (Rx, 3)],
            Convention::Hayati if prismatic => &[(Rz, 0), (Tz, 1), (Tx, 2), (Rx, 3), (Ry, 4)],
            Convention::Hayati => &[(Rz, 0), (Tx, 1), (Rx, 2), (Ry, 3)],
            Convention::Mdh => &[(Rx, 0), (Tx, 1), (Rz, 2), (Tz, 3)],
            Convention::MdhBeta => &[(Rx, 0), (Tx, 1), (Ry, 2), (Rz, 3), (Tz, 4)],
            Convention::SModel => &[(Rz, 0), (Tz, 1), (Tx, 2), (Rx, 3), (Rz, 4), (Tz, 5)],
            Convention::Frame6 => &[(Tx, 0), (Ty, 1), (Tz, 2), (Rz, 5), (Ry, 4), (Rx, 3)],
            Convention::BookType3 => &[(Rz, 5), (Ry, 4), (Rx, 3), (Tx, 0), (Ty, 1), (Tz, 2)],
            Convention::Urdf if prismatic => &[
                (Tx, 0),
                (Ty, 1),
                (Tz, 2),
                (Rz, 5),
                (Ry, 4),
                (Rx, 3),
                (TransAxis, 6),
            ],
            Convention::Urdf => &[
                (Tx, 0),
                (Ty, 1),
                (Tz, 2),
                (Rz, 5),
                (Ry, 4),
                (Rx, 3),
                (RotAxis, 6),
            ],
            Convention::Point => &[(Tx, 0), (Ty, 1), (Tz, 2)],
            Convention::Zrp => return None,
        })
    }

    /// Index of the field the joint variable is added to (the joint offset), or `None` if
    /// the convention takes no joint.
    pub fn joint_field(self, kind: JointKind) -> Option<usize> {
        let prismatic = kind == JointKind::Prismatic;
        match self {
            Convention::Dh => Some(if prismatic { 1 } else { 0 }),
            Convention::Hayati => Some(if prismatic { 1 } else { 0 }),
            Convention::Mdh => Some(if prismatic { 3 } else { 2 }),
            Convention::MdhBeta => Some(if prismatic { 4 } else { 3 }),
            Convention::SModel => Some(if prismatic { 1 } else { 0 }),
            Convention::BookType3 => Some(if prismatic { 2 } else { 5 }),
            Convention::Urdf | Convention::Zrp => Some(6),
            Convention::Frame6 | Convention::Point => None,
        }
    }
}

impl fmt::Display for Convention {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A link's geometry: a convention and its parameter values in internal units (mm, rad).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LinkGeometry {
    /// How `values` parameterise the link transform.
    pub convention: Convention,
    /// Parameter values (mm, rad, or unitless axis components), in the order of
    /// [`Convention::fields`].
    pub values: Vec<f64>,
    /// The fixed joint axis of a URDF link (unit vector in the link's origin frame).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<[f64; 3]>,
}

impl LinkGeometry {
    /// Standard DH `Rz(θ+q) Tz(d) Tx(a) Rx(α)`; mm and rad.
    pub fn dh(theta: f64, d: f64, a: f64, alpha: f64) -> Self {
        Self::new(Convention::Dh, vec![theta, d, a, alpha])
    }

    /// Hayati `Rz(θ+q) Tx(a) Rx(α) Ry(β)` for a revolute joint; mm and rad.
    pub fn hayati(theta: f64, a: f64, alpha: f64, beta: f64) -> Self {
        Self::new(Convention::Hayati, vec![theta, a, alpha, beta])
    }

    /// Craig's modified DH `Rx(α) Tx(a) Rz(θ+q) Tz(d)`; mm and rad.
    pub fn mdh(alpha: f64, a: f64, theta: f64, d: f64) -> Self {
        Self::new(Convention::Mdh, vec![alpha, a, theta, d])
    }

    /// Modified DH with β `Rx(α) Tx(a) Ry(β) Rz(θ+q) Tz(d)`; mm and rad.
    pub fn mdh_beta(alpha: f64, a: f64, beta: f64, theta: f64, d: f64) -> Self {
        Self::new(Convention::MdhBeta, vec![alpha, a, beta, theta, d])
    }

    /// General frame from a pose (x, y, z in mm; roll, pitch, yaw in rad about x, y, z).
    pub fn frame6(xyz: [f64; 3], rpy: [f64; 3]) -> Self {
        Self::new(
            Convention::Frame6,
            vec![xyz[0], xyz[1], xyz[2], rpy[0], rpy[1], rpy[2]],
        )
    }

    /// Zero-reference joint: axis `u`, point `p` (mm), joint offset (rad or mm).
    pub fn zrp(u: [f64; 3], p: [f64; 3], offset: f64) -> Self {
        Self::new(
            Convention::Zrp,
            vec![u[0], u[1], u[2], p[0], p[1], p[2], offset],
        )
    }

    /// Target point (mm).
    pub fn point(xyz: [f64; 3]) -> Self {
        Self::new(Convention::Point, xyz.to_vec())
    }

    /// Geometry from raw values in [`Convention::fields`] order (mm, rad); no URDF axis.
    pub fn new(convention: Convention, values: Vec<f64>) -> Self {
        LinkGeometry {
            convention,
            values,
            axis: None,
        }
    }

    /// Value of a named field, if the convention has it.
    pub fn get(&self, field: &str, joint: Option<JointKind>) -> Option<f64> {
        self.convention
            .fields(joint)
            .iter()
            .position(|(f, _)| *f == field)
            .map(|i| self.values[i])
    }

    /// Unit axis of a URDF link as a vector.
    pub fn axis_vector(&self) -> Vector3<f64> {
        let a = self.axis.unwrap_or([0.0, 0.0, 1.0]);
        Vector3::from(a).normalize()
    }
}
