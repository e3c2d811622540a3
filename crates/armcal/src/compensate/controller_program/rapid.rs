//! ABB RAPID: declarations `[LOCAL|TASK] CONST|PERS|VAR robtarget|jointtarget name := […];`
//! and literal targets of `MoveJ`, `MoveL`, `MoveC` (two: circle and end point) and
//! `MoveAbsJ` (ABB RAPID reference manual, "robtarget", "jointtarget", "confdata"). A
//! `robtarget` is `[[x,y,z],[q1,q2,q3,q4],[cf1,cf4,cf6,cfx],[eax_a,…,eax_f]]` (mm; the
//! orientation quaternion w x y z; the configuration; external axes, left as they are), a
//! `jointtarget` `[[rax_1,…,rax_6],[eax_a,…,eax_f]]` (deg). `!` starts a comment. RAPID's
//! `num` is single precision: the controller rounds the 6 decimals of mm and deg and the 9 of
//! the quaternion written here to about 0.1 µm at 1 m.

use super::configuration::Configuration;
use super::scan::{fixed, ident_byte, items, number, Code};
use super::{Dialect, Target, Value};
use crate::model::Pose;
use crate::Error;
use nalgebra::{Quaternion, Rotation3, UnitQuaternion};
use std::ops::Range;

pub(crate) struct Rapid;

const DECIMALS: usize = 6;
const QUATERNION_DECIMALS: usize = 9;

/// The items of the bracket `[…]` at `open` (an error naming `field` if it is not one).
fn bracket(code: &Code, open: usize, field: &str) -> Result<(Vec<Range<usize>>, usize), Error> {
    let open = code.skip_space(open);
    if open >= code.code.len() || code.code[open] != b'[' {
        return Err(code.err(open, field, "expected `[`"));
    }
    let close = code.closing(open, field)?;
    Ok((items(code, open, close), close))
}

/// The numbers of `[a, b, …]` at `span` (exactly `n` of them).
fn numbers(
    code: &Code,
    span: &Range<usize>,
    n: usize,
    field: &str,
) -> Result<Vec<super::scan::Number>, Error> {
    let (list, _) = bracket(code, span.start, field)?;
    if list.len() != n {
        return Err(code.err(
            span.start,
            field,
            format!("expected {n} numbers, found {}", list.len()),
        ));
    }
    list.into_iter()
        .enumerate()
        .map(|(i, s)| number(code, s, &format!("{field}[{}]", i + 1)))
        .collect()
}

/// The target of the literal `[…]` at `open`: a `jointtarget` if `joints`, else a
/// `robtarget`.
fn target(
    code: &Code,
    open: usize,
    name: String,
    joints: bool,
    dof: usize,
) -> Result<Target, Error> {
    let (groups, close) = bracket(code, open, &name)?;
    let mut t = Target {
        at: open,
        name: name.clone(),
        value: Err(String::new()),
        numbers: Vec::new(),
        literal: open..close,
        joint_form: false,
    };
    if joints {
        if groups.len() != 2 {
            return Err(code.err(open, &name, "a jointtarget is [[robax], [extax]]"));
        }
        let robax = numbers(code, &groups[0], 6, "robax")?;
        if dof > 6 {
            return Err(code.err(
                open,
                "robax",
                format!("holds 6 axes, the robot has {dof} joints"),
            ));
        }
        t.numbers = robax[..dof].iter().map(|n| n.span.clone()).collect();
        t.value = Ok(Value::Joints(
            robax[..dof].iter().map(|n| n.value.to_radians()).collect(),
        ));
        return Ok(t);
    }
    if groups.len() != 4 {
        return Err(code.err(
            open,
            &name,
            "a robtarget is [[x,y,z], [q1,q2,q3,q4], [cf1,cf4,cf6,cfx], [extax]]",
        ));
    }
    let trans = numbers(code, &groups[0], 3, "trans")?;
    let rot = numbers(code, &groups[1], 4, "rot")?;
    let conf = numbers(code, &groups[2], 4, "robconf")?;
    let q = Quaternion::new(rot[0].value, rot[1].value, rot[2].value, rot[3].value);
    if (q.norm() - 1.0).abs() > 1e-3 {
        return Err(code.err(
            rot[0].span.start,
            "rot",
            format!(
                "the quaternion is not normalised (|q| = {:.6}; RAPID needs 1 ± 0.001)",
                q.norm()
            ),
        ));
    }
    let mut cf = [0i32; 4];
    for (k, n) in conf.iter().enumerate() {
        if n.value.fract() != 0.0 || n.value.abs() > 1e6 {
            return Err(code.err(
                n.span.start,
                "robconf",
                format!("`{}` is not an integer", n.value),
            ));
        }
        cf[k] = n.value as i32;
    }
    let pose = Pose {
        rot: *UnitQuaternion::from_quaternion(q)
            .to_rotation_matrix()
            .matrix(),
        trans: nalgebra::Vector3::new(trans[0].value, trans[1].value, trans[2].value),
    };
    t.numbers = trans
        .iter()
        .chain(&rot)
        .chain(&conf)
        .map(|n| n.span.clone())
        .collect();
    t.value = Ok(Value::Pose {
        pose,
        configuration: Configuration::Abb(cf),
    });
    Ok(t)
}

/// The words of a statement from `at` (identifiers, lower case) with their end offsets, up
/// to `stop` or the first non-word, non-space byte.
fn words(code: &Code, mut at: usize, stop: usize) -> Vec<(String, usize)> {
    let mut out = Vec::new();
    loop {
        at = code.skip_space(at);
        let mut end = at;
        while end < stop && ident_byte(code.code[end]) {
            end += 1;
        }
        if end == at {
            return out;
        }
        out.push((code.slice(at..end).to_ascii_lowercase(), end));
        at = end;
    }
}

impl Dialect for Rapid {
    fn targets(&self, code: &Code, dof: usize) -> Result<Vec<Target>, Error> {
        let mut out = Vec::new();
        let len = code.code.len();
        // Statements end at `;` outside brackets.
        let (mut start, mut depth) = (0usize, 0i32);
        for i in 0..len {
            match code.code[i] {
                b'[' | b'(' => depth += 1,
                b']' | b')' => depth -= 1,
                b';' if depth <= 0 => {
                    self.statement(code, start, i, dof, &mut out)?;
                    start = i + 1;
                    depth = 0;
                }
                _ => {}
            }
        }
        Ok(out)
    }

    fn joints(&self, c: &[f64]) -> Vec<String> {
        c.iter().map(|v| fixed(v.to_degrees(), DECIMALS)).collect()
    }

    fn pose(&self, pose: &Pose<f64>, previous: &Pose<f64>, c: &Configuration) -> Vec<String> {
        let quaternion = |p: &Pose<f64>| {
            UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(p.rot))
        };
        let (mut q, q0) = (quaternion(pose), quaternion(previous));
        if q.coords.dot(&q0.coords) < 0.0 {
            // The same rotation, in the hemisphere of the program's quaternion.
            q = UnitQuaternion::new_unchecked(-q.into_inner());
        }
        let mut out: Vec<String> = pose.trans.iter().map(|v| fixed(*v, DECIMALS)).collect();
        out.extend([q.w, q.i, q.j, q.k].map(|v| fixed(v, QUATERNION_DECIMALS)));
        if let Configuration::Abb(cf) = c {
            out.extend(cf.iter().map(i32::to_string));
        }
        out
    }

    fn joint_literal(&self, _c: &[f64], original: &str) -> String {
        // RAPID never takes a jointtarget where a robtarget stands (MoveJ/MoveL/MoveC need
        // robtargets, MoveAbsJ a jointtarget): `joint_form` is never set.
        original.to_string()
    }
}

impl Rapid {
    /// The targets of the statement `start..end` (without its `;`): a declaration or a move
    /// instruction starting one of its lines (after `PROC main()`, `IF … THEN`, a label).
    fn statement(
        &self,
        code: &Code,
        start: usize,
        end: usize,
        dof: usize,
        out: &mut Vec<Target>,
    ) -> Result<(), Error> {
        let mut line = start;
        loop {
            if self.from(code, line, end, dof, out)? {
                return Ok(());
            }
            match code.code[line..end].iter().position(|&b| b == b'\n') {
                Some(p) => line += p + 1,
                None => return Ok(()),
            }
        }
    }

    /// The targets of a declaration or move instruction at `start` (its first word);
    /// whether there was one.
    fn from(
        &self,
        code: &Code,
        start: usize,
        end: usize,
        dof: usize,
        out: &mut Vec<Target>,
    ) -> Result<bool, Error> {
        let w = words(code, start, end);
        let first = code.skip_space(start);
        // A declaration: [LOCAL|TASK] CONST|PERS|VAR robtarget|jointtarget name := [...]
        let mut k = usize::from(matches!(
            w.first().map(|x| x.0.as_str()),
            Some("local" | "task")
        ));
        if matches!(
            w.get(k).map(|x| x.0.as_str()),
            Some("const" | "pers" | "var")
        ) {
            k += 1;
            let ty = w.get(k).map(|x| x.0.as_str());
            if let (Some(ty @ ("robtarget" | "jointtarget")), Some((_, name_end))) =
                (ty, w.get(k + 1))
            {
                let after = code.skip_space(*name_end);
                if code.slice(after..(after + 2).min(end)) == ":=" {
                    let open = code.skip_space(after + 2);
                    if open < end && code.code[open] == b'[' {
                        let name_start = name_end - w[k + 1].0.len();
                        let name = code.text[name_start..*name_end].to_string();
                        out.push(target(code, open, name, ty == "jointtarget", dof)?);
                    }
                }
            }
            return Ok(true);
        }
        let Some((instruction, after)) = w.first() else {
            return Ok(false);
        };
        let (count, joints) = match instruction.as_str() {
            "movej" | "movel" => (1, false),
            "movec" => (2, false),
            "moveabsj" => (1, true),
            _ => return Ok(false),
        };
        let name = code.text[first..*after].to_string();
        // Arguments at depth 0; optional switches (`\Conc`) come first and start with `\`.
        let args = items(code, after - 1, end + 1);
        let mut taken = 0;
        for a in args {
            let at = code.skip_space(a.start);
            if at >= a.end || code.code[at] == b'\\' {
                continue;
            }
            if taken == count {
                break;
            }
            taken += 1;
            if code.code[at] == b'[' {
                let label = if count == 2 && taken == 1 {
                    format!("{name} (circle point)")
                } else {
                    name.clone()
                };
                out.push(target(code, at, label, joints, dof)?);
            }
        }
        Ok(true)
    }
}
