//! `[[obstacles]]`: capsules and half-spaces in the world frame.

use super::fields::*;
use super::*;

/// Every `[[obstacles]]` entry, in order.
pub(super) fn obstacles(
    ctx: &Ctx,
    tables: &[Spanned<toml::Table>],
) -> Result<Vec<Obstacle>, Error> {
    let mut obstacles = Vec::new();
    let mut seen = Vec::new();
    for (i, o) in tables.iter().enumerate() {
        let field = format!("obstacles[{i}]");
        let named = string_field(o.get_ref(), "name")
            .map(|n| n.map_or_else(|| format!("obstacle{}", i + 1), str::to_string))
            .and_then(|name| {
                unique_name(&mut seen, &name, ctx.line(o.span()), "obstacle")?;
                obstacle(o.get_ref(), name)
            });
        obstacles.push(named.map_err(|e| ctx.err(o.span(), &field, e))?);
    }
    Ok(obstacles)
}

fn obstacle(t: &toml::Table, name: String) -> Result<Obstacle, String> {
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
            let valid = ["normal".to_string(), unit_spellings("offset", Unit::Mm)];
            let allowed = ["kind", "name"];
            let n = unit_triple(t, "normal", Unit::Unitless, &mut used)?
                .ok_or_else(|| missing(t, &allowed, &valid, "missing `normal = [x, y, z]`"))?;
            let offset = unit_value(t, "offset", Unit::Mm, &mut used)?
                .ok_or_else(|| missing(t, &allowed, &valid, "missing `offset_mm`"))?;
            let norm = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if norm < 1e-12 {
                return Err("`normal` must be non-zero".into());
            }
            check_unused(t, &used, &allowed, &valid)?;
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
