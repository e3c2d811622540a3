//! The per-configuration constraint set of a cell for measurement-pose design (paper
//! eq. 24b), every constraint written as `g(q) ≥ 0`, with its value and its exact gradient
//! w.r.t. the joints (through the world joint twists of
//! [`forward_kinematics`](crate::model::forward_kinematics); no finite differences).
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
//! | half-space | `n · x − rᵢ − offset` at both capsule endpoints | §3.2 (wall `x − r ≥ −450`, floor `z − r ≥ 0`) |
//! | line of sight | `d_P(beam, b) − r_beam − r_b` | §3.2, Table 5 |
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
//! segment distance is `n · (Ṗ − Q̇)` (see [`segment_distance`](super::segment_distance)); for
//! two robot capsules only the joints between their frames contribute (a common joint moves
//! both rigidly and `n · (ω × (P − Q)) = 0`).
//!
//! **Which robot pairs are checked (the set 𝓘 of eq. 24b).** The robot's bodies are its
//! capsule-carrying chain frames (`base, j1, …, jn, tool`, in chain order), each body being
//! all capsules on one frame. Two robot capsules are compared unless
//! - they are on the same frame;
//! - their frames are neighbouring bodies (no other capsule-carrying frame between them) —
//!   "two neighboring segments do not have to be compared as the limitation of joint movement
//!   automatically prevents their collision" (paper §2.2; with one capsule per body this is
//!   exactly the count of eq. 22, `n(n − 1)/2 − (n − 1)`);
//! - no joint separates them (their distance would not depend on q).
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
//! **Line of sight.** The beam from the reflector to the tracker origin is a capsule of radius
//! [`ConstraintSettings::beam_radius`]. It is checked against every robot capsule and every
//! obstacle capsule, except the robot capsules that carry the reflector: a capsule whose
//! frame has at most one joint between it and the reflector is left out when the reflector
//! point lies within its radius plus the beam radius (for a frame with one joint in between,
//! at any of 16 values of that joint over its range, nominal parameters). In the paper cell
//! that removes the reflector holder on `tool`; the wrist capsule on `j5` keeps its
//! constraint because the reflector sits 339 mm beyond it.
//!
//! Constraints that need the tracker (incidence, line of sight) are left out when the model
//! has no instrument frame; incidence also needs `instrument.max_incidence` in the cell.

use crate::cell::{half_space_unit_normal, Cell, Obstacle};
use crate::geometry::segment_distance::{point_segment_distance, segment_distance};
use crate::model::{forward_kinematics, Data, Model, Twist};
use crate::Error;
use nalgebra::Vector3;

/// What a constraint guards against.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ConstraintKind {
    /// Reflector incidence angle (paper eq. 4).
    Incidence,
    /// Two robot capsules (eq. 20).
    SelfCollision,
    /// A robot capsule and an obstacle capsule.
    Obstacle,
    /// A robot capsule endpoint and a half-space (wall, floor).
    HalfSpace,
    /// The laser beam and a robot or obstacle capsule.
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
}

impl Default for ConstraintSettings {
    fn default() -> Self {
        ConstraintSettings {
            incidence: true,
            collisions: true,
            line_of_sight: true,
            beam_radius: 5.0,
            reflector: None,
        }
    }
}

/// A robot capsule compiled against the model.
#[derive(Clone, Debug)]
struct RobotCapsule {
    link: usize,
    /// Joints `0..joints` move it.
    joints: usize,
    a: Vector3<f64>,
    b: Vector3<f64>,
    radius: f64,
    label: String,
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
    HalfSpace { i: usize, end: usize, h: usize },
    BeamRobot { i: usize },
    BeamObstacle { o: usize },
}

impl Item {
    fn kind(self) -> ConstraintKind {
        match self {
            Item::Incidence => ConstraintKind::Incidence,
            Item::Pair { .. } => ConstraintKind::SelfCollision,
            Item::Obstacle { .. } => ConstraintKind::Obstacle,
            Item::HalfSpace { .. } => ConstraintKind::HalfSpace,
            Item::BeamRobot { .. } | Item::BeamObstacle { .. } => ConstraintKind::LineOfSight,
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
    pub index: usize,
    pub value: f64,
    pub name: &'a str,
    pub kind: ConstraintKind,
}

/// The constraints of one measurement configuration of a cell (paper eq. 24b without the
/// joint bounds, which [`ConstraintSet::feasible`] adds).
#[derive(Clone, Debug)]
pub struct ConstraintSet {
    model: Model,
    capsules: Vec<RobotCapsule>,
    obstacles: Vec<WorldCapsule>,
    half_spaces: Vec<HalfSpace>,
    items: Vec<Item>,
    names: Vec<String>,
    reflector: Reflector,
    cos_max: f64,
    beam_radius: f64,
    lower: Vec<f64>,
    upper: Vec<f64>,
}

/// Reusable buffers for [`ConstraintSet::evaluate`].
#[derive(Clone, Debug)]
pub struct ConstraintWorkspace {
    data: Data<f64>,
    /// World endpoints of every robot capsule.
    ends: Vec<[Vector3<f64>; 2]>,
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
        let model = cell.model.clone();
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
        let dof = model.dof();

        let mut per_frame = std::collections::HashMap::<&str, usize>::new();
        let mut capsules = Vec::new();
        for c in &cell.capsules {
            let link = model.link_index(&c.frame).ok_or_else(|| {
                Error::Model(format!(
                    "capsule on frame `{}`: the model has no such chain frame",
                    c.frame
                ))
            })?;
            if !(c.radius.is_finite() && c.radius >= 0.0) {
                return Err(Error::Model(format!(
                    "capsule on frame `{}` has radius {}",
                    c.frame, c.radius
                )));
            }
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
        let mut obstacles = Vec::new();
        let mut obstacle_names = Vec::new();
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
        let has_tracker = model.instrument.is_some();
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
            let carriers = reflector_carriers(&model, &capsules, reflector, options.beam_radius);
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
        }
        let (lower, upper) = model.joint_limits();
        debug_assert_eq!(lower.len(), dof);
        Ok(ConstraintSet {
            model,
            capsules,
            obstacles,
            half_spaces,
            items,
            names,
            reflector,
            cos_max: max_incidence.map_or(-1.0, f64::cos),
            beam_radius: options.beam_radius,
            lower,
            upper,
        })
    }

    /// Number of constraints.
    pub fn len(&self) -> usize {
        self.items.len()
    }

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

    /// Kind of constraint `i`.
    pub fn kind(&self, i: usize) -> ConstraintKind {
        self.items[i].kind()
    }

    /// Number of constraints of one kind.
    pub fn count(&self, kind: ConstraintKind) -> usize {
        self.items.iter().filter(|it| it.kind() == kind).count()
    }

    /// Buffers for [`ConstraintSet::evaluate`].
    pub fn workspace(&self) -> ConstraintWorkspace {
        ConstraintWorkspace::new(self)
    }

    /// Evaluates every constraint at parameters `params` (internal units, the model's full
    /// parameter vector) and joints `q`: `values[i] = g_i(q)` (≥ 0 is feasible) and, if given,
    /// `jacobian[i · dof + j] = ∂g_i/∂q_j` (row major, `len × dof`). Allocates nothing.
    ///
    /// # Panics
    /// If `params`, `q`, `values` or `jacobian` have the wrong length.
    pub fn evaluate(
        &self,
        ws: &mut ConstraintWorkspace,
        params: &[f64],
        q: &[f64],
        values: &mut [f64],
        mut jacobian: Option<&mut [f64]>,
    ) {
        self.check_lengths(params, q, values, jacobian.as_deref());
        self.place(ws, params, q);
        let dof = self.dof();
        for (row, value) in values.iter_mut().enumerate() {
            let grad = jacobian
                .as_deref_mut()
                .map(|jac| &mut jac[row * dof..(row + 1) * dof]);
            *value = self.evaluate_row(ws, row, grad);
        }
    }

    /// Like [`ConstraintSet::evaluate`], but only the constraints listed in `rows`: their
    /// values (and Jacobian rows) are written at their own index of the full-length `values`
    /// (and `jacobian`); the other entries are left as they are. One forward kinematics plus
    /// the listed constraints: the cost of a projection that knows which constraints can be
    /// near their boundary.
    ///
    /// # Panics
    /// If a length is wrong or a row is out of range.
    pub fn evaluate_rows(
        &self,
        ws: &mut ConstraintWorkspace,
        params: &[f64],
        q: &[f64],
        rows: &[usize],
        values: &mut [f64],
        mut jacobian: Option<&mut [f64]>,
    ) {
        self.check_lengths(params, q, values, jacobian.as_deref());
        self.place(ws, params, q);
        let dof = self.dof();
        for &row in rows {
            let grad = jacobian
                .as_deref_mut()
                .map(|jac| &mut jac[row * dof..(row + 1) * dof]);
            values[row] = self.evaluate_row(ws, row, grad);
        }
    }

    fn check_lengths(&self, params: &[f64], q: &[f64], values: &[f64], jac: Option<&[f64]>) {
        assert_eq!(params.len(), self.model.param_count(), "parameter count");
        assert_eq!(q.len(), self.dof(), "joint count");
        assert_eq!(values.len(), self.len(), "values length");
        if let Some(jac) = jac {
            assert_eq!(
                jac.len(),
                self.len() * self.dof(),
                "jacobian length (len × dof)"
            );
        }
    }

    /// Forward kinematics and the world endpoints of every robot capsule at `q`.
    fn place(&self, ws: &mut ConstraintWorkspace, params: &[f64], q: &[f64]) {
        forward_kinematics(&self.model, &mut ws.data, params, q);
        for (c, ends) in self.capsules.iter().zip(ws.ends.iter_mut()) {
            let f = &ws.data.frames[c.link];
            ends[0] = f.transform_point(&c.a);
            ends[1] = f.transform_point(&c.b);
        }
    }

    /// Value (and gradient) of constraint `row` at the configuration [`Self::place`]d in `ws`.
    #[inline]
    fn evaluate_row(&self, ws: &ConstraintWorkspace, row: usize, grad: Option<&mut [f64]>) -> f64 {
        let data = &ws.data;
        let ends = &ws.ends;
        let refl = match self.reflector {
            Reflector::Target(k) => &data.targets[k],
            Reflector::Tool => data.tool(),
        };
        let p = refl.trans;
        let tracker = data.instrument.trans;
        let twists = &data.joint_twists;
        match self.items[row] {
            Item::Incidence => {
                let z = refl.rot.column(2).into_owned();
                let beam = tracker - p;
                let len = beam.norm();
                let g = beam / len;
                let cos_b = z.dot(&g);
                if let Some(grad) = grad {
                    let perp = z - g * cos_b;
                    for (gj, tw) in grad.iter_mut().zip(twists) {
                        let dp = tw.point_velocity(&p);
                        *gj = tw.w.cross(&z).dot(&g) - perp.dot(&dp) / len;
                    }
                }
                cos_b - self.cos_max
            }
            Item::Pair { i, j } => {
                let (ci, cj) = (&self.capsules[i], &self.capsules[j]);
                let sd = segment_distance(&ends[i][0], &ends[i][1], &ends[j][0], &ends[j][1]);
                if let Some(grad) = grad {
                    two_point_gradient(
                        grad, twists, &sd.normal, &sd.p, ci.joints, &sd.q, cj.joints,
                    );
                }
                sd.distance - ci.radius - cj.radius
            }
            Item::Obstacle { i, o } => {
                let (ci, ob) = (&self.capsules[i], &self.obstacles[o]);
                let sd = segment_distance(&ends[i][0], &ends[i][1], &ob.a, &ob.b);
                if let Some(grad) = grad {
                    two_point_gradient(grad, twists, &sd.normal, &sd.p, ci.joints, &sd.q, 0);
                }
                sd.distance - ci.radius - ob.radius
            }
            Item::HalfSpace { i, end, h } => {
                let (ci, hs) = (&self.capsules[i], &self.half_spaces[h]);
                let x = ends[i][end];
                if let Some(grad) = grad {
                    two_point_gradient(grad, twists, &hs.normal, &x, ci.joints, &x, 0);
                }
                hs.normal.dot(&x) - ci.radius - hs.offset
            }
            Item::BeamRobot { i } => {
                let ci = &self.capsules[i];
                let sd = segment_distance(&p, &tracker, &ends[i][0], &ends[i][1]);
                if let Some(grad) = grad {
                    beam_gradient(grad, twists, &sd.normal, sd.s, &p, &sd.q, ci.joints);
                }
                sd.distance - self.beam_radius - ci.radius
            }
            Item::BeamObstacle { o } => {
                let ob = &self.obstacles[o];
                let sd = segment_distance(&p, &tracker, &ob.a, &ob.b);
                if let Some(grad) = grad {
                    beam_gradient(grad, twists, &sd.normal, sd.s, &p, &sd.q, 0);
                }
                sd.distance - self.beam_radius - ob.radius
            }
        }
    }

    /// Whether `q` lies within the joint limits (inclusive).
    pub fn within_limits(&self, q: &[f64]) -> bool {
        q.iter()
            .zip(self.lower.iter().zip(&self.upper))
            .all(|(v, (lo, hi))| *v >= *lo && *v <= *hi)
    }

    /// The smallest of `values` (one per constraint) with its index, name and kind; `None`
    /// for an empty set.
    pub fn min_margin<'a>(&'a self, values: &[f64]) -> Option<Margin<'a>> {
        let (index, value) = values
            .iter()
            .copied()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(&b.1))?;
        Some(Margin {
            index,
            value,
            name: &self.names[index],
            kind: self.items[index].kind(),
        })
    }

    /// Evaluates the constraints at `q` (into `ws.values`) and returns the smallest.
    pub fn min_margin_at<'a>(
        &'a self,
        ws: &mut ConstraintWorkspace,
        params: &[f64],
        q: &[f64],
    ) -> Option<Margin<'a>> {
        let mut values = std::mem::take(&mut ws.values);
        self.evaluate(ws, params, q, &mut values, None);
        ws.values = values;
        self.min_margin(&ws.values)
    }

    /// `q` within the joint limits and every constraint ≥ 0 (paper eq. 24b). Stops at the
    /// first violated constraint (random draws are mostly rejected by one of the first few),
    /// so `ws.values` is not filled; use [`ConstraintSet::min_margin_at`] for the values.
    pub fn feasible(&self, ws: &mut ConstraintWorkspace, params: &[f64], q: &[f64]) -> bool {
        if !self.within_limits(q) {
            return false;
        }
        assert_eq!(params.len(), self.model.param_count(), "parameter count");
        assert_eq!(q.len(), self.dof(), "joint count");
        self.place(ws, params, q);
        (0..self.len()).all(|row| self.evaluate_row(ws, row, None) >= 0.0)
    }
}

impl ConstraintWorkspace {
    pub fn new(set: &ConstraintSet) -> Self {
        ConstraintWorkspace {
            data: Data::new(&set.model),
            ends: vec![[Vector3::zeros(); 2]; set.capsules.len()],
            values: vec![0.0; set.len()],
        }
    }
}

/// `∂/∂q_j` of a distance whose closest points `P` (moved by joints `0..jp`) and `Q` (moved by
/// joints `0..jq`) separate along the unit vector `n`: `n · (Ṗ_j − Q̇_j)`.
#[inline]
fn two_point_gradient(
    grad: &mut [f64],
    twists: &[Twist<f64>],
    n: &Vector3<f64>,
    p: &Vector3<f64>,
    jp: usize,
    q: &Vector3<f64>,
    jq: usize,
) {
    for (j, (gj, tw)) in grad.iter_mut().zip(twists).enumerate() {
        let mut v = 0.0;
        if j < jp {
            v += n.dot(&tw.point_velocity(p));
        }
        if j < jq {
            v -= n.dot(&tw.point_velocity(q));
        }
        *gj = v;
    }
}

/// Gradient of the beam–capsule distance: the beam's closest point `(1 − s) p + s t` moves
/// with `(1 − s) ṗ` (the tracker origin `t` is fixed), the capsule's `Q` with joints `0..jq`.
#[inline]
fn beam_gradient(
    grad: &mut [f64],
    twists: &[Twist<f64>],
    n: &Vector3<f64>,
    s: f64,
    p: &Vector3<f64>,
    q: &Vector3<f64>,
    jq: usize,
) {
    for (j, (gj, tw)) in grad.iter_mut().zip(twists).enumerate() {
        let mut v = (1.0 - s) * n.dot(&tw.point_velocity(p));
        if j < jq {
            v -= n.dot(&tw.point_velocity(q));
        }
        *gj = v;
    }
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
                let f = &data.frames[c.link];
                let (d, _) =
                    point_segment_distance(&p, &f.transform_point(&c.a), &f.transform_point(&c.b));
                d <= c.radius + beam_radius
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    const CELL: &str = include_str!("../../../../examples/paper-cell-obstacles.toml");

    fn cell() -> Cell {
        Cell::from_toml(CELL, "paper-cell-obstacles.toml", Path::new(".")).expect("paper cell")
    }

    fn random_q(set: &ConstraintSet, r: &mut rand_chacha::ChaCha8Rng) -> Vec<f64> {
        use rand::Rng;
        set.lower
            .iter()
            .zip(&set.upper)
            .map(|(lo, hi)| r.random_range(*lo..*hi))
            .collect()
    }

    /// Every constraint kind against central differences at random configurations.
    #[test]
    fn jacobian_matches_central_differences() {
        use rand::SeedableRng;
        let cell = cell();
        let set = ConstraintSet::new(&cell, &ConstraintSettings::default()).unwrap();
        let params = cell.model.nominal();
        let (n, dof) = (set.len(), set.dof());
        let mut ws = set.workspace();
        let mut values = vec![0.0; n];
        let mut jac = vec![0.0; n * dof];
        let (mut plus, mut minus) = (vec![0.0; n], vec![0.0; n]);
        let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let h = 1e-6;
        let mut checked = std::collections::HashMap::new();
        for _ in 0..200 {
            let q = random_q(&set, &mut r);
            set.evaluate(&mut ws, &params, &q, &mut values, Some(&mut jac));
            for j in 0..dof {
                let mut qp = q.clone();
                let mut qm = q.clone();
                qp[j] += h;
                qm[j] -= h;
                set.evaluate(&mut ws, &params, &qp, &mut plus, None);
                set.evaluate(&mut ws, &params, &qm, &mut minus, None);
                for i in 0..n {
                    let fd = (plus[i] - minus[i]) / (2.0 * h);
                    let an = jac[i * dof + j];
                    // Kinks (closest-point switches, contact) are skipped: the one-sided
                    // differences disagree there.
                    let fwd = (plus[i] - values[i]) / h;
                    let bwd = (values[i] - minus[i]) / h;
                    if (fwd - bwd).abs() > 1e-3 * (1.0 + fwd.abs()) {
                        continue;
                    }
                    let tol = 1e-5 * (1.0 + an.abs());
                    assert!(
                        (fd - an).abs() < tol,
                        "{} d/dq{}: analytic {an} fd {fd}",
                        set.name(i),
                        j + 1
                    );
                    *checked.entry(set.kind(i)).or_insert(0usize) += 1;
                }
            }
        }
        for kind in [
            ConstraintKind::Incidence,
            ConstraintKind::SelfCollision,
            ConstraintKind::Obstacle,
            ConstraintKind::HalfSpace,
            ConstraintKind::LineOfSight,
        ] {
            assert!(checked.get(&kind).copied().unwrap_or(0) > 100, "{kind:?}");
        }
        eprintln!("jacobian vs central differences, entries checked per kind: {checked:?}");
    }

    /// Capsule distances from the FK agree with parry: its closed-form segment–segment
    /// distance minus the radii to 1e-9 mm, and its capsule–capsule distance (GJK, iterative,
    /// ≈ 1e-7 relative accuracy) to 1e-6 relative.
    #[test]
    fn capsule_distances_agree_with_parry() {
        use parry3d_f64::math::{Pose, Vector};
        use parry3d_f64::query;
        use parry3d_f64::shape::{Capsule, Segment};
        use rand::SeedableRng;
        let cell = cell();
        let set = ConstraintSet::new(&cell, &ConstraintSettings::default()).unwrap();
        let params = cell.model.nominal();
        let mut ws = set.workspace();
        let mut values = vec![0.0; set.len()];
        let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(2);
        let v = |x: &Vector3<f64>| Vector::new(x[0], x[1], x[2]);
        let id = Pose::identity();
        let (mut compared, mut worst_seg, mut worst_gjk) = (0, 0.0f64, 0.0f64);
        for _ in 0..300 {
            let q = random_q(&set, &mut r);
            set.evaluate(&mut ws, &params, &q, &mut values, None);
            for (row, item) in set.items.iter().enumerate() {
                let (a, b) = match *item {
                    Item::Pair { i, j } => (
                        (ws.ends[i], set.capsules[i].radius),
                        (ws.ends[j], set.capsules[j].radius),
                    ),
                    Item::Obstacle { i, o } => {
                        let ob = &set.obstacles[o];
                        (
                            (ws.ends[i], set.capsules[i].radius),
                            ([ob.a, ob.b], ob.radius),
                        )
                    }
                    _ => continue,
                };
                let s1 = Segment::new(v(&a.0[0]), v(&a.0[1]));
                let s2 = Segment::new(v(&b.0[0]), v(&b.0[1]));
                let seg = query::distance(&id, &s1, &id, &s2).unwrap().distance - a.1 - b.1;
                let err = (seg - values[row]).abs();
                worst_seg = worst_seg.max(err);
                assert!(
                    err < 1e-9,
                    "{}: ours {} parry {seg}",
                    set.name(row),
                    values[row]
                );
                let c1 = Capsule::new(v(&a.0[0]), v(&a.0[1]), a.1);
                let c2 = Capsule::new(v(&b.0[0]), v(&b.0[1]), b.1);
                let d = query::distance(&id, &c1, &id, &c2).unwrap().distance;
                if values[row] > 0.0 {
                    let err = (d - values[row]).abs();
                    worst_gjk = worst_gjk.max(err / (1.0 + d));
                    assert!(
                        err < 1e-6 * (1.0 + d),
                        "{}: ours {} parry {d}",
                        set.name(row),
                        values[row]
                    );
                    compared += 1;
                } else {
                    // parry reports 0 for overlapping capsules.
                    assert!(
                        d < 1e-6,
                        "{}: ours {} parry {d}",
                        set.name(row),
                        values[row]
                    );
                }
            }
        }
        eprintln!(
            "FK capsules vs parry: segments max |Δ| {worst_seg:.2e} mm, GJK capsules max \
             relative |Δ| {worst_gjk:.2e} ({compared} separated pairs)"
        );
        assert!(compared > 1000);
    }

    /// `evaluate_rows` gives the same values and Jacobian rows as `evaluate` and leaves the
    /// other entries alone; the early-exit `feasible` agrees with the smallest margin.
    #[test]
    fn row_subsets_and_early_exit_agree_with_the_full_evaluation() {
        let c = cell();
        let set = ConstraintSet::new(&c, &ConstraintSettings::default()).unwrap();
        let params = c.model.nominal();
        let (m, dof) = (set.len(), set.dof());
        let mut ws = set.workspace();
        let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(11);
        let rows: Vec<usize> = (0..m).filter(|r| r % 3 == 1).collect();
        let (mut feasible, mut infeasible) = (0, 0);
        for _ in 0..300 {
            let q = random_q(&set, &mut rng);
            let (mut v, mut jac) = (vec![0.0; m], vec![0.0; m * dof]);
            set.evaluate(&mut ws, &params, &q, &mut v, Some(&mut jac));
            let (mut vs, mut js) = (vec![7.0; m], vec![7.0; m * dof]);
            set.evaluate_rows(&mut ws, &params, &q, &rows, &mut vs, Some(&mut js));
            for r in 0..m {
                if rows.contains(&r) {
                    assert_eq!(vs[r], v[r]);
                    assert_eq!(js[r * dof..(r + 1) * dof], jac[r * dof..(r + 1) * dof]);
                } else {
                    assert_eq!(vs[r], 7.0);
                }
            }
            let ok = set.feasible(&mut ws, &params, &q);
            assert_eq!(ok, v.iter().all(|x| *x >= 0.0), "{q:?}");
            if ok {
                feasible += 1;
            } else {
                infeasible += 1;
            }
        }
        assert!(feasible > 0 && infeasible > 0, "{feasible} / {infeasible}");
    }

    #[test]
    fn bad_options_are_rejected() {
        let cell = cell();
        let opts = ConstraintSettings {
            beam_radius: -1.0,
            ..Default::default()
        };
        assert!(ConstraintSet::new(&cell, &opts).is_err());
        let opts = ConstraintSettings {
            reflector: Some("nope".into()),
            ..Default::default()
        };
        assert!(ConstraintSet::new(&cell, &opts).is_err());
    }
}
