//! The per-configuration constraint set of a cell for measurement-pose design (paper
//! eq. 24b), every constraint written as `g(q) ≥ 0`, with its value and its exact gradient
//! w.r.t. the joints (through the world joint twists of
//! [`forward_kinematics`]; no finite differences).
//!
//! A joint twist `(ω_j, v_j)` moves a world point `x` on a link it drives with velocity
//! `ẋ = ω_j × x + v_j`; joint `j` drives the chain frames from its own link onwards and the
//! targets. The constraints:
//!
//! | kind | value `g(q)` | source |
//! |---|---|---|
//! | incidence | `cos β − cos β_max` | paper eq. 4, Table 4 (β_max = 30°) |
//! | self collision | `d_P(bᵢ, bⱼ) − rᵢ − rⱼ` | eq. 20–21 |
//! | obstacle | `d_P(bᵢ, o) − rᵢ − r_o` | eq. 20, §3.2 (car body) |
//! | box obstacle | `φ_B(bᵢ) − rᵢ` | signed segment–box distance ([`segment_box_distance`]) |
//! | half-space | `n · x − rᵢ − offset` at both capsule endpoints | §3.2 (wall `x − r ≥ −450`, floor `z − r ≥ 0`) |
//! | line of sight | `d_P(beam, b) − r_beam − r_b` (`φ_B(beam) − r_beam` for a box) | §3.2, Table 5 |
//!
//! **Incidence.** β is the angle between the reflector's z axis `z` and the unit beam
//! `g = (t − p)/|t − p|` from the reflector position `p` to the tracker origin `t` (the
//! instrument frame's origin): `cos β = zᵀg`. The paper takes `z` as the flange (TCP) z axis
//! with the reflector on the flange. Here `p` is the reflector target (the first target of the
//! model unless [`ConstraintSettings::reflector`] names another; the tool-frame origin if the
//! model has no target) and `z` is that target's world z axis. A reflector given as a point
//! (`Convention::Point`) carries the tool frame's orientation, so `z` is the tool/flange z
//! axis as in the paper; a target given as a full frame uses its own z axis. Gradient:
//! `∂cos β/∂q_j = (ω_j × z)·g − (z − (zᵀg) g)·ṗ_j / |t − p|` with `ṗ_j = ω_j × p + v_j`.
//!
//! **Capsule distances.** With `(s, t)` the closest-point parameters and `n` the unit vector
//! from the second segment's closest point `Q` to the first's `P`, the derivative of the
//! segment distance is `n · (Ṗ − Q̇)` (see
//! [`segment_distance`](crate::geometry::segment_distance())); for two robot capsules only
//! the joints between their frames contribute (a common joint moves both rigidly and
//! `n · (ω × (P − Q)) = 0`). A box stands still: the derivative of the signed segment–box
//! distance is `n · Ṗ`, with `P` the segment's closest (or deepest) point and `n` the box's
//! outward normal there ([`segment_box_distance`](crate::geometry::segment_box_distance())).
//!
//! **Which robot pairs are checked (the set 𝓘 of eq. 24b).** The robot's bodies are its
//! capsule-carrying chain frames (`base, j1, …, jn, tool`, in chain order), each body being
//! all capsules on one frame. Two robot capsules are compared unless
//! - they are on the same frame;
//! - their frames are neighbouring bodies (no other capsule-carrying frame between them) —
//!   "two neighboring segments do not have to be compared as the limitation of joint movement
//!   automatically prevents their collision" (paper §2.2; with one capsule per body this is
//!   exactly the count of eq. 22, `n(n − 1)/2 − (n − 1)`);
//! - no joint separates them (their distance would not depend on q);
//! - they overlap at every one of 256 spread configurations (nominal parameters): bodies in
//!   contact by construction, like neighbours (a short elbow link whose capsule is shorter
//!   than the two radii: the IRB 120's upper arm and forearm, the PUMA's shoulder and base).
//!   No design could satisfy such a pair; it is listed in [`ConstraintSet::pairs_in_contact`]
//!   and printed by `plan`, so a user can shorten a capsule to have it checked.
//!
//! "Link indices differ by ≥ 2" is the same rule when every link carries capsules. It is not
//! when a frame carries none: in the paper robot the wrist capsule (on `j5`, wrist centre to
//! flange) and the reflector holder (on `tool`, from the flange) touch at the flange for every
//! q although their link indices differ by 2 (the flange frame `j6` carries no capsule); the
//! KUKA models' forearm (`j4`) and wrist (`j6`) likewise meet at the wrist centre.
//!
//! **Fixed capsules.** Robot capsules on frames before the first joint (the pedestal on
//! `base`) do not move: they are checked against the moving robot capsules and against the
//! beam, but not against obstacles and half-spaces (the value would not depend on q).
//!
//! **Obstacles in contact by construction.** A robot capsule's obstacle or half-space
//! constraint whose value is the same negative number at every one of the 256 spread
//! configurations is left out like a pair in contact, and listed with them: a capsule that
//! starts at the base origin on the floor (a skeleton-derived first link,
//! [`crate::robots::skeleton`]) dips into the floor by its radius whatever the joints do; no
//! design could change that. A constraint negative everywhere but not constant (an arm that
//! always hits a table) stays, and makes the design infeasible.
//!
//! **Line of sight.** The beam from the reflector to the tracker origin is a capsule of radius
//! [`ConstraintSettings::beam_radius`]. It is checked against every robot capsule and every
//! obstacle capsule, except the robot capsules that carry the reflector: a capsule whose
//! frame has at most one joint between it and the reflector is left out when the reflector
//! point lies within its radius plus the beam radius and line-of-sight margin (for a frame
//! with one joint in between, at any of 16 values of that joint, nominal parameters). In the paper cell
//! that removes the reflector holder on `tool`; the wrist capsule on `j5` keeps its
//! constraint because the reflector sits 339 mm beyond it.
//!
//! Constraints that need the tracker (incidence, line of sight) are left out when the model
//! has no instrument frame, or when the cell does not place it (no `[instrument] xyz_mm`:
//! its frame stands at the world origin, inside the robot's base, until a fit places it, and
//! every beam from there would be called blocked by the arm; [`unplaced_instrument`] says
//! so); incidence also needs `instrument.max_incidence` in the cell.
//!
//! **Clearance and margins** (the cell's `[design]`, [`DesignClearance`]; `required.rs`). A
//! set requires `g(q) ≥` [`ConstraintSettings::clearance`] of every robot and obstacle
//! distance, `≥` [`ConstraintSettings::line_of_sight_margin`] of the beam, `β ≤ β_max −`
//! [`ConstraintSettings::incidence_margin`], and keeps every revolute joint
//! [`ConstraintSettings::joint_margin`] inside its limits; [`ConstraintSet::evaluate`]
//! still returns the distances themselves, [`ConstraintSet::required`] the least value each
//! must keep. A distance that no configuration changes and that lies below the clearance (a
//! base column standing on the floor: 0 mm for every q) is exempt — no design can widen it,
//! and the cell says it is allowed; "no configuration changes" is checked at 256 spread
//! configurations.
//!
//! (Over 600 lines, about 180 of them this documentation: one concept, the set's assembly;
//! its evaluation is already in `evaluate.rs`.)
//!
//! This file assembles the set from a cell ([`ConstraintSet::new`]); `evaluate.rs` computes
//! values and gradients at a configuration; `measurable.rs` lists what makes a pose
//! unmeasurable; `tracker_shift.rs` what does when the instrument stands up to `D` mm off.

use crate::cell::{box_cuboid, half_space_unit_normal, Cell, DesignClearance, Obstacle};
use crate::geometry::{point_segment_distance, segment_box_distance, segment_distance, Cuboid};
use crate::model::fixed_kinematics::FixedKinematics;
use crate::model::pose::Twist;
use crate::model::{forward_kinematics, Data, Model};
use crate::Error;
use nalgebra::Vector3;

/// What a constraint guards against.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ConstraintKind {
    /// Reflector incidence angle (paper eq. 4).
    Incidence,
    /// Two robot capsules (eq. 20).
    SelfCollision,
    /// A robot capsule and an obstacle (capsule or box).
    Obstacle,
    /// A robot capsule endpoint and a half-space (wall, floor).
    HalfSpace,
    /// The laser beam and a robot capsule or an obstacle.
    LineOfSight,
}

/// Which constraints a [`ConstraintSet`] contains.
#[derive(Clone, Debug, PartialEq)]
pub struct ConstraintSettings {
    /// The incidence limit (paper eq. 4), if the cell has one.
    pub incidence: bool,
    /// Self collision, robot vs obstacle capsules, robot vs half-spaces.
    pub collisions: bool,
    /// The beam from the reflector to the tracker clear of robot and obstacle capsules (the
    /// paper counts these among its collision constraints).
    pub line_of_sight: bool,
    /// Radius of the beam capsule (mm).
    pub beam_radius: f64,
    /// Name of the reflector target; `None`: the model's first target (the tool origin if
    /// there is none).
    pub reflector: Option<String>,
    /// Least value (mm) every q-dependent distance constraint must keep (0: touching is
    /// allowed, as in paper eq. 24b).
    pub clearance: f64,
    /// Distance (rad) every revolute joint keeps from its limits (0: the limits themselves).
    pub joint_margin: f64,
    /// Angle (rad) the incidence keeps below the cell's limit, `β ≤ β_max − m` (0: eq. 4).
    pub incidence_margin: f64,
    /// Least value (mm) of every q-dependent line-of-sight constraint (0: may touch).
    pub line_of_sight_margin: f64,
}

impl ConstraintSettings {
    /// These settings with the cell's `[design]` clearance, joint, incidence and
    /// line-of-sight margins.
    pub fn with_clearance(self, design: &DesignClearance) -> Self {
        ConstraintSettings {
            clearance: design.clearance,
            joint_margin: design.joint_margin,
            incidence_margin: design.incidence_margin,
            line_of_sight_margin: design.line_of_sight_margin,
            ..self
        }
    }
}

impl Default for ConstraintSettings {
    fn default() -> Self {
        ConstraintSettings {
            incidence: true,
            collisions: true,
            line_of_sight: true,
            beam_radius: 5.0,
            reflector: None,
            clearance: 0.0,
            joint_margin: 0.0,
            incidence_margin: 0.0,
            line_of_sight_margin: 0.0,
        }
    }
}

/// A robot capsule of a cell compiled against its model.
#[derive(Clone, Debug)]
pub struct RobotCapsule {
    /// The chain frame (link index) it moves with.
    pub link: usize,
    /// Joints `0..joints` move it.
    pub joints: usize,
    /// Endpoints in the frame of `link` (mm).
    pub a: Vector3<f64>,
    /// Second endpoint, in the same frame (mm).
    pub b: Vector3<f64>,
    /// Radius (mm).
    pub radius: f64,
    /// `frame#k`: the k-th capsule on that frame, as the constraint names call it.
    pub label: String,
}

impl RobotCapsule {
    /// World endpoints `T_f(q) a`, `T_f(q) b` at the configuration placed in `data` by
    /// [`forward_kinematics`].
    #[inline]
    pub fn place(&self, data: &Data<f64>) -> [Vector3<f64>; 2] {
        let f = &data.frames[self.link];
        [f.transform_point(&self.a), f.transform_point(&self.b)]
    }
}

/// The robot capsules of `cell`, in the cell's order, compiled against its model; an error
/// names a capsule on a frame the model does not have.
pub fn robot_capsules(cell: &Cell) -> Result<Vec<RobotCapsule>, Error> {
    let model = &cell.model;
    // joints_through[L]: number of joints in links 0..=L (joints are numbered in chain
    // order), i.e. the joints that move frame L are 0..joints_through[L].
    let mut joints_through = Vec::with_capacity(model.links.len());
    let mut count = 0;
    for l in &model.links {
        if l.joint.is_some() {
            count += 1;
        }
        joints_through.push(count);
    }
    let mut per_frame = std::collections::HashMap::<&str, usize>::new();
    let mut capsules = Vec::with_capacity(cell.capsules.len());
    for c in &cell.capsules {
        let link = model.link_index(&c.frame).ok_or_else(|| {
            Error::Model(format!(
                "capsule on frame `{}`: the model has no such chain frame",
                c.frame
            ))
        })?;
        let k = per_frame.entry(c.frame.as_str()).or_insert(0);
        capsules.push(RobotCapsule {
            link,
            joints: joints_through[link],
            a: Vector3::from(c.a),
            b: Vector3::from(c.b),
            radius: c.radius,
            label: format!("{}#{}", c.frame, k),
        });
        *k += 1;
    }
    Ok(capsules)
}

#[derive(Clone, Debug)]
struct WorldCapsule {
    a: Vector3<f64>,
    b: Vector3<f64>,
    radius: f64,
}

#[derive(Clone, Debug)]
struct HalfSpace {
    normal: Vector3<f64>,
    offset: f64,
}

#[derive(Clone, Copy, Debug)]
enum Item {
    Incidence,
    Pair { i: usize, j: usize },
    Obstacle { i: usize, o: usize },
    Box { i: usize, b: usize },
    HalfSpace { i: usize, end: usize, h: usize },
    BeamRobot { i: usize },
    BeamObstacle { o: usize },
    BeamBox { b: usize },
}

impl Item {
    fn kind(self) -> ConstraintKind {
        match self {
            Item::Incidence => ConstraintKind::Incidence,
            Item::Pair { .. } => ConstraintKind::SelfCollision,
            Item::Obstacle { .. } | Item::Box { .. } => ConstraintKind::Obstacle,
            Item::HalfSpace { .. } => ConstraintKind::HalfSpace,
            Item::BeamRobot { .. } | Item::BeamObstacle { .. } | Item::BeamBox { .. } => {
                ConstraintKind::LineOfSight
            }
        }
    }
}

/// Where the reflector is.
#[derive(Clone, Copy, Debug)]
enum Reflector {
    Target(usize),
    Tool,
}

/// The smallest constraint value of a configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Margin<'a> {
    /// Index of the constraint in the set.
    pub index: usize,
    /// Its value `g(q)`: mm for distances, `cos β − cos β_max` for the incidence; negative when
    /// violated.
    pub value: f64,
    /// Its name (see [`ConstraintSet::names`]).
    pub name: &'a str,
    /// What it guards against.
    pub kind: ConstraintKind,
}

/// The constraints of one measurement configuration of a cell (paper eq. 24b without the
/// joint bounds, which [`ConstraintSet::feasible`] adds).
#[derive(Clone, Debug)]
pub struct ConstraintSet {
    model: Model,
    capsules: Vec<RobotCapsule>,
    obstacles: Vec<WorldCapsule>,
    boxes: Vec<Cuboid>,
    half_spaces: Vec<HalfSpace>,
    items: Vec<Item>,
    names: Vec<String>,
    reflector: Reflector,
    cos_max: f64,
    beam_radius: f64,
    /// Joint bounds: the limits, revolute joints shrunk by the joint margin.
    lower: Vec<f64>,
    upper: Vec<f64>,
    /// Least value of each constraint (the clearance for q-dependent distances, else 0).
    required: Vec<f64>,
    /// Constraints whose value is the same at 16 spread configurations (`evaluate.rs`,
    /// `constraint_ranges`).
    constant: Vec<bool>,
    /// How far a configuration may sit inside the joint margin and still count as within
    /// the bounds ([`JOINT_MARGIN_TOLERANCE`] with a margin, 0 without).
    joint_tolerance: f64,
    /// Robot capsule pairs left out because they overlap everywhere (`evaluate.rs`).
    pairs_in_contact: Vec<String>,
    /// Robot capsules that move with a joint, if collisions are checked.
    arm_capsules: usize,
    /// The cell robot's [`crate::robots::Robot::collision`].
    collision_model: String,
}

/// Reusable buffers for [`ConstraintSet::evaluate`], of the set that made them
/// ([`ConstraintSet::workspace`]): they remember the configuration last placed.
#[derive(Clone, Debug)]
pub struct ConstraintWorkspace {
    data: Data<f64>,
    /// The model's chain compiled at the parameters of the last evaluation.
    fixed: FixedKinematics,
    /// World endpoints of every robot capsule.
    ends: Vec<[Vector3<f64>; 2]>,
    /// The parameters, then the configuration, that `data` and `ends` hold (empty: none).
    placed: Vec<f64>,
    /// Constraint values of the last [`ConstraintSet::feasible`] / `min_margin_at` call.
    pub values: Vec<f64>,
}

impl ConstraintSet {
    /// Compiles the constraints of `cell` (see the module documentation for what is
    /// included).
    pub fn new(cell: &Cell, options: &ConstraintSettings) -> Result<ConstraintSet, Error> {
        if !(options.beam_radius.is_finite() && options.beam_radius >= 0.0) {
            return Err(Error::Input(format!(
                "beam radius must be a finite length ≥ 0 mm, got {}",
                options.beam_radius
            )));
        }
        for (what, v) in [
            ("clearance", options.clearance),
            ("joint margin", options.joint_margin),
            ("incidence margin", options.incidence_margin),
            ("line-of-sight margin", options.line_of_sight_margin),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::Input(format!(
                    "the {what} must be finite and ≥ 0, got {v}"
                )));
            }
        }
        let model = cell.model.clone();
        let dof = model.dof();
        let capsules = robot_capsules(cell)?;
        if let Some(c) = cell
            .capsules
            .iter()
            .find(|c| !(c.radius.is_finite() && c.radius >= 0.0))
        {
            return Err(Error::Model(format!(
                "capsule on frame `{}` has radius {}",
                c.frame, c.radius
            )));
        }
        let mut obstacles = Vec::new();
        let mut obstacle_names = Vec::new();
        let mut boxes = Vec::new();
        let mut box_names = Vec::new();
        let mut half_spaces = Vec::new();
        let mut half_space_names = Vec::new();
        for o in &cell.obstacles {
            match o {
                Obstacle::Capsule { name, a, b, radius } => {
                    obstacles.push(WorldCapsule {
                        a: Vector3::from(*a),
                        b: Vector3::from(*b),
                        radius: *radius,
                    });
                    obstacle_names.push(name.clone());
                }
                Obstacle::Box {
                    name,
                    center,
                    size,
                    rpy,
                } => {
                    boxes.push(box_cuboid(center, size, rpy));
                    box_names.push(name.clone());
                }
                Obstacle::HalfSpace {
                    name,
                    normal,
                    offset,
                } => {
                    half_spaces.push(HalfSpace {
                        normal: half_space_unit_normal(name, normal)?,
                        offset: *offset,
                    });
                    half_space_names.push(name.clone());
                }
            }
        }

        let reflector =
            match &options.reflector {
                Some(name) => Reflector::Target(model.target_index(name).ok_or_else(|| {
                    Error::Input(format!("the cell has no target named `{name}`"))
                })?),
                None if !model.targets.is_empty() => Reflector::Target(0),
                None => Reflector::Tool,
            };
        let has_tracker = model.instrument.is_some() && unplaced_instrument(cell).is_none();
        let max_incidence = cell.instrument.as_ref().and_then(|i| i.max_incidence);

        let mut items = Vec::new();
        let mut names = Vec::new();
        if options.incidence && has_tracker && max_incidence.is_some() {
            items.push(Item::Incidence);
            names.push("incidence".to_string());
        }
        if options.collisions {
            // Capsule-carrying frames in chain order: body rank of every capsule.
            let mut bodies: Vec<usize> = capsules.iter().map(|c| c.link).collect();
            bodies.sort_unstable();
            bodies.dedup();
            let rank = |c: &RobotCapsule| bodies.binary_search(&c.link).unwrap_or(0);
            for i in 0..capsules.len() {
                for j in i + 1..capsules.len() {
                    let (ci, cj) = (&capsules[i], &capsules[j]);
                    if rank(ci).abs_diff(rank(cj)) >= 2 && ci.joints != cj.joints {
                        items.push(Item::Pair { i, j });
                        names.push(format!("capsule {} / {}", ci.label, cj.label));
                    }
                }
            }
            for (i, c) in capsules.iter().enumerate() {
                if c.joints == 0 {
                    continue;
                }
                for (o, name) in obstacle_names.iter().enumerate() {
                    items.push(Item::Obstacle { i, o });
                    names.push(format!("{} / {name}", c.label));
                }
                for (b, name) in box_names.iter().enumerate() {
                    items.push(Item::Box { i, b });
                    names.push(format!("{} / {name}", c.label));
                }
            }
            for (i, c) in capsules.iter().enumerate() {
                if c.joints == 0 {
                    continue;
                }
                for (h, name) in half_space_names.iter().enumerate() {
                    for (end, tag) in ["a", "b"].iter().enumerate() {
                        items.push(Item::HalfSpace { i, end, h });
                        names.push(format!("{}.{tag} / {name}", c.label));
                    }
                }
            }
        }
        if options.line_of_sight && has_tracker {
            let reach = options.beam_radius + options.line_of_sight_margin;
            let carriers = reflector_carriers(&model, &capsules, reflector, reach);
            for (i, c) in capsules.iter().enumerate() {
                if !carriers[i] {
                    items.push(Item::BeamRobot { i });
                    names.push(format!("beam / {}", c.label));
                }
            }
            for (o, name) in obstacle_names.iter().enumerate() {
                items.push(Item::BeamObstacle { o });
                names.push(format!("beam / {name}"));
            }
            for (b, name) in box_names.iter().enumerate() {
                items.push(Item::BeamBox { b });
                names.push(format!("beam / {name}"));
            }
        }
        let (mut lower, mut upper) = model.joint_limits();
        debug_assert_eq!(lower.len(), dof);
        for (j, joint) in model.joints.iter().enumerate() {
            if joint.kind == crate::model::JointKind::Revolute {
                lower[j] += options.joint_margin;
                upper[j] -= options.joint_margin;
            }
        }
        if let Some(j) = (0..dof).find(|&j| lower[j] > upper[j]) {
            return Err(Error::Input(format!(
                "a joint margin of {:.3}° leaves joint `{}` no range",
                options.joint_margin.to_degrees(),
                model.joints[j].name
            )));
        }
        let n = items.len();
        let mut set = ConstraintSet {
            model,
            capsules,
            obstacles,
            boxes,
            half_spaces,
            items,
            names,
            reflector,
            cos_max: max_incidence.map_or(-1.0, f64::cos),
            beam_radius: options.beam_radius,
            lower,
            upper,
            required: vec![0.0; n],
            constant: vec![false; n],
            joint_tolerance: 0.0,
            pairs_in_contact: Vec::new(),
            arm_capsules: 0,
            collision_model: cell.robot.collision.clone(),
        };
        if options.collisions {
            set.arm_capsules = set.capsules.iter().filter(|c| c.joints > 0).count();
        }
        drop_pairs_in_contact(&mut set, 256);
        // 16 samples: the constraints the refinement keeps no margin from (see
        // `CellConstraints` in plan.rs).
        set.constant = constraint_ranges(&set, 16)
            .into_iter()
            .map(is_flat)
            .collect();
        required::set_required(&mut set, options, max_incidence)?;
        set.joint_tolerance = if options.joint_margin > 0.0 {
            JOINT_MARGIN_TOLERANCE
        } else {
            0.0
        };
        Ok(set)
    }

    /// Number of constraints.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// Whether the set has no constraints.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// Number of joints (columns of the Jacobian).
    pub fn dof(&self) -> usize {
        self.model.dof()
    }

    /// The model the set was compiled against (the cell's model).
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// Constraint names, e.g. `incidence`, `capsule j2#0 / j5#0`, `j3#0 / car-body`,
    /// `j2#0.a / wall` (endpoint a of capsule 0 on j2), `beam / car-roof`. `frame#k` is the
    /// k-th capsule on that frame in the cell's capsule list.
    pub fn names(&self) -> Vec<String> {
        self.names.clone()
    }

    /// Name of constraint `i`.
    pub fn name(&self, i: usize) -> &str {
        &self.names[i]
    }

    /// Robot capsules that move with a joint, checked against each other, the obstacles and
    /// the half-spaces (0 when the set checks no collisions, or when the arm has no
    /// collision model: then a feasible pose is only within the joint limits, and a caller
    /// should say so).
    pub fn arm_capsules(&self) -> usize {
        self.arm_capsules
    }

    /// Where the cell robot's capsules come from ([`crate::robots::Robot::collision`]).
    pub fn collision_model(&self) -> &str {
        &self.collision_model
    }

    /// Kind of constraint `i`.
    pub fn kind(&self, i: usize) -> ConstraintKind {
        self.items[i].kind()
    }
}

/// Why the cell's line of sight and incidence are not checked, if that is why: the cell has
/// an instrument but does not place it (`[instrument] xyz_mm`; module documentation).
pub fn unplaced_instrument(cell: &Cell) -> Option<String> {
    cell.instrument.as_ref().filter(|i| !i.placed).map(|_| {
        format!(
            "cell `{}` does not place its instrument (no `[instrument] xyz_mm`): the line of sight and the incidence are not checked; give where the instrument stands, or place it where a calibration puts it (`armcal export --cell … --format cell`)",
            cell.name
        )
    })
}

/// Robot capsules that carry the reflector (see the module documentation): at most one joint
/// between the capsule's frame and the reflector, and the reflector within the capsule's
/// radius plus the beam radius, at nominal parameters and any of 16 values of that joint.
fn reflector_carriers(
    model: &Model,
    capsules: &[RobotCapsule],
    reflector: Reflector,
    beam_radius: f64,
) -> Vec<bool> {
    let dof = model.dof();
    let params = model.nominal();
    let (lower, upper) = model.joint_limits();
    let mid: Vec<f64> = lower
        .iter()
        .zip(&upper)
        .map(|(lo, hi)| 0.5 * (lo + hi))
        .collect();
    let mut data = Data::<f64>::new(model);
    capsules
        .iter()
        .map(|c| {
            let between = dof - c.joints;
            if between > 1 {
                return false;
            }
            let samples = if between == 0 { 1 } else { 16 };
            (0..samples).any(|k| {
                let mut q = mid.clone();
                if between == 1 {
                    let j = dof - 1;
                    q[j] = lower[j] + (upper[j] - lower[j]) * k as f64 / (samples - 1) as f64;
                }
                forward_kinematics(model, &mut data, &params, &q);
                let p = match reflector {
                    Reflector::Target(t) => data.targets[t].trans,
                    Reflector::Tool => data.tool().trans,
                };
                let [a, b] = c.place(&data);
                let (d, _) = point_segment_distance(&p, &a, &b);
                d <= c.radius + beam_radius
            })
        })
        .collect()
}

mod evaluate;
mod measurable;
mod required;
mod tracker_shift;
pub use evaluate::JOINT_MARGIN_TOLERANCE;
use evaluate::{constraint_ranges, drop_pairs_in_contact, is_flat};
#[cfg(test)]
mod tests;

pub use measurable::{unmeasurable_poses, unmeasurable_poses_at, Unmeasurable, Violation};
pub use tracker_shift::{tracker_shift, TrackerShift};
