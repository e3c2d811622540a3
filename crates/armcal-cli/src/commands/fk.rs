//! `armcal fk <robot-or-cell> --joints ...`

use anyhow::{bail, Context};
use armcal::model::{forward_kinematics, observed_pose, Data, JointKind, Observed, Pose};

#[derive(clap::Args)]
pub struct Args {
    /// Built-in robot name or cell file.
    pub target: String,
    /// Joint values, comma separated: degrees for revolute joints, mm for prismatic ones.
    #[arg(long, allow_hyphen_values = true)]
    pub joints: String,
    /// Joint values are in radians (revolute) instead of degrees.
    #[arg(long)]
    pub rad: bool,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

fn pose_json(p: &Pose<f64>) -> serde_json::Value {
    let (xyz, rpy) = p.to_xyz_rpy();
    serde_json::json!({
        "xyz_mm": xyz,
        "rpy_deg": rpy.map(f64::to_degrees),
        "matrix": p.to_matrix(),
    })
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let cell = super::output::load_cell(&a.target)?;
    let model = &cell.model;
    let values: Vec<f64> = a
        .joints
        .split([',', ' '])
        .filter(|s| !s.is_empty())
        .enumerate()
        .map(|(i, s)| {
            s.trim()
                .parse::<f64>()
                .with_context(|| format!("--joints: value {} (`{s}`) is not a number", i + 1))
        })
        .collect::<anyhow::Result<_>>()?;
    if values.len() != model.dof() {
        bail!(
            "--joints: {} values given, `{}` has {} joints ({})",
            values.len(),
            cell.name,
            model.dof(),
            model
                .joints
                .iter()
                .map(|j| j.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let q: Vec<f64> = values
        .iter()
        .zip(&model.joints)
        .map(|(v, j)| match (j.kind, a.rad) {
            (JointKind::Revolute, false) => v.to_radians(),
            _ => *v,
        })
        .collect();
    model.check_joints(&q)?;
    let params = model.nominal();
    let mut data = Data::new(model);
    forward_kinematics(model, &mut data, &params, &q);
    let frames: Vec<(String, Pose<f64>)> = model
        .links
        .iter()
        .zip(&data.frames)
        .map(|(l, p)| (l.spec.name.clone(), *p))
        .chain(
            model
                .targets
                .iter()
                .zip(&data.targets)
                .map(|(l, p)| (l.spec.name.clone(), *p)),
        )
        .collect();
    let measured: Vec<(String, Pose<f64>)> = (0..model.targets.len())
        .map(|k| {
            (
                model.targets[k].spec.name.clone(),
                observed_pose(&data, Observed::Target(k)),
            )
        })
        .collect();
    if a.json {
        let out = serde_json::json!({
            "cell": cell.name,
            "joints": model.joints.iter().zip(&q).map(|(j, v)| serde_json::json!({"name": j.name, "value": v * j.kind.unit().display_factor(), "unit": j.kind.unit().display_name()})).collect::<Vec<_>>(),
            "frames_world": frames.iter().map(|(n, p)| serde_json::json!({"frame": n, "pose": pose_json(p)})).collect::<Vec<_>>(),
            "in_instrument_frame": measured.iter().map(|(n, p)| serde_json::json!({"target": n, "pose": pose_json(p)})).collect::<Vec<_>>(),
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!(
        "{}: forward kinematics (world frame; mm, deg as roll-pitch-yaw)",
        cell.name
    );
    println!(
        "{:<10} {:>11} {:>11} {:>11} {:>9} {:>9} {:>9}",
        "frame", "x", "y", "z", "roll", "pitch", "yaw"
    );
    let row = |n: &str, p: &Pose<f64>| {
        let (t, r) = p.to_xyz_rpy();
        println!(
            "{n:<10} {:>11.4} {:>11.4} {:>11.4} {:>9.4} {:>9.4} {:>9.4}",
            t[0],
            t[1],
            t[2],
            r[0].to_degrees(),
            r[1].to_degrees(),
            r[2].to_degrees()
        );
    };
    for (n, p) in &frames {
        row(n, p);
    }
    if let Some(inst) = &model.instrument {
        println!(
            "\nas the instrument `{}` measures them (instrument frame):",
            inst.spec.name
        );
        for (n, p) in &measured {
            row(n, p);
        }
    }
    Ok(())
}
