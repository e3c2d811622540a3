//! KUKA KR 15, KR 300 and KR 500 in the link structure of the paper's notional robot (paper
//! Table 2, [`super::paper`]), so the three robots of the paper's Table 6 run through the
//! same study: DH links `Rz(θ+q) Tz(d) Tx(a) Rx(α)` with joint 2 in Hayati form
//! `Rz(θ+q) Tx(a) Rx(α) Ry(β)`,
//!
//! | joint | θ | d | a | α |
//! |---|---|---|---|---|
//! | 1 | 0 | 0 | a1 | 90° |
//! | 2 (Hayati, β = 0) | 0 | – | a2 | 0 |
//! | 3 | −90° | 0 | a3 | 90° |
//! | 4 | 0 | −d4 | 0 | −90° |
//! | 5 | 0 | 0 | 0 | 90° |
//! | 6 | 180° | −d6 | 0 | 180° |
//!
//! with a1 the shoulder offset, a2 the upper arm, a3 the elbow offset, d4 the forearm (axis 3
//! to the wrist centre) and d6 the wrist centre to the flange. As in the paper, frame 0 sits at
//! shoulder height (the base height h1 is absorbed by the base/instrument frame) and the base
//! and tool frames are the identity.
//!
//! Joint variables and ranges: the paper's Table 4 ranges for its notional robot are a subset
//! of KUKA datasheet axis ranges taken with KUKA's signs (q2 ≤ 31° against A2 ≤ +35°,
//! q3 ≤ 154° = A3 max, q5 ±87° within A5 ±130°), so here `q_i` is the KUKA axis angle `A_i`
//! and the limits are the datasheet ranges unchanged; the study's working pose
//! (0, −30°, 30°, 0, −90°, 0) lies inside all three. KUKA turns A1, A4, A6 mathematically
//! negative about the upward / forward axes and A2, A3, A5 positive about the horizontal
//! axis; with this DH that makes frame 0 KUKA's DH base frame: at shoulder height, x forward,
//! **z pointing down** (q2 > 0 moves the upper arm towards +z0, i.e. down). The capsules are
//! placed accordingly: the pedestal runs from the floor at z0 = +h1 up towards the shoulder,
//! and a3 > 0 puts the forearm axis above the upper-arm line at A = 0 (as in the
//! KR 300 R2700-2 CAD-based model; not checked for the KR 15/2 and KR 500). A cell that wants
//! z up mounts the robot with base `rx = 180°`; without it the robot hangs like a ceiling
//! mount, reaching towards −z0 as the paper robot does with its Table 4 ranges.

use super::{capsule, dh_capsules, frame_link, joint_link, Capsule, Robot};
use crate::model::{LinkGeometry, ModelSpec};

/// Geometry (mm), axis ranges (deg) and capsule radii (mm) of one KUKA arm.
struct Kr {
    name: &'static str,
    summary: &'static str,
    source: &'static str,
    /// Base height: floor to axis 2 (only used by the pedestal capsule).
    h1: f64,
    a1: f64,
    a2: f64,
    a3: f64,
    d4: f64,
    d6: f64,
    /// Ranges of A1…A6 in degrees.
    ranges: [(f64, f64); 6],
    /// Capsule radii: pedestal, shoulder, upper arm, elbow, forearm, wrist.
    radii: [f64; 6],
}

fn build(k: Kr) -> Robot {
    let d = f64::to_radians;
    let r = k.ranges;
    let links = vec![
        frame_link("base", [0.0; 3], [0.0; 3]),
        joint_link(1, LinkGeometry::dh(0.0, 0.0, k.a1, d(90.0)), r[0]),
        joint_link(2, LinkGeometry::hayati(0.0, k.a2, 0.0, 0.0), r[1]),
        joint_link(3, LinkGeometry::dh(d(-90.0), 0.0, k.a3, d(90.0)), r[2]),
        joint_link(4, LinkGeometry::dh(0.0, -k.d4, 0.0, d(-90.0)), r[3]),
        joint_link(5, LinkGeometry::dh(0.0, 0.0, 0.0, d(90.0)), r[4]),
        joint_link(6, LinkGeometry::dh(d(180.0), -k.d6, 0.0, d(180.0)), r[5]),
        frame_link("tool", [0.0; 3], [0.0; 3]),
    ];
    let [r_ped, r_sh, r_ua, r_el, r_fa, r_wr] = k.radii;
    // Pedestal and rotating column, from the floor (z0 = +h1, z0 points down) up to where its
    // cap clears the upper-arm capsule at the axis-2 point (a1, 0, 0) by 20 mm; the A2
    // gearbox above it is the shoulder capsule.
    let top = ((r_ped + r_ua + 20.0).powi(2) - k.a1 * k.a1).sqrt();
    let mut capsules: Vec<Capsule> =
        vec![capsule("base", [0.0, 0.0, top], [0.0, 0.0, k.h1], r_ped)];
    capsules.extend(dh_capsules("j1", 0.0, k.a1, d(90.0), r_sh));
    capsules.extend(dh_capsules("j2", 0.0, k.a2, 0.0, r_ua));
    capsules.extend(dh_capsules("j3", 0.0, k.a3, d(90.0), r_el));
    // Forearm along −z3 = +y4 in the wrist frame: it starts clear of the upper-arm capsule
    // (which ends at the elbow axis, a3 away) and ends clear of the wrist, so that only real
    // contacts count (a capsule chain that overlaps at every configuration would make every
    // pose infeasible).
    let start = k.d4 - (r_ua + r_fa + 10.0);
    let end = r_fa + 50.0;
    capsules.push(capsule("j4", [0.0, start, 0.0], [0.0, end, 0.0], r_fa));
    capsules.extend(dh_capsules("j6", -k.d6, 0.0, d(180.0), r_wr));
    Robot {
        name: k.name.into(),
        summary: k.summary.into(),
        source: format!("{} {COMMON}", k.source),
        spec: ModelSpec {
            compliance: None,
            periodic: None,
            payloads: Vec::new(),
            name: k.name.into(),
            instrument: None,
            links,
            targets: vec![],
        },
        capsules,
        collision: super::HAND_MADE.into(),
    }
}

const COMMON: &str = "Link structure of the paper's notional robot (Table 2: DH, joint 2 \
     Hayati, d4 = −forearm, joint 6 DH(180°, −d6, 0, 180°)); frame 0 at shoulder height, \
     identity base and tool. q_i = KUKA axis angle A_i with the datasheet ranges (the paper's \
     Table 4 uses KUKA's signs), which makes z0 point down (mount with base rx = 180° for z \
     up). a3 > 0 puts the forearm axis above the upper arm at A = 0. Capsule radii are \
     armcal's choice, sized from the datasheet outline drawings; the pedestal capsule runs \
     from the floor at z0 = +h1 to just below the shoulder.";

/// KUKA KR 15/2 (15 kg, reach 1570 mm).
pub fn kr15() -> Robot {
    build(Kr {
        name: "kr15",
        summary: "KUKA KR 15/2 (approximate, paper structure), reach 1570 mm",
        source: "KUKA KR 15/2 datasheet drawing: h1 = 675, a1 = 300, a2 = 650, a3 = 155, \
             d4 = 600, d6 = 140 mm (read from the drawing; a1 + a2 + √(d4² + a3²) = \
             1569.7 mm matches the stated reach of 1570 mm to the wrist centre). Ranges \
             A1 ±185°, A2 −155°/+35°, A3 −130°/+154°, A4 ±350°, A5 ±130°, A6 ±350° (the \
             KR 6/15/16 family's ranges; the KR 15/2 sheet was not at hand, so treat them \
             as approximate).",
        h1: 675.0,
        a1: 300.0,
        a2: 650.0,
        a3: 155.0,
        d4: 600.0,
        d6: 140.0,
        ranges: [
            (-185.0, 185.0),
            (-155.0, 35.0),
            (-130.0, 154.0),
            (-350.0, 350.0),
            (-130.0, 130.0),
            (-350.0, 350.0),
        ],
        radii: [250.0, 200.0, 120.0, 140.0, 110.0, 70.0],
    })
}

/// KUKA KR 300 R2700-2 (KR QUANTEC, 300 kg, reach 2701 mm).
pub fn kr300() -> Robot {
    build(Kr {
        name: "kr300",
        summary: "KUKA KR 300 R2700-2 (QUANTEC, approximate, paper structure), reach 2701 mm",
        source: "KUKA KR 300 R2700-2 (KR QUANTEC): h1 = 645, a1 = 330, a2 = 1145, a3 = 112, \
             d4 = 1220, d6 = 237.5 mm, as in the ROS-Industrial kuka_experimental model \
             kr300r2700_2 (built from KUKA's CAD; its ±y offsets of the axes sum to zero and \
             are dropped); a1 + a2 + √(d4² + a3²) = 2700.1 mm matches the datasheet reach of \
             2701 mm. Ranges A1 ±185°, A2 −145°/−5°, A3 −120°/+168°, A4 ±350°, A5 ±125°, \
             A6 ±350° (the same model's limits, shifted by its zero A2 = −90°, A3 = +90°).",
        h1: 645.0,
        a1: 330.0,
        a2: 1145.0,
        a3: 112.0,
        d4: 1220.0,
        d6: 237.5,
        ranges: [
            (-185.0, 185.0),
            (-145.0, -5.0),
            (-120.0, 168.0),
            (-350.0, 350.0),
            (-125.0, 125.0),
            (-350.0, 350.0),
        ],
        radii: [350.0, 400.0, 250.0, 280.0, 220.0, 150.0],
    })
}

/// KUKA KR 500 (2000 series, KR 500-3 / R2830, 500 kg, reach 2826 mm).
pub fn kr500() -> Robot {
    build(Kr {
        name: "kr500",
        summary: "KUKA KR 500 R2830 (2000 series, approximate, paper structure), reach 2826 mm",
        source: "KUKA KR 500 (2000 series, KR 500-3 / R2830) datasheet drawing: h1 = 1045, \
             a1 = 500, a2 = 1300, a3 = 55, d4 = 1025, d6 = 290 mm (read from the drawing; \
             a1 + a2 + √(d4² + a3²) = 2826.5 mm matches the stated reach of 2826 mm; d6 is \
             the least certain). Ranges A1 ±185°, A2 −130°/+20°, A3 −100°/+144°, A4 ±350°, \
             A5 ±120°, A6 ±350° (approximate).",
        h1: 1045.0,
        a1: 500.0,
        a2: 1300.0,
        a3: 55.0,
        d4: 1025.0,
        d6: 290.0,
        ranges: [
            (-185.0, 185.0),
            (-130.0, 20.0),
            (-100.0, 144.0),
            (-350.0, 350.0),
            (-120.0, 120.0),
            (-350.0, 350.0),
        ],
        radii: [450.0, 450.0, 300.0, 320.0, 250.0, 170.0],
    })
}
