//! Evidence for program filtering: each language's sample (`tests/fixtures/programs/`,
//! armcal's own) is filtered with a perturbed calibration; the output is read back, every
//! byte outside the motion targets' numbers is the input's, and every compensated target
//! drives the calibrated model to what the nominal controller would have reached (< 1 µm).

use super::configuration::{Configuration, Geometry};
use super::*;
use crate::compensate::ik::{calibrated_ik, IkTarget, IkWorkspace};
use crate::model::controller::JointMap;
use crate::model::pose::rotation_log;
use crate::model::{forward_kinematics, Data, Unit};
use crate::Cell;

const KRL_DAT: &str = include_str!("../../../tests/fixtures/programs/robot.dat");
const KRL_SRC: &str = include_str!("../../../tests/fixtures/programs/robot.src");
const RAPID: &str = include_str!("../../../tests/fixtures/programs/robot.mod");
const URSCRIPT: &str = include_str!("../../../tests/fixtures/programs/robot.script");

/// The nominal parameters with every length changed by up to 0.4 mm and every angle by up
/// to 0.02° (deterministic), as a calibration finds them.
fn calibrated(model: &Model) -> Vec<f64> {
    model
        .registry
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let s = ((i + 1) as f64 * 1.7).sin();
            match p.unit {
                Unit::Mm => p.nominal + 0.4 * s,
                Unit::Rad => p.nominal + 0.02f64.to_radians() * s,
                _ => p.nominal,
            }
        })
        .collect()
}

fn settings(language: Language, to_joints: bool) -> ProgramSettings {
    ProgramSettings {
        language,
        to_joints,
        ik: IkSettings::default(),
    }
}

/// Every target as read: its line, name and value.
fn read(text: &str, language: Language, dof: usize) -> Vec<Target> {
    let code = scan::Code::new(text, "test", comment_byte(language));
    dialect(language).targets(&code, dof).unwrap()
}

/// The text outside the targets' number spans (and, for a converted target, its literal).
fn skeleton(text: &str, targets: &[Target]) -> String {
    let mut spans: Vec<Range<usize>> = targets
        .iter()
        .flat_map(|t| match &t.value {
            Ok(Value::Joints(_)) | Ok(Value::Pose { .. }) => t.numbers.clone(),
            Err(_) => Vec::new(),
        })
        .collect();
    spans.sort_by_key(|s| s.start);
    let mut out = String::new();
    let mut at = 0;
    for s in spans {
        out.push_str(&text[at..s.start]);
        out.push('#');
        at = s.end;
    }
    out.push_str(&text[at..]);
    out
}

/// The tool pose of model joints `q` with parameters `p`.
fn fk(model: &Model, p: &[f64], q: &[f64]) -> Pose<f64> {
    let mut data = Data::new(model);
    forward_kinematics(model, &mut data, p, q);
    *data.tool()
}

/// Position (mm) and orientation (rad) distance of two poses.
fn distance(a: &Pose<f64>, b: &Pose<f64>) -> (f64, f64) {
    (
        (a.trans - b.trans).norm(),
        rotation_log(&(a.rot.transpose() * b.rot)).norm(),
    )
}

/// Filters `text` for `cell` and checks the evidence: returns the outcomes.
fn filter_and_check(
    cell: &Cell,
    convention: &ControllerConvention,
    text: &str,
    language: Language,
    to_joints: bool,
) -> (FilteredControllerProgram, usize) {
    let model = &cell.model;
    let (nominal, cal) = (model.nominal(), calibrated(model));
    let out = filter_controller_program(
        model,
        &cal,
        convention,
        text,
        "sample",
        &settings(language, to_joints),
    )
    .unwrap();
    let before = read(text, language, model.dof());
    let after = read(&out.text, language, model.dof());
    assert_eq!(before.len(), after.len());
    assert_eq!(before.len(), out.targets.len());
    // Every byte outside the targets' numbers is unchanged (a converted target's literal
    // is checked by its own reading below).
    if !out.targets.iter().any(|t| t.converted_to_joints) {
        assert_eq!(skeleton(text, &before), skeleton(&out.text, &after));
    }
    let geometry = Geometry::new(model, &nominal, convention).ok();
    let mut ws = IkWorkspace::new(model);
    let mut previous_in: Option<Vec<f64>> = None;
    let mut previous_out: Option<Vec<f64>> = None;
    let mut checked = 0;
    for ((b, a), o) in before.iter().zip(&after).zip(&out.targets) {
        // What the nominal controller reaches with the program as read.
        let (intended, q_in) = match &b.value {
            Ok(Value::Joints(c)) => {
                let q = convention.to_model(c);
                (fk(model, &nominal, &q), Some(q))
            }
            Ok(Value::Pose {
                pose,
                configuration,
            }) => {
                let q = match configuration {
                    Configuration::Nearest => previous_in.clone(),
                    c => geometry.as_ref().unwrap().select(model, pose, c).ok(),
                };
                (*pose, q)
            }
            Err(_) => {
                assert!(!o.compensated);
                assert_eq!(&text[b.literal.clone()], &out.text[a.literal.clone()]);
                continue;
            }
        };
        previous_in = q_in.clone().or(previous_in);
        if !o.compensated {
            continue;
        }
        // Where the compensated target drives the real (calibrated) robot: the nominal
        // controller's joints for it.
        let q_out = match &a.value {
            Ok(Value::Joints(c)) => convention.to_model(c),
            Ok(Value::Pose {
                pose,
                configuration,
            }) => match configuration {
                Configuration::Nearest => {
                    let seed = previous_out.clone().unwrap();
                    let r = calibrated_ik(
                        model,
                        &nominal,
                        &IkTarget::Pose(*pose),
                        &seed,
                        &IkSettings::default(),
                        &mut ws,
                    );
                    assert_eq!(r.status, IkStatus::Converged, "{o:?}");
                    r.q
                }
                c => geometry.as_ref().unwrap().select(model, pose, c).unwrap(),
            },
            Err(e) => panic!("compensated target unreadable: {e}"),
        };
        previous_out = Some(q_out.clone());
        let (dp, dr) = distance(&fk(model, &cal, &q_out), &intended);
        assert!(dp < 1e-3 && dr < 1e-6, "{o:?}: {dp} mm, {dr} rad");
        // The calibration matters at this target: the uncompensated one misses.
        let (miss, _) = distance(&fk(model, &cal, q_in.as_ref().unwrap()), &intended);
        assert!(
            miss > 0.01,
            "{o:?}: the calibration moves the tool {miss} mm only"
        );
        checked += 1;
    }
    (out, checked)
}

fn cell(name: &str) -> Cell {
    Cell::load(name).unwrap()
}

#[test]
fn krl_dat_is_filtered_in_place() {
    let c = cell("kr15");
    let (out, checked) = filter_and_check(&c, &c.controller, KRL_DAT, Language::Krl, false);
    assert_eq!(checked, out.compensated());
    assert_eq!(out.compensated(), out.targets.len(), "{:?}", out.targets);
}

#[test]
fn krl_src_inline_targets_are_filtered_and_partial_ones_kept() {
    let c = cell("kr15");
    let (out, checked) = filter_and_check(&c, &c.controller, KRL_SRC, Language::Krl, false);
    assert_eq!(checked, out.compensated());
    let left: Vec<&TargetOutcome> = out.targets.iter().filter(|t| !t.compensated).collect();
    assert_eq!(left.len(), 2, "{left:?}");
    assert!(left.iter().any(|t| t.reason.contains("partial aggregate")));
    assert!(left.iter().any(|t| t.reason.contains("relative motion")));
}

#[test]
fn krl_inline_ptp_converts_to_joints() {
    let c = cell("kr15");
    let (out, _) = filter_and_check(&c, &c.controller, KRL_SRC, Language::Krl, true);
    let converted: Vec<&TargetOutcome> = out
        .targets
        .iter()
        .filter(|t| t.converted_to_joints)
        .collect();
    assert_eq!(converted.len(), 1, "{:?}", out.targets);
    assert_eq!(converted[0].name, "SPTP");
    assert!(out
        .targets
        .iter()
        .any(|t| t.reason.starts_with("kept Cartesian")));
}

#[test]
fn rapid_module_is_filtered_in_place() {
    let c = cell("irb120");
    let (out, checked) = filter_and_check(&c, &c.controller, RAPID, Language::Rapid, false);
    assert_eq!(checked, out.compensated());
    assert_eq!(out.compensated(), out.targets.len(), "{:?}", out.targets);
}

#[test]
fn urscript_is_filtered_and_run_time_targets_kept() {
    let c = cell("ur10");
    let (out, checked) = filter_and_check(&c, &c.controller, URSCRIPT, Language::UrScript, false);
    assert_eq!(checked, out.compensated());
    let left: Vec<&TargetOutcome> = out.targets.iter().filter(|t| !t.compensated).collect();
    assert_eq!(left.len(), 1, "{left:?}");
    assert!(left[0].reason.contains("run time"));
    let (joints, _) = filter_and_check(&c, &c.controller, URSCRIPT, Language::UrScript, true);
    assert_eq!(
        joints
            .targets
            .iter()
            .filter(|t| t.converted_to_joints)
            .count(),
        out.targets
            .iter()
            .filter(|t| t.cartesian && t.compensated)
            .count()
    );
}

/// A controller that negates axes 2, 3 and 5 and counts axis 2 from −90°: the program
/// written in its angles filters to the same model joints as the model-angle program.
#[test]
fn a_negated_axis_convention_round_trips() {
    let c = cell("ur10");
    let mut negated = ControllerConvention::model_angles(6);
    negated.joints[1] = JointMap {
        sign: -1.0,
        offset: -90f64.to_radians(),
    };
    negated.joints[2].sign = -1.0;
    negated.joints[4].sign = -1.0;
    // The sample's joint lists rewritten in the negated controller's angles.
    let identity = ControllerConvention::model_angles(6);
    let targets = read(URSCRIPT, Language::UrScript, 6);
    let mut text = String::new();
    let mut at = 0;
    for t in &targets {
        if let Ok(Value::Joints(c)) = &t.value {
            let written = urscript::UrScript.joints(&negated.to_controller(c));
            for (span, w) in t.numbers.iter().zip(written) {
                text.push_str(&URSCRIPT[at..span.start]);
                text.push_str(&w);
                at = span.end;
            }
        }
    }
    text.push_str(&URSCRIPT[at..]);
    assert_ne!(text, URSCRIPT);
    let (a, _) = filter_and_check(&c, &identity, URSCRIPT, Language::UrScript, false);
    let (b, _) = filter_and_check(&c, &negated, &text, Language::UrScript, false);
    let (ra, rb) = (
        read(&a.text, Language::UrScript, 6),
        read(&b.text, Language::UrScript, 6),
    );
    for (x, y) in ra.iter().zip(&rb) {
        match (&x.value, &y.value) {
            (Ok(Value::Joints(p)), Ok(Value::Joints(q))) => {
                let (p, q) = (identity.to_model(p), negated.to_model(q));
                for (u, v) in p.iter().zip(&q) {
                    assert!((u - v).abs() < 1e-8, "{p:?} {q:?}");
                }
            }
            (Ok(Value::Pose { pose: p, .. }), Ok(Value::Pose { pose: q, .. })) => {
                let (dp, dr) = distance(p, q);
                assert!(dp < 1e-6 && dr < 1e-9);
            }
            _ => {}
        }
    }
}

#[test]
fn bad_input_names_file_line_and_field() {
    let c = cell("kr15");
    let model = &c.model;
    let cases = [
        (Language::Krl, "DEF a()\nLIN {X 1,Y 2,Z abc,A 0,B 0,C 0}\nEND\n", "line 2: `Z`"),
        (Language::Krl, "DECL E6POS XP1={X 1,Y 2,Z 3,A 0,B 0,C 0,S 'B2',T 0}\n", "line 1: `S`"),
        (Language::Krl, "PTP {A1 0,A2 0\n", "line 1: `{`"),
        (Language::Rapid, "MODULE m\n  CONST robtarget p := [[1,2,3],[1,0,0,0],[0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\nENDMODULE\n", "line 2: `robconf`"),
        (Language::Rapid, "MODULE m\nMoveL [[1,2,3],[2,0,0,0],[0,0,0,0],[0,0,0,0,0,0]], v1, z1, tool0;\n", "line 2: `rot`"),
        (Language::UrScript, "def a():\n  movel(p[0.1, 0.2, 0.3, 0, 0], a=1)\nend\n", "line 2: `movel`"),
        (Language::UrScript, "def a():\n  movej([0, 1, x, 0, 0, 0])\nend\n", "line 2: `q3`"),
    ];
    for (language, text, want) in cases {
        let e = filter_controller_program(
            model,
            &model.nominal(),
            &c.controller,
            text,
            "prog",
            &settings(language, false),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("prog") && e.contains(want), "{e}");
    }
}

#[test]
fn configuration_bits_are_refused_for_a_robot_they_do_not_fit() {
    let c = cell("ur10");
    let text = "DECL E6POS XP1={X 100,Y 200,Z 300,A 0,B 0,C 0,S 2,T 0}\n";
    let e = filter_controller_program(
        &c.model,
        &c.model.nominal(),
        &c.controller,
        text,
        "p.dat",
        &settings(Language::Krl, false),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("configuration bits cannot be mapped"), "{e}");
}

/// A fuzzer's find: an `E6POS` aggregate left open closes lines later, over other
/// declarations. Those were read a second time, two targets shared text, and applying the
/// edits panicked. Now the reader resumes after the aggregate and the program filters (or
/// is refused with its line), without a panic.
#[test]
fn an_aggregate_left_open_is_read_once() {
    let text = include_str!("../../../tests/fixtures/programs/fuzz-krl-open-aggregate.dat");
    let c = cell("kr15");
    let targets = read(text, Language::Krl, 6);
    for w in targets.windows(2) {
        assert!(
            w[0].literal.end <= w[1].literal.start,
            "{:?} {:?}",
            w[0].literal,
            w[1].literal
        );
    }
    let filtered = filter_controller_program(
        &c.model,
        &calibrated(&c.model),
        &c.controller,
        text,
        "fuzz.dat",
        &settings(Language::Krl, false),
    );
    if let Err(e) = filtered {
        assert!(e.to_string().contains("fuzz.dat: line"), "{e}");
    }
}

/// A number written right after its field's name (`C.4519`, `A6.5`: KRL reads the name up to
/// the first byte that cannot continue it) is rewritten with a space before it, so the
/// filtered program reads back with the same fields (`C0.4…` would be a field `C0`). The
/// fuzz finding (`fuzz-krl-glued-number.dat`) and the same in the sample program.
#[test]
fn a_number_glued_to_its_field_name_stays_apart() {
    let c = cell("kr15");
    let sample = KRL_DAT
        .replace("C 3.4519,S 2", "C.4519,S 2")
        .replace("A6 60.0}", "A6.5}");
    assert_ne!(sample, KRL_DAT);
    let fuzz = include_str!("../../../tests/fixtures/programs/fuzz-krl-glued-number.dat");
    for (text, to_joints) in [
        (sample.as_str(), false),
        (sample.as_str(), true),
        (fuzz, false),
    ] {
        let s = settings(Language::Krl, to_joints);
        let run = |t: &str| {
            filter_controller_program(&c.model, &calibrated(&c.model), &c.controller, t, "f", &s)
        };
        let first = run(text).unwrap();
        let again = run(&first.text).unwrap_or_else(|e| panic!("{e}\n{}", first.text));
        assert_eq!(first.targets.len(), again.targets.len());
        let compensated = |t: &str| {
            let targets = read(t, Language::Krl, 6);
            targets.iter().filter(|t| t.value.is_ok()).count()
        };
        assert_eq!(
            compensated(text),
            compensated(&first.text),
            "{}",
            first.text
        );
        if text == sample && !to_joints {
            let line = |start: &str| {
                let l = first.text.lines().find(|l| l.starts_with(start));
                l.unwrap_or_else(|| panic!("no line {start}")).to_string()
            };
            assert!(line("DECL E6POS XP1=").contains(",C 0."), "{}", first.text);
            assert!(
                line("DECL GLOBAL AXIS XP3=").contains(",A6 0."),
                "{}",
                first.text
            );
        }
    }
}
