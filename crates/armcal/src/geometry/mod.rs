//! Collision and visibility geometry for measurement-pose design (paper §2.2, §3.2):
//! capsules, segment distances with exact gradients, and the per-configuration constraint
//! set `g(q) ≥ 0` of a cell (paper eq. 24b).
//!
//! One small module per query, in the style of parry:
//! - [`segment_distance`]: closest points between two segments and the gradient of their
//!   distance w.r.t. the endpoints (Ericson §5.1.9; the paper's eq. 21 and 23);
//! - [`constraints`]: incidence (eq. 4), capsule–capsule (eq. 20), half-space (§3.2) and
//!   line-of-sight constraints of a [`crate::cell::Cell`], with values and exact Jacobians
//!   w.r.t. the joints.

pub mod constraints;
pub mod segment_distance;

pub use constraints::{
    ConstraintKind, ConstraintSet, ConstraintSettings, ConstraintWorkspace, Margin,
};
pub use segment_distance::{point_segment_distance, segment_distance, SegmentDistance};
