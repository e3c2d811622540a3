//! armcal: kinematic calibration of industrial robots, from the nominal model to a
//! calibrated, compensated, proven-accurate robot.
//!
//! The two sources are Mooring, Roth & Driels, *Fundamentals of Manipulator Calibration*
//! (1991) ("book") and Jost, Kudruss, Körkel & Walter (2017), optimum experimental design of
//! laser-tracker measurement poses ("paper").
//!
//! # The pipeline in one page
//!
//! A cell ([`Cell`]: robot, instrument, targets, working poses, obstacles) gives the
//! [`Model`]; [`plan`] chooses measurement poses and [`assess`] predicts what any design
//! gives; [`simulate`] measures a virtual robot (or a [`Dataset`] is read from a file with
//! [`measure::csv::read`]); [`identify`] fits the parameters with their uncertainty into an
//! [`Estimate`]; [`calibrated_ik`] and [`compensate::program`] use it; [`accuracy`] proves
//! it. Every solver reports a [`Status`] and its progress to an [`Observer`]; every file
//! armcal writes is a typed record of the module that produces it ([`Estimate`],
//! [`DesignRecord`], …), read by [`report`].
//!
//! # Where to read on
//!
//! - **The user guide** (`docs/` in the repository, an mdBook: `mdbook serve docs`) holds the
//!   tutorial, a page per task (model, plan, measure, identify, uncertainty, campaigns,
//!   compensation, accuracy, reports), the real-data case studies and the reference of every
//!   file format, convention and error message.
//! - **Runnable examples** (`crates/armcal/examples/`, `cargo run --release -p armcal
//!   --example NAME`): `plan_and_calibrate` (plan KPI poses, measure, identify, compare with
//!   the prediction), `compensate_program` (filter a joint program through the calibrated
//!   inverse kinematics and check it on the robot), `adaptive_campaign` (measure batch by
//!   batch until the TCP is precise enough), `accuracy_iso9283` (pose accuracy and
//!   repeatability).
//! - The `armcal` command-line tool (crate `armcal-cli`) makes one call of this library per
//!   command.
//!
//! # Example
//!
//! ```
//! use armcal::{calibrated_ik, identify, simulate, Cell, IdentifySettings, IkSettings, IkTarget};
//! use armcal::compensate::ik::IkWorkspace;
//! use armcal::model::{random_configurations, tool_pose};
//! use armcal::progress::Silent;
//! use armcal::sim::{perturbed_truth, Perturbation};
//!
//! # fn main() -> armcal::Result<()> {
//! let cell = armcal::cell::builtin::paper_cell()?;
//! let model = &cell.model;
//! // A virtual robot that differs from its nominal model, measured at 40 random poses.
//! let truth = perturbed_truth(model, &Perturbation::default(), 7);
//! let poses = random_configurations(model, 40, 1);
//! let data = simulate(model, &truth, &poses, Some(&cell.noise()), 2)?;
//! let estimate = identify(&cell, &data, &IdentifySettings::default(), &mut Silent)?;
//! assert!(estimate.solver.status.is_converged());
//! // The calibrated model drives the tool to where the nominal one says it is.
//! let params = estimate.params_for(model)?;
//! let q = &poses[0];
//! let target = tool_pose(model, &model.nominal(), q);
//! let ik = calibrated_ik(model, &params, &IkTarget::Pose(target), q, &IkSettings::default(),
//!     &mut IkWorkspace::new(model));
//! assert!(ik.position_error < 1e-6);
//! # Ok(())
//! # }
//! ```

#![warn(missing_docs)]

pub mod accuracy;
pub mod campaign;
pub mod cell;
pub mod compensate;
pub mod design;
pub mod error;
pub mod geometry;
pub mod identify;
pub mod input;
pub mod json;
pub mod linalg;
pub mod measure;
pub mod model;
pub mod performance;
pub mod progress;
pub mod report;
pub mod robots;
pub mod sim;
pub mod solve;
pub mod study;
pub mod table;
pub mod toml_text;
pub mod workflow;

pub use error::{Error, Result};

// The handful of names a program needs; everything else by its module path.
pub use cell::tree::{analyze_tree_file, TreeAnalysis, TreeCell};
pub use cell::Cell;
pub use compensate::{calibrated_ik, IkSettings, IkStatus, IkTarget};
pub use design::assess::assess;
pub use design::plan::{plan, PlanResult, PlanSettings};
pub use design::{Criterion, DesignRecord};
pub use identify::{identify, Estimate, IdentifySettings};
pub use measure::Dataset;
pub use model::Model;
/// The linear-algebra crate of the public API.
pub use nalgebra;
pub use progress::{Observer, Silent};
pub use sim::simulate;
pub use solve::Status;
