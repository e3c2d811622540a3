//! What an estimate was identified on (issue #10 item 5): the cell's nominal model
//! (conventions, joints, nominal geometry, instrument, base, tool and target frames) and its
//! free set. Using the estimate with a cell that differs is an error that names every
//! difference ("link `j2` a: 650 mm in the estimate's cell, 700 mm in this cell").

use crate::model::{LinkSpec, Model, ModelSpec};
use serde::{Deserialize, Serialize};

/// The model an estimate belongs to.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ModelFingerprint {
    /// The cell's nominal model (internal units: mm, rad).
    pub nominal: ModelSpec,
    /// The parameters the cell leaves free (before any reduction for the data at hand).
    pub free: Vec<String>,
}

/// Two nominal values agree to 1e-9 relative (absolute below 1 mm or 1 rad): what survives
/// a round trip through a cell file's decimal text, and nothing a geometry change could be.
fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1.0)
}

/// The differences between two links at the same place, `what` naming the place.
fn link_differences(what: &str, a: &LinkSpec, b: &LinkSpec, out: &mut Vec<String>) {
    let theirs = "in the estimate's cell";
    if a.name != b.name {
        out.push(format!(
            "{what}: `{}` {theirs}, `{}` in this cell",
            a.name, b.name
        ));
        return;
    }
    let what = format!("{what} `{}`", a.name);
    let (ja, jb) = (a.joint.as_ref(), b.joint.as_ref());
    let describe = |j: Option<&crate::model::Joint>| match j {
        Some(j) => format!("{:?} joint `{}`", j.kind, j.name).to_lowercase(),
        None => "no joint".to_string(),
    };
    if ja.map(|j| (&j.name, j.kind)) != jb.map(|j| (&j.name, j.kind)) {
        out.push(format!(
            "{what}: {} {theirs}, {} in this cell",
            describe(ja),
            describe(jb)
        ));
        return;
    }
    let (ga, gb) = (&a.geometry, &b.geometry);
    if ga.convention != gb.convention || ga.values.len() != gb.values.len() {
        out.push(format!(
            "{what}: {} convention {theirs}, {} in this cell",
            ga.convention, gb.convention
        ));
        return;
    }
    let fields = ga.convention.fields(ja.map(|j| j.kind));
    for (k, (x, y)) in ga.values.iter().zip(&gb.values).enumerate() {
        if !close(*x, *y) {
            let (field, unit) = fields
                .get(k)
                .map(|(f, u)| (f.to_string(), *u))
                .unwrap_or((format!("value {}", k + 1), crate::model::Unit::Mm));
            let (f, u) = (unit.display_factor(), unit.display_name());
            out.push(format!(
                "{what} {field}: {} {u} {theirs}, {} {u} in this cell",
                shown(x * f),
                shown(y * f)
            ));
        }
    }
    let axis_close = match (ga.axis, gb.axis) {
        (None, None) => true,
        (Some(u), Some(v)) => u.iter().zip(&v).all(|(x, y)| close(*x, *y)),
        _ => false,
    };
    if !axis_close {
        out.push(format!(
            "{what} axis: {:?} {theirs}, {:?} in this cell",
            ga.axis, gb.axis
        ));
    }
}

/// A value to 1e-6 of its display unit, without trailing zeros.
fn shown(x: f64) -> String {
    let s = format!("{x:.6}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Up to 8 names, then how many more.
fn listed(names: &[String]) -> String {
    let shown: Vec<String> = names.iter().take(8).map(|n| format!("`{n}`")).collect();
    match names.len() {
        n if n > 8 => format!("{} and {} more", shown.join(", "), n - 8),
        _ => shown.join(", "),
    }
}

impl ModelFingerprint {
    /// The fingerprint of a cell's model.
    pub fn of(model: &Model) -> ModelFingerprint {
        ModelFingerprint {
            nominal: model.spec(),
            free: model
                .registry
                .free()
                .into_iter()
                .map(|i| model.registry.get(i).name.clone())
                .collect(),
        }
    }

    /// Every way `model` differs from the model this fingerprint describes (empty: the
    /// same). Model names are not compared: a renamed cell with the same geometry is the
    /// same model. Joint limits are not compared either: they do not enter the kinematics.
    pub fn differences(&self, model: &Model) -> Vec<String> {
        let other = ModelFingerprint::of(model);
        let (a, b) = (&self.nominal, &other.nominal);
        let mut out = Vec::new();
        match (&a.instrument, &b.instrument) {
            (None, None) => {}
            (Some(x), Some(y)) => link_differences("instrument", x, y, &mut out),
            (x, y) => out.push(format!(
                "instrument: {} in the estimate's cell, {} in this cell",
                x.as_ref()
                    .map_or("none".to_string(), |l| format!("`{}`", l.name)),
                y.as_ref()
                    .map_or("none".to_string(), |l| format!("`{}`", l.name)),
            )),
        }
        if a.links.len() != b.links.len() {
            let names = |s: &ModelSpec| {
                s.links
                    .iter()
                    .map(|l| l.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            out.push(format!(
                "chain: {} links ({}) in the estimate's cell, {} ({}) in this cell",
                a.links.len(),
                names(a),
                b.links.len(),
                names(b)
            ));
        } else {
            for (k, (x, y)) in a.links.iter().zip(&b.links).enumerate() {
                link_differences(&format!("link {}", k + 1), x, y, &mut out);
            }
        }
        for x in &a.targets {
            match b.targets.iter().find(|y| y.name == x.name) {
                Some(y) => link_differences("target", x, y, &mut out),
                None => out.push(format!(
                    "target `{}`: in the estimate's cell, not in this cell",
                    x.name
                )),
            }
        }
        for y in b
            .targets
            .iter()
            .filter(|y| a.targets.iter().all(|x| x.name != y.name))
        {
            out.push(format!(
                "target `{}`: in this cell, not in the estimate's cell",
                y.name
            ));
        }
        let only = |p: &[String], q: &[String]| -> Vec<String> {
            p.iter().filter(|n| !q.contains(n)).cloned().collect()
        };
        let (dropped, added) = (only(&self.free, &other.free), only(&other.free, &self.free));
        if !dropped.is_empty() || !added.is_empty() {
            let mut parts = Vec::new();
            if !dropped.is_empty() {
                parts.push(format!(
                    "the estimate's cell frees {} that this cell fixes",
                    listed(&dropped)
                ));
            }
            if !added.is_empty() {
                parts.push(format!(
                    "this cell frees {} that the estimate's cell fixed",
                    listed(&added)
                ));
            }
            out.push(format!("free set: {}", parts.join("; ")));
        }
        out
    }
}
