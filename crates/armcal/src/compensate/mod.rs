//! Compensation (book ch. 5): making the robot move differently because of a calibration —
//! calibrated inverse kinematics and program filtering.

pub mod closed_form;
pub mod cmac;
pub(crate) mod controller_program;
pub(crate) mod damped_step;
pub(crate) mod ik;
pub(crate) mod joint_change;
pub mod lqr;
pub(crate) mod nonparametric;
pub(crate) mod program;

// The solver's parts and the lower-level program filters, one path each (the calls and
// records are root items: `armcal::calibrated_ik`, `armcal::compensate`, …).
pub(crate) use ik::IkSettings;
pub use ik::{damped_step, task_jacobian_columns, CalibratedIk};
pub use joint_change::joint_change;
pub use nonparametric::chebyshev_nodes;
pub use program::{
    corrected_cartesian_targets, filter_joint_program, filter_joint_program_corrected,
    CorrectedTarget, FilteredRow,
};
