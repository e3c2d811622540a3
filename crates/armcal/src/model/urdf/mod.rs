//! URDF import (`import`) and export (`export`) (urdf-rs 0.10).
//!
//! **Import** ([`read_urdf`], [`from_urdf_str`], [`from_urdf_robot`]) takes the serial chain
//! from the root link (the one link that is no joint's child) to a tip link (by default the
//! single leaf). Every joint on it becomes one link of the model, named after the URDF joint
//! (`.` and `*`, which armcal reserves for parameter patterns, become `_`):
//!
//! - revolute, continuous, prismatic: a [`Convention::Urdf`](crate::model::Convention::Urdf)
//!   link, origin `T(x, y, z) Rz(yaw) Ry(pitch) Rx(roll)` then a rotation about (translation
//!   along) the unit `axis` by `q + offset`, offset 0; its joint carries the URDF joint's
//!   name and limits;
//! - fixed: a [`Convention::Frame6`](crate::model::Convention::Frame6) link with the same
//!   origin (`Frame6` is the URDF origin).
//!
//! URDF lengths are metres, armcal's millimetres. Limits: revolute `[lower, upper]` rad as
//! given (an omitted limit, URDF ≥ 1.2, means ±[`CONTINUOUS_RANGE`]); continuous joints get
//! ±[`CONTINUOUS_RANGE`] = ±2π; prismatic joints need finite limits (m → mm). An identity
//! `base` frame precedes the chain and an identity `tool` frame ends it, so the result has the
//! shape of every armcal robot. [`read_urdf_with_collisions`] also returns the chain links'
//! `<collision>` shapes (box, cylinder, capsule, sphere; a mesh by its file name, which armcal
//! does not read), each on the chain frame its link moves with; the cell bounds them by
//! capsules (`robots/bounding.rs`). Inertia, visual geometry and links off the chain are
//! ignored; a `<mimic>` joint on the chain is refused (a serial chain has no coupled
//! joints): a URDF that branches or has mimic joints loads as a kinematic tree
//! ([`read_urdf_tree`], module `tree`).
//!
//! **Export** ([`to_urdf`]) writes any chain, in any convention, as a URDF serial chain. Every
//! link transform is split at its joint motion, `T_i(q) = A_i · J(q) · B_i`, with `A_i` the
//! elementary factors up to and including the joint's own factor at its nominal value, `J` the
//! unit joint motion (about / along the axis `e` of that factor) and `B_i` the factors after
//! it (for the zero-reference model `T(p) Rot(û, off + q) T(−p)`: `A = T(p) Rot(û, off)`,
//! `J = Rot(û, q)`, `B = T(−p)`). The fixed transforms between two joint motions,
//! `B_{i−1} · (fixed links) · A_i`, become joint `i`'s `<origin>`, `e` its `<axis>`, and its
//! limits are kept (mm → m). The chain ends in a fixed joint to a link named after the last
//! chain link (the tool), and every target hangs off that link with a fixed joint. The
//! instrument frame belongs to a cell, not to the robot, and is not exported. The intermediate
//! URDF links are the joint frames, not armcal's link-end frames; the end of the chain and the
//! targets are exact.

pub(crate) mod calibration;
pub mod depth;
pub(crate) mod export;
pub(crate) mod import;
pub mod joint_corrections;
pub(crate) mod tree;

pub use calibration::{conservative, Dropped};
pub use export::to_urdf;
pub use import::{
    from_urdf_robot, from_urdf_str, from_urdf_str_with_collisions, read_urdf,
    read_urdf_with_collisions, CollisionGeometry, CollisionShape,
};
pub use tree::{read_urdf_tree, tree_from_urdf_str, tree_to_urdf};

use std::collections::HashSet;

/// Joint range given to continuous joints and to revolute joints without limits: ±2π rad.
pub const CONTINUOUS_RANGE: f64 = 2.0 * std::f64::consts::PI;

/// Metres per millimetre.
const M_PER_MM: f64 = 1e-3;

/// Reads the text file `path` (capped at [`crate::input::TEXT_CAP`]) and parses it with
/// `parse`; every error names the file, an input error as the file's message. `what` names
/// the kind of file in a read error ("the URDF file").
pub(crate) fn parse_file<T>(
    path: &std::path::Path,
    what: &str,
    parse: impl FnOnce(&str) -> Result<T, crate::Error>,
) -> Result<T, crate::Error> {
    use crate::Error;
    let file = path.display().to_string();
    let text =
        crate::input::read_capped(path, crate::input::TEXT_CAP).map_err(|e| Error::File {
            file: file.clone(),
            message: format!("cannot read {what}: {e}"),
        })?;
    parse(&text).map_err(|e| Error::File {
        file,
        message: match e {
            Error::Input(m) => m,
            other => other.to_string(),
        },
    })
}

/// `name`, or `name_2`, `name_3`, … if taken; records the result as taken.
fn unique(name: &str, taken: &mut HashSet<String>) -> String {
    let mut candidate = name.to_string();
    let mut k = 1;
    while taken.contains(&candidate) {
        k += 1;
        candidate = format!("{name}_{k}");
    }
    taken.insert(candidate.clone());
    candidate
}

#[cfg(test)]
mod tests;
