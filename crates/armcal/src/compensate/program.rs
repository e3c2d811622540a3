//! Program filtering (book §5.1): (a) a joint program taught or computed with the nominal
//! model becomes the joint program that makes the real (calibrated) robot reach what the
//! nominal model meant; (b) Cartesian targets for a controller that keeps its nominal model
//! are shifted so that its nominal inverse kinematics lands on the calibrated solution.
//!
//! Every row carries its own status ([`IkResult::describe`]): a row outside the joint limits
//! or out of reach is reported, never an error for the whole program. With a
//! [`ResidualCorrection`] (book §5.4) the remaining, non-kinematic position error it
//! predicts is compensated too: the calibrated model is asked to reach `t − ê(q)` so that
//! the real robot, which lands at `FK_cal(q) + e(q)`, reaches `t`.
//!
//! [`compensate_program`] does either for a program file (`armcal compensate`): Cartesian
//! targets if its header has orientation columns, a joint program otherwise, and returns the
//! compensated program as CSV with a status per row.
//!
//! (Over 600 lines: one filter — the rows as values, their CSV reader and writer, and the
//! program record — whose parts share the row types; split, each would re-export the others.)

use crate::compensate::ik::{CalibratedIk, IkResult, IkSettings, IkStatus, IkTarget};
use crate::compensate::joint_change::{self, within_joint_change_limit};
use crate::compensate::nonparametric::ResidualCorrection;
use crate::measure::format::DataFormat;
use crate::measure::{csv, MeasurementKind};
use crate::model::{forward_kinematics, Data, Model, Pose};
use crate::table::Table;
use crate::Error;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Fixed-point passes of the nonparametric correction: `q_{k+1} = IK(t − ê(q_k))`. The
/// correction changes little over the joint step it causes, so two passes settle it far
/// below its own accuracy.
const CORRECTION_PASSES: usize = 2;

/// Decimals of the compensated program's joints (deg, or mm for a prismatic joint), its
/// Cartesian targets (mm, deg) and its residuals: 10⁻⁶° is 17 nrad, 0.03 µm at 2 m of
/// reach, and 10⁻⁶ mm is 1 nm — a thousand times below the finest robot's resolution
/// (0.001° and 0.01 mm for an industrial controller's joint and Cartesian targets), and
/// above the last digits in which builds on different platforms (libm, FMA) may differ.
const DECIMALS: usize = 6;

/// One filtered program row.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FilteredRow {
    /// The row's `pose_id`.
    pub id: String,
    /// The program's joint values (nominal model).
    pub q_nominal: Vec<f64>,
    /// The solve with the calibrated model.
    pub result: IkResult,
    /// The nonparametric correction applied to the target position (world, mm): the
    /// negated predicted residual error at the solution, zero without a correction.
    pub correction: Vector3<f64>,
}

/// What every row of a program shares: the calibrated IK, the nonparametric correction and
/// the previous row's joint correction (for continuity within the joint-change limit).
struct RowCompensator<'a> {
    ik: CalibratedIk<'a>,
    model: &'a Model,
    calibrated: &'a [f64],
    correction: Option<&'a ResidualCorrection>,
    data: Data<f64>,
    previous: Option<Vec<f64>>,
}

impl<'a> RowCompensator<'a> {
    fn new(
        model: &'a Model,
        nominal: &[f64],
        calibrated: &'a [f64],
        settings: &IkSettings,
        correction: Option<&'a ResidualCorrection>,
    ) -> Self {
        RowCompensator {
            ik: CalibratedIk::new(model, nominal, calibrated, settings.clone()),
            model,
            calibrated,
            correction,
            data: Data::new(model),
            previous: None,
        }
    }

    /// `exact` (an unlimited solve for `target`) within the joint-change limit around the
    /// `uncompensated` joints, if the row has them ([`within_joint_change_limit`]).
    fn limited(
        &mut self,
        target: &IkTarget,
        exact: IkResult,
        uncompensated: Option<&[f64]>,
    ) -> IkResult {
        match uncompensated {
            Some(q0) => within_joint_change_limit(
                &mut self.ik,
                self.model,
                target,
                exact,
                q0,
                self.previous.as_deref(),
            ),
            None => exact,
        }
    }

    /// The row for `pose` whose unlimited solve gave `exact`: within the joint-change limit,
    /// then with the nonparametric correction if any — re-solved for the target position
    /// shifted by `−ê(q)` (book §5.4), seeded with the previous solution. Returns the final
    /// result and the shift applied (zero without a correction), and keeps the row's joint
    /// correction for the next row.
    fn row(
        &mut self,
        pose: &Pose<f64>,
        exact: IkResult,
        uncompensated: Option<&[f64]>,
    ) -> (IkResult, Vector3<f64>) {
        let mut result = self.limited(&IkTarget::Pose(*pose), exact, uncompensated);
        let mut shift = Vector3::zeros();
        if let Some(corr) = self.correction {
            for _ in 0..CORRECTION_PASSES {
                forward_kinematics(self.model, &mut self.data, self.calibrated, &result.q);
                shift = -corr.predict(&result.q, &self.data.tool().trans);
                let shifted = IkTarget::Pose(Pose {
                    rot: pose.rot,
                    trans: pose.trans + shift,
                });
                let seed = std::mem::take(&mut result.q);
                let exact = self.ik.solve_from(&shifted, &seed);
                result = self.limited(&shifted, exact, uncompensated);
            }
        }
        self.previous = match (uncompensated, result.status) {
            (Some(q0), IkStatus::Converged | IkStatus::JointChangeLimit) => {
                Some(joint_change::correction(self.model, q0, &result.q))
            }
            _ => None,
        };
        (result, shift)
    }
}

/// (a) For each joint configuration of a nominal program, the joints with which the
/// calibrated robot reaches the pose the nominal model predicts there (full tool pose),
/// each joint changed by no more than [`IkSettings::joint_change_limit`]
/// ([`crate::compensate::joint_change`]). The row's own joints seed the solve: they are
/// the exact nominal solution of that pose (the branch the program chose), so no closed
/// form is needed.
///
/// ```
/// use armcal::compensate::filter_joint_program;
/// use armcal::model::random_configurations;
/// use armcal::{IkSettings, IkStatus};
///
/// # fn main() -> armcal::Result<()> {
/// let cell = armcal::cell::builtin::paper_cell()?;
/// let model = &cell.model;
/// let nominal = model.nominal();
/// let mut calibrated = nominal.clone();
/// let k = model.registry.index_of("j2.a").unwrap();
/// calibrated[k] += 0.5; // the calibration found link 2 half a millimetre longer
/// let program: Vec<(String, Vec<f64>)> = random_configurations(model, 5, 3)
///     .into_iter()
///     .enumerate()
///     .map(|(i, q)| (format!("p{i}"), q))
///     .collect();
/// let rows = filter_joint_program(model, &nominal, &calibrated, &program, &IkSettings::default());
/// for (row, (_, q)) in rows.iter().zip(&program) {
///     if row.result.status == IkStatus::Converged {
///         // The joints change a little, and the calibrated robot reaches the nominal pose.
///         assert!(row.result.q.iter().zip(q).any(|(a, b)| a != b));
///         assert!(row.result.position_error < 1e-6);
///     }
/// }
/// # Ok(())
/// # }
/// ```
pub fn filter_joint_program(
    model: &Model,
    nominal: &[f64],
    calibrated: &[f64],
    program: &[(String, Vec<f64>)],
    settings: &IkSettings,
) -> Vec<FilteredRow> {
    filter_joint_program_corrected(model, nominal, calibrated, program, settings, None)
}

/// [`filter_joint_program`] with an optional nonparametric correction of the residual.
pub fn filter_joint_program_corrected(
    model: &Model,
    nominal: &[f64],
    calibrated: &[f64],
    program: &[(String, Vec<f64>)],
    settings: &IkSettings,
    correction: Option<&ResidualCorrection>,
) -> Vec<FilteredRow> {
    let mut rc = RowCompensator::new(model, nominal, calibrated, settings, correction);
    let mut data = Data::new(model);
    program
        .iter()
        .map(|(id, q)| {
            forward_kinematics(model, &mut data, nominal, q);
            let target = *data.tool();
            let exact = rc.ik.solve_from(&IkTarget::Pose(target), q);
            let (result, applied) = rc.row(&target, exact, Some(q));
            FilteredRow {
                id: id.clone(),
                q_nominal: q.clone(),
                result,
                correction: applied,
            }
        })
        .collect()
}

/// A compensated joint program as a record (the demo's summary holds one, the report draws
/// its joint corrections): every row's joints before and after compensation, in the joints'
/// display units (deg, mm for a prismatic joint).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ProgramRecord {
    /// The joints' names, the order of every row's values.
    pub joints: Vec<String>,
    /// Each joint's display unit (`deg` or `mm`).
    pub units: Vec<String>,
    /// The rows in program order.
    pub rows: Vec<ProgramRecordRow>,
}

/// One row of a [`ProgramRecord`].
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ProgramRecordRow {
    /// The row's `pose_id`.
    pub id: String,
    /// The program's joints (nominal model; display units).
    pub nominal: Vec<f64>,
    /// The compensated joints (display units).
    pub compensated: Vec<f64>,
    /// Whether the calibrated solve converged.
    pub converged: bool,
    /// The solve's status in words ([`IkResult::describe`]).
    pub status: String,
    /// Remaining position error of the calibrated solve (mm).
    pub position_error_mm: f64,
    /// Remaining orientation error of the calibrated solve (deg).
    #[serde(default)]
    pub orientation_error_deg: f64,
    /// Whether the exact solution changes a joint by more than the joint-change limit
    /// ([`IkStatus::JointChangeLimit`]): the row holds the position-priority solution within
    /// the limit, which misses by the remaining errors.
    #[serde(default)]
    pub beyond_change_limit: bool,
    /// Whether the row was solved with position priority within the joint-change limit.
    #[serde(default)]
    pub position_priority: bool,
}

impl ProgramRecord {
    /// The record of the filtered rows `rows` of `model`.
    pub fn of(model: &Model, rows: &[FilteredRow]) -> ProgramRecord {
        let display = |q: &[f64]| -> Vec<f64> {
            q.iter()
                .zip(&model.joints)
                .map(|(v, j)| csv::joint_display(j, *v))
                .collect()
        };
        ProgramRecord {
            joints: model.joints.iter().map(|j| j.name.clone()).collect(),
            units: model
                .joints
                .iter()
                .map(|j| j.kind.unit().display_name().to_string())
                .collect(),
            rows: rows
                .iter()
                .map(|r| ProgramRecordRow {
                    id: r.id.clone(),
                    nominal: display(&r.q_nominal),
                    compensated: display(&r.result.q),
                    converged: r.result.status.status().is_converged(),
                    status: r.result.describe(model),
                    position_error_mm: r.result.position_error,
                    orientation_error_deg: r.result.orientation_error.to_degrees(),
                    beyond_change_limit: r.result.status == IkStatus::JointChangeLimit,
                    position_priority: r.result.position_priority,
                })
                .collect(),
        }
    }
}

/// One corrected Cartesian target.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CorrectedTarget {
    /// The pose to send to the controller (its nominal model's pose at the solution).
    pub pose: Pose<f64>,
    /// The solve with the calibrated model.
    pub result: IkResult,
    /// The nonparametric correction applied to the target position (world, mm).
    pub correction: Vector3<f64>,
}

/// (b) For each desired tool pose, the pose to send to a controller that uses the nominal
/// model: the nominal model's pose at the calibrated solution. The solve starts from the
/// nominal closed-form branch nearest `references[i]` (e.g. the controller's current or
/// nominal joints) where the robot has a closed form, from `references[i]` otherwise; each
/// joint changes by no more than [`IkSettings::joint_change_limit`] from the joints the
/// controller would command with its nominal model
/// ([`CalibratedIk::nominal_solution`]; no limit for a target the nominal model cannot
/// solve).
pub fn corrected_cartesian_targets(
    model: &Model,
    nominal: &[f64],
    calibrated: &[f64],
    targets: &[Pose<f64>],
    references: &[Vec<f64>],
    settings: &IkSettings,
    correction: Option<&ResidualCorrection>,
) -> Vec<CorrectedTarget> {
    let mut rc = RowCompensator::new(model, nominal, calibrated, settings, correction);
    let mut data = Data::new(model);
    targets
        .iter()
        .zip(references)
        .map(|(t, reference)| {
            let target = IkTarget::Pose(*t);
            let exact = rc.ik.solve(&target, reference);
            let uncompensated = rc.ik.nominal_solution(&target, reference);
            let (result, correction) = rc.row(t, exact, uncompensated.as_deref());
            forward_kinematics(model, &mut data, nominal, &result.q);
            CorrectedTarget {
                pose: *data.tool(),
                result,
                correction,
            }
        })
        .collect()
}

/// A program as values: the input of [`compensate`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Program {
    /// Joint rows taught or computed with the nominal model: `(pose_id, q)`, internal units
    /// (rad, mm).
    Joints {
        /// The rows.
        rows: Vec<(String, Vec<f64>)>,
    },
    /// Cartesian tool targets in the world frame (mm, rad), each with the joints its solve
    /// starts from (the controller's current or nominal joints; internal units).
    Targets {
        /// `(pose_id, target, reference joints)` per row.
        rows: Vec<(String, Pose<f64>, Vec<f64>)>,
    },
}

/// One compensated row of [`compensate`].
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CompensatedRow {
    /// The row's `pose_id`.
    pub id: String,
    /// For Cartesian targets, the pose to send to the controller (world, mm); `None` for a
    /// joint row (send `result.q`).
    pub send: Option<Pose<f64>>,
    /// The calibrated solve: its joints (internal units), status and residual errors.
    pub result: IkResult,
    /// The nonparametric correction applied to the target position (world, mm; zero
    /// without one).
    pub correction: Vector3<f64>,
}

/// Compensates `program` (book §5.1) for `model` with the `calibrated` parameters and the
/// residual `correction`, if any (book §5.4): [`filter_joint_program_corrected`] or
/// [`corrected_cartesian_targets`]. Every row has its own status; none fails the program.
///
/// ```
/// use armcal::{compensate, IkSettings, Program};
/// let cell = armcal::cell::builtin::paper_cell()?;
/// let model = &cell.model;
/// let program = Program::Joints { rows: vec![("p1".into(), vec![0.1, -0.2, 0.3, 0.0, 0.4, 0.0])] };
/// // With the nominal parameters as the calibration, every row stays where it is.
/// let rows = compensate(model, &model.nominal(), &program, &IkSettings::default(), None);
/// assert!(rows[0].result.status.status().is_converged());
/// assert!((rows[0].result.q[4] - 0.4).abs() < 1e-9);
/// # Ok::<(), armcal::Error>(())
/// ```
pub fn compensate(
    model: &Model,
    calibrated: &[f64],
    program: &Program,
    settings: &IkSettings,
    correction: Option<&ResidualCorrection>,
) -> Vec<CompensatedRow> {
    let nominal = model.nominal();
    match program {
        Program::Joints { rows } => {
            filter_joint_program_corrected(model, &nominal, calibrated, rows, settings, correction)
                .into_iter()
                .map(|r| CompensatedRow {
                    id: r.id,
                    send: None,
                    result: r.result,
                    correction: r.correction,
                })
                .collect()
        }
        Program::Targets { rows } => {
            let poses: Vec<Pose<f64>> = rows.iter().map(|r| r.1).collect();
            let references: Vec<Vec<f64>> = rows.iter().map(|r| r.2.clone()).collect();
            corrected_cartesian_targets(
                model,
                &nominal,
                calibrated,
                &poses,
                &references,
                settings,
                correction,
            )
            .into_iter()
            .zip(rows)
            .map(|(r, row)| CompensatedRow {
                id: row.0.clone(),
                send: Some(r.pose),
                result: r.result,
                correction: r.correction,
            })
            .collect()
        }
    }
}

/// A compensated program file.
#[derive(Clone, Debug)]
pub struct CompensatedProgram {
    /// Whether the file held Cartesian targets (else a joint program).
    pub cartesian: bool,
    /// Rows compensated.
    pub rows: usize,
    /// Rows whose solve did not converge (their status column says why).
    pub not_converged: usize,
    /// Of those, rows whose exact solution changes a joint by more than the joint-change
    /// limit ([`IkStatus::JointChangeLimit`]).
    pub beyond_change_limit: usize,
    /// Rows solved with position priority within the joint-change limit (converged or
    /// not; [`crate::compensate::joint_change`]).
    pub position_priority: usize,
    /// The output CSV: `pose_id`, the joints, for Cartesian targets the pose to send, with a
    /// correction the `correction_*_mm` shift, then `status`, `position_error_mm`,
    /// `orientation_error_deg`, `solution` (`calibrated-ik`, or `position-priority` for a
    /// row solved within the joint-change limit).
    pub csv: String,
}

/// A program file as read: its text and name, whether it holds Cartesian targets (its
/// header has a `roll…` column) and its rows' ids and joint values.
#[derive(Clone, Debug)]
pub struct ProgramFile {
    /// The file's text.
    pub text: String,
    /// The file's name, for messages.
    pub file: String,
    /// Whether the rows are Cartesian tool targets (else joint configurations).
    pub cartesian: bool,
    /// `(pose_id, q)` per row: the program, or the Cartesian targets' starting guesses.
    pub rows: Vec<(String, Vec<f64>)>,
    /// How its joint columns are laid out.
    pub format: DataFormat,
}

impl ProgramFile {
    /// Reads a program file's text for `model`, its joint columns laid out as `format` says
    /// (a cell's [`crate::cell::Cell::data_format`]: armcal's own `q1_deg` … model columns,
    /// `q1_controller_deg` … controller columns, or the cell's `[data]` mapping).
    pub fn read(
        text: String,
        file: &str,
        model: &Model,
        format: &DataFormat,
    ) -> Result<ProgramFile, Error> {
        let cartesian = csv::header_str(&text, file)?
            .iter()
            .any(|h| h.starts_with("roll"));
        let rows = csv::read_configurations_format_str(&text, file, model, format)?;
        Ok(ProgramFile {
            file: file.into(),
            cartesian,
            rows,
            text,
            format: format.clone(),
        })
    }
}

/// Compensates a program file for `model` with the `calibrated` parameters (and the residual
/// `correction`, if any): the CSV layer on [`compensate`], Cartesian targets (the joint
/// columns their starting guesses) or a joint program.
pub fn compensate_program(
    model: &Model,
    calibrated: &[f64],
    program: &ProgramFile,
    settings: &IkSettings,
    correction: Option<&ResidualCorrection>,
) -> Result<CompensatedProgram, Error> {
    let (text, file, cartesian) = (
        program.text.as_str(),
        program.file.as_str(),
        program.cartesian,
    );
    let with = correction.is_some();
    // pose_id, the joints, [the Cartesian target], [the correction], status and residuals.
    let header = |target: &[&str]| {
        let mut h = vec!["pose_id".to_string()];
        h.extend(model.joints.iter().map(csv::joint_column));
        h.extend(target.iter().map(|c| c.to_string()));
        if with {
            h.extend(["correction_x_mm", "correction_y_mm", "correction_z_mm"].map(String::from));
        }
        h.extend(
            [
                "status",
                "position_error_mm",
                "orientation_error_deg",
                "solution",
            ]
            .map(String::from),
        );
        h
    };
    // A row: its id, the solved joints, `middle` (the target), the correction and status.
    let row = |id: &str, r: &IkResult, middle: Vec<String>, c: &Vector3<f64>| {
        let mut fields = vec![id.to_string()];
        fields.extend(
            r.q.iter()
                .zip(&model.joints)
                .map(|(v, j)| format!("{:.DECIMALS$}", csv::joint_display(j, *v))),
        );
        fields.extend(middle);
        if with {
            fields.extend([c.x, c.y, c.z].map(|x| format!("{x:.6}")));
        }
        fields.extend([
            r.describe(model),
            format!("{:.DECIMALS$}", r.position_error),
            format!("{:.DECIMALS$}", r.orientation_error.to_degrees()),
            if r.position_priority {
                "position-priority"
            } else {
                "calibrated-ik"
            }
            .to_string(),
        ]);
        fields
    };
    let values = if cartesian {
        // Read the tool poses with a robot-only model: rows become world-frame poses.
        let mut robot_only = model.spec();
        robot_only.instrument = None;
        robot_only.targets.clear();
        let robot = Model::from_spec(&robot_only)?;
        let data = csv::read_targets_str(
            text,
            file,
            &robot,
            program.format.controller_columns.as_ref(),
        )?;
        let rows = data
            .measurements
            .iter()
            .map(|m| match &m.kind {
                MeasurementKind::Pose { value, .. } => Ok((
                    data.config_ids[m.config].clone(),
                    *value,
                    data.configurations[m.config].clone(),
                )),
                _ => Err(Error::Input(format!(
                    "line {}: Cartesian targets need x, y, z, roll, pitch, yaw",
                    m.line
                ))),
            })
            .collect::<Result<_, Error>>()?;
        Program::Targets { rows }
    } else {
        Program::Joints {
            rows: program.rows.clone(),
        }
    };
    let rows = compensate(model, calibrated, &values, settings, correction);
    let target: &[&str] = if cartesian {
        &["x_mm", "y_mm", "z_mm", "roll_deg", "pitch_deg", "yaw_deg"]
    } else {
        &[]
    };
    let mut out = Table::new(header(target));
    let (mut failed, mut beyond, mut priority) = (0, 0, 0);
    for r in &rows {
        failed += usize::from(!r.result.status.status().is_converged());
        beyond += usize::from(r.result.status == IkStatus::JointChangeLimit);
        priority += usize::from(r.result.position_priority);
        let target = match &r.send {
            Some(pose) => {
                let (xyz, rpy) = pose.to_xyz_rpy();
                xyz.into_iter()
                    .chain(rpy.iter().map(|a| a.to_degrees()))
                    .map(|x| format!("{x:.DECIMALS$}"))
                    .collect()
            }
            None => Vec::new(),
        };
        out.row(row(&r.id, &r.result, target, &r.correction));
    }
    Ok(CompensatedProgram {
        cartesian,
        rows: program.rows.len(),
        not_converged: failed,
        beyond_change_limit: beyond,
        position_priority: priority,
        csv: out.into_string(),
    })
}
