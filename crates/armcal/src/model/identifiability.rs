//! Completeness and identifiability of a model for a measurement type.
