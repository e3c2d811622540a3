//! Proof of accuracy: statistics of position errors and the ISO 9283 pose characteristics
//! (book ch. 7).

pub(crate) mod iso9283;
pub(crate) mod report;
pub(crate) mod same_pose;
pub(crate) mod stats;

pub(crate) use stats::ErrorStats;
