//! URDF → armcal: the serial chain from the root link to a tip link (see the [module
//! documentation](super) for the mapping of joints, origins and limits).

use crate::model::chain::{LinkSpec, ModelSpec};
use crate::model::link::{Convention, Joint, JointKind, LinkGeometry};
use crate::Error;
use nalgebra::Vector3;
use std::collections::{HashMap, HashSet};
use std::path::Path;

use super::{unique, CONTINUOUS_RANGE, M_PER_MM};

/// Reads a URDF file and imports the chain from its root to `tip` (default: the single leaf
/// link). Errors name the file.
pub fn read_urdf(path: impl AsRef<Path>, tip: Option<&str>) -> Result<ModelSpec, Error> {
    read_urdf_with_collisions(path, tip).map(|(spec, _)| spec)
}

/// [`read_urdf`], with the `<collision>` shapes of the chain's links, each on the chain frame
/// its URDF link moves with (the root link's on `base`, a joint's child link's on the frame
/// named for that joint).
pub fn read_urdf_with_collisions(
    path: impl AsRef<Path>,
    tip: Option<&str>,
) -> Result<(ModelSpec, Vec<CollisionShape>), Error> {
    super::parse_file(path.as_ref(), "the URDF file", |text| parse(text, tip))
}

/// Parses URDF text and imports the chain from its root to `tip` (default: the single leaf);
/// a text nesting deeper than [`super::depth::MAX_DEPTH`] is refused before parsing.
pub fn from_urdf_str(xml: &str, tip: Option<&str>) -> Result<ModelSpec, Error> {
    parse(xml, tip).map(|(spec, _)| spec)
}

/// [`from_urdf_str`], with the `<collision>` shapes of the chain's links (see
/// [`read_urdf_with_collisions`]).
pub fn from_urdf_str_with_collisions(
    xml: &str,
    tip: Option<&str>,
) -> Result<(ModelSpec, Vec<CollisionShape>), Error> {
    parse(xml, tip)
}

/// The chain of `xml` and its links' collision shapes.
fn parse(xml: &str, tip: Option<&str>) -> Result<(ModelSpec, Vec<CollisionShape>), Error> {
    let robot = parse_robot(xml)?;
    let (spec, frames) = import(&robot, tip)?;
    let shapes = collision_shapes(&robot, &frames)?;
    Ok((spec, shapes))
}

/// The parsed URDF robot of `xml`; a text nesting deeper than [`super::depth::MAX_DEPTH`]
/// is refused before parsing.
pub(super) fn parse_robot(xml: &str) -> Result<urdf_rs::Robot, Error> {
    super::depth::check_depth(xml)?;
    // The XML parser under urdf-rs (RustyXML 0.3) panics on some malformed documents instead
    // of returning an error: an attribute name with an undeclared namespace prefix
    // (`effort="0":velocity="0"`, found by fuzz/urdf) hits an `expect` in its element code.
    // No maintained release fixes it, so the panic is caught here and becomes the error it
    // should have been (tests/suite/hostile/urdf_parser_panic.rs). The default hook would
    // still print the parser's panic message before armcal's error, so a silent hook stands
    // in while it parses (process-wide: a panic of another thread in that window goes
    // unprinted, but still unwinds and fails as it would).
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let parsed = std::panic::catch_unwind(|| urdf_rs::read_from_string(xml));
    std::panic::set_hook(hook);
    let parsed = parsed.map_err(|_| {
        Error::Input(
            "not a valid URDF document: the XML parser gave up on it (a name with an \
             undeclared namespace prefix, or a malformed attribute list); check the file with \
             an XML validator"
                .into(),
        )
    })?;
    parsed.map_err(|e| Error::Input(format!("not a valid URDF document: {e}")))
}

/// A `<collision>` shape of a chain link, in armcal's units.
#[derive(Clone, Debug, PartialEq)]
pub struct CollisionShape {
    /// The chain frame it moves with.
    pub frame: String,
    /// The URDF link it belongs to.
    pub link: String,
    /// Its `<origin>` in the link frame (mm, rad).
    pub origin: crate::model::Pose<f64>,
    /// The shape.
    pub geometry: CollisionGeometry,
}

/// A URDF collision geometry (lengths in mm), centred on its origin; a cylinder's and a
/// capsule's axis is the origin's z axis.
#[derive(Clone, Debug, PartialEq)]
pub enum CollisionGeometry {
    /// Edge lengths along x, y, z.
    Box([f64; 3]),
    /// Radius and length.
    Cylinder(f64, f64),
    /// Radius and the length of its cylindrical part.
    Capsule(f64, f64),
    /// Radius.
    Sphere(f64),
    /// A mesh file: armcal does not read meshes.
    Mesh(String),
}

/// The collision shapes of the chain's URDF links (`frames`: URDF link → chain frame). A
/// dimension that is not a finite length ≥ 0, or an origin that is not finite, is an error
/// naming the link: a negative radius would otherwise become a capsule that shrinks its
/// neighbours' clearance (silent garbage, issue 30).
fn collision_shapes(
    robot: &urdf_rs::Robot,
    frames: &[(String, String)],
) -> Result<Vec<CollisionShape>, Error> {
    use urdf_rs::Geometry as G;
    let mut out = Vec::new();
    for (link, frame) in frames {
        let Some(l) = robot.links.iter().find(|l| l.name == *link) else {
            continue;
        };
        for c in &l.collision {
            let mm = |what: &str, v: f64| {
                if v.is_finite() && v >= 0.0 {
                    Ok(v / M_PER_MM)
                } else {
                    Err(Error::Input(format!(
                        "URDF robot `{}`, link `{link}`: the <collision> {what} is {v} m, not a \
                         length ≥ 0; fix the URDF (lengths in metres)",
                        robot.name
                    )))
                }
            };
            let geometry = match &c.geometry {
                G::Box { size } => CollisionGeometry::Box([
                    mm("box size x", size.0[0])?,
                    mm("box size y", size.0[1])?,
                    mm("box size z", size.0[2])?,
                ]),
                G::Cylinder { radius, length } => CollisionGeometry::Cylinder(
                    mm("cylinder radius", *radius)?,
                    mm("cylinder length", *length)?,
                ),
                G::Capsule { radius, length } => CollisionGeometry::Capsule(
                    mm("capsule radius", *radius)?,
                    mm("capsule length", *length)?,
                ),
                G::Sphere { radius } => CollisionGeometry::Sphere(mm("sphere radius", *radius)?),
                G::Mesh { filename, .. } => CollisionGeometry::Mesh(filename.clone()),
            };
            let (xyz, rpy) = (c.origin.xyz.0, c.origin.rpy.0);
            if xyz.iter().chain(&rpy).any(|v| !v.is_finite()) {
                return Err(Error::Input(format!(
                    "URDF robot `{}`, link `{link}`: the <collision> origin (xyz {xyz:?}, rpy \
                     {rpy:?}) is not finite; fix the URDF",
                    robot.name
                )));
            }
            out.push(CollisionShape {
                frame: frame.clone(),
                link: link.clone(),
                origin: crate::model::Pose::from_xyz_rpy(xyz.map(|v| v / M_PER_MM), rpy),
                geometry,
            });
        }
    }
    Ok(out)
}

/// Imports the serial chain of a parsed URDF robot from its root link to `tip` (default: the
/// single leaf link).
pub fn from_urdf_robot(robot: &urdf_rs::Robot, tip: Option<&str>) -> Result<ModelSpec, Error> {
    import(robot, tip).map(|(spec, _)| spec)
}

/// The chain, and which chain frame each URDF link on it moves with.
fn import(
    robot: &urdf_rs::Robot,
    tip: Option<&str>,
) -> Result<(ModelSpec, Vec<(String, String)>), Error> {
    let err = |m: String| Error::Input(format!("URDF robot `{}`: {m}", robot.name));
    let Structure {
        root,
        links,
        parent_joint,
        has_children,
    } = structure(robot)?;
    let tip = match tip {
        Some(t) => {
            if !links.contains(t) {
                let mut known: Vec<&str> = links.iter().copied().collect();
                known.sort_unstable();
                return Err(err(format!(
                    "unknown tip link `{t}`; links: {}",
                    known.join(", ")
                )));
            }
            t
        }
        None => {
            let leaves: Vec<&str> = robot
                .links
                .iter()
                .map(|l| l.name.as_str())
                .filter(|l| !has_children.contains(l))
                .collect();
            match leaves.as_slice() {
                [l] => *l,
                _ => {
                    return Err(err(format!(
                        "the tree branches into several leaf links ({}); choose the tip link \
                         the chain ends in (`tip`), or load the whole tree (a cell whose \
                         `[[targets]]` name the URDF `link` they hang from)",
                        leaves.join(", ")
                    )))
                }
            }
        }
    };
    // Walk up from the tip to the root.
    let mut path = Vec::new();
    let mut link = tip;
    let mut seen = HashSet::new();
    while let Some(j) = parent_joint.get(link) {
        if !seen.insert(link) {
            return Err(err(format!("the joints above link `{tip}` form a cycle")));
        }
        path.push(*j);
        link = &j.parent.link;
    }
    debug_assert_eq!(link, root);
    path.reverse();

    let mut names: HashSet<String> = ["base".to_string(), "tool".to_string()].into();
    let mut out = vec![identity_frame("base")];
    let mut frames = vec![(root.to_string(), "base".to_string())];
    for j in path {
        if let Some(m) = &j.mimic {
            return Err(err(format!(
                "joint `{}` mimics `{}`: a serial chain has no coupled joints; load the URDF \
                 as a kinematic tree (a cell whose `[[targets]]` name the URDF `link` they \
                 hang from), where a <mimic> joint is a coupled joint",
                j.name, m.joint
            )));
        }
        let name = unique(&sanitise(&j.name), &mut names);
        frames.push((j.child.link.clone(), name.clone()));
        out.push(import_joint(j, name).map_err(|m| err(format!("joint `{}`: {m}", j.name)))?);
    }
    if out.iter().all(|l| l.joint.is_none()) {
        return Err(err(format!(
            "no movable joint between the root link `{root}` and the tip link `{tip}`"
        )));
    }
    out.push(identity_frame("tool"));
    let spec = ModelSpec {
        compliance: None,
        periodic: None,
        payloads: Vec::new(),
        name: robot.name.clone(),
        instrument: None,
        links: out,
        targets: Vec::new(),
    };
    Ok((spec, frames))
}

/// The link graph of a URDF robot, checked: link and joint names unique, every joint's links
/// known, every link the child of at most one joint, one root.
pub(super) struct Structure<'a> {
    /// The one link that is no joint's child.
    pub root: &'a str,
    /// Every link's name.
    pub links: HashSet<&'a str>,
    /// The joint whose child each link is (every link but the root).
    pub parent_joint: HashMap<&'a str, &'a urdf_rs::Joint>,
    /// The links some joint leaves.
    pub has_children: HashSet<&'a str>,
}

/// The checked link graph of `robot`; errors name the robot and the link or joint.
pub(super) fn structure(robot: &urdf_rs::Robot) -> Result<Structure<'_>, Error> {
    let err = |m: String| Error::Input(format!("URDF robot `{}`: {m}", robot.name));
    if robot.links.is_empty() {
        return Err(err("has no links".into()));
    }
    let mut links = HashSet::new();
    for l in &robot.links {
        if !links.insert(l.name.as_str()) {
            return Err(err(format!("link `{}` is defined twice", l.name)));
        }
    }
    let mut joint_names = HashSet::new();
    for j in &robot.joints {
        if !joint_names.insert(j.name.as_str()) {
            return Err(err(format!(
                "two joints are named `{}`: a URDF's joint names are unique (data files and \
                 limits name joints), rename one",
                j.name
            )));
        }
    }
    // parent joint of every child link, and the joints leaving every link
    let mut parent_joint: HashMap<&str, &urdf_rs::Joint> = HashMap::new();
    let mut has_children: HashSet<&str> = HashSet::new();
    for j in &robot.joints {
        for end in [&j.parent.link, &j.child.link] {
            if !links.contains(end.as_str()) {
                return Err(err(format!(
                    "joint `{}` refers to unknown link `{end}`",
                    j.name
                )));
            }
        }
        if let Some(other) = parent_joint.insert(&j.child.link, j) {
            return Err(err(format!(
                "link `{}` is the child of two joints, `{}` and `{}` (a URDF is a tree)",
                j.child.link, other.name, j.name
            )));
        }
        has_children.insert(&j.parent.link);
    }
    let roots: Vec<&str> = robot
        .links
        .iter()
        .map(|l| l.name.as_str())
        .filter(|l| !parent_joint.contains_key(l))
        .collect();
    let root = match roots.as_slice() {
        [r] => *r,
        [] => return Err(err("has no root link: its joints form a cycle".into())),
        _ => {
            return Err(err(format!(
                "has several root links ({}): the links are not connected into one tree",
                roots.join(", ")
            )))
        }
    };
    Ok(Structure {
        root,
        links,
        parent_joint,
        has_children,
    })
}

/// One URDF joint as a link spec (lengths in mm).
pub(super) fn import_joint(j: &urdf_rs::Joint, name: String) -> Result<LinkSpec, String> {
    use urdf_rs::JointType as T;
    let xyz = j.origin.xyz.0.map(|v| v / M_PER_MM);
    let rpy = j.origin.rpy.0;
    if !xyz.iter().chain(&rpy).all(|v| v.is_finite()) {
        return Err(format!("origin xyz {xyz:?} mm / rpy {rpy:?} is not finite"));
    }
    let kind = match j.joint_type {
        T::Fixed => {
            return Ok(LinkSpec {
                name,
                geometry: LinkGeometry::frame6(xyz, rpy),
                joint: None,
            })
        }
        T::Revolute | T::Continuous => JointKind::Revolute,
        T::Prismatic => JointKind::Prismatic,
        ref other => {
            return Err(format!(
                "joint type `{}` is not supported (revolute, continuous, prismatic, fixed)",
                format!("{other:?}").to_lowercase()
            ))
        }
    };
    let axis = Vector3::from(j.axis.xyz.0);
    if !axis.iter().all(|v| v.is_finite()) || axis.norm() < 1e-12 {
        return Err(format!(
            "axis {:?} must be a finite, non-zero vector",
            j.axis.xyz.0
        ));
    }
    let axis = axis.normalize();
    let (lower, upper) = match j.joint_type {
        T::Continuous => (-CONTINUOUS_RANGE, CONTINUOUS_RANGE),
        T::Revolute => {
            let (l, u) = (j.limit.lower, j.limit.upper);
            (
                if l.is_finite() { l } else { -CONTINUOUS_RANGE },
                if u.is_finite() { u } else { CONTINUOUS_RANGE },
            )
        }
        _ => {
            let (l, u) = (j.limit.lower, j.limit.upper);
            if !(l.is_finite() && u.is_finite()) {
                return Err(format!(
                    "a prismatic joint needs finite limits, got [{l}, {u}] m"
                ));
            }
            (l / M_PER_MM, u / M_PER_MM)
        }
    };
    if lower.is_nan() || upper.is_nan() || lower >= upper {
        return Err(format!(
            "empty joint range [{}, {}] {} (is <limit> missing? use a fixed joint for a \
             locked axis)",
            j.limit.lower,
            j.limit.upper,
            if kind == JointKind::Prismatic {
                "m"
            } else {
                "rad"
            }
        ));
    }
    // `<calibration rising="δ"/>`: the joint offset ROS calibration tools write (the joint
    // moves by q + δ, super::calibration); `falling` marks a reference switch and is not read.
    let rising = j.calibration.as_ref().and_then(|c| c.rising).unwrap_or(0.0);
    let offset = match kind {
        JointKind::Revolute => rising,
        JointKind::Prismatic => rising / M_PER_MM,
    };
    if !offset.is_finite() {
        return Err(format!(
            "<calibration rising=\"{rising}\"> is not a finite joint offset; fix the URDF"
        ));
    }
    let mut values = xyz.to_vec();
    values.extend(rpy);
    values.push(offset);
    Ok(LinkSpec {
        name: name.clone(),
        geometry: LinkGeometry {
            convention: Convention::Urdf,
            values,
            axis: Some([axis.x, axis.y, axis.z]),
        },
        joint: Some(Joint {
            name,
            kind,
            lower,
            upper,
        }),
    })
}

pub(super) fn identity_frame(name: &str) -> LinkSpec {
    LinkSpec {
        name: name.into(),
        geometry: LinkGeometry::frame6([0.0; 3], [0.0; 3]),
        joint: None,
    }
}

/// A URDF name as an armcal frame name: `.` and `*` become `_`; empty becomes `joint`.
pub(super) fn sanitise(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| if c == '.' || c == '*' { '_' } else { c })
        .collect();
    if s.is_empty() {
        "joint".into()
    } else {
        s
    }
}
