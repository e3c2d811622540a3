//! `[[obstacles]]`: capsules and half-spaces in the world frame.

use super::fields::*;
use super::*;

/// Every `[[obstacles]]` entry, in order.
pub(super) fn obstacles(
    ctx: &Ctx,
    tables: &[Spanned<toml::Table>],
) -> Result<Vec<Obstacle>, Error> {
    let mut obstacles = Vec::new();
    for (i, o) in tables.iter().enumerate() {
        obstacles.push(
            obstacle(o.get_ref(), i)
                .map_err(|e| ctx.err(o.span(), &format!("obstacles[{i}]"), e))?,
        );
    }
    Ok(obstacles)
}

fn obstacle(t: &toml::Table, i: usize) -> Result<Obstacle, String> {
    let name = string_field(t, "name")?
        .map(str::to_string)
        .unwrap_or_else(|| format!("obstacle{}", i + 1));
    match string_field(t, "kind")? {
        Some("capsule") => {
            let c = capsule(t, false)?;
            if t.contains_key("frame") {
                return Err("obstacles are in the world frame; `frame` is not allowed".into());
            }
            Ok(Obstacle::Capsule {
                name,
                a: c.a,
                b: c.b,
                radius: c.radius,
            })
        }
        Some("half-space") => {
            let mut used = Vec::new();
            let n = unit_triple(t, "normal", Unit::Unitless, &mut used)?
                .ok_or("missing `normal = [x, y, z]`")?;
            let offset =
                unit_value(t, "offset", Unit::Mm, &mut used)?.ok_or("missing `offset_mm`")?;
            let norm = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if norm < 1e-12 {
                return Err("`normal` must be non-zero".into());
            }
            let valid = ["normal".to_string(), unit_spellings("offset", Unit::Mm)];
            check_unused(t, &used, &["kind", "name"], &valid)?;
            Ok(Obstacle::HalfSpace {
                name,
                normal: n.map(|x| x / norm),
                offset,
            })
        }
        Some(k) => Err(format!(
            "unknown obstacle kind `{k}`; use capsule or half-space"
        )),
        None => Err("missing `kind` (capsule or half-space)".into()),
    }
}
