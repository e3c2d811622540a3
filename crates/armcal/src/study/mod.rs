//! Reproductions of the sources' experiments.

pub(crate) mod demo;
pub(crate) mod paper;
pub mod puma;
