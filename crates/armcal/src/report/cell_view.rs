//! A 3D view of the cell for the HTML report: robot capsules, obstacles, tracker and beam at
//! each planned pose, steppable pose by pose.
//!
//! All world-space geometry is computed here, in Rust, and embedded in the page as compact
//! JSON (mm, rounded to 0.1 mm); the inline script (`cell_view.js`, compiled into the binary)
//! only projects and draws with the Canvas 2D API, so the view needs no network, no WebGL and
//! no GPU.
//!
//! For every pose `q` of every design, forward kinematics at the nominal parameters gives the
//! world pose `T_f(q)` of each chain frame `f`; a robot capsule `(f, a, b, r)` is drawn from
//! `T_f(q)·a` to `T_f(q)·b` with radius `r` (the same placement as
//! [`ConstraintSet::evaluate`](crate::design::ConstraintSet::evaluate)). The beam runs from
//! the instrument frame's origin (the tracker) to each target (reflector) position. A pose
//! outside the joint limits or with a constraint of the planner's set (paper eq. 24b;
//! [`constraint_set`]) negative is marked violating, its beam and the capsules and obstacles
//! named drawn red; one that keeps less than the cell's `[design]` asks is listed as such.
//! Half-spaces are drawn as the polygon where their plane `n·x = offset` cuts the scene's
//! box: every capsule at every pose, the tracker and targets, stretched until each plane
//! crosses it, plus 200 mm.
//!
//! (Over 600 lines: one scene, its JSON types and the geometry that places every body of it
//! — capsules, boxes, planes and their bounds — for the script.)

use super::html::escape;
use crate::cell::{box_cuboid, half_space_unit_normal, Cell, Obstacle};
use crate::design::cell_constraints::{robot_capsules, JOINT_MARGIN_TOLERANCE};
use crate::design::plan::constraint_set;
use crate::design::ConstraintKind;
use crate::model::{forward_kinematics, Data};
use crate::Error;
use nalgebra::Vector3;
use serde::Serialize;

/// The drawing script: reads the section's JSON, draws, handles the controls.
const SCRIPT: &str = include_str!("cell_view.js");

/// Margin added around the scene's bounding box (mm).
const BOX_MARGIN: f64 = 200.0;

/// A robot capsule's fixed data: the chain frame it moves with and its radius (mm).
#[derive(Serialize)]
pub(super) struct RobotCapsule {
    pub(super) frame: String,
    /// `frame#k`: the k-th capsule on that frame, as the constraint names call it.
    pub(super) label: String,
    pub(super) r: f64,
}

/// An obstacle capsule in world coordinates (mm).
#[derive(Serialize)]
pub(super) struct ObstacleCapsule {
    pub(super) name: String,
    pub(super) a: [f64; 3],
    pub(super) b: [f64; 3],
    pub(super) r: f64,
}

/// The boundary of a half-space, clipped to the scene box; or a face of a box obstacle.
#[derive(Serialize)]
pub(super) struct Plane {
    pub(super) name: String,
    /// Unit normal, pointing into the free side.
    pub(super) normal: [f64; 3],
    /// Polygon corners in order (mm).
    pub(super) corners: Vec<[f64; 3]>,
}

/// A joint's name and the unit its values are shown in.
#[derive(Serialize)]
pub(super) struct JointLabel {
    pub(super) name: String,
    pub(super) unit: &'static str,
}

/// One pose of a design in world coordinates.
#[derive(Serialize)]
pub(super) struct PoseView {
    /// Joint values in display units (deg, mm), rounded to 0.01.
    pub(super) q: Vec<f64>,
    /// Robot capsule endpoints `[ax, ay, az, bx, by, bz]` (mm), in the order of `robot`.
    pub(super) caps: Vec<[f64; 6]>,
    /// World position of each target (mm).
    pub(super) targets: Vec<[f64; 3]>,
    /// Within the joint limits and every constraint ≥ 0.
    pub(super) ok: bool,
    /// Smallest clearance over the distance constraints (mm) and the constraint's name.
    pub(super) clearance: Option<(f64, String)>,
    /// Angle between the reflector's z axis and the beam to the tracker (deg, paper eq. 4).
    pub(super) incidence: Option<f64>,
    /// Joints outside their limits and violated constraints.
    pub(super) violations: Vec<String>,
    /// Constraints met but closer than the cell's `[design]` asks (a distance under
    /// `clearance_mm`, a joint within `joint_margin_deg` of a limit, …), each with its value.
    pub(super) below_required: Vec<String>,
    /// Indices (into `robot`) of the capsules named in violated constraints.
    pub(super) hit: Vec<usize>,
    /// Names of the obstacles and half-spaces named in violated constraints.
    pub(super) hit_obstacles: Vec<String>,
}

#[derive(Serialize)]
pub(super) struct DesignView {
    pub(super) name: String,
    pub(super) poses: Vec<PoseView>,
}

/// Everything the script draws.
#[derive(Serialize)]
pub(super) struct Scene {
    pub(super) cell: String,
    /// Scene bounding box `[min, max]` (mm).
    pub(super) bounds: [[f64; 3]; 2],
    /// What the initial view frames: the robot at every pose, the targets, the tracker and
    /// the foot of its plumb line on the ground (mm).
    pub(super) focus: [[f64; 3]; 2],
    /// Height of the ground grid: the offset of a half-space with normal +z (the floor), else
    /// the bottom of the box (mm).
    pub(super) ground: f64,
    pub(super) robot: Vec<RobotCapsule>,
    pub(super) obstacles: Vec<ObstacleCapsule>,
    /// Box obstacles: each one's six faces (outward normals), named for the box.
    pub(super) boxes: Vec<Vec<Plane>>,
    pub(super) planes: Vec<Plane>,
    /// The instrument frame's origin (mm), if the cell has an instrument.
    pub(super) tracker: Option<[f64; 3]>,
    pub(super) target_names: Vec<String>,
    pub(super) joints: Vec<JointLabel>,
    pub(super) designs: Vec<DesignView>,
}

/// The HTML fragment of the 3D view: a `<section class="cell-view">` with a heading, a
/// `<canvas>`, the controls (a design selector when there are several designs, previous/next
/// buttons and a slider over the poses, the pose's joints and margins), the scene as
/// `<script type="application/json">` and the inline drawing script. `designs` are
/// (name, poses) with joint values in internal units (rad, mm).
///
/// The section's id is derived from a hash of its data, so the same input gives the same
/// bytes and different views on one page get different ids; the script finds its elements
/// through its own section, never through global ids.
pub fn cell_view_section(cell: &Cell, designs: &[(&str, &[Vec<f64>])]) -> Result<String, Error> {
    view_section(
        &scene(cell, designs)?,
        &format!("3D view of the cell: {}", cell.name),
        "Robot capsules (orange), obstacles (blue-grey capsules and boxes), wall and \
         floor (translucent), tracker and laser beam to the reflector (green; red when the \
         pose violates a constraint, with the capsules involved). Drag to orbit, wheel to \
         zoom, arrow keys or the slider to step through the poses.",
    )
}

/// The HTML fragment of a 3D view of `scene` (its designs' poses steppable) under `heading`,
/// with `help` below it (plain text): what [`cell_view_section`] writes for a cell, and
/// [`super::tree`] for a kinematic tree.
pub(super) fn view_section(scene: &Scene, heading: &str, help: &str) -> Result<String, Error> {
    let json = serde_json::to_string(scene)
        .map_err(|e| Error::Output(format!("3D view: cannot serialise the scene: {e}")))?;
    // JSON can only hold `<` inside strings, where `\u003c` means the same; this keeps a
    // `</script>` in a name from ending the element.
    let json = json.replace('<', "\\u003c");
    let id = format!("cell-view-{:012x}", fnv1a(json.as_bytes()) >> 16);
    let mut html = String::with_capacity(json.len() + SCRIPT.len() + 2048);
    html.push_str(&format!(
        "<section class=\"cell-view\" id=\"{id}\">\n<h2>{}</h2>\n<p class=\"cell-view-help\">{}</p>\n",
        escape(heading),
        escape(help)
    ));
    html.push_str("<div class=\"cell-view-controls\">\n");
    if scene.designs.len() > 1 {
        html.push_str(&format!(
            "<label for=\"{id}-design\">design</label> <select id=\"{id}-design\" \
             class=\"cell-view-design\">"
        ));
        for (k, d) in scene.designs.iter().enumerate() {
            html.push_str(&format!(
                "<option value=\"{k}\">{}</option>",
                escape(&d.name)
            ));
        }
        html.push_str("</select>\n");
    }
    let max = scene.designs[0].poses.len() - 1;
    html.push_str(&format!(
        "<button type=\"button\" class=\"cell-view-prev\">&#9664; previous</button>\n\
         <input type=\"range\" id=\"{id}-pose\" class=\"cell-view-slider\" min=\"0\" \
         max=\"{max}\" value=\"0\" step=\"1\" aria-label=\"pose\">\n\
         <button type=\"button\" class=\"cell-view-next\">next &#9654;</button>\n\
         <span class=\"cell-view-label\"></span>\n</div>\n\
         <canvas id=\"{id}-canvas\" width=\"960\" height=\"600\" tabindex=\"0\" \
         style=\"width:100%;max-width:960px;height:auto;border:1px solid #ccc;\
         cursor:grab;touch-action:none\"></canvas>\n\
         <div class=\"cell-view-pose\" style=\"font:12px monospace;white-space:pre-wrap\">\
         </div>\n"
    ));
    html.push_str("<script type=\"application/json\" class=\"cell-view-data\">");
    html.push_str(&json);
    html.push_str("</script>\n<script>\n");
    html.push_str(SCRIPT);
    html.push_str("</script>\n</section>\n");
    Ok(html)
}

/// Computes the scene: robot capsules, targets and constraint status at every pose.
fn scene(cell: &Cell, designs: &[(&str, &[Vec<f64>])]) -> Result<Scene, Error> {
    let model = &cell.model;
    let dof = model.dof();
    if designs.is_empty() {
        return Err(Error::Input("3D view: no design to show".into()));
    }
    for (name, poses) in designs {
        if poses.is_empty() {
            return Err(Error::Input(format!(
                "3D view: design `{name}` has no poses"
            )));
        }
        for (i, q) in poses.iter().enumerate() {
            if q.len() != dof {
                return Err(Error::Input(format!(
                    "3D view: design `{name}`, pose {}: model `{}` has {dof} joints, got {} \
                     values",
                    i + 1,
                    model.name,
                    q.len()
                )));
            }
            if let Some(j) = q.iter().position(|v| !v.is_finite()) {
                return Err(Error::Input(format!(
                    "3D view: design `{name}`, pose {}: joint {} is not finite",
                    i + 1,
                    j + 1
                )));
            }
        }
    }

    // Robot capsules compiled against the model, labelled as the constraint set labels them.
    let links = robot_capsules(cell)?;
    let robot: Vec<RobotCapsule> = links
        .iter()
        .zip(&cell.capsules)
        .map(|(l, c)| RobotCapsule {
            frame: c.frame.clone(),
            label: l.label.clone(),
            r: mm(c.radius),
        })
        .collect();

    let set = constraint_set(cell, true)?;
    let mut ws = set.workspace();
    let mut values = vec![0.0; set.len()];
    let params = model.nominal();
    let mut data = Data::<f64>::new(model);
    let (lower, upper) = model.joint_limits();
    // The limits shrunk by the cell's joint margin (revolute joints), as the planner keeps them.
    let (planned_lower, planned_upper) = set.joint_bounds();
    let (planned_lower, planned_upper) = (planned_lower.to_vec(), planned_upper.to_vec());
    let display: Vec<f64> = model
        .joints
        .iter()
        .map(|j| j.kind.unit().display_factor())
        .collect();
    let tracker = model.instrument.as_ref().map(|_| {
        forward_kinematics(model, &mut data, &params, &vec![0.0; dof]);
        data.instrument.trans
    });
    let mut bounds = Bounds::default();
    if let Some(t) = &tracker {
        bounds.add(t, 0.0);
    }

    let mut design_views = Vec::with_capacity(designs.len());
    for (name, poses) in designs {
        let mut views = Vec::with_capacity(poses.len());
        for q in poses.iter() {
            forward_kinematics(model, &mut data, &params, q);
            let mut caps = Vec::with_capacity(links.len());
            for (c, l) in cell.capsules.iter().zip(&links) {
                let [wa, wb] = l.place(&data);
                bounds.add(&wa, c.radius);
                bounds.add(&wb, c.radius);
                caps.push([wa.x, wa.y, wa.z, wb.x, wb.y, wb.z].map(mm));
            }
            let targets: Vec<Vector3<f64>> = if data.targets.is_empty() {
                vec![data.tool().trans]
            } else {
                data.targets.iter().map(|t| t.trans).collect()
            };
            for t in &targets {
                bounds.add(t, 0.0);
            }

            let reflector = data.targets.first().unwrap_or(data.tool());
            let incidence = tracker.map(|t| {
                let beam = (t - reflector.trans).normalize();
                let z = reflector.rot.column(2);
                z.dot(&beam).clamp(-1.0, 1.0).acos().to_degrees()
            });

            let mut violations = Vec::new();
            let mut below_required = Vec::new();
            for (j, v) in q.iter().enumerate() {
                let unit = model.joints[j].kind.unit().display_name();
                if *v < lower[j] || *v > upper[j] {
                    violations.push(format!(
                        "{} = {:.2} outside [{:.2}, {:.2}] {unit}",
                        model.joints[j].name,
                        v * display[j],
                        lower[j] * display[j],
                        upper[j] * display[j],
                    ));
                } else if *v < planned_lower[j] - JOINT_MARGIN_TOLERANCE
                    || *v > planned_upper[j] + JOINT_MARGIN_TOLERANCE
                {
                    below_required.push(format!(
                        "{} {:.2} {unit} from its limit (joint_margin_deg {:.2})",
                        model.joints[j].name,
                        (v - lower[j]).min(upper[j] - v) * display[j],
                        cell.design.joint_margin.to_degrees()
                    ));
                }
            }
            set.evaluate(&mut ws, &params, q, &mut values, None);
            let mut clearance: Option<(f64, String)> = None;
            let mut hit = Vec::new();
            let mut hit_obstacles = Vec::new();
            for (i, v) in values.iter().enumerate() {
                if set.kind(i) != ConstraintKind::Incidence
                    && clearance.as_ref().is_none_or(|c| *v < c.0)
                {
                    clearance = Some((*v, set.name(i).to_string()));
                }
                if *v < 0.0 {
                    let name = set.name(i);
                    violations.push(name.to_string());
                    mark_named(name, &robot, cell, &mut hit, &mut hit_obstacles);
                } else if *v < set.required(i) {
                    below_required.push(set.shortfall(i, *v));
                }
            }
            hit.sort_unstable();
            hit.dedup();
            hit_obstacles.sort();
            hit_obstacles.dedup();
            views.push(PoseView {
                q: q.iter()
                    .zip(&display)
                    .map(|(v, f)| round_to(v * f, 100.0))
                    .collect(),
                caps,
                targets: targets.iter().map(|t| [t.x, t.y, t.z].map(mm)).collect(),
                ok: violations.is_empty(),
                clearance: clearance.map(|(v, n)| (mm(v), n)),
                incidence: incidence.map(|b| round_to(b, 100.0)),
                violations,
                below_required,
                hit,
                hit_obstacles,
            });
        }
        design_views.push(DesignView {
            name: name.to_string(),
            poses: views,
        });
    }

    let mut focus = bounds.clone();
    let mut obstacles = Vec::new();
    let mut half_spaces = Vec::new();
    let mut boxes = Vec::new();
    for o in &cell.obstacles {
        match o {
            Obstacle::Capsule { name, a, b, radius } => {
                bounds.add(&Vector3::from(*a), *radius);
                bounds.add(&Vector3::from(*b), *radius);
                obstacles.push(ObstacleCapsule {
                    name: name.clone(),
                    a: a.map(mm),
                    b: b.map(mm),
                    r: mm(*radius),
                });
            }
            Obstacle::Box {
                name,
                center,
                size,
                rpy,
            } => {
                let faces = box_faces(name, &box_cuboid(center, size, rpy));
                for f in &faces {
                    for c in &f.corners {
                        bounds.add(&Vector3::from(*c), 0.0);
                    }
                }
                boxes.push(faces);
            }
            Obstacle::HalfSpace {
                name,
                normal,
                offset,
            } => {
                half_spaces.push((name, half_space_unit_normal(name, normal)?, *offset));
            }
        }
    }
    // Stretch the box until every boundary plane crosses it: add the foot of the box centre
    // on the plane, c − (n·c − offset) n.
    for (_, n, offset) in &half_spaces {
        let c = bounds.center();
        bounds.add(&(c - n * (n.dot(&c) - offset)), 0.0);
    }
    bounds.pad(BOX_MARGIN);
    let planes = half_spaces
        .iter()
        .filter_map(|(name, n, offset)| {
            let corners = bounds.plane_section(n, *offset);
            (corners.len() >= 3).then(|| Plane {
                name: name.to_string(),
                normal: [n.x, n.y, n.z].map(|v| round_to(v, 1e4)),
                corners: corners.iter().map(|p| [p.x, p.y, p.z].map(mm)).collect(),
            })
        })
        .collect();
    let ground = half_spaces
        .iter()
        .find(|(_, n, _)| n.z > 1.0 - 1e-9)
        .map_or(bounds.min.z, |(_, _, offset)| *offset);
    if let Some(t) = &tracker {
        focus.add(&Vector3::new(t.x, t.y, ground), 0.0);
    }
    focus.pad(BOX_MARGIN);

    Ok(Scene {
        cell: cell.name.clone(),
        bounds: [
            [bounds.min.x, bounds.min.y, bounds.min.z].map(mm),
            [bounds.max.x, bounds.max.y, bounds.max.z].map(mm),
        ],
        focus: [
            [focus.min.x, focus.min.y, focus.min.z].map(mm),
            [focus.max.x, focus.max.y, focus.max.z].map(mm),
        ],
        ground: mm(ground),
        robot,
        obstacles,
        boxes,
        planes,
        tracker: tracker.map(|t| [t.x, t.y, t.z].map(mm)),
        target_names: if model.targets.is_empty() {
            vec!["tool".to_string()]
        } else {
            model.targets.iter().map(|t| t.spec.name.clone()).collect()
        },
        joints: joint_labels(&model.joints),
        designs: design_views,
    })
}

/// Each joint's name and display unit, for the pose readout.
pub(super) fn joint_labels(joints: &[crate::model::link::Joint]) -> Vec<JointLabel> {
    joints
        .iter()
        .map(|j| JointLabel {
            name: j.name.clone(),
            unit: j.kind.unit().display_name(),
        })
        .collect()
}

/// Records the robot capsules and obstacles a constraint name refers to. Names are
/// `capsule j2#0 / j5#0`, `j3#0 / car-body`, `j2#0.a / wall`, `beam / car-roof`, `incidence`
/// ([`ConstraintSet::names`](crate::design::ConstraintSet::names)): robot capsules appear
/// as `frame#k` (with `.a`/`.b` for an endpoint), an obstacle as the part after ` / `.
fn mark_named(
    name: &str,
    robot: &[RobotCapsule],
    cell: &Cell,
    hit: &mut Vec<usize>,
    hit_obstacles: &mut Vec<String>,
) {
    for part in name.split(" / ") {
        let token = part.strip_prefix("capsule ").unwrap_or(part);
        let token = token
            .strip_suffix(".a")
            .or_else(|| token.strip_suffix(".b"))
            .unwrap_or(token);
        if let Some(i) = robot.iter().position(|c| c.label == token) {
            hit.push(i);
        }
    }
    if let Some((_, other)) = name.rsplit_once(" / ") {
        let is_obstacle = cell.obstacles.iter().any(|o| o.name() == other);
        if is_obstacle {
            hit_obstacles.push(other.to_string());
        }
    }
}

/// The six faces of a box obstacle: outward normal and four corners each (mm).
fn box_faces(name: &str, b: &crate::geometry::Cuboid) -> Vec<Plane> {
    let corner = |k: usize| {
        let sign = |bit: usize| if k & bit != 0 { 1.0 } else { -1.0 };
        let local = Vector3::new(sign(1) * b.half.x, sign(2) * b.half.y, sign(4) * b.half.z);
        let p = b.center + b.rotation * local;
        [p.x, p.y, p.z].map(mm)
    };
    // Corner k has +x if bit 1 is set, +y for bit 2, +z for bit 4; each face in order.
    const FACES: [(usize, f64, [usize; 4]); 6] = [
        (0, 1.0, [1, 3, 7, 5]),
        (0, -1.0, [0, 4, 6, 2]),
        (1, 1.0, [2, 6, 7, 3]),
        (1, -1.0, [0, 1, 5, 4]),
        (2, 1.0, [4, 5, 7, 6]),
        (2, -1.0, [0, 2, 3, 1]),
    ];
    FACES
        .iter()
        .map(|(axis, sign, corners)| {
            let n = b.rotation.column(*axis) * *sign;
            Plane {
                name: name.to_string(),
                normal: [n.x, n.y, n.z].map(|v| round_to(v, 1e4)),
                corners: corners.iter().map(|&k| corner(k)).collect(),
            }
        })
        .collect()
}

/// An axis-aligned box that grows to hold points and spheres.
#[derive(Clone)]
pub(super) struct Bounds {
    pub(super) min: Vector3<f64>,
    pub(super) max: Vector3<f64>,
}

impl Default for Bounds {
    fn default() -> Self {
        Bounds {
            min: Vector3::repeat(f64::INFINITY),
            max: Vector3::repeat(f64::NEG_INFINITY),
        }
    }
}

impl Bounds {
    pub(super) fn add(&mut self, p: &Vector3<f64>, radius: f64) {
        let r = Vector3::repeat(radius);
        self.min = self.min.inf(&(p - r));
        self.max = self.max.sup(&(p + r));
    }

    pub(super) fn center(&self) -> Vector3<f64> {
        0.5 * (self.min + self.max)
    }

    pub(super) fn pad(&mut self, margin: f64) {
        self.min -= Vector3::repeat(margin);
        self.max += Vector3::repeat(margin);
    }

    /// The polygon where the plane `n·x = offset` (unit `n`) cuts the box: the crossings of
    /// the box's 12 edges, ordered by angle about their centroid in the plane. Fewer than 3
    /// corners when the plane misses the box.
    fn plane_section(&self, n: &Vector3<f64>, offset: f64) -> Vec<Vector3<f64>> {
        let corner = |k: usize| {
            Vector3::new(
                if k & 1 == 0 { self.min.x } else { self.max.x },
                if k & 2 == 0 { self.min.y } else { self.max.y },
                if k & 4 == 0 { self.min.z } else { self.max.z },
            )
        };
        let mut points: Vec<Vector3<f64>> = Vec::with_capacity(12);
        let mut push = |p: Vector3<f64>| {
            if points.iter().all(|x| (x - p).norm() > 1e-6) {
                points.push(p);
            }
        };
        for k in 0..8 {
            for bit in [1, 2, 4] {
                if k & bit != 0 {
                    continue;
                }
                let (p0, p1) = (corner(k), corner(k | bit));
                let (s0, s1) = (n.dot(&p0) - offset, n.dot(&p1) - offset);
                if s0 == 0.0 {
                    push(p0);
                }
                if s1 == 0.0 {
                    push(p1);
                }
                if s0 * s1 < 0.0 {
                    push(p0 + (p1 - p0) * (s0 / (s0 - s1)));
                }
            }
        }
        if points.len() < 3 {
            return points;
        }
        let centroid = points.iter().sum::<Vector3<f64>>() / points.len() as f64;
        let helper = if n.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let u = n.cross(&helper).normalize();
        let v = n.cross(&u);
        points.sort_by(|p, q| {
            let (dp, dq) = (p - centroid, q - centroid);
            dp.dot(&v)
                .atan2(dp.dot(&u))
                .total_cmp(&dq.dot(&v).atan2(dq.dot(&u)))
        });
        points
    }
}

/// Rounds to `1/scale` and turns −0 into 0.
pub(super) fn round_to(x: f64, scale: f64) -> f64 {
    (x * scale).round() / scale + 0.0
}

/// A length rounded to 0.1 mm.
pub(super) fn mm(x: f64) -> f64 {
    round_to(x, 10.0)
}

/// FNV-1a, 64 bit: a stable hash of the section's data for its id.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(*b)).wrapping_mul(0x0100_0000_01b3)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The section of a unit cube by planes through its corners, edges and faces.
    #[test]
    fn plane_sections_of_a_box() {
        let b = Bounds {
            min: Vector3::zeros(),
            max: Vector3::repeat(1.0),
        };
        // Mid plane x = 0.5: a square.
        assert_eq!(b.plane_section(&Vector3::x(), 0.5).len(), 4);
        // A face: the square of its four corners.
        assert_eq!(b.plane_section(&Vector3::z(), 0.0).len(), 4);
        // x + y + z = 1.5 (normalised): the regular hexagon.
        let n = Vector3::repeat(1.0).normalize();
        let hex = b.plane_section(&n, 1.5 / 3f64.sqrt());
        assert_eq!(hex.len(), 6);
        // Consecutive corners of the ordered hexagon are one side apart (√2/2).
        for (k, (p, q)) in hex.iter().zip(hex.iter().cycle().skip(1)).enumerate() {
            let d = (p - q).norm();
            assert!((d - 0.5f64.sqrt()).abs() < 1e-12, "side {k}: {d}");
        }
        // A plane outside the box.
        assert!(b.plane_section(&Vector3::x(), 2.0).len() < 3);
    }
}
