//! `[instrument]`: name, kind, placement, `max_incidence_deg` and `[instrument.noise]`.

use super::fields::*;
use super::*;

/// The instrument kinds `[instrument] kind` accepts. The kind is a label (records and exports
/// carry it; what the instrument measures is `[parameters] measurement`), but a misspelt one
/// is an error rather than a silent new kind.
const KINDS: [&str; 4] = ["laser-tracker", "optical-tracker", "cmm", "ballbar"];

/// The instrument of `[instrument]`, its frame's geometry and its name (`tracker` by
/// default); no instrument without the section.
pub(super) fn instrument(
    ctx: &Ctx,
    section: Option<Spanned<RawInstrument>>,
) -> Result<(Option<Instrument>, Option<LinkGeometry>, String), Error> {
    let (instrument, instrument_geometry, instrument_name) = match section {
        None => (None, None, "instrument".to_string()),
        Some(ri) => {
            let span = ri.span();
            let ri = ri.into_inner();
            let placed = ri.xyz_mm.is_some() || ri.xyz_m.is_some();
            let xyz = match (ri.xyz_mm, ri.xyz_m) {
                (Some(v), None) => v,
                (None, Some(v)) => v.map(|x| x * 1000.0),
                (None, None) => [0.0; 3],
                _ => return Err(ctx.err(span, "instrument", "give `xyz_mm` or `xyz_m`, not both")),
            };
            let rpy = match (ri.rpy_deg, ri.rpy_rad) {
                (Some(v), None) => v.map(f64::to_radians),
                (None, Some(v)) => v,
                (None, None) => [0.0; 3],
                _ => {
                    return Err(ctx.err(
                        span,
                        "instrument",
                        "give `rpy_deg` or `rpy_rad`, not both",
                    ))
                }
            };
            if let Some(k) = ri.kind.as_deref().filter(|k| !KINDS.contains(k)) {
                return Err(ctx.err(
                    span,
                    "instrument.kind",
                    format!("unknown instrument kind `{k}`; use {}", KINDS.join(", ")),
                ));
            }
            let frame = LinkSpec {
                name: ri.name.as_deref().unwrap_or("tracker").into(),
                geometry: LinkGeometry::frame6(xyz, rpy),
                joint: None,
            };
            frame
                .check_values()
                .map_err(|e| ctx.err(span.clone(), "instrument", e))?;
            let noise = match &ri.noise {
                Some(t) => noise(t).map_err(|e| ctx.err(span.clone(), "instrument.noise", e))?,
                None => NoiseModel::default(),
            };
            if let Some(a) = ri.max_incidence_deg {
                if !(0.0..=180.0).contains(&a) {
                    return Err(ctx.err(
                        span,
                        "instrument.max_incidence_deg",
                        "must be in [0, 180]",
                    ));
                }
            }
            (
                Some(Instrument {
                    kind: ri.kind.unwrap_or_else(|| "laser-tracker".into()),
                    noise,
                    max_incidence: ri.max_incidence_deg.map(f64::to_radians),
                    placed,
                }),
                Some(LinkGeometry::frame6(xyz, rpy)),
                ri.name.unwrap_or_else(|| "tracker".into()),
            )
        }
    };
    Ok((instrument, instrument_geometry, instrument_name))
}

fn noise(t: &toml::Table) -> Result<NoiseModel, String> {
    let mut used = vec!["model".to_string()];
    let valid: Vec<String> = match string_field(t, "model")? {
        Some("constant") => vec![
            unit_spellings("sigma", Unit::Mm),
            unit_spellings("sigma_angle", Unit::Rad),
        ],
        Some("range") => vec![unit_spellings("a", Unit::Mm), "b_um_per_m".into()],
        Some("per-measurement") => vec![unit_spellings("floor", Unit::Mm)],
        _ => Vec::new(),
    };
    let n = match string_field(t, "model")? {
        Some("constant") => {
            let is_array = ["sigma_mm", "sigma_m"]
                .iter()
                .any(|k| t.get(*k).map(|v| v.is_array()).unwrap_or(false));
            let s = if is_array {
                unit_triple(t, "sigma", Unit::Mm, &mut used)?
                    .ok_or_else(|| missing(t, &["model"], &valid, "missing `sigma_mm`"))?
            } else {
                [unit_value(t, "sigma", Unit::Mm, &mut used)?.ok_or_else(|| {
                    missing(
                        t,
                        &["model"],
                        &valid,
                        "missing `sigma_mm` (a number or 3 numbers)",
                    )
                })?; 3]
            };
            if s.iter().any(|x| *x <= 0.0) {
                return Err("`sigma_mm` must be positive".into());
            }
            let sigma_angle = unit_value(t, "sigma_angle", Unit::Rad, &mut used)?.unwrap_or(1e-3);
            if sigma_angle <= 0.0 {
                return Err("`sigma_angle_deg` must be positive".into());
            }
            NoiseModel::Constant {
                sigma: s,
                sigma_angle,
            }
        }
        Some("range") => {
            let a = unit_value(t, "a", Unit::Mm, &mut used)?
                .ok_or_else(|| missing(t, &["model"], &valid, "missing `a_mm`"))?;
            let b = t.get("b_um_per_m").and_then(number).ok_or_else(|| {
                missing(
                    t,
                    &["model"],
                    &valid,
                    "missing `b_um_per_m` (µm per metre of range)",
                )
            })?;
            used.push("b_um_per_m".into());
            if a <= 0.0 || b < 0.0 {
                return Err("need `a_mm` > 0 and `b_um_per_m` ≥ 0".into());
            }
            NoiseModel::Range {
                a,
                b_per_m: b / 1000.0,
            }
        }
        Some("per-measurement") => {
            let floor = unit_value(t, "floor", Unit::Mm, &mut used)?.unwrap_or(1e-3);
            if floor <= 0.0 {
                return Err("`floor_mm` must be positive".into());
            }
            NoiseModel::PerMeasurement { floor }
        }
        Some(m) => {
            return Err(format!(
                "unknown noise model `{m}`; use constant, range or per-measurement"
            ))
        }
        None => return Err("missing `model` (constant, range or per-measurement)".into()),
    };
    check_unused(t, &used, &[], &valid)?;
    Ok(n)
}
