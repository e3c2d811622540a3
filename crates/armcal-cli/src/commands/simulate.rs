//! `armcal simulate`: measure joint configurations on a perturbed virtual robot.

use super::output::{load_cell_to_measure, Outputs};
use anyhow::bail;
use armcal::{simulate_poses, unmeasurable_poses, Perturbation, Unit};
use std::path::{Path, PathBuf};

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
    /// σ of the joint compliance terms of the true robot (µrad per m of lever; the cell's
    /// `[parameters] compliance`): κ = nominal + σ|z|, an arm that sags under gravity.
    #[arg(long, default_value_t = 200.0)]
    pub perturb_urad_per_m: f64,
    /// σ of the periodic joint error amplitudes of the true robot (arcsec; the cell's
    /// `[parameters] periodic`): nominal + σz.
    #[arg(long, default_value_t = 20.0)]
    pub perturb_arcsec: f64,
    /// σ of the joints' own compliance in the true robot (µrad/(N·m); the payload terms
    /// `<joint>.compliance.payload` of a cell with `[parameters] compliance` and
    /// `[[payload]]`): c = nominal + σ|z|.
    #[arg(long, default_value_t = 5.0)]
    pub perturb_urad_per_nm: f64,
    /// The payload the robot carries at every pose (a cell's `[[payload]]` name; default
    /// none); the data get a `payload` column. Simulate each payload with the same --seed
    /// (the same true robot) and give both files to `identify`.
    #[arg(long)]
    pub payload: Option<String>,
    /// Perturb every parameter, not only the identifiable (free) ones.
    #[arg(long)]
    pub perturb_all: bool,
    /// Perturb the parameters the cell holds fixed by their stated prior (`[parameters]
    /// fixed_prior`, `fixed_priors`; default 0.5 mm, 0.1°; 0 for a frame the cell does not
    /// give): the robot the model floor of `identify` describes. Overrides --perturb-all for
    /// them.
    #[arg(long)]
    pub perturb_fixed: bool,
    /// σ (mm, per axis) of where the virtual instrument stands off the cell's position, as
    /// `campaign simulate`'s: a tracker set up by tape measure is centimetres off.
    #[arg(long, default_value_t = 20.0, value_name = "MM")]
    pub instrument_offset_mm: f64,
    /// Measure without noise.
    #[arg(long)]
    pub noise_free: bool,
    /// Output data file (CSV).
    #[arg(long)]
    pub out: PathBuf,
    /// Also write the true parameters (JSON).
    #[arg(long)]
    pub truth_out: Option<PathBuf>,
    /// Simulate poses the instrument cannot measure (incidence, line of sight, collisions)
    /// too, instead of refusing them; stderr says how many there were.
    #[arg(long)]
    pub allow_unmeasurable: bool,
    /// A tree cell: the target each pose measures (repeat it for several; default: every
    /// target at every pose, an instrument that sees every branch's reflector).
    #[arg(long)]
    pub target: Vec<String>,
    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let cell_path = Path::new(&a.cell);
    if cell_path.is_file() && armcal::describes_tree(cell_path)? {
        return super::tree::simulate(a, cell_path);
    }
    if !a.target.is_empty() {
        bail!("--target chooses the targets of a tree cell's poses; `{}` is a serial cell (its data measure every target)", a.cell);
    }
    let mut outs = vec![a.out.as_path()];
    outs.extend(a.truth_out.as_deref());
    let outputs = Outputs::plan(a.force, &[Path::new(&a.cell), &a.poses], &outs)?;
    for (flag, v) in [
        ("--instrument-offset-mm", a.instrument_offset_mm),
        ("--perturb-urad-per-m", a.perturb_urad_per_m),
        ("--perturb-arcsec", a.perturb_arcsec),
        ("--perturb-urad-per-nm", a.perturb_urad_per_nm),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            bail!("{flag} {v}: give a magnitude ≥ 0");
        }
    }
    let cell = load_cell_to_measure(&a.cell)?;
    let model = &cell.model;
    let payload = model
        .payload_index(a.payload.as_deref().unwrap_or("none"))
        .map_err(|e| anyhow::anyhow!("--payload: {e}"))?;
    let poses = cell.read_reachable_poses(&a.poses)?;
    let unmeasurable = unmeasurable_poses(&cell, &poses)?;
    if !unmeasurable.is_empty() {
        let (n, total) = (unmeasurable.len(), poses.len());
        if !a.allow_unmeasurable {
            let list: Vec<String> = unmeasurable.iter().map(|u| format!("  {u}")).collect();
            bail!(
                "{n} of {total} poses in {} cannot be measured in `{}`:\n{}\nuse poses planned for this cell (`armcal plan`), or pass --allow-unmeasurable to simulate them anyway",
                a.poses.display(),
                cell.name,
                list.join("\n")
            );
        }
        eprintln!(
            "warning: {n} of {total} poses cannot be measured in `{}` (incidence, line of sight or collision); simulated anyway (--allow-unmeasurable)",
            cell.name
        );
    }
    let pert = Perturbation {
        length: a.perturb_mm,
        angle: a.perturb_deg.to_radians(),
        compliance: a.perturb_urad_per_m / Unit::RadPerMm.display_factor(),
        periodic: a.perturb_arcsec / Unit::Arcsec.display_factor(),
        joint_compliance: a.perturb_urad_per_nm / Unit::RadPerNmm.display_factor(),
        all: a.perturb_all,
        fixed: a.perturb_fixed.then(|| cell.fixed_prior.clone()),
        instrument_length: Some(a.instrument_offset_mm),
        ..Perturbation::default()
    };
    let noise = cell.noise();
    let sim = simulate_poses(
        &cell.name,
        model,
        &poses,
        payload,
        cell.measurement,
        &pert,
        (!a.noise_free).then_some(&noise),
        a.seed,
    )?;
    let data = cell.write_data(&sim.data)?;
    commit_and_print(
        a,
        &outputs,
        &data,
        &sim.truth.to_json()?,
        sim.data.measurements.len(),
        poses.len(),
        &format!("`{}`", cell.name),
    )
}

/// Writes the simulated data (and the true parameters, `--truth-out`) all or nothing and
/// says what was simulated of `what` (a serial cell's or a tree's name) and where it went.
pub fn commit_and_print(
    a: &Args,
    outputs: &Outputs,
    data: &str,
    truth: &str,
    measurements: usize,
    configurations: usize,
    what: &str,
) -> anyhow::Result<()> {
    let mut files = vec![(a.out.as_path(), data)];
    files.extend(a.truth_out.as_deref().map(|t| (t, truth)));
    outputs.commit(&files)?;
    println!(
        "simulated {measurements} measurements at {configurations} configurations of {what} (seed {}) → {}",
        a.seed,
        a.out.display()
    );
    if let Some(t) = &a.truth_out {
        println!("true parameters → {}", t.display());
    }
    Ok(())
}
