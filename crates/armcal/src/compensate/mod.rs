//! Compensation (book ch. 5): making the robot move differently because of a calibration —
//! calibrated inverse kinematics and program filtering.

pub mod ik;
pub mod nonparametric;
pub mod program;

pub use ik::{calibrated_ik, IkResult, IkSettings, IkStatus, IkTarget};
