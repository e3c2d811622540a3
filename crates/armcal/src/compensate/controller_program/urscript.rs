//! Universal Robots script: the first argument of `movej`, `movel` and `movep` (Universal
//! Robots, "The URScript Programming Language", "Module motion"): a joint list `[q1, …, q6]`
//! (rad) or a pose `p[x, y, z, rx, ry, rz]` (m, rotation vector in rad), written there or
//! assigned to a variable the file moves to (`global wp1 = p[…]`, `wp1 = […]`). A target
//! computed at run time (`get_inverse_kin(…)`, `pose_trans(…)`) is listed and left unchanged.
//! The controller solves a pose on the branch nearest the robot's joints when it gets
//! there, so the reference of a pose is the target before it in the file (a script starts
//! with a `movej` to joints, as PolyScope's do). `#` starts a comment. Metres and radians
//! are written with 9 decimals (1 nm, 1 nrad).

use super::configuration::Configuration;
use super::scan::{fixed, ident_byte, items, number, Code};
use super::{Dialect, Target, Value};
use crate::model::pose::{rot_axis, rotation_log};
use crate::model::Pose;
use crate::Error;
use nalgebra::Vector3;

pub(crate) struct UrScript;

const DECIMALS: usize = 9;
const MOVES: [&str; 3] = ["movej", "movel", "movep"];

/// Identifier occurrences `(start, end)` in the code.
fn identifiers(code: &Code) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    let b = &code.code;
    while i < b.len() {
        if ident_byte(b[i]) && (i == 0 || !ident_byte(b[i - 1])) {
            let mut e = i;
            while e < b.len() && ident_byte(b[e]) {
                e += 1;
            }
            out.push((i, e));
            i = e;
        } else {
            i += 1;
        }
    }
    out
}

/// The target of the literal at `at` (`[…]` or `p[…]`).
fn literal(code: &Code, at: usize, name: String, dof: usize) -> Result<Target, Error> {
    let pose = code.code[at] == b'p';
    let open = if pose { code.skip_space(at + 1) } else { at };
    let close = code.closing(open, &name)?;
    let list = items(code, open, close);
    let n = if pose { 6 } else { dof };
    if list.len() != n {
        return Err(code.err(
            open,
            &name,
            format!(
                "{} needs {n} numbers, found {}",
                if pose {
                    "a pose p[x, y, z, rx, ry, rz]"
                } else {
                    "a joint list"
                },
                list.len()
            ),
        ));
    }
    let fields = if pose {
        ["x", "y", "z", "rx", "ry", "rz"].as_slice()
    } else {
        ["q1", "q2", "q3", "q4", "q5", "q6"].as_slice()
    };
    let nums = list
        .into_iter()
        .enumerate()
        .map(|(k, s)| number(code, s, fields.get(k).copied().unwrap_or("q")))
        .collect::<Result<Vec<_>, _>>()?;
    let v: Vec<f64> = nums.iter().map(|n| n.value).collect();
    let value = if pose {
        let r = Vector3::new(v[3], v[4], v[5]);
        let angle = r.norm();
        let rot = if angle > 0.0 {
            rot_axis(&(r / angle), angle)
        } else {
            nalgebra::Matrix3::identity()
        };
        Value::Pose {
            pose: Pose {
                rot,
                trans: Vector3::new(v[0], v[1], v[2]) * 1000.0,
            },
            configuration: Configuration::Nearest,
        }
    } else {
        Value::Joints(v)
    };
    Ok(Target {
        at,
        name,
        value: Ok(value),
        numbers: nums.into_iter().map(|n| n.span).collect(),
        literal: at..close,
        joint_form: true,
    })
}

/// Whether the code at `at` starts a literal target (`[` or `p[`).
fn is_literal(code: &Code, at: usize) -> bool {
    let b = &code.code;
    at < b.len()
        && (b[at] == b'[' || (b[at] == b'p' && b.get(code.skip_space(at + 1)) == Some(&b'[')))
}

impl Dialect for UrScript {
    fn targets(&self, code: &Code, dof: usize) -> Result<Vec<Target>, Error> {
        let ids = identifiers(code);
        let mut out = Vec::new();
        let mut variables: Vec<String> = Vec::new();
        // Moves: their literal targets, and the variables they move to.
        for &(s, e) in &ids {
            let word = code.slice(s..e);
            let open = code.skip_space(e);
            if !MOVES.contains(&word) || open >= code.code.len() || code.code[open] != b'(' {
                continue;
            }
            let arg = code.skip_space(open + 1);
            if is_literal(code, arg) {
                out.push(literal(code, arg, word.to_string(), dof)?);
                continue;
            }
            let mut end = arg;
            while end < code.code.len() && ident_byte(code.code[end]) {
                end += 1;
            }
            let after = code.skip_space(end);
            if end > arg && code.code.get(after) != Some(&b'(') {
                variables.push(code.slice(arg..end).to_string());
            } else if end > arg {
                out.push(Target {
                    at: arg,
                    name: word.to_string(),
                    value: Err(format!(
                        "a target computed at run time (`{}(…)`)",
                        code.slice(arg..end)
                    )),
                    numbers: Vec::new(),
                    literal: arg..arg,
                    joint_form: false,
                });
            }
        }
        // Assignments of literals to those variables: `[global|local] name = p[…]`.
        for &(s, e) in &ids {
            let name = code.slice(s..e);
            if !variables.iter().any(|v| v == name) {
                continue;
            }
            let eq = code.skip_space(e);
            if code.code.get(eq) != Some(&b'=') || code.code.get(eq + 1) == Some(&b'=') {
                continue;
            }
            let at = code.skip_space(eq + 1);
            if is_literal(code, at) {
                out.push(literal(code, at, name.to_string(), dof)?);
            }
        }
        out.sort_by_key(|t| t.at);
        Ok(out)
    }

    fn joints(&self, c: &[f64]) -> Vec<String> {
        c.iter().map(|v| fixed(*v, DECIMALS)).collect()
    }

    fn pose(&self, pose: &Pose<f64>, _previous: &Pose<f64>, _c: &Configuration) -> Vec<String> {
        let r = rotation_log(&pose.rot);
        (pose.trans / 1000.0)
            .iter()
            .chain(r.iter())
            .map(|v| fixed(*v, DECIMALS))
            .collect()
    }

    fn joint_literal(&self, c: &[f64], _original: &str) -> String {
        format!("[{}]", self.joints(c).join(", "))
    }
}
