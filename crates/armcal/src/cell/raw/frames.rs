//! `[base]`, `[tool]` and `[[targets]]`: the frames the cell adds to the robot's chain.

use super::fields::*;
use super::*;

/// The `[base]` and `[tool]` frames, if given.
pub(super) fn base_and_tool(
    ctx: &Ctx,
    base: &Option<Spanned<toml::Table>>,
    tool: &Option<Spanned<toml::Table>>,
) -> Result<(Option<LinkGeometry>, Option<LinkGeometry>), Error> {
    let base = match base {
        Some(t) => Some(frame(t.get_ref(), &[]).map_err(|e| ctx.err(t.span(), "base", e))?),
        None => None,
    };
    let tool = match tool {
        Some(t) => Some(frame(t.get_ref(), &[]).map_err(|e| ctx.err(t.span(), "tool", e))?),
        None => None,
    };
    Ok((base, tool))
}

/// `[[targets]]`: a point (`xyz_mm`) or, with `rpy`, a frame; named `smr1`, `smr2`, … by
/// default; with the `link` it hangs from, if it names one (a tree cell's, `raw/tree.rs`).
pub(super) fn targets(
    ctx: &Ctx,
    tables: &[Spanned<toml::Table>],
) -> Result<Vec<(LinkSpec, Option<String>)>, Error> {
    let mut targets = Vec::new();
    let mut seen = Vec::new();
    for (i, t) in tables.iter().enumerate() {
        let tt = t.get_ref();
        let field = format!("targets[{i}]");
        let name = string_field(tt, "name")
            .map_err(|e| ctx.err(t.span(), &field, e))?
            .map(str::to_string)
            .unwrap_or_else(|| format!("smr{}", i + 1));
        unique_name(&mut seen, &name, ctx.line(t.span()), "target")
            .map_err(|e| ctx.err(t.span(), &field, e))?;
        let is_frame = tt.keys().any(|k| k.starts_with("rpy"));
        let geometry = if is_frame {
            frame(tt, &["name", "link"]).map_err(|e| ctx.err(t.span(), &field, e))?
        } else {
            let mut used = vec!["name".to_string(), "link".to_string()];
            let valid = [unit_spellings("xyz", Unit::Mm)];
            let xyz = unit_triple(tt, "xyz", Unit::Mm, &mut used)
                .and_then(|v| {
                    v.ok_or_else(|| missing(tt, &["name", "link"], &valid, "missing `xyz_mm`"))
                })
                .map_err(|e| ctx.err(t.span(), &field, e))?;
            check_unused(tt, &used, &[], &valid).map_err(|e| ctx.err(t.span(), &field, e))?;
            LinkGeometry::point(xyz)
        };
        let link = string_field(tt, "link")
            .map_err(|e| ctx.err(t.span(), &format!("{field}.link"), e))?
            .map(str::to_string);
        let target = LinkSpec {
            name,
            geometry,
            joint: None,
        };
        targets.push((target, link));
    }
    Ok(targets)
}
