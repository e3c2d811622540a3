//! `armcal axes`: joint-axis identification by circle point analysis (book §4.6) from
//! one-joint-at-a-time sweeps, with each axis' σ (direction in degrees, point across the
//! axis in mm), compared with the cell's nominal axes; warnings for axes not to be trusted.

use super::output::{load_cell, load_data, Outputs};
use armcal::axes_record;
use std::path::{Path, PathBuf};

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
    /// Overwrite existing output files (never an input file).
    #[arg(long)]
    pub force: bool,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let outs: Vec<&Path> = a.out.iter().map(PathBuf::as_path).collect();
    let outputs = Outputs::plan(a.force, &[Path::new(&a.cell), &a.data], &outs)?;
    let cell = load_cell(&a.cell)?;
    let data = load_data(&cell, &a.data)?;
    let rec = axes_record(&cell.model, &data)?;
    if let Some(p) = &a.out {
        outputs.commit(&[(p, &rec.to_json()?)])?;
    }
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
    let show = |v: Option<f64>, w: usize, p: usize| match v {
        Some(v) => format!("{v:>w$.p$}"),
        None => format!("{:>w$}", "—"),
    };
    for ax in &rec.axes {
        let (d, p) = (ax.direction, ax.point_mm);
        println!(
            "{:<6} ({:>8.5}, {:>8.5}, {:>8.5}) ({:>10.3}, {:>10.3}, {:>10.3}) {:>10.3} {:>7.1}{:<2} {:>9.4} {} {} {:>10.4} {:>10.3}",
            ax.joint, d[0], d[1], d[2], p[0], p[1], p[2], ax.radius_mm,
            ax.span, ax.span_unit, ax.rms_mm, show(ax.sigma_direction_deg, 8, 4), show(ax.sigma_point_mm, 9, 3),
            ax.angle_to_nominal_deg, ax.distance_to_nominal_mm
        );
    }
    for w in &rec.warnings {
        eprintln!("warning: {w}");
    }
    if let Some(p) = &a.out {
        println!("→ {}", p.display());
    }
    Ok(())
}
