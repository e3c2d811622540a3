//! A robot armcal does not know — an inline DH table, a URDF of the test's own making — is
//! planned for collision-free against a table (a box obstacle) and the floor, and the test
//! checks every planned pose by itself: its own forward kinematics (DH products, URDF origins
//! and axes), its own capsules between successive joint origins with the radius the cell
//! sets, the URDF's own cylinders, and parry3d's distances (GJK) to the table and the floor.
//! Before issue 30 such a robot had no capsules at all and `plan` printed "every pose
//! feasible" for poses through the table (and the cell's box obstacle did not load); the
//! test also shows that the same check finds many configurations of a grid in the table or
//! the floor. The arm's own self collision is checked the same way, over the pairs the
//! planner checks (not neighbouring bodies, not the pairs `plan` names as in contact
//! everywhere), with a grid showing that check can fail too.

use super::common::{armcal, scratch};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use parry3d_f64::math::{Pose, Rot3, Vector};
use parry3d_f64::query;
use parry3d_f64::shape::{Capsule, Cuboid, Cylinder, HalfSpace, Shape};

/// The link radius the cells set (mm), and the clearance every planned pose keeps (the
/// cell's default `[design] clearance_mm`, less the refinement's rounding).
const RADIUS: f64 = 60.0;
const CLEARANCE: f64 = 5.0 - 1e-3;

/// KR 6 R900-like standard DH table: θ offset (deg), d, a (mm), α (deg), limits (deg).
const DH: [(f64, f64, f64, f64, [f64; 2]); 6] = [
    (0.0, 400.0, 25.0, -90.0, [-170.0, 170.0]),
    (-90.0, 0.0, 455.0, 0.0, [-190.0, 45.0]),
    (0.0, 0.0, 35.0, -90.0, [-120.0, 156.0]),
    (0.0, 420.0, 0.0, 90.0, [-185.0, 185.0]),
    (0.0, 0.0, 0.0, -90.0, [-120.0, 120.0]),
    (0.0, 80.0, 0.0, 0.0, [-350.0, 350.0]),
];

/// The table: centre and edge lengths (mm), axis-aligned.
const TABLE_CENTER: [f64; 3] = [650.0, 0.0, 300.0];
const TABLE_SIZE: [f64; 3] = [500.0, 1000.0, 600.0];

fn rest_of_cell() -> String {
    format!(
        "[instrument]\nname = \"tracker\"\nkind = \"laser-tracker\"\nxyz_mm = [2200, -1800, 900]\n\
         rpy_deg = [0, 0, 0]\nnoise = {{ model = \"constant\", sigma_mm = 0.05 }}\n\n\
         [[targets]]\nname = \"smr1\"\nxyz_mm = [0, 0, 60]\n\n[parameters]\n\
         fixed = [\"base\", \"tool\"]\nfree = \"auto\"\nmeasurement = \"position\"\n\n\
         [[working]]\nname = \"over-the-table\"\njoints_deg = [0, -60, 40, 0, 60, 0]\n\n\
         [[obstacles]]\nname = \"floor\"\nkind = \"half-space\"\nnormal = [0, 0, 1]\noffset_mm = 0\n\n\
         [[obstacles]]\nname = \"table\"\nkind = \"box\"\ncenter_mm = {TABLE_CENTER:?}\n\
         size_mm = {TABLE_SIZE:?}\n"
    )
}

fn dh_cell() -> String {
    let mut s = format!(
        "name = \"kr6-dh-table\"\n[robot]\nname = \"kr6-like\"\nlink_radius_mm = {RADIUS}\n"
    );
    for (theta, d, a, alpha, lim) in DH {
        s += &format!(
            "\n[[robot.links]]\nconvention = \"dh\"\njoint = \"revolute\"\nlimits = {lim:?}\n\
             theta_deg = {theta}\nd_mm = {d}\na_mm = {a}\nalpha_deg = {alpha}\n"
        );
    }
    s + "\n" + &rest_of_cell()
}

/// Frame origins O₀ … O₆ of the DH chain at `q` (deg): `T_i = Rz(θ_i + q_i) Tz(d_i) Tx(a_i)
/// Rx(α_i)`. O_{i−1} lies on joint i's axis.
fn dh_origins(q: &[f64]) -> Vec<Vector3<f64>> {
    let mut t = Isometry3::identity();
    let mut out = vec![t.translation.vector];
    for (i, (theta, d, a, alpha, _)) in DH.iter().enumerate() {
        t =
            t * Isometry3::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_axis_angle(&Vector3::z_axis(), (theta + q[i]).to_radians()),
            ) * Translation3::new(*a, 0.0, *d)
                * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), alpha.to_radians());
        out.push(t.translation.vector);
    }
    out
}

/// A URDF of the same arm: origins and axes per joint (m), a tool0 80 mm beyond joint 6;
/// the upper arm and forearm carry collision cylinders (radius 70 mm), the rest nothing.
const URDF_JOINTS: [([f64; 3], [f64; 3], [f64; 2]); 6] = [
    ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [-2.96, 2.96]),
    ([0.025, 0.0, 0.4], [0.0, 1.0, 0.0], [-2.4, 0.78]),
    ([0.0, 0.0, 0.455], [0.0, 1.0, 0.0], [-2.0, 2.7]),
    ([0.42, 0.0, 0.035], [1.0, 0.0, 0.0], [-3.2, 3.2]),
    ([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-2.0, 2.0]),
    ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [-6.0, 6.0]),
];
const CYLINDER_RADIUS: f64 = 70.0;

fn urdf() -> String {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<robot name=\"kr6-urdf\">\n  <link name=\"base_link\"/>\n",
    );
    for (k, (xyz, axis, lim)) in URDF_JOINTS.iter().enumerate() {
        let i = k + 1;
        // Link 2 (upper arm, up to joint 3) and link 3 (forearm to the wrist): cylinders along
        // the link, centred between the joints.
        let collision = match i {
            2 => format!("<collision><origin xyz=\"0 0 0.2275\" rpy=\"0 0 0\"/><geometry><cylinder radius=\"{}\" length=\"0.455\"/></geometry></collision>", CYLINDER_RADIUS / 1000.0),
            3 => format!("<collision><origin xyz=\"0.21 0 0.035\" rpy=\"0 1.5707963267948966 0\"/><geometry><cylinder radius=\"{}\" length=\"0.42\"/></geometry></collision>", CYLINDER_RADIUS / 1000.0),
            _ => String::new(),
        };
        s += &format!("  <link name=\"link{i}\">{collision}</link>\n");
        s += &format!(
            "  <joint name=\"joint{i}\" type=\"revolute\"><parent link=\"{}\"/><child link=\"link{i}\"/>\
             <origin xyz=\"{} {} {}\" rpy=\"0 0 0\"/><axis xyz=\"{} {} {}\"/>\
             <limit lower=\"{}\" upper=\"{}\" effort=\"0\" velocity=\"0\"/></joint>\n",
            if i == 1 { "base_link".to_string() } else { format!("link{}", i - 1) },
            xyz[0], xyz[1], xyz[2], axis[0], axis[1], axis[2], lim[0], lim[1]
        );
    }
    s += "  <link name=\"tool0\"/>\n  <joint name=\"flange\" type=\"fixed\"><parent link=\"link6\"/><child link=\"tool0\"/><origin xyz=\"0.08 0 0\" rpy=\"0 0 0\"/></joint>\n</robot>\n";
    s
}

/// World poses of the URDF links 1…6 and tool0 at `q` (deg), in mm.
fn urdf_frames(q: &[f64]) -> Vec<Isometry3<f64>> {
    let mut t = Isometry3::identity();
    let mut out = Vec::new();
    for (k, (xyz, axis, _)) in URDF_JOINTS.iter().enumerate() {
        let axis = nalgebra::Unit::new_normalize(Vector3::from(*axis));
        t = t
            * Translation3::new(xyz[0] * 1e3, xyz[1] * 1e3, xyz[2] * 1e3)
            * UnitQuaternion::from_axis_angle(&axis, q[k].to_radians());
        out.push(t);
    }
    out.push(t * Translation3::new(80.0, 0.0, 0.0));
    out
}

fn pose(iso: &Isometry3<f64>) -> Pose {
    let q = iso.rotation;
    let v = iso.translation.vector;
    Pose::from_parts(
        Vector::new(v.x, v.y, v.z),
        Rot3::from_xyzw(q.i, q.j, q.k, q.w).normalize(),
    )
}

fn capsule(a: &Vector3<f64>, b: &Vector3<f64>) -> Capsule {
    Capsule::new(
        Vector::new(a.x, a.y, a.z),
        Vector::new(b.x, b.y, b.z),
        RADIUS,
    )
}

/// parry's distance of two placed shapes, or its signed contact depth where they overlap
/// (negative).
fn signed(shape: &dyn Shape, at: &Pose, other: &dyn Shape, other_at: &Pose) -> f64 {
    let d = query::distance(at, shape, other_at, other)
        .expect("supported")
        .distance;
    if d > 0.0 {
        return d;
    }
    query::contact(at, shape, other_at, other, 0.0)
        .expect("supported")
        .map_or(0.0, |c| c.dist)
}

/// Smallest parry distance of `bodies` (shape, world pose) to the table and to the floor;
/// a negative value is an overlap (parry's signed contact depth).
fn clearances(bodies: &[(Box<dyn Shape>, Pose)]) -> (f64, f64) {
    let table = Cuboid::new(Vector::new(
        TABLE_SIZE[0] / 2.0,
        TABLE_SIZE[1] / 2.0,
        TABLE_SIZE[2] / 2.0,
    ));
    let table_pose = Pose::from_translation(Vector::new(
        TABLE_CENTER[0],
        TABLE_CENTER[1],
        TABLE_CENTER[2],
    ));
    let floor = HalfSpace::new(Vector::new(0.0, 0.0, 1.0));
    let mut out = (f64::INFINITY, f64::INFINITY);
    for (shape, at) in bodies {
        out.0 = out.0.min(signed(shape.as_ref(), at, &table, &table_pose));
        out.1 = out
            .1
            .min(signed(shape.as_ref(), at, &floor, &Pose::identity()));
    }
    out
}

/// The DH arm's bodies at `q`: a capsule between successive distinct frame origins (the
/// base's first one from O₁, which stands on the floor by construction at O₀).
fn dh_bodies(q: &[f64]) -> Vec<(Box<dyn Shape>, Pose)> {
    let o = dh_origins(q);
    let mut bodies: Vec<(Box<dyn Shape>, Pose)> = Vec::new();
    // O₀ → O₁ starts in the floor (the base); its upper end is checked as a sphere.
    bodies.push((Box::new(capsule(&o[1], &o[1])), Pose::identity()));
    for w in o[1..].windows(2) {
        if (w[1] - w[0]).norm() > 1e-6 {
            bodies.push((Box::new(capsule(&w[0], &w[1])), Pose::identity()));
        }
    }
    bodies
}

/// The URDF arm's bodies at `q`: its two cylinders where it has them, and capsules between
/// the joint origins where it has none (links 1, 4–6, and the flange to tool0).
fn urdf_bodies(q: &[f64]) -> Vec<(Box<dyn Shape>, Pose)> {
    let f = urdf_frames(q);
    let o: Vec<Vector3<f64>> = f.iter().map(|t| t.translation.vector).collect();
    let mut bodies: Vec<(Box<dyn Shape>, Pose)> = vec![
        (Box::new(capsule(&o[1], &o[1])), Pose::identity()),
        // link 2: along its z from the joint-2 origin; link 3: along its x (rpy pitch 90°).
        (
            Box::new(Cylinder::new(227.5, CYLINDER_RADIUS)),
            pose(
                &(f[1]
                    * Translation3::new(0.0, 0.0, 227.5)
                    * UnitQuaternion::from_axis_angle(
                        &Vector3::x_axis(),
                        std::f64::consts::FRAC_PI_2,
                    )),
            ),
        ),
        (
            Box::new(Cylinder::new(210.0, CYLINDER_RADIUS)),
            pose(
                &(f[2]
                    * Translation3::new(210.0, 0.0, 35.0)
                    * UnitQuaternion::from_axis_angle(
                        &Vector3::z_axis(),
                        std::f64::consts::FRAC_PI_2,
                    )),
            ),
        ),
    ];
    for w in o[3..].windows(2) {
        if (w[1] - w[0]).norm() > 1e-6 {
            bodies.push((Box::new(capsule(&w[0], &w[1])), Pose::identity()));
        }
    }
    bodies
}

/// A body of the arm with the frame it moves with (`plan`'s capsule names).
type Labelled = (String, Box<dyn Shape>, Pose);

/// The DH arm's skeleton as the planner derives it (`robots/skeleton.rs`): the segment
/// O_{k−1} O_k from joint k's point to the next on the frame of joint k (`jk`), a segment
/// shorter than 1 µm left out (the spherical wrist's O₄ O₅), each a capsule of the cell's
/// radius. The tool frame is the flange: no tool segment.
fn dh_skeleton(q: &[f64]) -> Vec<Labelled> {
    let o = dh_origins(q);
    (1..o.len())
        .filter(|&k| (o[k] - o[k - 1]).norm() > 1e-3)
        .map(|k| {
            let shape: Box<dyn Shape> = Box::new(capsule(&o[k - 1], &o[k]));
            (format!("j{k}"), shape, Pose::identity())
        })
        .collect()
}

/// The URDF arm's bodies by frame, as `plan` names them: `joint1`'s skeleton segment (its
/// origin to joint 2's), the URDF's own cylinders on `joint2` and `joint3` (the planner
/// checks capsules bounding them, so the cylinders inside keep at least its clearance), and
/// the `tool` segment from the wrist to tool0 (the wrist's own segments have no length).
fn urdf_labelled(q: &[f64]) -> Vec<Labelled> {
    let f = urdf_frames(q);
    let o: Vec<Vector3<f64>> = f.iter().map(|t| t.translation.vector).collect();
    let mut bodies = urdf_bodies(q);
    let tool = bodies.pop().expect("the flange segment");
    let cylinders: Vec<_> = bodies.drain(1..3).collect();
    let mut out: Vec<Labelled> = vec![(
        "joint1".into(),
        Box::new(capsule(&o[0], &o[1])),
        Pose::identity(),
    )];
    for (k, (shape, at)) in cylinders.into_iter().enumerate() {
        out.push((format!("joint{}", k + 2), shape, at));
    }
    out.push(("tool".into(), tool.0, tool.1));
    out
}

/// The capsule pairs `plan` names as in contact everywhere (and so does not check), as
/// frame names: from `not checked, in contact … : capsule j2#0 / j4#0, …`.
fn pairs_in_contact(plan_stdout: &str) -> Vec<(String, String)> {
    let frame = |s: &str| {
        s.trim()
            .trim_start_matches("capsule ")
            .split('#')
            .next()
            .unwrap()
            .to_string()
    };
    plan_stdout
        .lines()
        .find(|l| l.starts_with("not checked, in contact"))
        .map(|l| {
            l.split_once("): ")
                .unwrap()
                .1
                .split(", ")
                .map(|p| {
                    let (a, b) = p.split_once(" / ").unwrap();
                    (frame(a), frame(b))
                })
                .collect()
        })
        .unwrap_or_default()
}

/// The arm's least self clearance by parry over the pairs of `bodies` the planner checks
/// (paper eq. 24b, `design/cell_constraints`): not neighbours in chain order among the
/// frames that carry a body (`bodies` lists them in that order, one per frame), and not a
/// pair `plan` names as in contact everywhere (`skip`). Negative: an overlap.
fn self_clearance(bodies: &[Labelled], skip: &[(String, String)]) -> f64 {
    let mut least = f64::INFINITY;
    for i in 0..bodies.len() {
        for j in i + 2..bodies.len() {
            let (a, b) = (&bodies[i], &bodies[j]);
            if skip
                .iter()
                .any(|(x, y)| (x == &a.0 && y == &b.0) || (x == &b.0 && y == &a.0))
            {
                continue;
            }
            least = least.min(signed(a.1.as_ref(), &a.2, b.1.as_ref(), &b.2));
        }
    }
    least
}

/// Joint values (deg) of every pose of a design CSV.
fn design(path: &std::path::Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| {
            l.split(',')
                .skip(1)
                .map(|v| v.trim().parse().unwrap())
                .collect()
        })
        .collect()
}

/// `plan` of `cell` (written as `dir/name.toml`): stdout, stderr and the planned poses.
fn plan(dir: &std::path::Path, cell: &str, name: &str) -> (String, String, Vec<Vec<f64>>) {
    let cell_path = dir.join(format!("{name}.toml"));
    std::fs::write(&cell_path, cell).unwrap();
    let out = dir.join(format!("{name}.csv"));
    let (ok, stdout, err) = armcal(&[
        "plan",
        "--cell",
        cell_path.to_str().unwrap(),
        "--poses",
        "24",
        "--starts",
        "1",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "plan of {name}:\n{stdout}\n{err}");
    (stdout, err, design(&out))
}

#[test]
fn a_users_dh_and_urdf_robots_plan_clear_of_a_table_and_the_floor() {
    let dir = scratch("collision-model");
    std::fs::write(dir.join("kr6.urdf"), urdf()).unwrap();
    let urdf_cell = format!(
        "name = \"kr6-urdf-table\"\n[robot]\nurdf = \"kr6.urdf\"\nlink_radius_mm = {RADIUS}\n\n{}",
        rest_of_cell()
    );
    type Bodies = fn(&[f64]) -> Vec<(Box<dyn Shape>, Pose)>;
    type Arm = fn(&[f64]) -> Vec<Labelled>;
    for (name, cell, bodies, arm) in [
        ("dh", dh_cell(), dh_bodies as Bodies, dh_skeleton as Arm),
        ("urdf", urdf_cell, urdf_bodies, urdf_labelled),
    ] {
        let (stdout, _, poses) = plan(&dir, &cell, name);
        assert!(stdout.contains("every pose feasible"), "{name}:\n{stdout}");
        assert!(
            stdout.contains("arm collision model: "),
            "{name}:\n{stdout}"
        );
        assert_eq!(poses.len(), 24);
        let mut worst = (f64::INFINITY, f64::INFINITY);
        for (k, q) in poses.iter().enumerate() {
            let (table, floor) = clearances(&bodies(q));
            assert!(
                table >= CLEARANCE && floor >= CLEARANCE,
                "{name}: pose {} {q:?}: {table:.2} mm from the table, {floor:.2} mm from the floor",
                k + 1
            );
            worst = (worst.0.min(table), worst.1.min(floor));
        }
        eprintln!(
            "{name}: least clearance of 24 planned poses: table {:.2} mm, floor {:.2} mm",
            worst.0, worst.1
        );
        // The arm's own self collision, by the test's own bodies and parry.
        let skip = pairs_in_contact(&stdout);
        let least = poses
            .iter()
            .map(|q| self_clearance(&arm(q), &skip))
            .fold(f64::INFINITY, f64::min);
        eprintln!("{name}: least self clearance of 24 planned poses {least:.2} mm (pairs not checked: {skip:?})");
        assert!(
            least >= CLEARANCE,
            "{name}: a planned pose in self collision: {least:.2} mm"
        );
        // The check has teeth: over a grid of the shoulder, elbow and wrist joints, a good
        // share of configurations put the arm into the table or the floor.
        let mut grid = Vec::new();
        for q1 in [-30.0, 0.0, 30.0] {
            for k2 in 0..12 {
                for k3 in 0..10 {
                    for q5 in [-90.0, 0.0, 90.0] {
                        grid.push([
                            q1,
                            -170.0 + 18.0 * k2 as f64,
                            -110.0 + 25.0 * k3 as f64,
                            0.0,
                            q5,
                            0.0,
                        ]);
                    }
                }
            }
        }
        let hits = grid
            .iter()
            .filter(|q| {
                let (t, f) = clearances(&bodies(&q[..]));
                t < 0.0 || f < 0.0
            })
            .count();
        eprintln!(
            "{name}: {hits} of {} grid configurations hit the table or the floor",
            grid.len()
        );
        assert!(
            5 * hits >= grid.len(),
            "{name}: only {hits} of {} grid configurations hit",
            grid.len()
        );
        // The self-collision check has teeth too: the elbow folds the forearm and the
        // wrist onto the base and upper arm.
        let folded = grid
            .iter()
            .filter(|q| self_clearance(&arm(&q[..]), &skip) < 0.0)
            .count();
        eprintln!(
            "{name}: {folded} of {} grid configurations in self collision",
            grid.len()
        );
        assert!(
            folded > 0,
            "{name}: no grid configuration in self collision"
        );
    }
}

#[test]
fn an_arm_without_a_collision_model_is_planned_with_a_loud_warning() {
    let dir = scratch("collision-model-none");
    // The cell draws its arm with [[robot.capsules]], which replace the skeleton, but only
    // a pedestal on the base: no capsule moves with a joint.
    let cell = dh_cell()
        .replace(&format!("link_radius_mm = {RADIUS}\n"), "")
        .replace(
            "\n[instrument]",
            "\n[[robot.capsules]]\nframe = \"base\"\na_mm = [0, 0, 0]\nb_mm = [0, 0, 100]\nradius_mm = 50\n\n[instrument]",
        );
    assert!(cell.contains("[[robot.capsules]]") && !cell.contains("link_radius_mm"));
    let (stdout, err, _) = plan(&dir, &cell, "bare");
    assert!(
        err.contains("WARNING: the arm of `kr6-dh-table` has NO collision model (no capsule moves with a joint): self collision, the obstacles and the floor are NOT checked"),
        "{err}"
    );
    assert!(
        stdout.contains("every pose within them, but the arm's collisions are NOT checked")
            && !stdout.contains("every pose feasible"),
        "{stdout}"
    );
}

/// A zero skeleton radius builds lines, not an arm: the cell loads (a line is a valid
/// capsule) with a warning on every command that reads it; a positive radius warns nothing.
#[test]
fn a_zero_link_radius_warns_that_the_skeleton_has_no_volume() {
    let dir = scratch("collision-model-zero-radius");
    let path = dir.join("cell.toml");
    for (radius, warns) in [("0", true), ("0.0", true), ("60", false)] {
        let cell = dh_cell().replace(
            &format!("link_radius_mm = {RADIUS}\n"),
            &format!("link_radius_mm = {radius}\n"),
        );
        std::fs::write(&path, &cell).unwrap();
        let (ok, out, err) = armcal(&["model", path.to_str().unwrap()]);
        assert!(ok, "{err}");
        assert!(
            out.contains(&format!("radius {} mm", radius.trim_end_matches(".0"))),
            "{out}"
        );
        let warned = err.contains(
            "warning: `[robot] link_radius_mm = 0`: a skeleton capsule of radius 0 is the line \
             between two joint origins, which does not model the arm's volume",
        );
        assert_eq!(warned, warns, "radius {radius}: {err}");
    }
    // one frame's radius
    let cell = dh_cell().replace(
        &format!("link_radius_mm = {RADIUS}\n"),
        "link_radii_mm = { j2 = 0 }\n",
    );
    std::fs::write(&path, &cell).unwrap();
    let (ok, _, err) = armcal(&["model", path.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(
        err.contains("warning: `[robot] link_radii_mm.j2 = 0`: a skeleton capsule of radius 0"),
        "{err}"
    );
}
