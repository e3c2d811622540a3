//! `armcal`: the command-line front end. It parses arguments, calls the library, prints.

mod commands;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "armcal",
    version,
    about = "Kinematic calibration of industrial robots: model, plan poses, identify, compensate, prove accuracy"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// The whole workflow on the built-in paper cell: plan, simulate, identify, compensate, evaluate.
    Demo(commands::demo::Args),
    /// List the built-in robots.
    Robots,
    /// Parameter table, completeness count and identifiability report of a robot or cell.
    Model(commands::model::Args),
    /// Forward kinematics: pose of every frame at a joint configuration.
    Fk(commands::fk::Args),
    /// Simulate a measurement campaign on a perturbed virtual robot.
    Simulate(commands::simulate::Args),
    /// Identify the cell's parameters from a data file.
    Identify(commands::identify::Args),
    /// Read a data file as the cell's `[data]` section maps it; write it in armcal's CSV.
    Import(commands::import::Args),
    /// Predict what the instrument measures at given joint configurations.
    Predict(commands::predict::Args),
    /// Plan optimal measurement poses (paper's KPI method or a classic criterion).
    Plan(commands::plan::PlanArgs),
    /// Predicted C_p, C_s, criteria and constraint margins of any design.
    Evaluate(commands::plan::EvaluateArgs),
    /// The adaptive measurement campaign (paper §6): measure a batch, identify, stop at the
    /// target TCP precision or plan the next batch.
    #[command(subcommand_required = true)]
    Campaign(commands::campaign::Args),
    /// Drift check: check poses measured after the calibration against its prediction (χ²),
    /// and which parameter groups most likely moved (score tests).
    Check(commands::check::Args),
    /// Filter a joint program or Cartesian targets through the calibrated model.
    Compensate(commands::compensate::Args),
    /// ISO 9283 accuracy and repeatability, and a model's errors, from a data file.
    Accuracy(commands::accuracy::Args),
    /// TCP (tool-tip) calibration: the tool tip in the flange frame, with σ, from poses that
    /// touch one fixed point (pivot calibration).
    Pivot(commands::pivot::Args),
    /// Joint axes by circle point analysis from one-joint-at-a-time sweeps.
    Axes(commands::axes::Args),
    /// Export the calibrated model (cell file with DH / modified-DH / zero-reference links, JSON, URDF,
    /// URDF with calibration offsets, Universal Robots kinematics YAML, ROS 2 joint corrections).
    #[command(alias = "deploy")]
    Export(commands::export::Args),
    /// A self-contained HTML report (inline SVG figures, 3D cell view) of estimates, designs and studies.
    Report(commands::report::Args),
    /// Reproduce a source's experiment (`paper`: Jost et al. 2017, Tables 6–8; `puma`: the
    /// book's Chapter 6 PUMA 560 calibration, Tables 6.9/6.10 and 6.13).
    Study(commands::study::Args),
}

/// The environment variable that sets every input cap, in MiB (e.g. `ARMCAL_MAX_INPUT_MIB=4096`
/// for a larger data file): the command line's default of the library's setting.
const CAP_VARIABLE: &str = "ARMCAL_MAX_INPUT_MIB";

/// [`CAP_VARIABLE`]'s caps if it holds a whole number of MiB, else the library's defaults.
fn input_limits_from_env() -> armcal::InputLimits {
    std::env::var(CAP_VARIABLE)
        .ok()
        .and_then(|v| v.trim().parse::<u64>().ok())
        .map_or_else(armcal::InputLimits::default, armcal::InputLimits::all_mib)
}

fn main() {
    // Rust ignores SIGPIPE, so a write to a closed pipe makes `println!` panic (exit 101).
    // With the default action restored, `armcal … | head -1` ends quietly when `head` exits,
    // like any Unix tool. (A command that prints before it writes its files — axes, compensate,
    // export, identify, report, study — is then stopped before writing them; issue 12 item 2,
    // all-or-nothing writes, is where that ordering gets fixed.)
    #[cfg(unix)]
    // SAFETY: called first in `main`, before any thread exists; SIG_DFL is a valid handler.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let cli = Cli::parse();
    armcal::set_input_limits(input_limits_from_env());
    let result = match cli.command {
        Command::Robots => commands::robots::run(),
        Command::Demo(a) => commands::demo::run(&a),
        Command::Model(a) => commands::model::run(&a),
        Command::Fk(a) => commands::fk::run(&a),
        Command::Simulate(a) => commands::simulate::run(&a),
        Command::Identify(a) => commands::identify::run(&a),
        Command::Import(a) => commands::import::run(&a),
        Command::Predict(a) => commands::predict::run(&a),
        Command::Plan(a) => commands::plan::run_plan(&a),
        Command::Evaluate(a) => commands::plan::run_evaluate(&a),
        Command::Study(a) => commands::study::run_study(&a),
        Command::Report(a) => commands::report::run(&a),
        Command::Export(a) => commands::export::run(&a),
        Command::Campaign(a) => commands::campaign::run(&a),
        Command::Check(a) => commands::check::run(&a),
        Command::Compensate(a) => commands::compensate::run(&a),
        Command::Accuracy(a) => commands::accuracy::run(&a),
        Command::Axes(a) => commands::axes::run(&a),
        Command::Pivot(a) => commands::pivot::run(&a),
    };
    if let Err(e) = result {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

#[cfg(test)]
mod tests {
    use super::Cli;
    use clap::CommandFactory;

    /// Issue 12 item 9: every flag and argument of every command says what it is in `--help`.
    #[test]
    fn every_argument_has_a_help_line() {
        let cli = Cli::command();
        let mut missing = Vec::new();
        for command in cli.get_subcommands() {
            for arg in command.get_arguments() {
                let generated = matches!(arg.get_id().as_str(), "help" | "version");
                if !generated && arg.get_help().is_none() {
                    missing.push(format!("armcal {} {}", command.get_name(), arg.get_id()));
                }
            }
        }
        assert!(
            missing.is_empty(),
            "arguments without a help line:\n{}",
            missing.join("\n")
        );
    }
}
