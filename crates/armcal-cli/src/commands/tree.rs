//! `armcal identify` and `armcal simulate` of a tree cell (links that name a `parent`,
//! coupled joints, targets that name a `link`): parse, one library call, print.

use super::output::{station_files, with_note, NoteStyle, Outputs};
use super::progress::Progress;
use super::{export, identify, simulate};
use anyhow::bail;
use armcal::{ExportFormat, Perturbation, TreeCell, TreeEstimate};
use std::path::Path;

/// `armcal identify --cell <tree cell>`: one fit of the whole tree over every data file.
pub fn identify(a: &identify::Args, cell_path: &Path) -> anyhow::Result<()> {
    // `--data TARGET=FILE`: every row of FILE saw TARGET (a serial cell's STATION=FILE)
    let files = station_files(&a.data);
    if a.refit.is_some() {
        bail!("--refit: a tree fit does not refit frames yet (issue 32)");
    }
    let mut inputs = vec![cell_path];
    inputs.extend(files.iter().map(|(_, f)| f.as_path()));
    inputs.extend(a.test.as_deref());
    let outputs = Outputs::plan(a.force, &inputs, &[&a.out])?;
    let cell = TreeCell::from_file(cell_path)?;
    let mut data = armcal::Dataset::default();
    let mut sources = Vec::new();
    for (target, file) in &files {
        data.append(&cell.read_data(file, target.as_deref())?);
        sources.push(file.display().to_string());
    }
    data.source = sources.join(" + ");
    let test = a
        .test
        .as_deref()
        .map(|t| cell.read_data(t, None))
        .transpose()?;
    let opts = identify::settings(a, test, None);
    let est = armcal::identify_tree(&cell, &data, &opts, &mut Progress::new(a.quiet))?;
    outputs.commit(&[(&a.out, &est.to_json()?)])?;
    print_tree_summary(&est);
    println!("\nestimate → {}", a.out.display());
    if !est.solver.status.is_converged() {
        bail!(
            "the fit did not converge ({}); check the cell's nominal model and the data (units, joint columns, targets)",
            est.solver.status
        );
    }
    Ok(())
}

/// The summary of a tree estimate: solver, parameters, what is fixed and why, σ̂₀², the
/// fit per target.
fn print_tree_summary(e: &TreeEstimate) {
    println!(
        "{} (a tree): {} measurements at {} configurations from {}",
        e.cell, e.measurements, e.configurations, e.data
    );
    identify::print_solver_and_parameters(&e.solver, &e.parameters, 16);
    if !e.fixed_reasons.is_empty() {
        println!(
            "\n{} parameters fixed at nominal (not identifiable from these data)",
            e.fixed_reasons.len()
        );
    }
    let u = &e.uncertainty;
    println!(
        "\nvariance factor σ̂₀² = {:.3} (χ² = {:.1}, {} dof, p = {:.3}): {}",
        u.variance_factor, u.chi2, u.dof, u.p_value, u.verdict
    );
    if !e.outliers.is_empty() {
        println!(
            "  on the {} measurements kept; the {} outliers are left out of χ² and C_p",
            e.measurements - e.outliers.len(),
            e.outliers.len()
        );
    }
    println!("\nposition error (mm) per target   fitted RMS / max   held-out RMS / max   frames only RMS");
    for t in &e.targets {
        let held = if t.held_out.count == 0 {
            "         —".to_string()
        } else {
            format!(
                "{:>8.4} / {:<8.4}   {:>8.4}",
                t.held_out.rms, t.held_out.max, t.held_out_frames_only.rms
            )
        };
        println!(
            "  {:<30} {:>8.4} / {:<8.4}   {held}",
            t.target, t.fitted.rms, t.fitted.max
        );
    }
    if !e.validation.is_empty() {
        println!("held out: {}", e.validation);
    }
    identify::print_nongeometric(&e.nongeometric);
    identify::print_choice(e.nongeometric_choice.as_ref());
}

/// `armcal simulate --cell <tree cell>`: the tree measured at the poses, each pose at every
/// target (or those of `--target`).
pub fn simulate(a: &simulate::Args, cell_path: &Path) -> anyhow::Result<()> {
    if a.payload.is_some() || a.perturb_fixed {
        bail!("--payload and --perturb-fixed: a tree cell has no payloads or stated priors yet");
    }
    let mut outs = vec![a.out.as_path()];
    outs.extend(a.truth_out.as_deref());
    let outputs = Outputs::plan(a.force, &[cell_path, &a.poses], &outs)?;
    let cell = TreeCell::from_file(cell_path)?;
    let poses = cell.read_poses(&a.poses)?;
    let targets = a
        .target
        .iter()
        .map(|name| {
            cell.tree
                .targets
                .iter()
                .position(|t| t.0 == *name)
                .ok_or_else(|| {
                    let names: Vec<&str> = cell.tree.targets.iter().map(|t| t.0.as_str()).collect();
                    anyhow::anyhow!(
                        "--target {name}: no such target (the cell has: {})",
                        names.join(", ")
                    )
                })
        })
        .collect::<anyhow::Result<Vec<usize>>>()?;
    let pert = Perturbation {
        length: a.perturb_mm,
        angle: a.perturb_deg.to_radians(),
        all: a.perturb_all,
        instrument_length: Some(a.instrument_offset_mm),
        ..Perturbation::default()
    };
    let sim = armcal::simulate_tree(
        &cell.tree,
        cell.measurement,
        (!a.noise_free).then_some(&cell.noise),
        &poses,
        &targets,
        &pert,
        a.seed,
    )?;
    let data = cell.write_data(&sim.data)?;
    simulate::commit_and_print(
        a,
        &outputs,
        &data,
        &sim.truth.to_json()?,
        sim.data.measurements.len(),
        poses.len(),
        &format!("tree `{}`", cell.name),
    )
}

/// `armcal export --estimate <tree estimate>`: the tree at the estimate as one URDF file or a
/// tree cell (`--cell`: the tree cell it was identified in, for its noise and measurement).
pub fn export(a: &export::Args, est: &TreeEstimate) -> anyhow::Result<()> {
    let format = ExportFormat::from_name(&a.format).expect("clap checked");
    let mut inputs = vec![a.calibration.estimate.as_path()];
    inputs.extend(a.cell.as_deref().map(Path::new));
    let outputs = Outputs::plan(a.force, &inputs, &[&a.out])?;
    let cell = a
        .cell
        .as_deref()
        .map(|c| TreeCell::from_file(Path::new(c)))
        .transpose()?;
    let exported = armcal::export_tree_estimate(
        est,
        cell.as_ref(),
        format,
        &a.calibration.accept.acceptance(),
    )?;
    for w in &exported.warnings {
        eprintln!("warning: {w}");
    }
    for n in &exported.notes {
        eprintln!("note: {n}");
    }
    let style = match format {
        ExportFormat::Urdf => NoteStyle::Xml,
        _ => NoteStyle::Hash,
    };
    let note = exported.warnings.join("; ");
    let note = (!note.is_empty()).then_some(note.as_str());
    outputs.commit(&[(&a.out, &with_note(exported.content, note, style))])?;
    println!("{} of tree `{}` → {}", a.format, est.cell, a.out.display());
    Ok(())
}
