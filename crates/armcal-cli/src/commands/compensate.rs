//! `armcal compensate`: filter a nominal joint program (or Cartesian targets) through the
//! calibrated model, optionally with a nonparametric correction of the error it leaves
//! (book §5.4).

use super::output::{
    load_cell, load_data, warn_outside_fitted_ranges, with_note, Calibration, NoteStyle, Outputs,
};
use armcal::{
    compensate_program, read_capped, CorrectionInputs, IkSettings, JointChangeLimit, ProgramFile,
    ProgramLanguage as Language, ProgramSettings, ResidualCorrection, DATA_CAP, TEXT_CAP,
};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// Cell file or built-in robot.
    #[arg(long)]
    pub cell: String,
    #[command(flatten)]
    pub calibration: Calibration,
    /// Targets (CSV). Joint columns only: a nominal joint program, corrected so that the real
    /// robot reaches what the nominal model meant. With `x_mm … yaw_deg` too: Cartesian tool
    /// targets (world frame), corrected for a controller that keeps its nominal model; the
    /// joint columns are then the starting guesses (e.g. the controller's nominal solution).
    #[arg(long, required_unless_present = "program", conflicts_with = "program")]
    pub targets: Option<PathBuf>,
    /// A robot program in its controller's language to filter instead: KUKA KRL (`.src`,
    /// `.dat`), ABB RAPID (`.mod`) or Universal Robots script (`.script`). Every motion
    /// target is compensated in place (its angles are controller angles: the cell's
    /// `[robot.controller]`), every other byte is kept; `--out` gets the filtered program.
    #[arg(long, value_name = "PROGRAM")]
    pub program: Option<PathBuf>,
    /// The program's language when its extension does not say: `krl`, `rapid` or `urscript`.
    #[arg(long, requires = "program", value_parser = ["krl", "rapid", "urscript"])]
    pub language: Option<String>,
    /// Write a compensated Cartesian target as joints where the language takes joints at that
    /// place (UR `movej`/`movel`/`movep`, KRL inline `PTP`); elsewhere it stays Cartesian.
    #[arg(long, requires = "program")]
    pub to_joints: bool,
    /// Output: the compensated program (CSV: pose_id, the joints to command, for Cartesian
    /// targets the pose to send, then status, position_error_mm, orientation_error_deg,
    /// solution).
    #[arg(long)]
    pub out: PathBuf,
    /// The largest change of a revolute joint from the uncompensated row (deg). A row whose
    /// exact calibrated solution changes a joint by more (a branch change, or a whip near a
    /// singularity) is solved with position priority within the limit, and gets the status
    /// `joint-change-limit` if that misses the tolerance.
    #[arg(long, default_value_t = 5.0, value_name = "DEG")]
    pub max_joint_change_deg: f64,
    /// The largest change of a prismatic joint from the uncompensated row (mm).
    #[arg(long, default_value_t = 5.0, value_name = "MM")]
    pub max_joint_change_mm: f64,
    /// The payload the robot carries along the program (a cell's `[[payload]]` name, or
    /// `none`): the compensation includes its deflection, and the output's first line says
    /// which payload it is for. Default: the payload the calibration data carried if they
    /// carried one only, else none.
    #[arg(long)]
    pub payload: Option<String>,
    /// Overwrite existing output files (never an input file).
    #[arg(long)]
    pub force: bool,
    /// Calibration data (CSV, as for `identify`) on which to fit a polynomial correction of
    /// the position error the calibrated model leaves (measured − predicted, book §5.4); the
    /// targets are then shifted by its prediction and the output gets `correction_*_mm`
    /// columns (the shift applied to each target, world frame).
    #[arg(long, value_name = "DATA.csv", conflicts_with = "program")]
    pub nonparametric: Option<PathBuf>,
    /// Total degree of the correction polynomials.
    #[arg(long, default_value_t = 3, requires = "nonparametric")]
    pub degree: usize,
    /// What the correction is a function of: `arm-joints` (q1…q3: the configuration sets the
    /// non-geometric errors, and the same TCP position in another configuration has another
    /// error), `joints` (all joints) or `position` (TCP position, world frame).
    #[arg(long, default_value = "arm-joints", value_parser = ["arm-joints", "joints", "position"], requires = "nonparametric")]
    pub nonparametric_inputs: String,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    for (flag, v) in [
        ("--max-joint-change-deg", a.max_joint_change_deg),
        ("--max-joint-change-mm", a.max_joint_change_mm),
    ] {
        if !(v.is_finite() && v > 0.0) {
            anyhow::bail!("{flag} {v}: the joint-change limit must be a positive number");
        }
    }
    let limit = JointChangeLimit {
        revolute: a.max_joint_change_deg.to_radians(),
        prismatic: a.max_joint_change_mm,
    };
    let targets = match (&a.program, &a.targets) {
        (Some(program), _) => return run_program(a, program, limit),
        (None, Some(t)) => t,
        (None, None) => anyhow::bail!("give --targets or --program"),
    };
    let mut inputs = vec![Path::new(&a.cell), &a.calibration.estimate, targets];
    inputs.extend(a.nonparametric.as_deref());
    let outputs = Outputs::plan(a.force, &inputs, &[&a.out])?;
    let cell = load_cell(&a.cell)?;
    let model = &cell.model;
    let (est, note) = a.calibration.load(Some(model))?;
    let calibrated = est.params_for(model)?;
    let (payload, payload_how) = est.payload_for(model, a.payload.as_deref())?;
    let program = ProgramFile::read(
        read_capped(targets, DATA_CAP)?,
        &targets.display().to_string(),
        model,
        &cell.data_format(),
    )?;
    // the rows' joints: the program, or the Cartesian targets' starting configurations
    warn_outside_fitted_ranges(&est, model, &program.rows);
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
    let comp = compensate_program(
        model,
        &calibrated,
        &program,
        &IkSettings {
            payload,
            joint_change_limit: limit,
            ..IkSettings::default()
        },
        correction.as_ref(),
    )?;
    let csv = cell.with_controller_columns(comp.csv)?;
    let with_payload = if model.payloads.is_empty() {
        csv
    } else {
        with_note(
            csv,
            Some(&format!("compensated for {payload_how}")),
            NoteStyle::Hash,
        )
    };
    outputs.commit(&[(
        &a.out,
        &with_note(with_payload, note.as_deref(), NoteStyle::Hash),
    )])?;
    println!(
        "{} {} filtered through the calibrated model → {} ({} not converged; see the status column)",
        comp.rows,
        if comp.cartesian { "Cartesian targets" } else { "joint configurations" },
        a.out.display(),
        comp.not_converged
    );
    if comp.position_priority > 0 {
        println!(
            "{} rows need a joint change beyond {} deg / {} mm: solved with position priority \
             within it, {} of them beyond the tolerance (status joint-change-limit)",
            comp.position_priority,
            a.max_joint_change_deg,
            a.max_joint_change_mm,
            comp.beyond_change_limit
        );
    }
    if !model.payloads.is_empty() {
        println!("payload: {payload_how}");
    }
    Ok(())
}

/// `--program`: filter a controller program in place, print what was compensated and what
/// was left unchanged with its line.
fn run_program(a: &Args, path: &Path, limit: JointChangeLimit) -> anyhow::Result<()> {
    let shown = path.display().to_string();
    let language = match &a.language {
        Some(name) => Language::from_name(name).expect("clap checks the name"),
        None => Language::from_extension(&shown).ok_or_else(|| {
            anyhow::anyhow!(
                "{shown}: the extension does not say the language (.src/.dat KRL, .mod RAPID, \
                 .script UR); give --language krl|rapid|urscript"
            )
        })?,
    };
    let inputs = [Path::new(&a.cell), a.calibration.estimate.as_path(), path];
    let outputs = Outputs::plan(a.force, &inputs, &[&a.out])?;
    let cell = load_cell(&a.cell)?;
    let model = &cell.model;
    let (est, note) = a.calibration.load(Some(model))?;
    if let Some(note) = note {
        anyhow::bail!(
            "{note}: a controller program carries no note of it, so armcal does not filter \
             one with this calibration"
        );
    }
    let calibrated = est.params_for(model)?;
    let (payload, payload_how) = est.payload_for(model, a.payload.as_deref())?;
    let text = read_capped(path, TEXT_CAP)?;
    let filtered = armcal::filter_controller_program(
        model,
        &calibrated,
        &cell.controller,
        &text,
        &shown,
        &ProgramSettings {
            language,
            to_joints: a.to_joints,
            ik: IkSettings {
                payload,
                joint_change_limit: limit,
                ..IkSettings::default()
            },
        },
    )?;
    outputs.commit(&[(&a.out, &filtered.text)])?;
    let left: Vec<_> = filtered.targets.iter().filter(|t| !t.compensated).collect();
    println!(
        "{} ({}): {} motion targets, {} compensated, {} left unchanged → {}",
        shown,
        language.name(),
        filtered.targets.len(),
        filtered.compensated(),
        left.len(),
        a.out.display()
    );
    println!("controller angles: {}", cell.controller.source);
    for t in &filtered.targets {
        let what = if t.cartesian { "Cartesian" } else { "joints" };
        if t.compensated {
            let how = if t.converted_to_joints {
                ", written as joints"
            } else {
                ""
            };
            let note = if t.reason.is_empty() {
                String::new()
            } else {
                format!("; {}", t.reason)
            };
            println!(
                "  line {:>4}  {:<24} {what}: compensated, largest joint change {:.4}°{how}{note}",
                t.line, t.name, t.max_joint_change
            );
        } else {
            println!(
                "  line {:>4}  {:<24} left unchanged: {}",
                t.line, t.name, t.reason
            );
        }
    }
    if !model.payloads.is_empty() {
        println!("payload: {payload_how}");
    }
    Ok(())
}
