//! Pure geometry for measurement-pose design (paper §2.2, §3.2): shapes in, numbers out.
//!
//! One small module per query, in the style of parry:
//! - `segment_distance`: closest points between two segments and the gradient of their
//!   distance w.r.t. the endpoints (Ericson §5.1.9; the paper's eq. 21 and 23);
//! - `box_distance`: signed distance from a segment to a box, with its gradient (capsule
//!   against a table, a fixture, a fence);
//! - `cone_distance`: distance from a segment to the convex hull of a point and a ball
//!   (the beam's reach when the tracker may stand anywhere in the ball);
//! - `fit`: plane, circle and line through points, with the covariance of the fitted
//!   axis (book §4.6).
//!
//! The constraint set of a cell built from these (incidence, capsule–capsule, capsule–box, half-space,
//! line of sight) is design work: `crate::design::cell_constraints`.

pub(crate) mod box_distance;
pub(crate) mod cone_distance;
pub(crate) mod fit;
pub(crate) mod segment_distance;

pub use box_distance::{segment_box_distance, Cuboid, SegmentBoxDistance};
pub use cone_distance::segment_cone_distance;
pub use segment_distance::{point_segment_distance, segment_distance, SegmentDistance};
