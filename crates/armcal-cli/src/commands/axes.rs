//! `armcal axes`: joint-axis identification by circle point analysis (book §4.6) from
//! one-joint-at-a-time sweeps, compared with the cell's nominal axes.

use super::output::{load_cell, load_data, write_new};
use anyhow::bail;
use armcal::measure::MeasurementKind;
use armcal::model::axes::{identify_axes, JointSweep};
use armcal::model::{forward_kinematics, Data};
use armcal::nalgebra::Vector3;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Cell file or built-in robot.
    #[arg(long)]
    pub cell: String,
    /// Sweeps (data-file CSV): each configuration moves one joint with all others at zero.
    #[arg(long)]
    pub data: PathBuf,
    /// Write the axes as JSON.
    #[arg(long)]
    pub out: Option<PathBuf>,
    #[arg(long)]
    pub force: bool,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let cell = load_cell(&a.cell)?;
    let model = &cell.model;
    let data = load_data(&cell, &a.data)?;
    let dof = model.dof();
    let mut sweeps: Vec<JointSweep> = (0..dof)
        .map(|joint| JointSweep {
            joint,
            q: Vec::new(),
            points: Vec::new(),
        })
        .collect();
    for m in &data.measurements {
        let point = match &m.kind {
            MeasurementKind::Position { value, .. } => *value,
            MeasurementKind::Pose { value, .. } => value.trans,
            _ => continue,
        };
        let q = &data.configurations[m.config];
        let moving: Vec<usize> = (0..dof).filter(|&j| q[j].abs() > 1e-9).collect();
        let targets: Vec<usize> = match moving.as_slice() {
            [] => (0..dof).collect(),
            [j] => vec![*j],
            _ => bail!(
                "line {}: the configuration moves joints {}; sweeps move one joint at a time with the others at zero",
                m.line,
                moving.iter().map(|j| model.joints[*j].name.clone()).collect::<Vec<_>>().join(", ")
            ),
        };
        for j in targets {
            sweeps[j].q.push(q.clone());
            sweeps[j].points.push(point);
        }
    }
    let axes = identify_axes(model, &sweeps)?;
    // Nominal axes in the instrument frame at q = 0.
    let mut fk = Data::new(model);
    forward_kinematics(model, &mut fk, &model.nominal(), &vec![0.0; dof]);
    let rt = fk.instrument.rot.transpose();
    println!(
        "{:<6} {:>28} {:>34} {:>10} {:>9} {:>10} {:>10}",
        "joint", "direction", "point (mm)", "radius", "rms", "Δangle°", "Δline mm"
    );
    let mut json = Vec::new();
    for (ax, tw) in axes.axes.iter().zip(&fk.joint_twists) {
        let (du, dp) = if tw.w.norm() > 0.0 {
            let u = tw.w.normalize();
            let p = u.cross(&tw.v) / tw.w.norm_squared();
            (rt * u, rt * (p - fk.instrument.trans))
        } else {
            (rt * tw.v.normalize(), Vector3::zeros())
        };
        let angle = ax.direction.angle(&du).to_degrees();
        let dist = if tw.w.norm() > 0.0 {
            (ax.point - dp).cross(&du).norm()
        } else {
            0.0
        };
        println!(
            "{:<6} ({:>8.5}, {:>8.5}, {:>8.5}) ({:>10.3}, {:>10.3}, {:>10.3}) {:>10.3} {:>9.4} {:>10.4} {:>10.3}",
            ax.joint.name, ax.direction[0], ax.direction[1], ax.direction[2], ax.point[0], ax.point[1], ax.point[2], ax.radius, ax.rms, angle, dist
        );
        json.push(serde_json::json!({
            "joint": ax.joint.name, "direction": ax.direction.as_slice(), "point_mm": ax.point.as_slice(),
            "radius_mm": ax.radius, "rms_mm": ax.rms, "angle_to_nominal_deg": angle, "distance_to_nominal_mm": dist,
        }));
    }
    if let Some(p) = &a.out {
        write_new(p, &serde_json::to_string_pretty(&json)?, a.force)?;
        println!("→ {}", p.display());
    }
    Ok(())
}
