//! `armcal fk <robot-or-cell> --joints ...`

use anyhow::{bail, Context};
use armcal::{frames, JointKind, PoseRecord};

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
    let rec = frames(&cell.name, model, &q)?;
    if a.json {
        println!("{}", rec.to_json()?);
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
    let row = |n: &str, p: &PoseRecord| {
        let (t, r) = (p.xyz_mm, p.rpy_deg);
        println!(
            "{n:<10} {:>11.4} {:>11.4} {:>11.4} {:>9.4} {:>9.4} {:>9.4}",
            t[0], t[1], t[2], r[0], r[1], r[2]
        );
    };
    for f in &rec.frames_world {
        row(&f.frame, &f.pose);
    }
    if let Some(inst) = &model.instrument {
        println!(
            "\nas the instrument `{}` measures them (instrument frame):",
            inst.spec.name
        );
        for t in &rec.in_instrument_frame {
            row(&t.target, &t.pose);
        }
    }
    Ok(())
}
