//! `armcal simulate`: measure joint configurations on a perturbed virtual robot.

use super::output::{load_cell, write_new};
use armcal::measure::csv;
use armcal::sim::{perturbed_truth, simulate, Perturbation};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Cell file or built-in robot.
    #[arg(long)]
    pub cell: String,
    /// Joint configurations (CSV: pose_id, q1_deg, …).
    #[arg(long)]
    pub poses: PathBuf,
    /// Seed of the truth perturbation and of the measurement noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// σ of the length perturbation of the true robot (mm).
    #[arg(long, default_value_t = 0.5)]
    pub perturb_mm: f64,
    /// σ of the angle perturbation of the true robot (deg).
    #[arg(long, default_value_t = 0.1)]
    pub perturb_deg: f64,
    /// Perturb every parameter, not only the identifiable (free) ones.
    #[arg(long)]
    pub perturb_all: bool,
    /// Measure without noise.
    #[arg(long)]
    pub noise_free: bool,
    /// Output data file (CSV).
    #[arg(long)]
    pub out: PathBuf,
    /// Also write the true parameters (JSON).
    #[arg(long)]
    pub truth_out: Option<PathBuf>,
    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let cell = load_cell(&a.cell)?;
    let model = &cell.model;
    let poses = csv::read_configurations(&a.poses, model, None)?;
    let qs: Vec<Vec<f64>> = poses.iter().map(|(_, q)| q.clone()).collect();
    let pert = Perturbation {
        length: a.perturb_mm,
        angle: a.perturb_deg.to_radians(),
        all: a.perturb_all,
        ..Perturbation::default()
    };
    let truth = perturbed_truth(model, &pert, a.seed);
    let noise = cell.noise();
    let mut data = simulate(
        model,
        &truth,
        &qs,
        (!a.noise_free).then_some(&noise),
        a.seed.wrapping_add(0x5eed),
    )?;
    for (k, (id, _)) in poses.iter().enumerate() {
        data.config_ids[k] = id.clone();
    }
    write_new(&a.out, &csv::write_string(&data, model)?, a.force)?;
    println!(
        "simulated {} measurements at {} configurations of `{}` (seed {}) → {}",
        data.measurements.len(),
        qs.len(),
        cell.name,
        a.seed,
        a.out.display()
    );
    if let Some(t) = &a.truth_out {
        let params: Vec<_> = model
            .registry
            .iter()
            .zip(&truth)
            .map(|(p, v)| serde_json::json!({"name": p.name, "unit": p.unit.display_name(), "nominal": p.nominal * p.unit.display_factor(), "truth": v * p.unit.display_factor()}))
            .collect();
        let json = serde_json::json!({"cell": cell.name, "seed": a.seed, "parameters": params});
        write_new(t, &serde_json::to_string_pretty(&json)?, a.force)?;
        println!("true parameters → {}", t.display());
    }
    Ok(())
}
