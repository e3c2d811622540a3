//! Reproductions of the sources' experiments.

pub mod paper;
pub mod puma;
