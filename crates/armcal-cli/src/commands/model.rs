//! `armcal model <robot-or-cell>`: parameters, completeness and identifiability.
//!
//! With `--convention dh|mdh|zrp` the model is first converted by `armcal::model::convert`
//! (forward kinematics unchanged): `zrp` by `to_zrp` (identity base, one zero-reference
//! link per joint, the tool pose at q = 0 as tool frame); `dh` by `zrp_to_dh` without a
//! nominal (standard DH links by the common normals, book §6.3.4, and the tool frame that
//! remains); `mdh` by `dh_to_mdh` of that. The table and the identifiability analysis are
//! then those of the converted model. Its statuses, kept simple: the instrument and the
//! targets, which the conversion copies unchanged, keep the cell's declared statuses; every
//! chain parameter (base, links, tool) is a candidate, since the conversion redistributes
//! the geometry among the chain's links and a fixed base or tool of the cell has no
//! counterpart there. With `free = "auto"` in the cell the unidentifiable ones are shown
//! fixed, as for the original model.

use armcal::cell::Cell;
use armcal::model::complete::{in_form, LinkForm};
use armcal::model::identifiability::{self, IdentifiabilitySettings, Measurement};
use armcal::model::rank_deficit::rank_deficit;
use armcal::model::{Model, Segment, Status};

#[derive(clap::Args)]
pub struct Args {
    /// Built-in robot name or cell file.
    pub target: String,
    /// Measurement type for the identifiability analysis (default: the cell's).
    #[arg(long, value_parser = ["pose", "position", "distance"])]
    pub measurement: Option<String>,
    /// Random configurations used by the analysis.
    #[arg(long, default_value_t = 60)]
    pub poses: usize,
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

/// The cell's model converted to `convention`, with the statuses described in the module
/// documentation.
fn converted(cell: &Cell, convention: &str) -> anyhow::Result<Model> {
    let original = &cell.model;
    let form = LinkForm::from_name(convention)
        .ok_or_else(|| anyhow::anyhow!("unknown convention `{convention}`; use dh, mdh or zrp"))?;
    let mut model = Model::from_spec(&in_form(&original.spec(), form)?.spec)?;
    for i in 0..model.param_count() {
        let p = model.registry.get(i);
        let status = match p.segment {
            Segment::Chain => Status::Free,
            Segment::Instrument | Segment::Target(_) => {
                let k = original.registry.require(&p.name)?;
                if cell.declared_free.contains(&k) {
                    match original.registry.get(k).status {
                        Status::Prior { sigma } => Status::Prior { sigma },
                        _ => Status::Free,
                    }
                } else {
                    Status::Fixed
                }
            }
        };
        model.registry.set_status(i, status);
    }
    Ok(model)
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let cell = super::output::load_cell(&a.target)?;
    let measurement = a
        .measurement
        .as_deref()
        .and_then(Measurement::from_name)
        .unwrap_or(cell.measurement);
    let opts = IdentifiabilitySettings {
        measurement,
        poses: a.poses,
        seed: a.seed,
        ..cell.identifiability_settings()
    };
    // The analysis runs on the parameters the cell declared free, before the automatic
    // reduction, so that every excluded parameter gets its reason.
    let (model, report, deficit) = match a.convention.as_deref() {
        Some(c) => {
            let mut m = converted(&cell, c)?;
            let report = identifiability::analyze(&m, &m.nominal(), &opts)?;
            let deficit = rank_deficit(
                &m,
                &m.nominal(),
                report.identifiable.len(),
                measurement,
                None,
            )?;
            if cell.auto_free {
                report.apply(&mut m)?;
            }
            (std::borrow::Cow::Owned(m), report, deficit)
        }
        None => {
            let report = cell.identifiability(&opts)?;
            let deficit = cell.rank_deficit(&report, &cell.model.nominal(), None)?;
            (std::borrow::Cow::Borrowed(&cell.model), report, deficit)
        }
    };
    if a.json {
        let params: Vec<_> = model
            .registry
            .iter()
            .map(|p| {
                serde_json::json!({
                    "name": p.name,
                    "unit": p.unit.display_name(),
                    "nominal": p.nominal * p.unit.display_factor(),
                    "status": p.status,
                })
            })
            .collect();
        let out = serde_json::json!({
            "cell": cell.name,
            "source": cell.robot.source,
            "convention": a.convention,
            "form": cell.form.name(),
            "form_changes": cell.form_changes,
            "form_incomplete": cell.form_incomplete,
            "joints": model.joints,
            "parameters": params,
            "identifiability": report,
            "rank_deficit": deficit,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!("{} ({})", cell.name, cell.origin);
    println!("source: {}", cell.robot.source);
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
    println!(
        "{:<4} {:<14} {:>14} {:<4} status",
        "#", "parameter", "nominal", "unit"
    );
    for (i, p) in model.registry.iter().enumerate() {
        let status = match p.status {
            Status::Free => "free".to_string(),
            Status::Fixed if report.excluded.iter().any(|e| e.name == p.name) => {
                "fixed (not identifiable, see below)".to_string()
            }
            Status::Fixed => "fixed".to_string(),
            Status::Prior { sigma } => format!(
                "prior σ = {:.4} {}",
                sigma * p.unit.display_factor(),
                p.unit.display_name()
            ),
        };
        println!(
            "{:<4} {:<14} {:>14.6} {:<4} {status}",
            i + 1,
            p.name,
            p.nominal * p.unit.display_factor(),
            p.unit.display_name()
        );
    }
    println!("\njoints:");
    for j in &model.joints {
        let f = j.kind.unit().display_factor();
        println!(
            "  {:<6} {:?} [{:.2}, {:.2}] {}",
            j.name,
            j.kind,
            j.lower * f,
            j.upper * f,
            j.kind.unit().display_name()
        );
    }
    let c = &report.completeness;
    println!(
        "\ncompleteness (book §2.3): {} revolute, {} prismatic joints → complete pose model 4R + 2P + 6 = {}",
        c.revolute, c.prismatic, c.complete_pose_model
    );
    match c.expected_for_measurement {
        Some(n) => println!(
            "expected identifiable from {measurement:?} measurements in generic geometry: {n}"
        ),
        None => {
            println!("no closed-form count for {measurement:?} measurements of several targets")
        }
    }
    println!(
        "numerical analysis over {} random configurations (seed {}): {} candidate parameters, rank {} (SVD), {} (pivoted QR)",
        report.poses, a.seed, report.candidates.len(), report.rank_svd, report.rank_qr
    );
    println!(
        "identifiable: {} parameters, condition number of the column-scaled Jacobian {:.1}",
        report.identifiable.len(),
        report.condition_number
    );
    println!("  {}", report.identifiable.join(", "));
    if let Some(d) = &deficit {
        println!("below the generic count: {d}");
    }
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
    Ok(())
}
