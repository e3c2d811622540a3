//! A cell that describes a kinematic tree ([`crate::model::tree`]): `[[robot.links]]` whose
//! links name their `parent` (default: the previous link) and whose coupled joints say what
//! they follow (`coupled = { q2 = -1, q3 = -1, offset_deg = 90 }`), and `[[targets]]` that
//! name the `link` they hang from (default: the last link). Read with `[name]`,
//! `[instrument]`, `[parameters] measurement`, `compliance` (joint compliance over the
//! tree, [`crate::model::tree::compliance`]) and `bending` (lateral compliance,
//! [`crate::model::tree::bending`]), both with `[robot] gravity`; the serial sections a fit
//! of a tree does not use yet are refused, by name.

use super::fields::*;
use super::*;
use crate::cell::tree::TreeCell;
use crate::model::compliance::{gravity_direction, ComplianceSpec};
use crate::model::tree::bending::lumped_tree_bending;
use crate::model::tree::compliance::lumped_tree_compliance;
use crate::model::tree::{Coupling, Tree, TreeLinkSpec, TreeSpec, TreeTargetSpec};

/// The keys a `[[robot.links]]` entry or a `[[targets]]` entry has only in a tree cell, and
/// the entry's field path (for the error of a serial load).
pub(super) fn tree_field(
    raw_links: &[Spanned<toml::Table>],
    targets: &[Spanned<toml::Table>],
) -> Option<(std::ops::Range<usize>, String)> {
    for (i, l) in raw_links.iter().enumerate() {
        for key in ["parent", "coupled"] {
            if l.get_ref().contains_key(key) {
                return Some((l.span(), format!("robot.links[{i}].{key}")));
            }
        }
    }
    targets.iter().enumerate().find_map(|(i, t)| {
        t.get_ref()
            .contains_key("link")
            .then(|| (t.span(), format!("targets[{i}].link")))
    })
}

/// Parses a tree cell.
pub(in crate::cell) fn parse_tree(text: &str, file: &str) -> Result<TreeCell, Error> {
    let (ctx, raw) = parse_raw(text, file)?;
    let rspan = raw.robot.span();
    let rr = raw.robot.into_inner();
    let unsupported = [
        ("robot.builtin", rr.builtin.is_some()),
        ("robot.tip", rr.tip.is_some()),
        ("robot.limits", rr.limits.is_some()),
        ("robot.capsules", !rr.capsules.is_empty()),
        ("robot.link_radius_mm", rr.link_radius_mm.is_some()),
        ("robot.link_radii_mm", rr.link_radii_mm.is_some()),
        ("robot.convention", rr.convention.is_some()),
        ("base", raw.base.is_some()),
        ("tool", raw.tool.is_some()),
        ("working", !raw.working.is_empty()),
        ("working_path", !raw.working_path.is_empty()),
        ("obstacles", !raw.obstacles.is_empty()),
        ("tool_capsules", !raw.tool_capsules.is_empty()),
        ("payload", !raw.payload.is_empty()),
        ("design", raw.design.is_some()),
        ("data", raw.data.is_some()),
    ];
    if let Some((field, _)) = unsupported.iter().find(|(_, given)| *given) {
        return Err(ctx.err(
            rspan,
            field,
            "a tree cell (links that name a `parent`, coupled joints, targets that name a \
             `link`) takes `[[robot.links]]` (each branch's base and tool frames as links), \
             or `urdf`, `[instrument]`, `[[targets]]`, `[parameters] measurement`, \
             `compliance` and `bending` (with `[robot] gravity`) for now; remove this field",
        ));
    }
    let (instrument, instrument_geometry, instrument_name) =
        instrument::instrument(&ctx, raw.instrument)?;
    let given_targets = frames::targets(&ctx, &raw.targets)?;
    let (spec_name, links, targets, names) = match &rr.urdf {
        Some(u) => {
            if !rr.links.is_empty() {
                return Err(ctx.err(
                    rspan,
                    "robot.urdf",
                    "give either `urdf` or `[[robot.links]]`, not both",
                ));
            }
            let targets = urdf_targets(&ctx, &raw.targets, given_targets)?;
            let path = Path::new(file)
                .parent()
                .map(|d| d.join(u))
                .unwrap_or_else(|| u.into());
            let spec = crate::model::urdf::read_urdf_tree(&path, targets.as_deref())
                .map_err(|e| ctx.err(rspan.clone(), "robot.urdf", e))?;
            robot::check_values(
                &ctx,
                &spec
                    .links
                    .iter()
                    .map(|l| l.link.clone())
                    .collect::<Vec<_>>(),
                rspan.clone(),
                "robot.urdf",
            )?;
            // a structural error names URDF joints, not entries of the cell
            (spec.name, spec.links, spec.targets, Vec::new())
        }
        None => {
            let (links, names) = inline_links(&ctx, &rr.links, rspan.clone())?;
            let targets = inline_targets(&ctx, &raw.targets, given_targets, &links, rspan.clone())?;
            (
                rr.name.clone().unwrap_or_else(|| "inline".into()),
                links,
                targets,
                names,
            )
        }
    };
    let spec = TreeSpec {
        name: rr.name.clone().unwrap_or(spec_name),
        instrument: instrument_geometry.map(|g| LinkSpec {
            name: instrument_name,
            geometry: g,
            joint: None,
        }),
        links,
        targets,
        compliance: None,
    };
    // a structural error (a cycle, a joint named twice, a coupling to an unknown joint, a
    // link no target hangs beyond) is placed at the first link it names
    let mut tree = Tree::from_spec(&spec).map_err(|e| {
        let message = match e {
            Error::Model(m) => m,
            other => other.to_string(),
        };
        let named = message
            .split('`')
            .skip(1)
            .step_by(2)
            .find_map(|n| names.iter().position(|(name, _)| name == n));
        match named {
            Some(i) => ctx.err(names[i].1.clone(), &format!("robot.links[{i}]"), message),
            None if rr.urdf.is_some() => ctx.err(rspan.clone(), "robot.urdf", message),
            None => ctx.err(rspan.clone(), "robot.links", message),
        }
    })?;
    let measurement = match raw.parameters.as_ref() {
        None => None,
        Some(p) => {
            let pr = p.get_ref();
            if pr.free.is_some()
                || !pr.fixed.is_empty()
                || !pr.priors.is_empty()
                || pr.fixed_prior.is_some()
                || !pr.fixed_priors.is_empty()
                || pr.periodic.is_some()
                || !pr.values.is_empty()
            {
                return Err(ctx.err(
                    p.span(),
                    "parameters",
                    "a tree cell takes `measurement`, `compliance` and `bending` here for now; \
                     remove the other fields",
                ));
            }
            match &pr.measurement {
                None => None,
                Some(m) => Some(match Measurement::from_name(m) {
                    Some(m @ (Measurement::Pose | Measurement::Position)) => m,
                    _ => {
                        return Err(ctx.err(
                            p.span(),
                            "parameters.measurement",
                            format!("`{m}`: a tree is measured by `pose` or `position`"),
                        ))
                    }
                }),
            }
        }
    };
    // joint and lateral compliance over the tree: the lumped terms of the named joints, on
    // the rigid tree
    let elastic = raw.parameters.as_ref().and_then(|p| {
        let pr = p.get_ref();
        (pr.compliance.is_some() || pr.bending.is_some()).then(|| (p.span(), pr))
    });
    let mut spec = spec;
    if let Some((span, p)) = elastic {
        let gravity = rr.gravity.unwrap_or([0.0, 0.0, -1.0]);
        let field = |what: &str| format!("parameters.{what}");
        let mut c = match &p.compliance {
            Some(joints) => lumped_tree_compliance(&tree, joints, gravity)
                .map_err(|e| ctx.err(span.clone(), &field("compliance"), e))?,
            None => {
                let g = gravity_direction(gravity)
                    .map_err(|e| ctx.err(rspan.clone(), "robot.gravity", e))?;
                ComplianceSpec {
                    gravity: g.into(),
                    levers: tree.nominal(),
                    terms: Vec::new(),
                    bending: Vec::new(),
                }
            }
        };
        if let Some(joints) = &p.bending {
            c.bending = lumped_tree_bending(&tree, joints, gravity)
                .map_err(|e| ctx.err(span.clone(), &field("bending"), e))?;
        }
        spec.compliance = Some(c);
        tree = Tree::from_spec(&spec).map_err(|e| {
            let e = e.to_string();
            let what = if e.contains(".bending.") {
                "bending"
            } else {
                "compliance"
            };
            ctx.err(span, &field(what), e)
        })?;
    } else if rr.gravity.is_some() {
        return Err(ctx.err(
            rspan,
            "robot.gravity",
            "gravity is used by `[parameters] compliance` and `bending`, and this tree cell \
             has neither: add the compliant joints or remove `gravity`",
        ));
    }
    let all_frames = spec
        .targets
        .iter()
        .all(|t| t.target.geometry.convention != Convention::Point);
    let measurement = measurement.unwrap_or(if all_frames {
        Measurement::Pose
    } else {
        Measurement::Position
    });
    TreeCell::new(
        raw.name.unwrap_or_else(|| spec.name.clone()),
        file.to_string(),
        spec,
        tree,
        measurement,
        instrument.map(|i| i.noise).unwrap_or_default(),
    )
    .map_err(|e| ctx.err(rspan, "robot.links", e))
}

/// The links of `[[robot.links]]`, each with its parent and coupling, and each link's name
/// with the span of its entry.
#[allow(clippy::type_complexity)]
fn inline_links(
    ctx: &Ctx,
    raw_links: &[Spanned<toml::Table>],
    rspan: std::ops::Range<usize>,
) -> Result<(Vec<TreeLinkSpec>, Vec<(String, std::ops::Range<usize>)>), Error> {
    let mut links = Vec::new();
    let mut joint_index = 0;
    let mut names: Vec<(String, std::ops::Range<usize>)> = Vec::new();
    for (i, l) in raw_links.iter().enumerate() {
        let t = l.get_ref();
        let field = format!("robot.links[{i}]");
        let has_joint = matches!(
            t.get("joint").and_then(|v| v.as_str()),
            Some("revolute") | Some("prismatic")
        );
        joint_index += usize::from(has_joint);
        let default_name = if has_joint {
            format!("j{joint_index}")
        } else {
            format!("fixed{}", i + 1)
        };
        let link = robot::inline_link(t, default_name, joint_index)
            .map_err(|e| ctx.err(l.span(), &field, e))?;
        robot::check_values(ctx, std::slice::from_ref(&link), l.span(), &field)?;
        let parent = string_field(t, "parent")
            .map_err(|e| ctx.err(l.span(), &format!("{field}.parent"), e))?
            .map(str::to_string);
        if let Some(p) = &parent {
            if !raw_links.iter().enumerate().any(|(k, o)| {
                string_field(o.get_ref(), "name").ok().flatten() == Some(p.as_str())
                    || (k != i && default_link_name(raw_links, k) == *p)
            }) {
                return Err(ctx.err(
                    l.span(),
                    &format!("{field}.parent"),
                    format!("names `{p}`, which is no link of the robot; a parent is the `name` of another `[[robot.links]]` entry"),
                ));
            }
        }
        let coupling = match t.get("coupled") {
            None => None,
            Some(v) => Some(
                coupling(v, link.joint.as_ref().map(|j| j.kind))
                    .map_err(|e| ctx.err(l.span(), &format!("{field}.coupled"), e))?,
            ),
        };
        names.push((link.name.clone(), l.span()));
        links.push(TreeLinkSpec {
            link,
            parent,
            coupling,
        });
    }
    if links.is_empty() {
        return Err(ctx.err(
            rspan,
            "robot.links",
            "a tree cell lists its links in `[[robot.links]]`",
        ));
    }
    Ok((links, names))
}

/// The targets of `[[targets]]` over inline links: each on the link it names, or the last
/// link.
fn inline_targets(
    ctx: &Ctx,
    raw_targets: &[Spanned<toml::Table>],
    given: Vec<(LinkSpec, Option<String>)>,
    links: &[TreeLinkSpec],
    rspan: std::ops::Range<usize>,
) -> Result<Vec<TreeTargetSpec>, Error> {
    let last = links
        .last()
        .map(|l| l.link.name.clone())
        .unwrap_or_default();
    let mut targets = Vec::new();
    for (i, (target, link)) in given.into_iter().enumerate() {
        let parent = link.unwrap_or_else(|| last.clone());
        if !links.iter().any(|l| l.link.name == parent) {
            return Err(ctx.err(
                raw_targets[i].span(),
                &format!("targets[{i}].link"),
                format!("names `{parent}`, which is no link of the robot"),
            ));
        }
        targets.push(TreeTargetSpec { target, parent });
    }
    if targets.is_empty() {
        return Err(ctx.err(
            rspan,
            "targets",
            "a tree cell needs `[[targets]]`, each naming the `link` it hangs from",
        ));
    }
    Ok(targets)
}

/// The targets of `[[targets]]` over a URDF robot, each naming the URDF `link` it hangs from;
/// `None` without `[[targets]]` (a frame at every leaf link of the URDF).
fn urdf_targets(
    ctx: &Ctx,
    raw_targets: &[Spanned<toml::Table>],
    given: Vec<(LinkSpec, Option<String>)>,
) -> Result<Option<Vec<TreeTargetSpec>>, Error> {
    if given.is_empty() {
        return Ok(None);
    }
    given
        .into_iter()
        .enumerate()
        .map(|(i, (target, link))| match link {
            Some(parent) => Ok(TreeTargetSpec { target, parent }),
            None => Err(ctx.err(
                raw_targets[i].span(),
                &format!("targets[{i}].link"),
                "a target of a URDF tree names the URDF `link` it hangs from (`link = \"l_tool\"`)",
            )),
        })
        .collect::<Result<_, _>>()
        .map(Some)
}

/// The name an unnamed `[[robot.links]]` entry `k` gets (as [`robot::inline_link`] names it).
fn default_link_name(links: &[Spanned<toml::Table>], k: usize) -> String {
    let jointed = |t: &toml::Table| {
        matches!(
            t.get("joint").and_then(|v| v.as_str()),
            Some("revolute") | Some("prismatic")
        )
    };
    match string_field(links[k].get_ref(), "name").ok().flatten() {
        Some(n) => n.to_string(),
        None if jointed(links[k].get_ref()) => {
            format!(
                "j{}",
                links[..=k].iter().filter(|l| jointed(l.get_ref())).count()
            )
        }
        None => format!("fixed{}", k + 1),
    }
}

/// `coupled = { q2 = -1, q3 = -1, offset_deg = 90 }`: the joints followed with their
/// coefficients, and the offset in the joint's unit (`offset_deg`/`offset_rad` for a
/// revolute joint, `offset_mm`/`offset_m` for a prismatic one; default 0).
fn coupling(v: &toml::Value, kind: Option<JointKind>) -> Result<Coupling, String> {
    let t = v
        .as_table()
        .ok_or("`coupled` is a table of joint names and coefficients, `{ q2 = -1, q3 = -1 }`")?;
    let unit = match kind {
        Some(JointKind::Revolute) => Unit::Rad,
        Some(JointKind::Prismatic) => Unit::Mm,
        None => return Err("a coupled link needs a `joint` (revolute or prismatic)".into()),
    };
    let mut used = Vec::new();
    let offset = unit_value(t, "offset", unit, &mut used)?.unwrap_or(0.0);
    let mut terms = Vec::new();
    for (k, c) in t {
        if used.contains(k) {
            continue;
        }
        if k.starts_with("offset") {
            return Err(format!(
                "`{k}`: the offset of this joint is `{}`",
                unit_spellings("offset", unit).replace('|', "` or `")
            ));
        }
        let c =
            number(c).ok_or_else(|| format!("the coefficient of `{k}` must be a finite number"))?;
        terms.push((k.clone(), c));
    }
    if terms.is_empty() {
        return Err("`coupled` names no joint; give the joints it follows with their coefficients, `{ q2 = -1, q3 = -1 }`".into());
    }
    Ok(Coupling { terms, offset })
}
