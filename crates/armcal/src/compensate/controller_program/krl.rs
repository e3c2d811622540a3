//! KUKA KRL: `.dat` declarations `DECL [GLOBAL] E6POS|POS|E6AXIS|AXIS name={…}` and inline
//! targets of `PTP`, `LIN`, `CIRC` (two: auxiliary and end point) and their spline forms
//! `SPTP`, `SLIN`, `SCIRC` in `.src` (KUKA System Software 8 operating and programming
//! instructions, "programming for user group Expert"). An aggregate is `{[TYPE:] NAME value,
//! …}`: `A1`…`A6` (deg) for a joint target; `X Y Z` (mm), `A B C` (deg: `Rz(A) Ry(B) Rx(C)`,
//! ZYX Euler) and optionally `S`, `T` (integers or binary literals `'B010'`) for a Cartesian
//! one. External axes `E1`…`E6` are left as they are. `;` starts a comment (`;FOLD` lines
//! included); `*_REL` motions are relative and left unchanged. KRL's REAL is single
//! precision (≈ 7 digits): the controller rounds the 6 decimals written here to 0.1 µm at
//! 1 m.

use super::configuration::{Bits, Configuration};
use super::scan::{fixed, ident_byte, number, Code};
use super::{Dialect, Target, Value};
use crate::model::Pose;
use crate::Error;
use std::ops::Range;

pub(crate) struct Krl;

/// The decimals KRL targets are written with (mm, deg): module docs of `program.rs`.
const DECIMALS: usize = 6;

/// A parsed aggregate: each field's upper-case name and value span.
struct Aggregate {
    fields: Vec<(String, Range<usize>)>,
}

impl Aggregate {
    fn get(&self, name: &str) -> Option<&Range<usize>> {
        self.fields.iter().find(|(n, _)| n == name).map(|(_, r)| r)
    }
}

/// The word at `at` (identifier bytes) and the offset after it.
fn word(code: &Code, at: usize) -> (String, usize) {
    let mut end = at;
    while end < code.code.len() && ident_byte(code.code[end]) {
        end += 1;
    }
    (code.slice(at..end).to_ascii_uppercase(), end)
}

/// The aggregate `{…}` starting at `open`.
fn aggregate(code: &Code, open: usize) -> Result<(Aggregate, usize), Error> {
    let close = code.closing(open, "{")?;
    let mut fields = Vec::new();
    for (i, item) in super::scan::items(code, open, close)
        .into_iter()
        .enumerate()
    {
        let mut at = code.skip_space(item.start);
        if at >= item.end {
            continue;
        }
        let (mut name, mut end) = word(code, at);
        if i == 0 && code.slice(end..item.end).trim_start().starts_with(':') {
            // `{E6POS: X 1, …}`: a type prefix before the first field.
            at = code.skip_space(end);
            at = code.skip_space(at + 1);
            (name, end) = word(code, at);
        }
        if name.is_empty() {
            return Err(code.err(at, "aggregate", "expected a field name (e.g. `X 100.0`)"));
        }
        fields.push((name, end..item.end));
    }
    Ok((Aggregate { fields }, close))
}

/// A KRL `S`/`T` value: an integer or a binary literal `'B010'`.
fn bits(code: &Code, span: Range<usize>, field: &str) -> Result<(Bits, Range<usize>), Error> {
    let raw = code.slice(span.clone());
    let start = span.start + (raw.len() - raw.trim_start().len());
    let t = raw.trim();
    let bad = || {
        code.err(
            start,
            field,
            format!("`{t}` is not an integer or a 'B…' binary literal"),
        )
    };
    if let Some(b) = t.strip_prefix("'B").or_else(|| t.strip_prefix("'b")) {
        let digits = b.strip_suffix('\'').ok_or_else(bad)?;
        let value = u32::from_str_radix(digits, 2).map_err(|_| bad())?;
        return Ok((
            Bits {
                value,
                binary_digits: Some(digits.len()),
            },
            start..start + t.len(),
        ));
    }
    let value: u32 = t.parse().map_err(|_| bad())?;
    Ok((
        Bits {
            value,
            binary_digits: None,
        },
        start..start + t.len(),
    ))
}

/// Where an aggregate stands: a declaration of a joint (`AXIS`) or Cartesian type, or inline
/// in a motion (its fields say which), a `PTP` one taking a joint target in its place.
#[derive(Clone, Copy)]
enum Place {
    Declaration { joints: bool },
    Inline { ptp: bool },
}

/// The target of aggregate `agg` at `place`.
fn target(
    code: &Code,
    at: usize,
    name: String,
    agg: &Aggregate,
    literal: Range<usize>,
    place: Place,
    dof: usize,
) -> Result<Target, Error> {
    let (joints, inline_ptp) = match place {
        Place::Declaration { joints } => (Some(joints), false),
        Place::Inline { ptp } => (None, ptp),
    };
    let axes: Vec<String> = (1..=dof).map(|k| format!("A{k}")).collect();
    let joints = joints.unwrap_or_else(|| axes.iter().any(|a| agg.get(a).is_some()));
    let wanted: Vec<&str> = if joints {
        axes.iter().map(String::as_str).collect()
    } else {
        vec!["X", "Y", "Z", "A", "B", "C"]
    };
    let mut t = Target {
        at,
        name,
        value: Err(String::new()),
        numbers: Vec::new(),
        literal,
        joint_form: inline_ptp && !agg.fields.iter().any(|(n, _)| n.starts_with('E')),
    };
    let missing: Vec<&str> = wanted
        .iter()
        .copied()
        .filter(|w| agg.get(w).is_none())
        .collect();
    if !missing.is_empty() {
        t.value = Err(format!(
            "partial aggregate (no {}): the controller completes it from the robot's current \
             position",
            missing.join(", ")
        ));
        return Ok(t);
    }
    let mut values = Vec::new();
    for w in &wanted {
        let n = number(code, agg.get(w).expect("checked").clone(), w)?;
        values.push(n.value);
        t.numbers.push(n.span);
    }
    if joints {
        t.value = Ok(Value::Joints(
            values.iter().map(|v| v.to_radians()).collect(),
        ));
        return Ok(t);
    }
    let pose = Pose::from_xyz_rpy(
        [values[0], values[1], values[2]],
        [
            values[5].to_radians(),
            values[4].to_radians(),
            values[3].to_radians(),
        ],
    );
    let configuration = match agg.get("S") {
        Some(s) => {
            let (s, span) = bits(code, s.clone(), "S")?;
            t.numbers.push(span);
            let t_bits = match agg.get("T") {
                Some(tt) => {
                    let (tb, span) = bits(code, tt.clone(), "T")?;
                    t.numbers.push(span);
                    Some(tb)
                }
                None => None,
            };
            Configuration::Kuka { s, t: t_bits }
        }
        None => Configuration::Nearest,
    };
    t.value = Ok(Value::Pose {
        pose,
        configuration,
    });
    Ok(t)
}

impl Dialect for Krl {
    fn targets(&self, code: &Code, dof: usize) -> Result<Vec<Target>, Error> {
        let mut out = Vec::new();
        let mut start = 0;
        let len = code.code.len();
        while start < len {
            let end = code.code[start..]
                .iter()
                .position(|&b| b == b'\n')
                .map_or(len, |p| start + p);
            let at = code.skip_space(start).min(end);
            let (first, after) = word(code, at);
            // The line after the statement: after its last aggregate's `}` (which a
            // malformed aggregate puts on a later line), so no text is read twice.
            let mut next_line = end + 1;
            let mut past = |close: usize| {
                let line_end = code.code[close..]
                    .iter()
                    .position(|&b| b == b'\n')
                    .map_or(len, |p| close + p);
                next_line = next_line.max(line_end + 1);
            };
            let (declared, rest) = if first == "DECL" {
                word(code, code.skip_space(after))
            } else {
                (first, after)
            };
            match declared.as_str() {
                "GLOBAL" | "E6POS" | "POS" | "E6AXIS" | "AXIS" => {
                    let (mut ty, mut a) = (declared.clone(), rest);
                    if ty == "GLOBAL" {
                        (ty, a) = word(code, code.skip_space(rest));
                    }
                    if matches!(ty.as_str(), "E6POS" | "POS" | "E6AXIS" | "AXIS") {
                        let (name, a) = word(code, code.skip_space(a));
                        let eq = code.skip_space(a);
                        if !name.is_empty() && eq < end && code.code[eq] == b'=' {
                            let open = code.skip_space(eq + 1);
                            if open < len && code.code[open] == b'{' {
                                let (agg, close) = aggregate(code, open)?;
                                past(close);
                                let place = Place::Declaration {
                                    joints: ty.ends_with("AXIS"),
                                };
                                out.push(target(
                                    code,
                                    at,
                                    code.text[a - name.len()..a].to_string(),
                                    &agg,
                                    open..close,
                                    place,
                                    dof,
                                )?);
                            }
                        }
                    }
                }
                "PTP" | "LIN" | "CIRC" | "SPTP" | "SLIN" | "SCIRC" => {
                    let count = if declared.ends_with("CIRC") { 2 } else { 1 };
                    let mut open = code.skip_space(rest);
                    for k in 0..count {
                        if open >= len || code.code[open] != b'{' {
                            break;
                        }
                        let (agg, close) = aggregate(code, open)?;
                        past(close);
                        let name = if count == 2 && k == 0 {
                            format!("{declared} (auxiliary point)")
                        } else {
                            declared.to_string()
                        };
                        let ptp = declared.ends_with("PTP");
                        let place = Place::Inline { ptp };
                        out.push(target(code, open, name, &agg, open..close, place, dof)?);
                        let comma = code.skip_space(close);
                        if comma < len && code.code[comma] == b',' {
                            open = code.skip_space(comma + 1);
                        } else {
                            break;
                        }
                    }
                }
                w if w.ends_with("_REL") && w.len() > 4 => {
                    let open = code.skip_space(rest);
                    if open < len && code.code[open] == b'{' {
                        let close = code.closing(open, "{")?;
                        past(close);
                        out.push(Target {
                            at: open,
                            name: w.to_string(),
                            value: Err("relative motion: its target depends on where the \
                                        robot is"
                                .into()),
                            numbers: Vec::new(),
                            literal: open..close,
                            joint_form: false,
                        });
                    }
                }
                _ => {}
            }
            start = next_line;
        }
        Ok(out)
    }

    fn joints(&self, c: &[f64]) -> Vec<String> {
        c.iter().map(|v| fixed(v.to_degrees(), DECIMALS)).collect()
    }

    fn pose(&self, pose: &Pose<f64>, _previous: &Pose<f64>, c: &Configuration) -> Vec<String> {
        let (xyz, rpy) = pose.to_xyz_rpy();
        let mut out: Vec<String> = xyz
            .iter()
            .chain([rpy[2], rpy[1], rpy[0]].map(f64::to_degrees).iter())
            .map(|v| fixed(*v, DECIMALS))
            .collect();
        if let Configuration::Kuka { s, t } = c {
            out.push(s.krl());
            out.extend(t.as_ref().map(Bits::krl));
        }
        out
    }

    fn joint_literal(&self, c: &[f64], _original: &str) -> String {
        let fields: Vec<String> = self
            .joints(c)
            .into_iter()
            .enumerate()
            .map(|(k, v)| format!("A{} {v}", k + 1))
            .collect();
        format!("{{{}}}", fields.join(","))
    }
}
