//! Kinematic models: conventions, chain, parameter registry, forward kinematics, exact
//! Jacobians, identifiability, configuration sampling, conversions and URDF.

pub(crate) mod branch;
pub(crate) mod chain;
pub(crate) mod complete;
pub mod compliance;
pub mod controller;
pub mod convert;
pub mod export;
pub mod fixed_kinematics;
pub(crate) mod frames;
pub(crate) mod identifiability;
pub(crate) mod jacobian;
pub(crate) mod jacobian_dq_along;
pub(crate) mod joint_correction;
pub(crate) mod kinematics;
pub(crate) mod link;
pub mod periodic;
pub(crate) mod pose;
pub(crate) mod prior;
pub(crate) mod rank_deficit;
pub(crate) mod registry;
pub(crate) mod sampling;
pub(crate) mod station;
pub mod tcp_shift;
pub mod tree;
pub mod ur_kinematics;
pub mod urdf;

pub(crate) use chain::Model;
pub use chain::{LimitTolerance, Link, LinkSpec, ModelSpec, MEASURED_LIMIT_TOLERANCE};
pub use complete::in_form;
pub use identifiability::{analyze, analyze_at, IdentifiableCount};
pub use jacobian::{
    identification_jacobian, identification_jacobian_dq, joint_jacobian, observed_pose,
    observed_position, observed_world, ChainOrder, MixedWorkspace, Observed, Rows,
};
pub use jacobian_dq_along::{identification_jacobian_dq_along, AlongWorkspace};
pub use kinematics::{forward_kinematics, tool_pose, Data};
pub use link::{Convention, LinkGeometry, Motion};
pub(crate) use link::{Joint, JointKind};
pub use pose::{rot_axis, rot_x, rot_y, rotation_log, Pose};
pub(crate) use registry::ParameterStatus;
pub use registry::{Parameter, Segment};
pub(crate) use registry::{Registry, Unit};
pub use sampling::random_configurations;
