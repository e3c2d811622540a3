//! `[[payload]]`: the payloads the robot may carry while it is measured or works — a name,
//! the mass (`mass_kg`) and the centre of mass in the tool frame (`com_mm` or `com_m`,
//! default the tool frame's origin). With `[parameters] compliance`, their gravity torque
//! deflects the compliant joints ([`crate::model::compliance`]); a data file's `payload`
//! column and `--payload` name them.

use super::fields::*;
use super::*;
use crate::model::compliance::Payload;

/// The payloads, in file order; each checked ([`Payload::check`]), names unique.
pub(super) fn payloads(ctx: &Ctx, tables: &[Spanned<toml::Table>]) -> Result<Vec<Payload>, Error> {
    let mut out: Vec<Payload> = Vec::new();
    for (i, p) in tables.iter().enumerate() {
        let field = format!("payload[{i}]");
        let fail = |e: String| ctx.err(p.span(), &field, e);
        let t = p.get_ref();
        let name = string_field(t, "name")
            .map_err(fail)?
            .ok_or_else(|| {
                fail("missing `name` (what a data file's `payload` column says)".into())
            })?
            .to_string();
        let mass_kg = match t.get("mass_kg") {
            Some(v) => number(v).ok_or_else(|| fail("`mass_kg` must be a finite number".into()))?,
            None => return Err(fail("missing `mass_kg` (the payload's mass, kg)".into())),
        };
        let mut used = vec!["name".to_string(), "mass_kg".to_string()];
        let com_mm = unit_triple(t, "com", Unit::Mm, &mut used)
            .map_err(fail)?
            .unwrap_or([0.0; 3]);
        check_unused(
            t,
            &used,
            &[],
            &["name".into(), "mass_kg".into(), "com_mm|com_m".into()],
        )
        .map_err(fail)?;
        let payload = Payload {
            name,
            mass_kg,
            com_mm,
        };
        payload.check().map_err(fail)?;
        if out.iter().any(|o| o.name == payload.name) {
            return Err(fail(format!("payload `{}` is named twice", payload.name)));
        }
        out.push(payload);
    }
    Ok(out)
}
