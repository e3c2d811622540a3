//! Reproductions of the sources' experiments.

pub(crate) mod demo;
pub mod paper;
pub mod puma;
