//! Reproductions of the sources' experiments.

pub mod demo;
pub mod paper;
pub mod puma;
