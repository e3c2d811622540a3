//! `[[obstacles]]`: capsules, boxes and half-spaces in the world frame.

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
        Some("box") => {
            let mut used = Vec::new();
            let center = unit_triple(t, "center", Unit::Mm, &mut used)?
                .ok_or("missing `center_mm = [x, y, z]` (the box's centre, world frame)")?;
            let size = unit_triple(t, "size", Unit::Mm, &mut used)?
                .ok_or("missing `size_mm = [x, y, z]` (the full edge lengths)")?;
            if let Some(s) = size.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
                return Err(format!(
                    "`size_mm` holds {s}: every edge length must be a finite length > 0 mm"
                ));
            }
            let rpy = unit_triple(t, "rpy", Unit::Rad, &mut used)?.unwrap_or([0.0; 3]);
            let valid = [
                unit_spellings("center", Unit::Mm),
                unit_spellings("size", Unit::Mm),
                unit_spellings("rpy", Unit::Rad),
            ];
            check_unused(t, &used, &["kind", "name"], &valid)?;
            Ok(Obstacle::Box {
                name,
                center,
                size,
                rpy,
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
            "unknown obstacle kind `{k}`; use capsule, box or half-space"
        )),
        None => Err("missing `kind` (capsule, box or half-space)".into()),
    }
}
