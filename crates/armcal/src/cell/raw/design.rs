//! `[design]`: the safety margins every planned pose keeps (`clearance_mm`,
//! `joint_margin_deg`, `incidence_margin_deg`, `line_of_sight_margin_mm`); the defaults of
//! [`DesignClearance`] for a field (or the section) left out.

use super::fields::*;
use super::*;

/// Largest clearance a cell may ask for (mm): half a metre is already more room than a
/// measurement cell has around a robot; a larger value is a typo (metres written as mm).
const MAX_CLEARANCE_MM: f64 = 500.0;
/// Largest joint margin (deg): a quarter turn off every limit leaves most joints little
/// range; a larger value is a typo.
const MAX_JOINT_MARGIN_DEG: f64 = 90.0;

/// The `[design]` section, or the defaults without one.
pub(super) fn design(
    ctx: &Ctx,
    section: Option<&Spanned<toml::Table>>,
) -> Result<DesignClearance, Error> {
    let Some(s) = section else {
        return Ok(DesignClearance::default());
    };
    let t = s.get_ref();
    let err = |field: &str, e: String| ctx.err(s.span(), field, e);
    let mut used = Vec::new();
    let defaults = DesignClearance::default();
    let clearance = unit_value(t, "clearance", Unit::Mm, &mut used)
        .map_err(|e| err("design", e))?
        .unwrap_or(defaults.clearance);
    let joint_margin = unit_value(t, "joint_margin", Unit::Rad, &mut used)
        .map_err(|e| err("design", e))?
        .unwrap_or(defaults.joint_margin);
    let incidence_margin = unit_value(t, "incidence_margin", Unit::Rad, &mut used)
        .map_err(|e| err("design", e))?
        .unwrap_or(defaults.incidence_margin);
    let line_of_sight_margin = unit_value(t, "line_of_sight_margin", Unit::Mm, &mut used)
        .map_err(|e| err("design", e))?
        .unwrap_or(defaults.line_of_sight_margin);
    let valid = [
        unit_spellings("clearance", Unit::Mm),
        unit_spellings("joint_margin", Unit::Rad),
        unit_spellings("incidence_margin", Unit::Rad),
        unit_spellings("line_of_sight_margin", Unit::Mm),
    ];
    check_unused(t, &used, &[], &valid).map_err(|e| err("design", e))?;
    for (field, v) in [
        ("design.clearance_mm", clearance),
        ("design.line_of_sight_margin_mm", line_of_sight_margin),
    ] {
        if !(0.0..=MAX_CLEARANCE_MM).contains(&v) {
            return Err(err(
                field,
                format!("must lie in [0, {MAX_CLEARANCE_MM}] mm, got {v} mm"),
            ));
        }
    }
    for (field, v) in [
        ("design.joint_margin_deg", joint_margin),
        ("design.incidence_margin_deg", incidence_margin),
    ] {
        if !(0.0..=MAX_JOINT_MARGIN_DEG.to_radians()).contains(&v) {
            return Err(err(
                field,
                format!(
                    "must lie in [0, {MAX_JOINT_MARGIN_DEG}]°, got {}°",
                    v.to_degrees()
                ),
            ));
        }
    }
    Ok(DesignClearance {
        clearance,
        joint_margin,
        incidence_margin,
        line_of_sight_margin,
    })
}

/// The incidence margin must leave the reflector some cone: an error when it is not below
/// the instrument's `max_incidence` (a cell without an incidence limit ignores it).
pub(super) fn check_incidence_margin(
    ctx: &Ctx,
    section: Option<&Spanned<toml::Table>>,
    design: &DesignClearance,
    max_incidence: Option<f64>,
) -> Result<(), Error> {
    match max_incidence {
        Some(max) if design.incidence_margin >= max => Err(ctx.err(
            section.map_or(0..0, |s| s.span()),
            "design.incidence_margin_deg",
            format!(
                "{}° below the instrument's max_incidence_deg = {}° leaves no incidence angle; use a smaller margin",
                design.incidence_margin.to_degrees(),
                max.to_degrees()
            ),
        )),
        _ => Ok(()),
    }
}

/// The joint margin must leave every revolute joint some range: an error names the first
/// joint whose range is not wider than twice the margin.
pub(super) fn check_joint_margin(
    ctx: &Ctx,
    section: Option<&Spanned<toml::Table>>,
    design: &DesignClearance,
    model: &Model,
) -> Result<(), Error> {
    for j in &model.joints {
        if j.kind == JointKind::Revolute && j.upper - j.lower <= 2.0 * design.joint_margin {
            return Err(ctx.err(
                section.map_or(0..0, |s| s.span()),
                "design.joint_margin_deg",
                format!(
                    "{}° off both limits leaves joint `{}` (range {:.3}° … {:.3}°) no range; use a smaller margin",
                    design.joint_margin.to_degrees(),
                    j.name,
                    j.lower.to_degrees(),
                    j.upper.to_degrees()
                ),
            ));
        }
    }
    Ok(())
}
