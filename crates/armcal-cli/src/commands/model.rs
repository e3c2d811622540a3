//! `armcal model <robot-or-cell>`: parameters, completeness and identifiability.
//!
//! With `--convention dh|mdh|zrp` the model is first converted (forward kinematics
//! unchanged; `armcal::analyze_model` says how and with which statuses); the table
//! and the identifiability analysis are then those of the converted model.

use super::digits::fixed;
use armcal::{
    analyze_model, Identifiability, IdentifiabilitySettings, Joint, JointKind, LinkForm,
    Measurement, ModelRecord, ParameterStatus, Registry,
};

#[derive(clap::Args)]
pub struct Args {
    /// Built-in robot name or cell file.
    pub target: String,
    /// Measurement type for the identifiability analysis (default: the cell's).
    #[arg(long, value_parser = ["pose", "position", "distance"])]
    pub measurement: Option<String>,
    /// Random configurations used by the analysis (at least 1).
    #[arg(long, default_value_t = 60, value_parser = clap::value_parser!(u32).range(1..))]
    pub poses: u32,
    /// Seed of the random configurations.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Print JSON instead of tables.
    #[arg(long)]
    pub json: bool,
    /// Convert the model to this convention first (forward kinematics unchanged): the
    /// table and the analysis are those of the converted model, all chain parameters free.
    #[arg(long, value_parser = ["dh", "mdh", "zrp"])]
    pub convention: Option<String>,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let path = std::path::Path::new(&a.target);
    if path.is_file() && armcal::describes_tree(path)? {
        return run_tree(a, path);
    }
    let cell = super::output::load_cell(&a.target)?;
    let measurement = a
        .measurement
        .as_deref()
        .and_then(Measurement::from_name)
        .unwrap_or(cell.measurement);
    let opts = IdentifiabilitySettings {
        measurement,
        poses: a.poses as usize,
        seed: a.seed,
        ..cell.identifiability_settings()
    };
    let convention = a
        .convention
        .as_deref()
        .map(|c| LinkForm::from_name(c).expect("clap checked"));
    let analysis = analyze_model(&cell, &opts, convention)?;
    if a.json {
        println!("{}", ModelRecord::new(&cell, &analysis).to_json()?);
        return Ok(());
    }
    let (model, report, deficit) = (
        &analysis.model,
        &analysis.identifiability,
        &analysis.rank_deficit,
    );
    println!("{} ({})", cell.name, cell.origin);
    println!("source: {}", cell.robot.source);
    println!(
        "collision model: {} ({} capsules with the tool's)",
        cell.robot.collision,
        cell.capsules.len()
    );
    for c in &cell.form_changes {
        println!(
            "complete, minimal form (convention = \"{}\"): {c}",
            cell.form.name()
        );
    }
    for c in &cell.form_incomplete {
        println!("incomplete: {c}");
    }
    if let Some(c) = &a.convention {
        println!(
            "converted to {c} (forward kinematics unchanged); chain parameters all free, \
             instrument and targets as the cell declares them"
        );
    }
    println!();
    print_parameters(&model.registry, report);
    print_joints(&model.joints);
    let c = &report.completeness;
    println!(
        "\ncompleteness (book §2.3): {} revolute, {} prismatic joints → complete pose model 4R + 2P + 6 = {}",
        c.revolute, c.prismatic, c.complete_pose_model
    );
    match c.expected_for_measurement {
        Some(n) => println!(
            "expected identifiable from {} measurements in generic geometry: {n}",
            measurement.words()
        ),
        None => {
            println!(
                "no closed-form count for {} measurements of several targets",
                measurement.words()
            )
        }
    }
    print_rank(report, a.seed);
    println!(
        "identifiable: {} at these random configurations and the nominal, condition number of the column-scaled Jacobian {:.1}",
        report.count(model),
        report.condition_number
    );
    println!("  {}", report.identifiable.join(", "));
    println!("  (`identify` counts again, by the same rule, at the data's configurations and at the fit: data that move some joints little, or terms they cannot separate, give fewer, and it says why)");
    if let Some(d) = &deficit {
        println!("below the generic count: {d}");
    }
    print_excluded(report);
    Ok(())
}

/// `armcal model` of a tree cell: its branches, coupled joints, parameters and the
/// identifiability over every target (`armcal::analyze_tree_file`).
fn run_tree(a: &Args, path: &std::path::Path) -> anyhow::Result<()> {
    if a.convention.is_some() {
        anyhow::bail!("--convention converts a serial chain; this cell describes a tree");
    }
    let measurement = a.measurement.as_deref().and_then(Measurement::from_name);
    let analysis = armcal::analyze_tree_file(path, measurement, a.poses as usize, a.seed)?;
    let (cell, report) = (&analysis.cell, &analysis.identifiability);
    if a.json {
        println!("{}", serde_json::to_string_pretty(report)?);
        return Ok(());
    }
    let tree = &cell.tree;
    println!("{} ({})", cell.name, cell.origin);
    let branches = match tree.branches.len() {
        1 => "1 branch".to_string(),
        n => format!("{n} branches"),
    };
    let forks = match tree.forks.is_empty() {
        true => "no fork".to_string(),
        false => format!("forks at {}", tree.forks.join(", ")),
    };
    println!(
        "a tree: {branches}, {} joints a data row carries, {forks}",
        tree.dof()
    );
    for b in &tree.branches {
        let links: Vec<&str> = b.model.links.iter().map(|l| l.spec.name.as_str()).collect();
        let targets: Vec<&str> = b
            .model
            .targets
            .iter()
            .map(|t| t.spec.name.as_str())
            .collect();
        println!("  branch {} → {}", links.join(" → "), targets.join(", "));
    }
    for c in &tree.coupled {
        if let Some(text) = tree.coupling_of(&c.link) {
            println!("coupled: {text} (link `{}`; not a data column)", c.link);
        }
    }
    for w in tree.incomplete_forks() {
        println!("incomplete: {w}");
    }
    println!();
    // what the analysis leaves out is held at nominal (as `armcal model` shows a chain)
    let mut registry = tree.registry.clone();
    for e in &report.excluded {
        if let Some(i) = registry.index_of(&e.name) {
            registry.set_status(i, ParameterStatus::Fixed);
        }
    }
    print_parameters(&registry, report);
    print_joints(&tree.joints);
    let c = &report.completeness;
    match c.expected_for_measurement {
        Some(n) => println!(
            "\nexpected identifiable from {} measurements in generic geometry: {n} (4R + 2P + {} per target: {} revolute, {} prismatic joints)",
            cell.measurement.words(),
            if cell.measurement == Measurement::Pose { 6 } else { 3 },
            c.revolute,
            c.prismatic
        ),
        None => println!(
            "\nno closed-form count for this tree (a coupled joint, several points on one link, or a fork the tree cannot place apart)"
        ),
    }
    print_rank(report, a.seed);
    println!(
        "identifiable: {} at these random configurations and the nominal, condition number of the column-scaled Jacobian {:.1}",
        report.identifiable.len(),
        report.condition_number
    );
    println!("  {}", report.identifiable.join(", "));
    print_excluded(report);
    Ok(())
}

fn print_rank(report: &Identifiability, seed: u64) {
    println!(
        "numerical analysis over {} random configurations (seed {}): {} candidate parameters, rank {} (SVD), {} (pivoted QR)",
        report.poses, seed, report.candidates.len(), report.rank_svd, report.rank_qr
    );
}

fn print_excluded(report: &Identifiability) {
    if !report.excluded.is_empty() {
        println!("not identifiable ({}):", report.excluded.len());
        for e in &report.excluded {
            println!("  - {}", e.reason);
        }
    }
    if !report.fixed.is_empty() {
        println!(
            "fixed by the cell ({}): {}",
            report.fixed.len(),
            report.fixed.join(", ")
        );
    }
}

fn print_joints(joints: &[Joint]) {
    println!("\njoints:");
    for j in joints {
        let f = j.kind.unit().display_factor();
        println!(
            "  {:<6} {} [{:.2}, {:.2}] {}",
            j.name,
            match j.kind {
                JointKind::Revolute => "revolute",
                JointKind::Prismatic => "prismatic",
            },
            j.lower * f,
            j.upper * f,
            j.kind.unit().display_name()
        );
    }
}

fn print_parameters(registry: &Registry, report: &Identifiability) {
    println!(
        "{:<4} {:<14} {:>14} {:<4} status",
        "#", "parameter", "nominal", "unit"
    );
    for (i, p) in registry.iter().enumerate() {
        let status = match p.status {
            ParameterStatus::Free => "free".to_string(),
            ParameterStatus::Fixed if report.excluded.iter().any(|e| e.name == p.name) => {
                "fixed (not identifiable, see below)".to_string()
            }
            ParameterStatus::Fixed => "fixed".to_string(),
            ParameterStatus::Prior { sigma } => format!(
                "prior σ = {:.4} {}",
                sigma * p.unit.display_factor(),
                p.unit.display_name()
            ),
        };
        println!(
            "{:<4} {:<14} {:>14} {:<4} {status}",
            i + 1,
            p.name,
            fixed(p.nominal * p.unit.display_factor(), 6),
            p.unit.display_name()
        );
    }
}
