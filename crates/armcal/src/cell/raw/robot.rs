//! `[robot]` (a built-in robot, a URDF file, a Universal Robots kinematics YAML or inline
//! `[[robot.links]]`, joint `limits`,
//! `[[robot.capsules]]`, the skeleton's `link_radius_mm` and `link_radii_mm`, `convention`)
//! and `[[tool_capsules]]`.

use super::fields::*;
use super::*;
use crate::model::urdf::CollisionShape;
use std::ops::Range;

/// The robot of `[robot]`: exactly one of `builtin`, `urdf`, `ur_kinematics` (both relative
/// to `dir`) or `[[robot.links]]`, with its `limits` overrides and `[[robot.capsules]]`; and a URDF's
/// `<collision>` shapes (for [`collision_model`]).
pub(super) fn robot(
    ctx: &Ctx,
    rr: &RawRobot,
    rspan: Range<usize>,
    dir: &Path,
) -> Result<(Robot, Vec<CollisionShape>), Error> {
    let mut shapes = Vec::new();
    let file = ctx.file;
    let sources = rr.builtin.is_some() as usize
        + rr.urdf.is_some() as usize
        + rr.ur_kinematics.is_some() as usize
        + (!rr.links.is_empty()) as usize;
    if sources != 1 {
        return Err(ctx.err(
            rspan,
            "robot",
            "give exactly one of `builtin`, `urdf`, `ur_kinematics` or `[[robot.links]]`",
        ));
    }
    let mut robot = if let Some(b) = &rr.builtin {
        let robot = robots::robot(b).map_err(|e| ctx.err(rspan.clone(), "robot.builtin", e))?;
        check_values(ctx, &robot.spec.links, rspan.clone(), "robot.builtin")?;
        robot
    } else if let Some(u) = &rr.urdf {
        let path = dir.join(u);
        let (spec, urdf_shapes) =
            crate::model::urdf::read_urdf_with_collisions(&path, rr.tip.as_deref())
                .map_err(|e| ctx.err(rspan.clone(), "robot.urdf", e))?;
        shapes = urdf_shapes;
        check_values(ctx, &spec.links, rspan.clone(), "robot.urdf")?;
        Robot {
            name: rr.name.clone().unwrap_or_else(|| spec.name.clone()),
            summary: format!("imported from {u}"),
            source: format!("URDF file {}", path.display()),
            spec,
            capsules: Vec::new(),
            collision: String::new(),
        }
    } else if let Some(u) = &rr.ur_kinematics {
        let path = dir.join(u);
        let spec = crate::model::ur_kinematics::read_ur_kinematics(&path)
            .map_err(|e| ctx.err(rspan.clone(), "robot.ur_kinematics", e))?;
        check_values(ctx, &spec.links, rspan.clone(), "robot.ur_kinematics")?;
        Robot {
            name: rr.name.clone().unwrap_or_else(|| spec.name.clone()),
            summary: format!("Universal Robots kinematics from {u}"),
            source: format!("UR kinematics file {}", path.display()),
            spec,
            capsules: Vec::new(),
            collision: String::new(),
        }
    } else {
        let mut links = Vec::new();
        let mut joint_index = 0;
        for (i, l) in rr.links.iter().enumerate() {
            let has_joint = matches!(
                l.get_ref().get("joint").and_then(|v| v.as_str()),
                Some("revolute") | Some("prismatic")
            );
            if has_joint {
                joint_index += 1;
            }
            let field = format!("robot.links[{i}]");
            // An unnamed link is named after its joint (`j3`); an unnamed fixed link after
            // its place in the list (`fixed4`), so it cannot take its joint's name.
            let default_name = if has_joint {
                format!("j{joint_index}")
            } else {
                format!("fixed{}", i + 1)
            };
            let spec = inline_link(l.get_ref(), default_name, joint_index)
                .map_err(|e| ctx.err(l.span(), &field, e))?;
            check_values(ctx, std::slice::from_ref(&spec), l.span(), &field)?;
            links.push(spec);
        }
        // Every chain starts with a base frame and ends with a tool frame.
        if links.first().map(|l| l.name.as_str()) != Some("base") {
            links.insert(0, crate::robots::frame_link("base", [0.0; 3], [0.0; 3]));
        }
        if links.last().map(|l| l.name.as_str()) != Some("tool") {
            links.push(crate::robots::frame_link("tool", [0.0; 3], [0.0; 3]));
        }
        let name = rr.name.clone().unwrap_or_else(|| "inline".into());
        Robot {
            name: name.clone(),
            summary: "inline robot from the cell file".into(),
            source: format!("cell file {file}"),
            spec: ModelSpec {
                compliance: None,
                periodic: None,
                payloads: Vec::new(),
                name,
                instrument: None,
                links,
                targets: vec![],
            },
            capsules: Vec::new(),
            collision: String::new(),
        }
    };
    if let Some(limits) = &rr.limits {
        for (jname, [lo, hi]) in limits {
            let link = robot
                .spec
                .links
                .iter_mut()
                .find(|l| l.joint.as_ref().map(|j| j.name == *jname).unwrap_or(false))
                .ok_or_else(|| {
                    ctx.err(
                        rspan.clone(),
                        &format!("robot.limits.{jname}"),
                        "no joint of that name",
                    )
                })?;
            let j = link.joint.as_mut().expect("found by joint");
            let f = match j.kind {
                JointKind::Revolute => std::f64::consts::PI / 180.0,
                JointKind::Prismatic => 1.0,
            };
            j.lower = lo * f;
            j.upper = hi * f;
            check_values(
                ctx,
                std::slice::from_ref(link),
                rspan.clone(),
                &format!("robot.limits.{jname}"),
            )?;
            let j = link.joint.as_ref().expect("found by joint");
            limit_order(j)
                .map_err(|e| ctx.err(rspan.clone(), &format!("robot.limits.{jname}"), e))?;
        }
    }
    for (i, c) in rr.capsules.iter().enumerate() {
        let cap = capsule(c.get_ref(), true)
            .map_err(|e| ctx.err(c.span(), &format!("robot.capsules[{i}]"), e))?;
        robot.capsules.push(cap);
    }
    if rr.builtin.is_some() && !rr.capsules.is_empty() {
        robot.collision = format!(
            "{}, and the cell's {} [[robot.capsules]]",
            robot.collision,
            rr.capsules.len()
        );
    } else if !rr.capsules.is_empty() {
        robot.collision = format!("the cell's {} [[robot.capsules]]", rr.capsules.len());
    }
    Ok((robot, shapes))
}

/// The arm's collision model when the cell does not draw it: a robot from `urdf` or
/// `[[robot.links]]` without `[[robot.capsules]]` gets the capsules bounding its URDF
/// `<collision>` shapes ([`crate::robots::bounding`]), and its skeleton
/// ([`crate::robots::skeleton`], on the frames of `given`, the chain as the cell assembles
/// it) on every frame no such capsule is on, with the radii of `link_radius_mm` and
/// `link_radii_mm`; the tool's own segment is left out when the cell has `[[tool_capsules]]`.
/// The radius fields are refused where no skeleton is built (a built-in robot's capsules are
/// hand-made; `[[robot.capsules]]` replace the skeleton). Returns warnings (meshes, which
/// armcal does not read).
pub(super) fn collision_model(
    ctx: &Ctx,
    rr: &RawRobot,
    rspan: Range<usize>,
    robot: &mut Robot,
    given: &Model,
    tool_capsules: &[Capsule],
    shapes: &[CollisionShape],
) -> Result<Vec<String>, Error> {
    use crate::robots::skeleton;
    let radius_field = match (&rr.link_radius_mm, &rr.link_radii_mm) {
        (Some(_), _) => Some("robot.link_radius_mm"),
        (None, Some(_)) => Some("robot.link_radii_mm"),
        (None, None) => None,
    };
    if rr.builtin.is_some() || !rr.capsules.is_empty() {
        if let Some(field) = radius_field {
            let why = if rr.builtin.is_some() {
                "a built-in robot has hand-made capsules; the skeleton's radius applies to a \
                 robot from `urdf` or `[[robot.links]]` (add capsules with [[robot.capsules]])"
            } else {
                "the cell draws the arm with [[robot.capsules]], which replace the skeleton; \
                 remove one or the other"
            };
            return Err(ctx.err(rspan, field, why));
        }
        return Ok(Vec::new());
    }
    let mut warnings = Vec::new();
    let mut bounded = Vec::new();
    for shape in shapes {
        match crate::robots::bounding::bounding_capsule(shape) {
            Some(c) => bounded.push(c),
            None => warnings.push(format!(
                "URDF link `{}` (frame `{}`): its collision mesh cannot be read (armcal reads \
                 boxes, cylinders, capsules and spheres); the skeleton stands in for it",
                shape.link, shape.frame
            )),
        }
    }
    let check = |field: &str, r: f64| {
        if r.is_finite() && r >= 0.0 {
            Ok(r)
        } else {
            Err(ctx.err(
                rspan.clone(),
                field,
                format!("{r} is not a radius: give a finite length ≥ 0 mm"),
            ))
        }
    };
    let (default, how) = match rr.link_radius_mm {
        Some(r) => (
            check("robot.link_radius_mm", r)?,
            "[robot] link_radius_mm".to_string(),
        ),
        None => {
            let r = skeleton::default_link_radius(given);
            let how = format!(
                "default: {:.0} % of the arm's {:.0} mm skeleton; set [robot] link_radius_mm",
                100.0 * skeleton::DEFAULT_RADIUS_SHARE,
                skeleton::arm_length(given)
            );
            (r, how)
        }
    };
    let per_frame = rr.link_radii_mm.clone().unwrap_or_default();
    for (frame, r) in &per_frame {
        check(&format!("robot.link_radii_mm.{frame}"), *r)?;
    }
    // A zero radius is a valid capsule (a line), but not a model of the arm's volume.
    let zero: Vec<String> = rr
        .link_radius_mm
        .filter(|&r| r == 0.0)
        .map(|_| "`[robot] link_radius_mm = 0`".to_string())
        .into_iter()
        .chain(
            per_frame
                .iter()
                .filter(|(_, &r)| r == 0.0)
                .map(|(frame, _)| format!("`[robot] link_radii_mm.{frame} = 0`")),
        )
        .collect();
    if !zero.is_empty() {
        warnings.push(format!(
            "{}: a skeleton capsule of radius 0 is the line between two joint origins, which \
             does not model the arm's volume: the obstacles, the floor and the arm itself are \
             checked against its centre line only, and a planned pose may drive the arm's \
             real links into them; give the links' half-width (the default is {:.0} % of the \
             arm's skeleton length, here {:.0} mm)",
            zero.join(", "),
            100.0 * skeleton::DEFAULT_RADIUS_SHARE,
            skeleton::default_link_radius(given)
        ));
    }
    let with_tool = tool_capsules.is_empty();
    let radius = |frame: &str| per_frame.get(frame).copied().unwrap_or(default);
    let mut capsules = skeleton::skeleton_capsules(given, &radius, with_tool);
    capsules.retain(|c| !bounded.iter().any(|b| b.frame == c.frame));
    if let Some(frame) = per_frame
        .keys()
        .find(|f| !capsules.iter().any(|c| c.frame == **f))
    {
        let mut carriers: Vec<&str> = capsules.iter().map(|c| c.frame.as_str()).collect();
        carriers.dedup();
        return Err(ctx.err(
            rspan,
            &format!("robot.link_radii_mm.{frame}"),
            format!(
                "no skeleton capsule is on frame `{frame}`; the skeleton's frames are {}",
                carriers.join(", ")
            ),
        ));
    }
    let mut text = if bounded.is_empty() {
        String::new()
    } else {
        format!(
            "{} bounding the URDF's <collision> shapes; on the other frames, ",
            capsule_count(bounded.len())
        )
    };
    text += &format!(
        "skeleton: {} between successive joint origins, radius {} mm ({how})",
        capsule_count(capsules.len()),
        default
    );
    for (frame, r) in &per_frame {
        text.push_str(&format!(", {frame} {r} mm"));
    }
    bounded.extend(capsules);
    robot.capsules = bounded;
    robot.collision = text;
    Ok(warnings)
}

/// "1 capsule", "3 capsules".
pub(crate) fn capsule_count(n: usize) -> String {
    format!("{n} capsule{}", if n == 1 { "" } else { "s" })
}

/// A joint's lower limit is not above its upper one (equal limits lock the joint); the error
/// gives both in the cell's units.
fn limit_order(j: &Joint) -> Result<(), String> {
    if j.lower <= j.upper {
        return Ok(());
    }
    let unit = j.kind.unit();
    let f = unit.display_factor();
    Err(format!(
        "joint `{}`: the lower limit {} {u} is above the upper limit {} {u} (write `[lower, upper]`)",
        j.name,
        j.lower * f,
        j.upper * f,
        u = unit.display_name()
    ))
}

/// Every value of `links` within the range a model holds
/// ([`crate::model::LinkSpec::check_values`]), after unit conversion; the error is at `field`.
pub(super) fn check_values(
    ctx: &Ctx,
    links: &[crate::model::LinkSpec],
    span: Range<usize>,
    field: &str,
) -> Result<(), Error> {
    links.iter().try_for_each(|l| {
        l.check_values()
            .map_err(|e| ctx.err(span.clone(), field, e))
    })
}

/// `robot.convention`: the form the chain is put in ([`LinkForm`]; default `auto`).
pub(super) fn link_form(ctx: &Ctx, rr: &RawRobot, rspan: Range<usize>) -> Result<LinkForm, Error> {
    let form = match &rr.convention {
        None => LinkForm::Auto,
        Some(c) => LinkForm::from_name(c).ok_or_else(|| {
            ctx.err(
                rspan.clone(),
                "robot.convention",
                format!(
                    "`{c}`; use {}",
                    LinkForm::ALL.map(LinkForm::name).join(", ")
                ),
            )
        })?,
    };
    Ok(form)
}

/// `[[tool_capsules]]`: capsules on the tool frame unless they name another.
pub(super) fn tool_capsules(
    ctx: &Ctx,
    tables: &[Spanned<toml::Table>],
) -> Result<Vec<Capsule>, Error> {
    let mut tool_capsules = Vec::new();
    for (i, c) in tables.iter().enumerate() {
        tool_capsules.push(
            capsule(c.get_ref(), false)
                .map_err(|e| ctx.err(c.span(), &format!("tool_capsules[{i}]"), e))?,
        );
    }
    Ok(tool_capsules)
}

/// An inline link: `name`, `convention`, the convention's fields with unit suffixes,
/// optional `joint = "revolute" | "prismatic" | "fixed"` (default fixed; `limits` without
/// `joint` is an error), `limits = [lo, hi]` (deg or mm),
/// `axis = [x, y, z]` for URDF-convention links.
pub(super) fn inline_link(
    t: &toml::Table,
    default_name: String,
    joint_index: usize,
) -> Result<LinkSpec, String> {
    let name = string_field(t, "name")?
        .map(str::to_string)
        .unwrap_or(default_name);
    let conv_name = string_field(t, "convention")?.ok_or("missing `convention`")?;
    let mut convention = Convention::from_name(conv_name).ok_or_else(|| {
        format!(
            "unknown convention `{conv_name}`; known: {}",
            Convention::ALL.map(|c| c.name()).join(", ")
        )
    })?;
    // A modified-DH link with β (book §2.6) is written `convention = "mdh"` + `beta_deg`.
    if convention == Convention::Mdh && (t.contains_key("beta_deg") || t.contains_key("beta_rad")) {
        convention = Convention::MdhBeta;
    }
    let kind = match string_field(t, "joint")? {
        // Joint limits on a link that names no joint: the user meant a joint, and without
        // `joint` the link would be fixed (a robot with fewer joints than its data).
        None if t.contains_key("limits") => {
            return Err(
                "`limits` without `joint`: a link without `joint` is fixed; add \
                 `joint = \"revolute\"` (or \"prismatic\"), or remove `limits` for a fixed link"
                    .into(),
            )
        }
        None | Some("fixed") => None,
        Some("revolute") => Some(JointKind::Revolute),
        Some("prismatic") => Some(JointKind::Prismatic),
        Some(other) => {
            return Err(format!(
                "`joint` is `{other}`; use revolute, prismatic or fixed"
            ))
        }
    };
    let mut valid: Vec<String> = convention
        .fields(kind)
        .iter()
        .map(|(f, u)| unit_spellings(f, *u))
        .collect();
    if convention == Convention::Mdh {
        valid.push(unit_spellings("beta", Unit::Rad));
    }
    let allowed = [
        "name",
        "convention",
        "joint",
        "limits",
        "axis",
        "joint_name",
        // a tree cell's (raw/tree.rs; a serial cell refuses them first)
        "parent",
        "coupled",
    ];
    let mut used = Vec::new();
    let mut values = Vec::new();
    for (field, unit) in convention.fields(kind) {
        let v = unit_value(t, field, *unit, &mut used)?;
        let default_zero = *field == "offset";
        values.push(match v {
            Some(v) => v,
            None if default_zero => 0.0,
            None => {
                let first = unit_spellings(field, *unit);
                let first = first.split('|').next().unwrap_or(field);
                return Err(missing(
                    t,
                    &allowed,
                    &valid,
                    format!("missing `{first}` for convention {convention}"),
                ));
            }
        });
    }
    let mut geometry = LinkGeometry::new(convention, values);
    if let Some(a) = t.get("axis") {
        let arr: Vec<f64> = a
            .as_array()
            .map(|v| v.iter().filter_map(number).collect())
            .unwrap_or_default();
        if arr.len() != 3 || arr.iter().all(|x| *x == 0.0) {
            return Err("`axis` must be a non-zero array of 3 numbers".into());
        }
        geometry.axis = Some([arr[0], arr[1], arr[2]]);
    }
    let joint = match kind {
        None => None,
        Some(k) => {
            let lim = t
                .get("limits")
                .and_then(|v| v.as_array())
                .filter(|a| a.len() == 2)
                .ok_or(
                    "a jointed link needs `limits = [lower, upper]` (deg, or mm for prismatic)",
                )?;
            let f = match k {
                JointKind::Revolute => std::f64::consts::PI / 180.0,
                JointKind::Prismatic => 1.0,
            };
            let num = |v: &toml::Value| number(v).ok_or("`limits` must hold finite numbers");
            let jname = string_field(t, "joint_name")?
                .map(str::to_string)
                .unwrap_or_else(|| format!("q{joint_index}"));
            let joint = Joint {
                name: jname,
                kind: k,
                lower: num(&lim[0])? * f,
                upper: num(&lim[1])? * f,
            };
            limit_order(&joint)?;
            Some(joint)
        }
    };
    check_unused(t, &used, &allowed, &valid)?;
    Ok(LinkSpec {
        name,
        geometry,
        joint,
    })
}
