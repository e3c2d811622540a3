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
//! [`measure::csv::read`]); [`identify()`] fits the parameters with their uncertainty into an
//! [`Estimate`]; [`calibrated_ik`] and [`compensate()`] use it; [`performance`] proves
//! it (ISO 9283 accuracy and repeatability). Every solver reports a [`Status`] and its
//! progress to an [`Observer`]; every file armcal writes is a typed record of the module
//! that produces it ([`Estimate`], [`DesignRecord`], …), read by [`report`].
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
//! use armcal::model::{random_configurations, tool_pose};
//! use armcal::{
//!     calibrated_ik, identify, perturbed_truth, simulate, Cell, IdentifySettings, IkSettings,
//!     IkTarget, IkWorkspace, Perturbation, Silent,
//! };
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

pub(crate) mod accuracy;
pub(crate) mod campaign;
pub mod cell;
pub mod compensate;
pub mod design;
pub(crate) mod error;
pub mod geometry;
pub mod identify;
pub(crate) mod input;
pub(crate) mod json;
pub(crate) mod linalg;
pub mod measure;
pub mod model;
pub(crate) mod performance;
pub(crate) mod progress;
pub mod report;
pub mod robots;
pub(crate) mod sim;
pub(crate) mod solve;
pub mod study;
pub(crate) mod table;
pub(crate) mod toml_text;
pub(crate) mod workflow;

pub use error::{Error, Result};

// The front door: the calls a program (and the Python package to come) makes, with plain
// inputs (numbers in internal units: mm, rad; names; records) and typed, serde records out.
// They stay in the module of the concept they compute (one concept per module, the layering
// test's order) and are named here once; docs/src/reference/library.md lists them.
// One path per item (tests/suite/repository/api_surface.rs): the file that defines a
// front-door item is a crate-private module, so the item's only path is the root; an internal
// part keeps its module path (its parent module re-exports it) and is not named here.

// A cell and its model; the model's parameters, completeness and identifiability.
pub use cell::loaded::Cell;
pub use cell::model_analysis::{analyze_model, ModelAnalysis, ModelRecord, ParameterRecord};
pub use model::chain::Model;
pub use model::complete::{FormChange, LinkForm};
pub use model::identifiability::{
    Completeness, Exclusion, Identifiability, IdentifiabilitySettings, Measurement,
};
pub use model::link::{Joint, JointKind};
pub use model::registry::{ParameterStatus, Registry, Unit};
pub use model::urdf::calibration::DEFAULT_K_SIGMA;
// Kinematic trees and coupled joints: analysis, simulation and identification.
pub use cell::tree::{analyze_tree_file, describes_tree, TreeAnalysis, TreeCell};
pub use identify::tree::{export_tree_estimate, identify_tree, TreeEstimate, TreeTargetFit};
pub use sim::tree::simulate_tree;
// Kinematics over many configurations; every frame at one configuration.
pub use model::frames::{frames, FramesRecord, PoseRecord};
pub use model::kinematics::fk;
// Measurements: from arrays, from several stations, simulated, predicted.
pub use measure::arrays::{DataArrays, RowKind};
pub use measure::dataset::Dataset;
pub use measure::pose_ids::next_pose_ids;
pub use measure::read_report::ReadReport;
pub use sim::{
    perturbed_truth, predict, simulate, simulate_carrying, simulate_measuring, simulate_poses,
    Perturbation, Simulation, TrueParameter, TruthRecord,
};
// Identification, its checks, the prediction σ of any configuration, joint axes by circle
// point analysis.
pub use identify::circle_point::record::{axes_record, AxesRecord};
pub use identify::estimate::{Acceptance, Estimate, ParameterEstimate, SolverReport};
pub use identify::fit_checks::FitChecks;
pub use identify::lm::LmSettings;
pub use identify::nongeometric_choice::{Candidate, NonGeometric, NonGeometricChoice};
pub use identify::nongeometric_gate::TermVerdict;
pub use identify::pivot::{pivot_calibration, PivotCalibration, PivotSettings};
pub use identify::prediction_sigma::{csv_with_sigmas, prediction_sigmas, RowSigma};
pub use identify::refit::FramesRefit;
pub use identify::robust::Loss;
pub use identify::run::identify;
pub use identify::settings::{IdentifySettings, Method};
pub use identify::solver::ToleranceSettings;
pub use identify::uncertainty::TcpCovariance;
// Optimal design: plan, plan from the user's pose pool, assess any design.
pub use design::assess::{
    assess, evaluate_design, DesignAssessment, DesignEvaluation, PathPrecision,
};
pub use design::cell_constraints::{
    unmeasurable_poses, unplaced_instrument, TrackerShift, Unmeasurable, Violation,
};
pub use design::criteria::Criterion;
pub use design::plan::{plan, DesignMargin, PlanResult, PlanSettings};
pub use design::record::{DesignRecord, JointRange, KindMargin};
pub use design::user_pool::{
    plan_pool, InfeasibleRow, PoolPlan, PoolReport, PoolRow, PoolSettings,
};
// Compensation: calibrated inverse kinematics, programs from values.
pub use compensate::ik::{
    calibrated_ik, IkResult, IkSettings, IkStatus, IkTarget, IkWorkspace, LimitViolation,
};
pub use compensate::joint_change::{ChangeViolation, JointChangeLimit};
pub use compensate::nonparametric::{
    CorrectionInputs, PolynomialBasis, PolynomialCorrection, ResidualCorrection,
};
pub use compensate::program::{
    compensate, compensate_program, CompensatedProgram, CompensatedRow, Program, ProgramFile,
    ProgramRecord, ProgramRecordRow,
};
// Robot programs in the controllers' languages (KRL, RAPID, UR script).
pub use compensate::controller_program::{
    filter_controller_program, FilteredControllerProgram, Language as ProgramLanguage,
    ProgramSettings, TargetOutcome,
};
// Accuracy (ISO 9283 before and after calibration): the whole comparison, one model's
// report, the commanded poses found in the data, the standard's figures of one pose.
pub use accuracy::iso9283::{
    position_accuracy, position_repeatability, Accuracy, OrientationAccuracy,
    OrientationRepeatability, Repeatability, ISO_CYCLES,
};
pub use accuracy::report::{
    accuracy_report, AccuracyReport, Iso9283Summary, Orientation as AccuracyOrientation,
    OrientationFigures, PoseFigures,
};
pub use accuracy::same_pose::{
    commanded_poses, ClosePoses, CommandedPoses, GroupingSummary, SamePose,
};
pub use accuracy::stats::ErrorStats;
pub use performance::{
    performance, Calibrated, ModelPerformance, PerformanceRecord, PerformanceSettings,
};
// The adaptive campaign (start, step, simulate), the drift check and the campaign after a
// drift (the calibration as the prior).
pub use campaign::drift::{check, CheckSettings, DriftCheck, DriftVerdict, GroupScore};
pub use campaign::precision::WorkingSigma;
pub use campaign::prior::CampaignPrior;
pub use campaign::simulate::simulate as campaign_simulate;
pub use campaign::simulate::{
    measure_until_stopped as campaign_measure_until_stopped, SimulatedCampaign,
};
pub use campaign::{
    fewest_poses as campaign_fewest_poses, largest_sigma as campaign_largest_sigma,
    start_after_check as campaign_start_after_check, step_with as campaign_step_with,
};
pub use campaign::{start as campaign_start, step as campaign_step};
pub use campaign::{
    CampaignPose, CampaignSettings, CampaignState, CampaignStep, Decision as CampaignDecision,
    FitSummary as CampaignFitSummary, Planner as CampaignPlanner, StepResult,
    StepSettings as CampaignStepSettings, JOINT_TOLERANCE as CAMPAIGN_JOINT_TOLERANCE,
};
// The seeded campaign study: adaptive against one-shot and random designs.
pub use campaign::study::{
    coverage as campaign_coverage, coverage_with_floor as campaign_coverage_with_floor,
    poses_summary as campaign_poses_summary, run as campaign_study, CampaignStudyRecord,
    RunOutcome as CampaignRunOutcome, StudySettings as CampaignStudySettings,
};
// The sources' experiments reproduced: the paper's Tables 6–8 (`armcal study paper`) and
// the book's PUMA 560 case (`armcal study puma`; its tables and helpers stay in
// `study::puma`).
pub use study::paper::{
    notional_robots, run_study as paper_study, NotionalSummary, PaperStudy, RobotSelection,
    Spread as StudySpread, StudyRecord as PaperStudyRecord, StudyRow as PaperStudyRow,
    StudySettings as PaperStudySettings, PAPER_SUMMARY, PAPER_TABLE6,
};
pub use study::puma::record::{run_record as puma_study, PumaRecord};
pub use study::puma::settings::PumaSettings;
// Export and report.
pub use cell::export::{export_model, ExportFormat, Exported};
pub use identify::export::export_estimate;
pub use report::files::{files_report, FilesReport};
// The one CSV writer behind every table armcal writes.
pub use table::Table;
// The whole workflow on the built-in paper cell.
pub use workflow::demo::{demo, DemoFiles, FILES as DEMO_FILES};
// The shared vocabulary: solver status, progress, the input caps.
pub use input::{input_limits, read_capped, set_input_limits, InputLimits, DATA_CAP, TEXT_CAP};
/// The linear-algebra crate of the public API.
pub use nalgebra;
pub use progress::{Observer, Silent};
pub use solve::Status;
