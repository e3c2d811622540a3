//! Program filtering in the controllers' own languages (book §5.1 applied to a robot
//! program as written): KUKA KRL (`.src`/`.dat`), ABB RAPID (`.mod`) and Universal Robots
//! script (`.script`). Every motion target of the program is compensated with the
//! calibrated model and written back in place; every other byte of the file is unchanged
//! (each reader returns the byte spans of the numbers it may rewrite, nothing else is
//! touched).
//!
//! * A **joint target** (KRL `E6AXIS`/`AXIS`, RAPID `jointtarget`, a UR joint list) holds
//!   controller angles: the cell's controller convention ([`ControllerConvention`]) maps them
//!   to the model's joints, the row is filtered as a nominal joint program is
//!   ([`filter_joint_program`]: the joints with which the calibrated robot reaches the
//!   pose the nominal model meant) and mapped back.
//! * A **Cartesian target** (KRL `E6POS`/`POS`, RAPID `robtarget`, UR `p[…]`) is the tool
//!   pose in the cell's world frame (the controller's base / work object, with the cell's
//!   tool = the controller's active tool). The controller solves it with its nominal model
//!   on the branch its configuration names ([`configuration`]); that branch's joints are the
//!   reference of [`corrected_cartesian_targets`], which returns the pose the nominal
//!   controller must be sent so that the real robot lands on the one intended — written back
//!   as a pose with its configuration recomputed at the compensated joints, or, with
//!   [`ProgramSettings::to_joints`] and where the language takes a joint target at that
//!   place, as the compensated joints.
//! * A target whose compensation does not converge within the joint-change limit
//!   ([`crate::compensate::joint_change`]), or that the reader cannot compensate (a partial
//!   KRL aggregate, a relative motion, a UR pose computed at run time), is left unchanged and
//!   listed with its line and the reason.

mod configuration;
mod krl;
mod rapid;
mod scan;
mod urscript;

use crate::compensate::ik::{CalibratedIk, IkSettings, IkStatus, IkTarget};
use crate::compensate::joint_change::joint_change;
use crate::compensate::program::{corrected_cartesian_targets, filter_joint_program};
use crate::model::controller::ControllerConvention;
use crate::model::{JointKind, Model, Pose};
use crate::Error;
use configuration::{Configuration, Geometry};
use serde::{Deserialize, Serialize};
use std::ops::Range;

/// The controller language of a program.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Language {
    /// KUKA Robot Language: `.src` (motions with inline targets) and `.dat` (declarations).
    Krl,
    /// ABB RAPID: `.mod` (or `.modx`).
    Rapid,
    /// Universal Robots script: `.script` (or `.urscript`).
    UrScript,
}

impl Language {
    /// The language of a file name's extension, if armcal knows it.
    pub fn from_extension(path: &str) -> Option<Language> {
        let ext = path.rsplit_once('.')?.1.to_ascii_lowercase();
        match ext.as_str() {
            "src" | "dat" => Some(Language::Krl),
            "mod" | "modx" | "prg" => Some(Language::Rapid),
            "script" | "urscript" => Some(Language::UrScript),
            _ => None,
        }
    }

    /// The language by name: `krl`, `rapid` or `urscript`.
    pub fn from_name(name: &str) -> Option<Language> {
        match name {
            "krl" => Some(Language::Krl),
            "rapid" => Some(Language::Rapid),
            "urscript" => Some(Language::UrScript),
            _ => None,
        }
    }

    /// The language's name in messages.
    pub fn name(self) -> &'static str {
        match self {
            Language::Krl => "KUKA KRL",
            Language::Rapid => "ABB RAPID",
            Language::UrScript => "Universal Robots script",
        }
    }
}

/// How to filter a controller program.
#[derive(Clone, Debug)]
pub struct ProgramSettings {
    /// The program's language.
    pub language: Language,
    /// Write a compensated Cartesian target as joints where the language takes a joint
    /// target at that place (a UR `movel`/`movep`/`movej` argument, a KRL inline `PTP`);
    /// elsewhere it stays Cartesian and the summary says so.
    pub to_joints: bool,
    /// The calibrated IK's settings (tolerances, joint-change limit, payload).
    pub ik: IkSettings,
}

/// What happened to one motion target.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TargetOutcome {
    /// The target's line in the program (1-based).
    pub line: usize,
    /// What it is: the declared name, or the motion instruction of an inline target.
    pub name: String,
    /// Whether the target is Cartesian (else joints).
    pub cartesian: bool,
    /// Whether it was rewritten; `false`: left unchanged, `reason` says why.
    pub compensated: bool,
    /// Whether a Cartesian target was written as joints ([`ProgramSettings::to_joints`]).
    pub converted_to_joints: bool,
    /// Why it was left unchanged, or (compensated) a note: kept Cartesian where joints were
    /// asked for, or its configuration bits changed.
    pub reason: String,
    /// The largest joint change of the compensation (deg, or mm for a prismatic joint); 0 if
    /// unchanged.
    pub max_joint_change: f64,
}

/// A filtered controller program.
#[derive(Clone, Debug)]
pub struct FilteredControllerProgram {
    /// The program's language.
    pub language: Language,
    /// The program with every compensated target rewritten, every other byte as read.
    pub text: String,
    /// Every motion target in program order.
    pub targets: Vec<TargetOutcome>,
}

impl FilteredControllerProgram {
    /// The number of targets rewritten.
    pub fn compensated(&self) -> usize {
        self.targets.iter().filter(|t| t.compensated).count()
    }
}

/// A target's value as read.
#[derive(Clone, Debug)]
pub(crate) enum Value {
    /// Controller axis values (rad, mm for a prismatic joint).
    Joints(Vec<f64>),
    /// A tool pose (world frame, mm) with the configuration the controller solves it on.
    Pose {
        pose: Pose<f64>,
        configuration: Configuration,
    },
}

/// A motion target found by a reader.
#[derive(Clone, Debug)]
pub(crate) struct Target {
    /// Byte offset of the target (its line in messages).
    pub at: usize,
    /// The declared name or the motion instruction.
    pub name: String,
    /// What the target holds, or why it cannot be compensated (left unchanged).
    pub value: Result<Value, String>,
    /// The spans of the numbers the writer rewrites, in the order the language's writer
    /// returns them (joints; or position, orientation, then configuration fields if any).
    pub numbers: Vec<Range<usize>>,
    /// The whole literal (for a joint target written in place of a Cartesian one).
    pub literal: Range<usize>,
    /// Whether a joint target may replace the literal here.
    pub joint_form: bool,
}

/// What a language provides: its reader and its writers.
pub(crate) trait Dialect {
    /// Every motion target of `code` for a robot of `dof` joints, in file order.
    fn targets(&self, code: &scan::Code, dof: usize) -> Result<Vec<Target>, Error>;
    /// The numbers of a joint target (controller values, internal units).
    fn joints(&self, c: &[f64]) -> Vec<String>;
    /// The numbers of a Cartesian target: position, orientation (`previous`: the pose as
    /// read, for a quaternion's sign), configuration.
    fn pose(&self, pose: &Pose<f64>, previous: &Pose<f64>, c: &Configuration) -> Vec<String>;
    /// A joint literal to stand in place of a Cartesian one (`original`: its text).
    fn joint_literal(&self, c: &[f64], original: &str) -> String;
}

fn dialect(language: Language) -> &'static dyn Dialect {
    match language {
        Language::Krl => &krl::Krl,
        Language::Rapid => &rapid::Rapid,
        Language::UrScript => &urscript::UrScript,
    }
}

fn comment_byte(language: Language) -> u8 {
    match language {
        Language::Krl => b';',
        Language::Rapid => b'!',
        Language::UrScript => b'#',
    }
}

/// Filters the controller program `text` (file name `file`, for messages) through the
/// calibrated model: see the module documentation. `convention` maps the program's
/// controller angles to `model`'s joints. Errors (a malformed target, naming file, line and
/// field; a Cartesian configuration that does not fit the robot's geometry) stop the whole
/// program: nothing is half filtered.
pub fn filter_controller_program(
    model: &Model,
    calibrated: &[f64],
    convention: &ControllerConvention,
    text: &str,
    file: &str,
    settings: &ProgramSettings,
) -> Result<FilteredControllerProgram, Error> {
    convention
        .check(model)
        .map_err(|e| Error::Input(format!("{file}: {e}")))?;
    if let Some(j) = model.joints.iter().find(|j| j.kind != JointKind::Revolute) {
        return Err(Error::Input(format!(
            "{file}: controller programs are read for arms of revolute joints (deg or rad);              joint `{}` is prismatic",
            j.name
        )));
    }
    let d = dialect(settings.language);
    let code = scan::Code::new(text, file, comment_byte(settings.language));
    let targets = d.targets(&code, model.dof())?;
    let nominal = model.nominal();
    let geometry = if targets.iter().any(|t| {
        matches!(
            &t.value,
            Ok(Value::Pose { configuration, .. }) if configuration.needs_geometry()
        )
    }) {
        Some(Geometry::new(model, &nominal, convention).map_err(|e| {
            Error::Input(format!(
                "{file}: the program's configuration bits cannot be mapped to this robot: {e}"
            ))
        })?)
    } else {
        None
    };

    // Joint targets as one nominal joint program; Cartesian targets with the joints their
    // configuration selects (the controller's nominal solution) as references.
    let mut outcomes: Vec<TargetOutcome> = Vec::with_capacity(targets.len());
    let mut joint_rows = Vec::new();
    let (mut poses, mut references, mut cartesian) = (Vec::new(), Vec::new(), Vec::new());
    let mut previous: Option<Vec<f64>> = None;
    // The nominal controller's solution of a target without configuration bits.
    let mut nominal_ik = CalibratedIk::new(model, &nominal, &nominal, settings.ik.clone());
    for (i, t) in targets.iter().enumerate() {
        let mut outcome = TargetOutcome {
            line: code.line(t.at),
            name: t.name.clone(),
            cartesian: matches!(t.value, Ok(Value::Pose { .. })),
            compensated: false,
            converted_to_joints: false,
            reason: String::new(),
            max_joint_change: 0.0,
        };
        match &t.value {
            Err(why) => outcome.reason = why.clone(),
            Ok(Value::Joints(c)) => {
                let q = convention.to_model(c);
                previous = Some(q.clone());
                joint_rows.push((i.to_string(), q));
            }
            Ok(Value::Pose {
                pose,
                configuration,
            }) => {
                let reference = match configuration {
                    Configuration::Nearest => match &previous {
                        None => Err("no target before it: the branch the controller chooses \
                                     (nearest the robot's joints when it gets there) is unknown"
                            .to_string()),
                        Some(p) => nominal_ik
                            .nominal_solution(&IkTarget::Pose(*pose), p)
                            .ok_or_else(|| {
                                "the nominal model does not reach it from the previous \
                                 target's joints"
                                    .to_string()
                            }),
                    },
                    c => geometry
                        .as_ref()
                        .expect("built for a configuration")
                        .select(model, pose, c),
                };
                match reference {
                    Ok(q0) => {
                        previous = Some(q0.clone());
                        poses.push(*pose);
                        references.push(q0);
                        cartesian.push(i);
                    }
                    Err(why) => outcome.reason = why,
                }
            }
        }
        outcomes.push(outcome);
    }

    let mut edits: Vec<(Range<usize>, String)> = Vec::new();
    let filtered = filter_joint_program(model, &nominal, calibrated, &joint_rows, &settings.ik);
    for (row, (id, q0)) in filtered.iter().zip(&joint_rows) {
        let i: usize = id.parse().expect("the row's index");
        let o = &mut outcomes[i];
        if row.result.status != IkStatus::Converged {
            o.reason = row.result.describe(model);
            continue;
        }
        o.compensated = true;
        o.max_joint_change = largest_change(model, q0, &row.result.q);
        let numbers = d.joints(&convention.to_controller(&row.result.q));
        edits.extend(targets[i].numbers.iter().cloned().zip(numbers));
    }
    let corrected = corrected_cartesian_targets(
        model,
        &nominal,
        calibrated,
        &poses,
        &references,
        &settings.ik,
        None,
    );
    for ((r, i), q0) in corrected.iter().zip(&cartesian).zip(&references) {
        let (t, o) = (&targets[*i], &mut outcomes[*i]);
        if r.result.status != IkStatus::Converged {
            o.reason = r.result.describe(model);
            continue;
        }
        // The controller's branch: the solve must stay on the joints the configuration
        // selected (a branch outside the joint limits is replaced by another one).
        let change = largest_change(model, q0, &r.result.q);
        let within = model
            .joints
            .iter()
            .zip(q0.iter().zip(&r.result.q))
            .all(|(j, (a, b))| (b - a).abs() <= settings.ik.joint_change_limit.of(j.kind) + 1e-12);
        if !within {
            o.reason = format!(
                "the compensated joints leave the branch its configuration selects (a joint \
                 moves by {change:.3}, beyond the joint-change limit): the nominal branch is \
                 outside the joint limits or the target lies at a branch boundary"
            );
            continue;
        }
        let c = convention.to_controller(&r.result.q);
        let Ok(Value::Pose {
            pose,
            configuration,
        }) = &t.value
        else {
            unreachable!("a Cartesian target")
        };
        o.compensated = true;
        o.max_joint_change = change;
        if settings.to_joints && t.joint_form {
            o.converted_to_joints = true;
            edits.push((
                t.literal.clone(),
                d.joint_literal(&c, &text[t.literal.clone()]),
            ));
            continue;
        }
        if settings.to_joints {
            o.reason = "kept Cartesian: the language takes no joint target here".into();
        }
        let new_configuration = match (configuration, &geometry) {
            (Configuration::Nearest, _) | (_, None) => configuration.clone(),
            (c0, Some(g)) => {
                let c1 = g.configuration_of(model, &r.result.q, c0);
                if c1 != *c0 {
                    o.reason = format!(
                        "configuration {} → {} (the compensated joints' own)",
                        c0.describe(),
                        c1.describe()
                    );
                }
                c1
            }
        };
        let numbers = d.pose(&r.pose, pose, &new_configuration);
        edits.extend(t.numbers.iter().cloned().zip(numbers));
    }
    edits.sort_by_key(|(span, _)| span.start);
    // A reader returns disjoint spans; overlapping ones would corrupt the program, so they
    // are refused rather than written.
    if let Some(w) = edits.windows(2).find(|w| w[1].0.start < w[0].0.end) {
        let line = |at: usize| text[..at].matches('\n').count() + 1;
        return Err(Error::Input(format!(
            "{file}: line {}: two motion targets share the text at line {}; armcal cannot \
             filter this program (is an aggregate or statement left open?)",
            line(w[0].0.start),
            line(w[1].0.start)
        )));
    }
    let mut out = String::with_capacity(text.len() + 64 * edits.len());
    let mut at = 0;
    let bytes = text.as_bytes();
    for (span, new) in edits {
        out.push_str(&text[at..span.start]);
        // A number written against a word (`C.4519` → `C0.401198`) would join it and be read
        // back as another field (`C0`); a space keeps the two tokens apart, as they were.
        let glued = |outside: Option<&u8>, inside: Option<u8>| {
            outside.is_some_and(|&b| scan::ident_byte(b)) && inside.is_some_and(scan::ident_byte)
        };
        if glued(
            span.start.checked_sub(1).and_then(|i| bytes.get(i)),
            new.bytes().next(),
        ) {
            out.push(' ');
        }
        out.push_str(&new);
        if glued(bytes.get(span.end), new.bytes().last()) {
            out.push(' ');
        }
        at = span.end;
    }
    out.push_str(&text[at..]);
    Ok(FilteredControllerProgram {
        language: settings.language,
        text: out,
        targets: outcomes,
    })
}

/// The largest change from `q0` to `q` over the joints (deg, or mm for a prismatic joint).
fn largest_change(model: &Model, q0: &[f64], q: &[f64]) -> f64 {
    model
        .joints
        .iter()
        .zip(q0.iter().zip(q))
        .map(|(j, (a, b))| {
            crate::measure::csv::joint_display(j, joint_change(j.kind, *a, *b)).abs()
        })
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests;
