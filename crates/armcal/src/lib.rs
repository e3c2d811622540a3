//! armcal: kinematic calibration of industrial robots, from the nominal model to a
//! calibrated, compensated, proven-accurate robot.
//!
//! The two sources are Mooring, Roth & Driels, *Fundamentals of Manipulator Calibration*
//! (1991) ("book") and Jost, Kudruss, Körkel & Walter (2017), optimum experimental design of
//! laser-tracker measurement poses ("paper").

#![warn(missing_docs)]

pub mod accuracy;
pub mod cell;
pub mod compensate;
pub mod design;
pub mod error;
pub mod geometry;
pub mod identify;
pub mod json;
pub mod measure;
pub mod model;
pub mod progress;
pub mod report;
pub mod robots;
pub mod sim;
pub mod solve;
pub mod study;
pub mod workflow;

pub use error::{Error, Result};
/// The linear-algebra crate of the public API.
pub use nalgebra;
