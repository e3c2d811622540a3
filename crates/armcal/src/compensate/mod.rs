//! Compensation (book ch. 5): making the robot move differently because of a calibration —
//! calibrated inverse kinematics and program filtering.

pub mod closed_form;
pub mod cmac;
pub(crate) mod controller_program;
pub(crate) mod damped_step;
pub mod ik;
pub mod joint_change;
pub mod lqr;
pub mod nonparametric;
pub mod program;

pub use ik::{CalibratedIk, IkSettings, IkStatus, IkTarget};
