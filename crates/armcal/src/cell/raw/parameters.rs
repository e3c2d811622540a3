//! `[parameters]`: the free set (`auto`, `all` or patterns), `fixed`, `priors`, the
//! measurement type, the compliant joints (with `[robot] gravity`) and the periodic joint
//! errors.

use super::fields::*;
use super::*;
use crate::model::compliance::ComplianceSpec;
use crate::model::periodic::PeriodicSpec;
use crate::model::prior::FixedPrior;

/// Applies `[parameters]` to `model`; returns the measurement type (pose if every target is
/// a frame, else position, unless given) and whether the free set is `auto`.
pub(super) fn parameters(
    ctx: &Ctx,
    section: Option<&Spanned<RawParameters>>,
    model: &mut Model,
) -> Result<(Measurement, bool), Error> {
    let all_frames = (0..model.targets.len()).all(|k| model.target_is_frame(k));
    let mut measurement = if all_frames {
        // No targets (the tool frame is measured) or only frame targets.
        Measurement::Pose
    } else {
        Measurement::Position
    };
    let mut auto_free = true;
    if let Some(p) = section {
        let span = p.span();
        let p = p.get_ref();
        let free: Vec<String> = match &p.free {
            None => Vec::new(),
            Some(toml::Value::String(s)) if s == "auto" => Vec::new(),
            Some(toml::Value::String(s)) if s == "all" => {
                auto_free = false;
                Vec::new()
            }
            Some(toml::Value::Array(a)) => {
                auto_free = false;
                a.iter()
                    .map(|v| v.as_str().map(str::to_string))
                    .collect::<Option<Vec<_>>>()
                    .ok_or_else(|| {
                        ctx.err(
                            span.clone(),
                            "parameters.free",
                            "must be \"auto\", \"all\" or a list of parameter patterns",
                        )
                    })?
            }
            Some(_) => {
                return Err(ctx.err(
                    span,
                    "parameters.free",
                    "must be \"auto\", \"all\" or a list of parameter patterns",
                ))
            }
        };
        let priors = pattern_sigmas(ctx, &span, "parameters.priors", &p.priors, model, false)?;
        if !free.is_empty() {
            // An explicit free list: everything else is fixed, but the compliance and periodic
            // terms the section asks for stay free (unless `fixed` names them).
            model
                .set_status("*", ParameterStatus::Fixed)
                .expect("every model has parameters");
            let terms: Vec<usize> = model.joint_corrections().map(|(p, _)| p).collect();
            for i in terms {
                model.registry.set_status(i, ParameterStatus::Free);
            }
        }
        apply_statuses(model, &p.fixed, &free, &priors)
            .map_err(|e| ctx.err(span.clone(), "parameters", e))?;
        if let Some(m) = &p.measurement {
            measurement = Measurement::from_name(m).ok_or_else(|| {
                ctx.err(
                    span.clone(),
                    "parameters.measurement",
                    format!("`{m}`: use pose, position or distance"),
                )
            })?;
        }
    }
    Ok((measurement, auto_free))
}

/// `(pattern, σ)` of every entry `pattern = { sigma_<unit> = … }` of `entries` (the field
/// `field`), σ in the unit of the parameters the pattern matches (internal units). The
/// error names the entry: a pattern matching nothing or parameters of different units, a
/// missing σ, a negative one, or a zero one unless `zero_allowed` (a fixed parameter's σ 0:
/// exact; a prior's must be positive).
fn pattern_sigmas(
    ctx: &Ctx,
    span: &std::ops::Range<usize>,
    field: &str,
    entries: &BTreeMap<String, toml::Table>,
    model: &Model,
    zero_allowed: bool,
) -> Result<Vec<(String, f64)>, Error> {
    let mut sigmas = Vec::new();
    for (name, t) in entries {
        let field = format!("{field}.{name}");
        let i = model
            .registry
            .matching(name)
            .map_err(|e| ctx.err(span.clone(), &field, e))?;
        let unit = model.registry.get(i[0]).unit;
        // One σ has one unit: a pattern over lengths and angles together is an error.
        if let Some(&other) = i.iter().find(|&&k| model.registry.get(k).unit != unit) {
            let (a, b) = (model.registry.get(i[0]), model.registry.get(other));
            return Err(ctx.err(
                span.clone(),
                &field,
                format!(
                    "the pattern matches parameters of different units, `{}` ({}) and `{}` \
                     ({}); give one prior per unit",
                    a.name,
                    a.unit.display_name(),
                    b.name,
                    b.unit.display_name()
                ),
            ));
        }
        let s = sole_unit_value(t, "sigma", unit).map_err(|e| ctx.err(span.clone(), &field, e))?;
        if s < 0.0 || (s == 0.0 && !zero_allowed) {
            let why = if zero_allowed {
                "sigma must be ≥ 0 (0: exact)"
            } else {
                "sigma must be positive"
            };
            return Err(ctx.err(span.clone(), &field, why));
        }
        sigmas.push((name.clone(), s));
    }
    Ok(sigmas)
}

/// The stated uncertainty of the fixed parameters ([`FixedPrior`]): `[parameters]
/// fixed_prior = { length_mm, angle_deg, unitless }` per kind (defaults
/// [`FixedPrior::default`]), then `fixed_priors = { pattern = { sigma_<unit> = … } }` per
/// parameter. A frame of `frames` (`("tool", given)`) the cell does not give is a
/// definition (the TCP is the flange origin): its parameters have σ = 0 unless
/// `fixed_priors` names them.
pub(super) fn fixed_prior(
    ctx: &Ctx,
    section: Option<&Spanned<RawParameters>>,
    model: &Model,
    frames: [(&str, bool); 2],
) -> Result<FixedPrior, Error> {
    let mut prior = FixedPrior::default();
    for (frame, given) in frames {
        if !given {
            for p in model.registry.iter().filter(|p| p.frame() == frame) {
                prior.set(&p.name, 0.0);
            }
        }
    }
    let Some(p) = section else {
        return Ok(prior);
    };
    let span = p.span();
    let p = p.get_ref();
    if let Some(t) = &p.fixed_prior {
        let field = "parameters.fixed_prior";
        let mut used = Vec::new();
        let kinds = [
            ("length", Unit::Mm, &mut prior.length_mm),
            ("angle", Unit::Rad, &mut prior.angle_rad),
            ("unitless", Unit::Unitless, &mut prior.unitless),
        ];
        for (key, unit, slot) in kinds {
            if let Some(v) =
                unit_value(t, key, unit, &mut used).map_err(|e| ctx.err(span.clone(), field, e))?
            {
                if v < 0.0 {
                    return Err(ctx.err(span.clone(), field, format!("`{key}` must be ≥ 0")));
                }
                *slot = v;
            }
        }
        let spellings = [
            unit_spellings("length", Unit::Mm),
            unit_spellings("angle", Unit::Rad),
            "unitless".to_string(),
        ];
        check_unused(t, &used, &[], &spellings).map_err(|e| ctx.err(span.clone(), field, e))?;
    }
    for (pattern, s) in pattern_sigmas(
        ctx,
        &span,
        "parameters.fixed_priors",
        &p.fixed_priors,
        model,
        true,
    )? {
        for i in model
            .registry
            .matching(&pattern)
            .expect("pattern_sigmas checked it")
        {
            prior.set(&model.registry.get(i).name, s);
        }
    }
    Ok(prior)
}

/// `[parameters] compliance = ["j2", "j3"]` and `periodic = { joints = ["j1"], harmonics =
/// [1, 2] }`: rebuilds `model` with the lumped compliance terms of those joints
/// ([`ComplianceSpec::lumped`], gravity from `[robot] gravity`, default `[0, 0, -1]`) and the
/// periodic terms ([`PeriodicSpec::new`]), free. The error names the joint and the line.
pub(super) fn joint_corrections(
    ctx: &Ctx,
    section: Option<&Spanned<RawParameters>>,
    gravity: Option<[f64; 3]>,
    model: &mut Model,
) -> Result<(), Error> {
    let Some(p) = section else {
        return Ok(());
    };
    let span = p.span();
    let p = p.get_ref();
    if p.bending.is_some() {
        return Err(ctx.err(
            span,
            "parameters.bending",
            "lateral (bending) compliance is modelled on kinematic trees only (links that name \
             a `parent`); for a serial chain use `compliance`, or remove `bending`",
        ));
    }
    if p.compliance.is_none() && p.periodic.is_none() {
        return match p.values.keys().next() {
            Some(name) => Err(ctx.err(
                span,
                &format!("parameters.values.{name}"),
                "`values` sets compliance and periodic terms, and this cell has none: add \
                 `compliance` or `periodic` to [parameters]",
            )),
            None => Ok(()),
        };
    }
    let mut spec = model.spec();
    if let Some(joints) = &p.compliance {
        let c = ComplianceSpec::lumped(model, joints, gravity.unwrap_or([0.0, 0.0, -1.0]))
            .map_err(|e| ctx.err(span.clone(), "parameters.compliance", e))?;
        spec.compliance = Some(c);
    }
    if let Some(periodic) = &p.periodic {
        let t = PeriodicSpec::new(&model.joints, &periodic.joints, &periodic.harmonics)
            .map_err(|e| ctx.err(span.clone(), "parameters.periodic", e))?;
        spec.periodic = Some(t);
    }
    let names = term_names(&spec);
    for (name, t) in &p.values {
        let field = format!("parameters.values.{name}");
        let (unit, value) = term_value(&mut spec, name).ok_or_else(|| {
            ctx.err(
                span.clone(),
                &field,
                format!(
                    "not a compliance or periodic term of this cell; they are: {}",
                    names.join(", ")
                ),
            )
        })?;
        *value = sole_unit_value(t, "value", unit).map_err(|e| ctx.err(span.clone(), &field, e))?;
    }
    *model = Model::from_spec(&spec).map_err(|e| ctx.err(span, "parameters", e))?;
    Ok(())
}

/// The unit and value slot of the joint-correction term `name` in `spec`.
fn term_value<'a>(spec: &'a mut ModelSpec, name: &str) -> Option<(Unit, &'a mut f64)> {
    let compliance = spec.compliance.iter_mut().flat_map(|c| c.terms.iter_mut());
    let periodic = spec.periodic.iter_mut().flat_map(|p| p.terms.iter_mut());
    compliance
        .filter(|t| ComplianceSpec::parameter_name(t) == name)
        .map(|t| (t.unit(), &mut t.value))
        .chain(
            periodic
                .filter(|t| PeriodicSpec::parameter_name(t) == name)
                .map(|t| (Unit::Arcsec, &mut t.value)),
        )
        .next()
}

/// The names of `spec`'s joint-correction terms.
fn term_names(spec: &ModelSpec) -> Vec<String> {
    let compliance = spec.compliance.iter().flat_map(|c| &c.terms);
    let periodic = spec.periodic.iter().flat_map(|p| &p.terms);
    compliance
        .map(ComplianceSpec::parameter_name)
        .chain(periodic.map(PeriodicSpec::parameter_name))
        .collect()
}
