//! Field readers shared by the sections: numbers with unit suffixes, unknown-field checks,
//! frames, strings and capsules.

use super::*;

/// The field `<key><suffix>` of a table with the suffixes a unit allows (`_mm` / `_m` for
/// lengths, `_deg` / `_rad` for angles, none for dimensionless), its value and the factor to
/// internal units. Giving the same key with two units is an error.
pub(super) fn find_with_unit<'t>(
    t: &'t toml::Table,
    key: &str,
    unit: Unit,
    used: &mut Vec<String>,
) -> Result<Option<(String, &'t toml::Value, f64)>, String> {
    let options: &[(&str, f64)] = match unit {
        Unit::Mm => &[("_mm", 1.0), ("_m", 1000.0)],
        Unit::Rad => &[("_deg", std::f64::consts::PI / 180.0), ("_rad", 1.0)],
        Unit::Unitless => &[("", 1.0)],
        Unit::RadPerMm => &[("_urad_per_m", 1e-9)],
        Unit::RadPerNmm => &[("_urad_per_Nm", 1e-9)],
        Unit::Arcsec => &[("_arcsec", std::f64::consts::PI / 648_000.0)],
    };
    let mut found = None;
    for (suffix, factor) in options {
        let k = format!("{key}{suffix}");
        if let Some(v) = t.get(&k) {
            if found.is_some() {
                return Err(format!("`{key}` is given twice with different units"));
            }
            used.push(k.clone());
            found = Some((k, v, *factor));
        }
    }
    Ok(found)
}

pub(super) fn number(v: &toml::Value) -> Option<f64> {
    v.as_float()
        .or_else(|| v.as_integer().map(|i| i as f64))
        .filter(|x| x.is_finite())
}

/// `x` times the unit factor `f`, checked after converting (`x_m = 1e306` is finite but
/// not in mm): within [`Unit::max_abs`], else an error naming the field `k` and the range.
fn converted(x: f64, f: f64, unit: Unit, k: &str) -> Result<f64, String> {
    let y = x * f;
    if unit.holds(y) {
        Ok(y)
    } else {
        Err(format!(
            "`{k}` = {x:e} is outside the range armcal accepts ({})",
            unit.range_text()
        ))
    }
}

/// A number with a unit suffix (see [`find_with_unit`]), in internal units.
pub(super) fn unit_value(
    t: &toml::Table,
    key: &str,
    unit: Unit,
    used: &mut Vec<String>,
) -> Result<Option<f64>, String> {
    match find_with_unit(t, key, unit, used)? {
        None => Ok(None),
        Some((k, v, f)) => {
            let x = number(v).ok_or_else(|| format!("`{k}` must be a finite number"))?;
            converted(x, f, unit, &k).map(Some)
        }
    }
}

/// A required number with a unit suffix and nothing else in `t` (`{ sigma_mm = 0.1 }`), in
/// internal units; the error names the spellings.
pub(super) fn sole_unit_value(t: &toml::Table, key: &str, unit: Unit) -> Result<f64, String> {
    let mut used = Vec::new();
    let spellings = unit_spellings(key, unit);
    let valid = [spellings];
    let v = unit_value(t, key, unit, &mut used)?
        .ok_or_else(|| missing(t, &[], &valid, format!("missing `{}`", valid[0])))?;
    check_unused(t, &used, &[], &valid)?;
    Ok(v)
}

/// Three numbers with a unit suffix (see [`find_with_unit`]), in internal units.
pub(super) fn unit_triple(
    t: &toml::Table,
    key: &str,
    unit: Unit,
    used: &mut Vec<String>,
) -> Result<Option<[f64; 3]>, String> {
    match find_with_unit(t, key, unit, used)? {
        None => Ok(None),
        Some((k, v, f)) => {
            let bad = || format!("`{k}` must be an array of 3 finite numbers");
            let arr = v.as_array().filter(|a| a.len() == 3).ok_or_else(bad)?;
            let mut out = [0.0; 3];
            for (o, x) in out.iter_mut().zip(arr) {
                *o = converted(number(x).ok_or_else(bad)?, f, unit, &k)?;
            }
            Ok(Some(out))
        }
    }
}

/// Every key of `t` must be one the parser read (`used`) or one of `allowed`. The error for
/// an unknown key lists what is valid there: `valid` (the fields with their unit suffixes,
/// e.g. `theta_deg|theta_rad`) and `allowed`.
pub(super) fn check_unused(
    t: &toml::Table,
    used: &[String],
    allowed: &[&str],
    valid: &[String],
) -> Result<(), String> {
    for k in t.keys() {
        if !used.iter().any(|u| u == k) && !allowed.contains(&k.as_str()) {
            let fields: Vec<String> = valid
                .iter()
                .cloned()
                .chain(allowed.iter().map(|a| a.to_string()))
                .collect();
            return Err(format!(
                "unknown field `{k}`; valid here: {} (mind the unit suffix: _mm, _m, _deg, _rad)",
                fields.join(", ")
            ));
        }
    }
    Ok(())
}

/// The error for a required field missing from `t`. A key of `t` that is no valid spelling
/// here (`d_in`, `alpah_deg`) is the likely cause, so the error names it as unknown
/// ([`check_unused`]'s message, which lists what is valid); otherwise the error is `missing`.
pub(super) fn missing(
    t: &toml::Table,
    allowed: &[&str],
    valid: &[String],
    missing: impl Into<String>,
) -> String {
    let spellings: Vec<&str> = valid.iter().flat_map(|v| v.split('|')).collect();
    let known: Vec<String> = t
        .keys()
        .filter(|k| spellings.contains(&k.as_str()))
        .cloned()
        .collect();
    match check_unused(t, &known, allowed, valid) {
        Err(unknown) => unknown,
        Ok(()) => missing.into(),
    }
}

/// Records `name` (of a `what`, at `line`) in `seen`; an error when an earlier entry has it
/// already (records, reports and the constraint margins name entries by it).
pub(super) fn unique_name(
    seen: &mut Vec<(String, usize)>,
    name: &str,
    line: usize,
    what: &str,
) -> Result<(), String> {
    if let Some((_, first)) = seen.iter().find(|(n, _)| n == name) {
        return Err(format!(
            "the {what} name `{name}` is used twice (first at line {first}); give each {what} its own name"
        ));
    }
    seen.push((name.to_string(), line));
    Ok(())
}

/// The spellings of a field with its unit suffixes: `theta_deg|theta_rad`.
pub(super) fn unit_spellings(field: &str, unit: Unit) -> String {
    match unit {
        Unit::Mm => format!("{field}_mm|{field}_m"),
        Unit::Rad => format!("{field}_deg|{field}_rad"),
        Unit::Unitless => field.to_string(),
        Unit::RadPerMm => format!("{field}_urad_per_m"),
        Unit::RadPerNmm => format!("{field}_urad_per_Nm"),
        Unit::Arcsec => format!("{field}_arcsec"),
    }
}

/// A frame table `{ xyz_mm = [...], rpy_deg = [...] }` (both optional, zero by default).
pub(super) fn frame(t: &toml::Table, allowed: &[&str]) -> Result<LinkGeometry, String> {
    let mut used = Vec::new();
    let xyz = unit_triple(t, "xyz", Unit::Mm, &mut used)?.unwrap_or([0.0; 3]);
    let rpy = unit_triple(t, "rpy", Unit::Rad, &mut used)?.unwrap_or([0.0; 3]);
    let valid = [
        unit_spellings("xyz", Unit::Mm),
        unit_spellings("rpy", Unit::Rad),
    ];
    check_unused(t, &used, allowed, &valid)?;
    Ok(LinkGeometry::frame6(xyz, rpy))
}

pub(super) fn string_field<'a>(t: &'a toml::Table, key: &str) -> Result<Option<&'a str>, String> {
    match t.get(key) {
        None => Ok(None),
        Some(v) => v
            .as_str()
            .map(Some)
            .ok_or_else(|| format!("`{key}` must be a string")),
    }
}

pub(super) fn capsule(t: &toml::Table, frame_required: bool) -> Result<Capsule, String> {
    let mut used = Vec::new();
    let valid = ["a", "b", "radius"].map(|k| unit_spellings(k, Unit::Mm));
    let allowed = ["frame", "name", "kind"];
    let absent = |what: &str| missing(t, &allowed, &valid, format!("missing `{what}`"));
    let a = unit_triple(t, "a", Unit::Mm, &mut used)?.ok_or_else(|| absent("a_mm"))?;
    let b = unit_triple(t, "b", Unit::Mm, &mut used)?.ok_or_else(|| absent("b_mm"))?;
    let radius =
        unit_value(t, "radius", Unit::Mm, &mut used)?.ok_or_else(|| absent("radius_mm"))?;
    if radius < 0.0 {
        return Err("`radius_mm` must be ≥ 0".into());
    }
    let frame = string_field(t, "frame")?;
    if frame_required && frame.is_none() {
        return Err("missing `frame` (the chain frame the capsule moves with)".into());
    }
    check_unused(t, &used, &allowed, &valid)?;
    Ok(Capsule {
        frame: frame.unwrap_or("tool").to_string(),
        a,
        b,
        radius,
    })
}
