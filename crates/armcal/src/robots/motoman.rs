//! The Yaskawa Motoman dual-arm robot of Rozlivek, Rustler, Stepanova & Hoffmann,
//! "Multisensorial robot calibration framework and toolbox", IEEE-RAS Humanoids 2021: a
//! rotating torso (external axis E) carrying two 6-joint arms (S, L, U, R, B, T), measured
//! with a Leica laser tracker whose reflector sits on the end effector. One chain per arm,
//! exactly the toolbox's nominal model (`UserData/Robots/Motoman/loadMotomanLeica.m` of
//! ctu-vras/multirobot-calibration, copied with the data to `data/motoman-leica/`), metres
//! converted to mm. Standard DH `Rz(θ+q) Tz(d) Tx(a) Rx(α)`:
//!
//! | link | joint | θ (offset) | d (mm) | a (mm) | α |
//! |---|---|---|---|---|---|
//! | `tt1` / `tt2` | `e` | −90° | −263 | 0 | +15° (right) / −15° (left) |
//! | `s1` / `s2` | `s1` / `s2` | 0 | 1415.9 | 150 | −90° |
//! | `l1` / `l2` | `l1` / `l2` | −90° | 0 | 614 | 180° |
//! | `u1` / `u2` | `u1` / `u2` | 0 | 0 | 200 | −90° |
//! | `r1` / `r2` | `r1` / `r2` | 0 | −640 | 0 | 90° |
//! | `b1` / `b2` | `b1` / `b2` | −90° | 0 | 30 | 90° |
//! | `t1` / `t2` | `t1` / `t2` | 0 | 200 | 0 | 0 |
//! | `lr1` / `lr2` | none | −0.38 rad / 0 | 245 / 250 | 45 / 50 | 0 |
//!
//! Link names are the toolbox's (lower case), joint names the data files' columns (`e`, `s1`,
//! …, `t1`; `s2`, …, `t2`). The reflector mount is a fixed DH link (`lr1` / `lr2`, no joint)
//! before the identity `tool` frame rather than being folded into the tool frame, so its
//! parameters keep the toolbox's names and values and can be freed one by one; the `tool`
//! frame origin is the reflector centre.
//!
//! Verified against the tracker data (`tests/suite/real_data/motoman_nominal.rs`): after fitting only the
//! tracker-to-base transform the nominal chains reproduce the 6×6×6 grids to about 0.35 mm RMS
//! for both arms, and reversing any one arm joint costs 9 mm RMS or more. The torso row and
//! the reflector offset cannot be checked with these data: E and the other arm do not move,
//! each arm was measured from its own tracker station, and the end-effector orientation is
//! constant (to 0.1°) over each grid.

use super::{dh_capsules, frame_link, revolute, Robot};
use crate::model::{LinkGeometry, LinkSpec, ModelSpec};

/// Which arm the chain ends in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Arm {
    Right,
    Left,
}

/// Stand-in joint range (deg): the toolbox gives no limits and the controller's ranges are
/// not tied to this DH's zero. ±180° covers every recorded pose (all within ±2 rad).
const RANGE_DEG: f64 = 180.0;

/// One arm of the Motoman dual-arm robot, torso joint first.
pub fn motoman(arm: Arm) -> Robot {
    let d = f64::to_radians;
    let (k, side, tilt, reflector) = match arm {
        // reflector link: θ (rad), d, a (mm)
        Arm::Right => (1, "right", 15.0, (-0.38, 245.0, 45.0)),
        Arm::Left => (2, "left", -15.0, (0.0, 250.0, 50.0)),
    };
    // The toolbox's rows: link prefix; θ offset (rad), d, a (mm), α (rad); capsule radius (mm).
    let rows: [(&str, [f64; 5]); 8] = [
        ("tt", [d(-90.0), -263.0, 0.0, d(tilt), 150.0]),
        ("s", [0.0, 1415.9, 150.0, d(-90.0), 150.0]),
        ("l", [d(-90.0), 0.0, 614.0, d(180.0), 90.0]),
        ("u", [0.0, 0.0, 200.0, d(-90.0), 80.0]),
        ("r", [0.0, -640.0, 0.0, d(90.0), 70.0]),
        ("b", [d(-90.0), 0.0, 30.0, d(90.0), 60.0]),
        ("t", [0.0, 200.0, 0.0, 0.0, 50.0]),
        ("lr", [reflector.0, reflector.1, reflector.2, 0.0, 25.0]),
    ];
    let mut links = vec![frame_link("base", [0.0; 3], [0.0; 3])];
    let mut capsules = Vec::new();
    for (prefix, [theta, dd, a, alpha, radius]) in rows {
        let link = format!("{prefix}{k}");
        // the torso joint is E, the reflector mount has none, arm joints share the link name
        let joint = match prefix {
            "tt" => Some("e".to_string()),
            "lr" => None,
            _ => Some(link.clone()),
        };
        capsules.extend(dh_capsules(&link, dd, a, alpha, radius));
        links.push(LinkSpec {
            name: link,
            geometry: LinkGeometry::dh(theta, dd, a, alpha),
            joint: joint.map(|j| revolute(&j, -RANGE_DEG, RANGE_DEG)),
        });
    }
    links.push(frame_link("tool", [0.0; 3], [0.0; 3]));
    let name = format!("motoman-{side}");
    Robot {
        name: name.clone(),
        summary: format!(
            "Yaskawa Motoman dual-arm (CTU Prague), torso + {side} arm + Leica reflector"
        ),
        source: "Nominal DH of the ctu-vras/multirobot-calibration toolbox \
                 (loadMotomanLeica.m, LGPL-3.0-or-later; Rozlivek et al., Humanoids 2021), \
                 metres → mm; data and licence note in data/motoman-leica/. Checked against \
                 the Leica grids to ≈0.35 mm RMS after fitting the tracker frame; the torso \
                 row and the reflector offset are not checked by those data. Joint limits are \
                 a ±180° stand-in (none published with the model). Capsules follow the DH \
                 segments with radii chosen by armcal; the 1415.9 mm S-axis segment stands \
                 for the torso body."
            .into(),
        spec: ModelSpec {
            compliance: None,
            periodic: None,
            payloads: Vec::new(),
            name,
            instrument: None,
            links,
            targets: vec![],
        },
        capsules,
        collision: super::HAND_MADE.into(),
    }
}
