//! `armcal compensate`: filter a nominal joint program (or Cartesian targets) through the
//! calibrated model.

use super::output::{load_cell, write_new};
use anyhow::bail;
use armcal::compensate::program::{corrected_cartesian_targets, filter_joint_program};
use armcal::compensate::{IkResult, IkSettings};
use armcal::identify::Estimate;
use armcal::measure::{csv, MeasurementKind};
use armcal::model::{JointKind, Model, Pose};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Cell file or built-in robot.
    #[arg(long)]
    pub cell: String,
    /// Identified parameters (estimate.json).
    #[arg(long)]
    pub estimate: PathBuf,
    /// Targets (CSV). Joint columns only: a nominal joint program, corrected so that the real
    /// robot reaches what the nominal model meant. With `x_mm … yaw_deg` too: Cartesian tool
    /// targets (world frame), corrected for a controller that keeps its nominal model; the
    /// joint columns are then the starting guesses (e.g. the controller's nominal solution).
    #[arg(long)]
    pub targets: PathBuf,
    #[arg(long)]
    pub out: PathBuf,
    #[arg(long)]
    pub force: bool,
}

fn joints_header(model: &Model) -> String {
    model
        .joints
        .iter()
        .map(|j| {
            format!(
                "{}_{}",
                j.name,
                if j.kind == JointKind::Revolute {
                    "deg"
                } else {
                    "mm"
                }
            )
        })
        .collect::<Vec<_>>()
        .join(",")
}

fn joint_values(model: &Model, q: &[f64]) -> String {
    q.iter()
        .zip(&model.joints)
        .map(|(v, j)| {
            format!(
                "{:.9}",
                if j.kind == JointKind::Revolute {
                    v.to_degrees()
                } else {
                    *v
                }
            )
        })
        .collect::<Vec<_>>()
        .join(",")
}

fn status_columns(r: &IkResult) -> String {
    format!(
        "{},{:.9},{:.9}",
        serde_json::to_value(r.status)
            .ok()
            .and_then(|v| v.as_str().map(String::from))
            .unwrap_or_default(),
        r.position_error,
        r.orientation_error.to_degrees()
    )
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let cell = load_cell(&a.cell)?;
    let model = &cell.model;
    let calibrated = Estimate::from_file(&a.estimate)?.params_for(model)?;
    let nominal = model.nominal();
    let settings = IkSettings::default();
    let text = std::fs::read_to_string(&a.targets)?;
    let header = text.lines().next().unwrap_or("");
    let cartesian = header.split(',').any(|h| h.trim().starts_with("roll"));
    let program =
        csv::read_configurations_str(&text, &a.targets.display().to_string(), model, None)?;
    let mut out = String::new();
    let mut failed = 0;
    if cartesian {
        // Read the tool poses with a robot-only model: rows become world-frame poses.
        let mut robot_only = model.spec();
        robot_only.instrument = None;
        robot_only.targets.clear();
        let robot = Model::from_spec(&robot_only)?;
        let (data, _) = csv::read_str(&text, &a.targets.display().to_string(), &robot, None)?;
        let poses: Vec<Pose<f64>> = data
            .measurements
            .iter()
            .map(|m| match &m.kind {
                MeasurementKind::Pose { value, .. } => Ok(*value),
                _ => bail!(
                    "line {}: Cartesian targets need x, y, z, roll, pitch, yaw",
                    m.line
                ),
            })
            .collect::<anyhow::Result<_>>()?;
        let seeds: Vec<Vec<f64>> = data
            .measurements
            .iter()
            .map(|m| data.configurations[m.config].clone())
            .collect();
        let rows =
            corrected_cartesian_targets(model, &nominal, &calibrated, &poses, &seeds, &settings);
        out.push_str(&format!("pose_id,{},x_mm,y_mm,z_mm,roll_deg,pitch_deg,yaw_deg,status,position_error_mm,orientation_error_deg\n", joints_header(model)));
        for (i, (pose, r)) in rows.iter().enumerate() {
            let (xyz, rpy) = pose.to_xyz_rpy();
            failed += usize::from(r.status != armcal::compensate::IkStatus::Converged);
            out.push_str(&format!(
                "{},{},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9},{}\n",
                data.config_ids[data.measurements[i].config],
                joint_values(model, &r.q),
                xyz[0],
                xyz[1],
                xyz[2],
                rpy[0].to_degrees(),
                rpy[1].to_degrees(),
                rpy[2].to_degrees(),
                status_columns(r)
            ));
        }
    } else {
        let rows = filter_joint_program(model, &nominal, &calibrated, &program, &settings);
        out.push_str(&format!(
            "pose_id,{},status,position_error_mm,orientation_error_deg\n",
            joints_header(model)
        ));
        for row in &rows {
            failed += usize::from(row.result.status != armcal::compensate::IkStatus::Converged);
            out.push_str(&format!(
                "{},{},{}\n",
                row.id,
                joint_values(model, &row.result.q),
                status_columns(&row.result)
            ));
        }
    }
    write_new(&a.out, &out, a.force)?;
    println!(
        "{} {} filtered through the calibrated model → {} ({} not converged; see the status column)",
        program.len(),
        if cartesian { "Cartesian targets" } else { "joint configurations" },
        a.out.display(),
        failed
    );
    Ok(())
}
