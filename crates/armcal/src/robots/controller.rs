//! The controller joint conventions of the built-in robots
//! ([`crate::model::controller`]): where the vendor's convention is public, the map from the
//! controller's axis values to the built-in model's joint variables, with its source; where
//! it is not, why not (the robot then reads and writes model angles).

use crate::model::controller::{ControllerConvention, JointMap};

/// The vendor convention of built-in robot `name` (`dof` joints), or why armcal has none.
///
/// Every built-in model of a robot with a public convention was built in the vendor's own
/// axis zero and directions, so the map is the identity — stated here with its source, so
/// that a cell importing the same robot from a URDF or `[[robot.links]]` can name it as a
/// preset and a reader sees where it comes from:
///
/// * `kr15`, `kr300`, `kr500`: KUKA axis angles A1–A6 — the joint variables are KUKA's
///   signs and zero (KUKA datasheet axis ranges taken with KUKA's signs; `robots/kuka.rs`,
///   after the KUKA System Software 8 operating and programming instructions, "axis-specific
///   coordinate system": A1, A4, A6 turn mathematically negative about the upward / forward
///   axes, A2, A3, A5 positive about the horizontal axis, HOME = A2 −90°, A3 +90°);
/// * `irb120`: ABB axis angles 1–6 at ABB's calibration position (ABB IRB 120 product
///   specification, "working range" figure; `robots/irb120.rs`);
/// * `ur10`: the UR controller's joint angles (Universal Robots, "DH parameters for
///   calculations of kinematics and dynamics": same zero and signs; `robots/ur10.rs`).
///
/// No public convention: the paper's notional robots (no controller), the PUMA 560 of the
/// book (its Table 6.1 model's zero is the book's, and no public source gives the VAL
/// controller's joint zero against it), and the Motoman arms (the toolbox model the
/// built-in copies does not state how Yaskawa's S, L, U, R, B, T axis values map to it).
pub fn vendor_convention(name: &str, dof: usize) -> Result<ControllerConvention, String> {
    let source = match name {
        "kr15" | "kr300" | "kr500" => {
            "KUKA axis angles A1–A6 (KUKA's signs and zero: the built-in model is built in them)"
        }
        "irb120" => {
            "ABB axis angles 1–6 (ABB's calibration position and directions: the \
                     built-in model is built in them)"
        }
        "ur10" => {
            "Universal Robots joint angles (the UR DH parameters' zero and signs: the \
                   built-in model is built in them)"
        }
        n if n == "paper" || n.starts_with("paper-") => {
            return Err(format!(
                "`{n}` is the paper's notional robot: it has no controller, so no controller \
                 convention (model angles)"
            ))
        }
        "puma560" | "puma560-zrp" => {
            return Err(format!(
                "`{name}`: no public source gives the PUMA controller's joint zero and \
                 directions against the book's model; give them per joint in \
                 [robot.controller]"
            ))
        }
        "motoman-right" | "motoman-left" => {
            return Err(format!(
                "`{name}`: the toolbox model it copies does not state how Yaskawa's axis \
                 values map to its joints; give them per joint in [robot.controller]"
            ))
        }
        _ => {
            return Err(format!(
                "no controller convention named `{name}` (presets: kr15, kr300, kr500, \
                 irb120, ur10)"
            ))
        }
    };
    Ok(ControllerConvention {
        joints: vec![JointMap::IDENTITY; dof],
        source: format!("{name}: {source}"),
    })
}
