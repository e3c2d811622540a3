//! Proof of accuracy: statistics of position errors and the ISO 9283 pose characteristics
//! (book ch. 7).

pub mod iso9283;
pub mod report;
pub mod same_pose;
pub mod stats;

pub use stats::ErrorStats;
