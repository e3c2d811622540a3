//! Reproductions of the sources' experiments.

pub mod paper;
