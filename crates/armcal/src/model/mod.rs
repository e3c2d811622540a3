//! Kinematic models: conventions, chain, parameter registry, forward kinematics, exact
//! Jacobians, identifiability, configuration sampling, conversions and URDF.

pub(crate) mod branch;
pub(crate) mod chain;
pub mod complete;
pub mod compliance;
pub mod controller;
pub mod convert;
pub mod export;
pub mod fixed_kinematics;
pub(crate) mod frames;
pub mod identifiability;
pub(crate) mod jacobian;
pub(crate) mod jacobian_dq_along;
pub(crate) mod joint_correction;
pub(crate) mod kinematics;
pub(crate) mod link;
pub mod periodic;
pub mod pose;
pub(crate) mod prior;
pub(crate) mod rank_deficit;
pub(crate) mod registry;
pub mod sampling;
pub(crate) mod station;
pub mod tcp_shift;
pub mod tree;
pub mod ur_kinematics;
pub mod urdf;

pub use chain::{LimitTolerance, Link, LinkSpec, Model, ModelSpec, MEASURED_LIMIT_TOLERANCE};
pub use jacobian::{
    identification_jacobian, identification_jacobian_dq, joint_jacobian, observed_pose,
    observed_position, observed_world, ChainOrder, MixedWorkspace, Observed, Rows,
};
pub use jacobian_dq_along::{identification_jacobian_dq_along, AlongWorkspace};
pub use kinematics::{forward_kinematics, tool_pose, Data};
pub use link::{Convention, Joint, JointKind, LinkGeometry, Motion};
pub use pose::Pose;
pub(crate) use registry::ParameterStatus;
pub use registry::{Parameter, Registry, Segment, Unit};
pub use sampling::random_configurations;
