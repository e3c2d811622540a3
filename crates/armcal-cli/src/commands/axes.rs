//! `armcal axes`: joint-axis identification by circle point analysis (book §4.6) from
//! one-joint-at-a-time sweeps, with each axis' σ (direction in degrees, point across the
//! axis in mm), compared with the cell's nominal axes; warnings for axes not to be trusted.

use super::output::{load_cell, load_data, write_new};
use anyhow::bail;
use armcal::identify::circle_point::{identify_axes, JointSweep};
use armcal::measure::MeasurementKind;
use armcal::model::{forward_kinematics, Data, JointKind};
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
        "{:<6} {:>28} {:>34} {:>10} {:>9} {:>9} {:>8} {:>9} {:>10} {:>10}",
        "joint",
        "direction",
        "point (mm)",
        "radius",
        "span",
        "rms",
        "σdir°",
        "σ⊥pt mm",
        "Δangle°",
        "Δline mm"
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
        let (span, unit) = match ax.joint.kind {
            JointKind::Revolute => (ax.span.to_degrees(), "°"),
            JointKind::Prismatic => (ax.span, "mm"),
        };
        let cov = ax.covariance.as_ref();
        let sigma_dir = cov.map(|c| c.sigma_direction().to_degrees());
        let sigma_point = cov.map(|c| c.sigma_point());
        let show = |v: Option<f64>, w: usize, p: usize| match v {
            Some(v) => format!("{v:>w$.p$}"),
            None => format!("{:>w$}", "—"),
        };
        println!(
            "{:<6} ({:>8.5}, {:>8.5}, {:>8.5}) ({:>10.3}, {:>10.3}, {:>10.3}) {:>10.3} {:>7.1}{:<2} {:>9.4} {} {} {:>10.4} {:>10.3}",
            ax.joint.name, ax.direction[0], ax.direction[1], ax.direction[2], ax.point[0], ax.point[1], ax.point[2], ax.radius,
            span, unit, ax.rms, show(sigma_dir, 8, 4), show(sigma_point, 9, 3), angle, dist
        );
        json.push(serde_json::json!({
            "joint": ax.joint.name, "direction": ax.direction.as_slice(), "point_mm": ax.point.as_slice(),
            "radius_mm": ax.radius, "rms_mm": ax.rms, "points": ax.points,
            "span": span, "span_unit": unit.trim(),
            "sigma_noise_mm": cov.map(|c| c.sigma_noise), "dof": cov.map(|c| c.dof),
            "sigma_direction_deg": sigma_dir, "sigma_point_mm": sigma_point,
            "covariance_basis": [ax.x_axis.as_slice(), ax.direction.cross(&ax.x_axis).as_slice()],
            "direction_covariance_rad2": cov.map(|c| [[c.direction[(0, 0)], c.direction[(0, 1)]], [c.direction[(1, 0)], c.direction[(1, 1)]]]),
            "point_covariance_mm2": cov.map(|c| [[c.point[(0, 0)], c.point[(0, 1)]], [c.point[(1, 0)], c.point[(1, 1)]]]),
            "warning": ax.warning,
            "angle_to_nominal_deg": angle, "distance_to_nominal_mm": dist,
        }));
    }
    for w in axes.warnings() {
        eprintln!("warning: {w}");
    }
    if let Some(p) = &a.out {
        write_new(p, &serde_json::to_string_pretty(&json)?, a.force)?;
        println!("→ {}", p.display());
    }
    Ok(())
}
