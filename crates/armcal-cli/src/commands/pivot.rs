//! `armcal pivot`: TCP (tool-tip) calibration from poses touching one fixed point.

use super::output::{
    load_cell, warn_outside_fitted_ranges, with_note, CalibrationOrNominal, NoteStyle, Outputs,
};
use armcal::{pivot_calibration, PivotSettings};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// Cell file or built-in robot: its model gives the flange pose of every touch pose.
    #[arg(long)]
    pub cell: String,
    /// The touch poses (CSV: pose_id, q1_deg, …): the tool tip on one fixed point, the tool
    /// tilted about at least two different axes.
    #[arg(long)]
    pub poses: PathBuf,
    #[command(flatten)]
    pub calibration: CalibrationOrNominal,
    /// Largest accepted condition number of the pivot design matrix [R_i −I] (unit-free).
    #[arg(long, default_value_t = PivotSettings::default().max_condition)]
    pub max_condition: f64,
    /// Output: the tool frame, its covariance and the residuals (JSON).
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let mut inputs = vec![Path::new(&a.cell), a.poses.as_path()];
    inputs.extend(a.calibration.estimate.as_deref());
    let outputs = Outputs::plan(a.force, &inputs, &[a.out.as_path()])?;
    let cell = load_cell(&a.cell)?;
    let model = &cell.model;
    let (params, note, _, est) = a.calibration.load_at_payload(model, None)?;
    let configurations = cell.read_armcal_poses(&a.poses)?;
    if let Some(est) = &est {
        warn_outside_fitted_ranges(est, model, &configurations);
    }
    let poses: Vec<Vec<f64>> = configurations.into_iter().map(|(_, q)| q).collect();
    let settings = PivotSettings {
        max_condition: a.max_condition,
    };
    let p = pivot_calibration(model, &params, &poses, &settings)?;
    let json = with_note(p.to_json()?, note.as_deref(), NoteStyle::Json);
    outputs.commit(&[(a.out.as_path(), json.as_str())])?;
    let [x, y, z] = p.tool_xyz_mm;
    let [sx, sy, sz] = p.tool_sigma_mm;
    let [px, py, pz] = p.point_xyz_mm;
    println!(
        "pivot calibration of `{}` from {} poses (largest tilt {:.1}°, condition number {:.1})",
        cell.name, p.poses, p.max_tilt_deg, p.condition_number
    );
    println!("tool tip in the flange frame: ({x:.4}, {y:.4}, {z:.4}) mm, σ = ({sx:.4}, {sy:.4}, {sz:.4}) mm");
    println!("touched point in the world:   ({px:.4}, {py:.4}, {pz:.4}) mm");
    println!(
        "residual σ̂ = {:.4} mm per axis (max distance of a pose's tip from the point {:.4} mm)",
        p.residual_sigma_mm,
        p.residuals_mm.iter().copied().fold(0.0, f64::max)
    );
    println!(
        "the cell's fixed_priors carry no correlations: they state σ = √λ_max(C_tool) = {:.4} mm on each of tool.x/y/z, never narrower than the pivot's full covariance (tool_covariance in {})",
        p.prior_sigma_mm(),
        a.out.display()
    );
    println!("in the cell file:\n{}", p.cell_snippet());
    println!("→ {}", a.out.display());
    Ok(())
}
