//! The `armcal` binary's tests in one test binary, a module per area.

mod common;

mod accuracy_cli;
mod augment_cli;
mod browser;
mod campaign_cli;
mod campaign_prediction_cli;
mod check_cli;
mod cli;
mod collision_model_cli;
mod compensate_cli;
mod degenerate_target_cli;
mod error_causes;
mod estimate_checks;
mod facing_target_cli;
mod fitted_ranges_cli;
mod fixed_priors_export_cli;
mod guide_links;
mod identifiable_count_cli;
mod import_cli;
mod instrument_offset_cli;
mod margins_cli;
mod measurable_cli;
mod nongeometric_cli;
mod outputs_cli;
mod perturb_fixed_cli;
mod pivot_cli;
mod pool_cli;
mod pose_design_cli;
mod predict_sigma_cli;
mod readme;
mod real_poses_measurable_cli;
mod refit_cli;
mod scale;
mod units_signs_cli;
mod workflow;
