//! `armcal compensate`: filter a nominal joint program (or Cartesian targets) through the
//! calibrated model, optionally with a nonparametric correction of the error it leaves
//! (book §5.4).

use super::output::{
    load_cell, load_data, load_estimate, with_note, write_new, AcceptUnconverged, NoteStyle,
};
use anyhow::bail;
use armcal::compensate::nonparametric::{CorrectionInputs, ResidualCorrection};
use armcal::compensate::program::{corrected_cartesian_targets, filter_joint_program_corrected};
use armcal::compensate::{IkResult, IkSettings, IkStatus};
use armcal::measure::{csv, MeasurementKind};
use armcal::model::{JointKind, Model, Pose};
use armcal::nalgebra::Vector3;
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
    /// Calibration data (CSV, as for `identify`) on which to fit a polynomial correction of
    /// the position error the calibrated model leaves (measured − predicted, book §5.4); the
    /// targets are then shifted by its prediction and the output gets `correction_*_mm`
    /// columns (the shift applied to each target, world frame).
    #[arg(long, value_name = "DATA.csv")]
    pub nonparametric: Option<PathBuf>,
    /// Total degree of the correction polynomials.
    #[arg(long, default_value_t = 3, requires = "nonparametric")]
    pub degree: usize,
    /// What the correction is a function of: `arm-joints` (q1…q3: the configuration sets the
    /// non-geometric errors, and the same TCP position in another configuration has another
    /// error), `joints` (all joints) or `position` (TCP position, world frame).
    #[arg(long, default_value = "arm-joints", value_parser = ["arm-joints", "joints", "position"], requires = "nonparametric")]
    pub nonparametric_inputs: String,
    #[command(flatten)]
    pub accept: AcceptUnconverged,
}

fn joints_header(model: &Model) -> String {
    model
        .joints
        .iter()
        .map(csv::joint_column)
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

/// Status (with the joint and limit, or the residual, for a row that did not converge) and
/// residual columns.
fn status_columns(model: &Model, r: &IkResult) -> String {
    format!(
        "{},{:.9},{:.9}",
        r.describe(model),
        r.position_error,
        r.orientation_error.to_degrees()
    )
}

/// `correction_x_mm,…,` columns (empty without a correction).
fn correction_columns(c: &Vector3<f64>, with: bool) -> String {
    if with {
        format!("{:.6},{:.6},{:.6},", c.x, c.y, c.z)
    } else {
        String::new()
    }
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let cell = load_cell(&a.cell)?;
    let model = &cell.model;
    let (est, note) = load_estimate(&a.estimate, &a.accept, Some(model))?;
    let calibrated = est.params_for(model)?;
    let nominal = model.nominal();
    let settings = IkSettings::default();
    let text = std::fs::read_to_string(&a.targets)?;
    let header = text.lines().find(|l| !l.starts_with('#')).unwrap_or("");
    let cartesian = header.split(',').any(|h| h.trim().starts_with("roll"));
    let program =
        csv::read_configurations_str(&text, &a.targets.display().to_string(), model, None)?;
    let correction = match &a.nonparametric {
        Some(path) => {
            let data = load_data(&cell, path)?;
            let inputs = match a.nonparametric_inputs.as_str() {
                "joints" => CorrectionInputs::Joints,
                "position" => CorrectionInputs::Position,
                _ => CorrectionInputs::ArmJoints,
            };
            let c = ResidualCorrection::fit(model, &calibrated, &data, inputs, a.degree)
                .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
            println!(
                "nonparametric correction ({}, degree {}, {} terms): position error RMS on {} \
                 {:.4} mm → {:.4} mm after the fit",
                a.nonparametric_inputs,
                a.degree,
                c.polynomial.basis.len(),
                path.display(),
                c.polynomial.training_rms_before,
                c.polynomial.training_rms
            );
            Some(c)
        }
        None => None,
    };
    let with = correction.is_some();
    let correction_header = if with {
        "correction_x_mm,correction_y_mm,correction_z_mm,"
    } else {
        ""
    };
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
        let rows = corrected_cartesian_targets(
            model,
            &nominal,
            &calibrated,
            &poses,
            &seeds,
            &settings,
            correction.as_ref(),
        );
        out.push_str(&format!(
            "pose_id,{},x_mm,y_mm,z_mm,roll_deg,pitch_deg,yaw_deg,{correction_header}status,position_error_mm,orientation_error_deg\n",
            joints_header(model)
        ));
        for (i, row) in rows.iter().enumerate() {
            let (xyz, rpy) = row.pose.to_xyz_rpy();
            failed += usize::from(row.result.status != IkStatus::Converged);
            out.push_str(&format!(
                "{},{},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9},{}{}\n",
                data.config_ids[data.measurements[i].config],
                joint_values(model, &row.result.q),
                xyz[0],
                xyz[1],
                xyz[2],
                rpy[0].to_degrees(),
                rpy[1].to_degrees(),
                rpy[2].to_degrees(),
                correction_columns(&row.correction, with),
                status_columns(model, &row.result)
            ));
        }
    } else {
        let rows = filter_joint_program_corrected(
            model,
            &nominal,
            &calibrated,
            &program,
            &settings,
            correction.as_ref(),
        );
        out.push_str(&format!(
            "pose_id,{},{correction_header}status,position_error_mm,orientation_error_deg\n",
            joints_header(model)
        ));
        for row in &rows {
            failed += usize::from(row.result.status != IkStatus::Converged);
            out.push_str(&format!(
                "{},{},{}{}\n",
                row.id,
                joint_values(model, &row.result.q),
                correction_columns(&row.correction, with),
                status_columns(model, &row.result)
            ));
        }
    }
    write_new(
        &a.out,
        &with_note(out, note.as_deref(), NoteStyle::Hash),
        a.force,
    )?;
    println!(
        "{} {} filtered through the calibrated model → {} ({} not converged; see the status column)",
        program.len(),
        if cartesian { "Cartesian targets" } else { "joint configurations" },
        a.out.display(),
        failed
    );
    Ok(())
}
