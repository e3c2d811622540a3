//! The section of a kinematic tree's estimate (`armcal identify` of a tree cell, issue 32
//! item 5): the fit and its solver, the fit per target (each branch's fitted and held-out
//! errors beside the frames-only ones), the non-geometric choice and gate, every free
//! parameter with its σ, and a 3D view of every branch at the estimate.
//!
//! The view draws each link of each branch as a segment from the origin of the frame it
//! starts from to its own, at the estimated parameters (a shared link, the torso, once),
//! the instrument at its fitted place and the beam to each target; the poses are the tree's
//! zero configuration (each joint clamped into its limits) and
//! [`VIEW_CONFIGURATIONS`] seeded random configurations within the limits — a tree estimate
//! does not keep the measured configurations.

use super::cell_view::{
    joint_labels, mm, round_to, view_section, Bounds, DesignView, PoseView, RobotCapsule, Scene,
};
use super::estimate::variance_factor;
use super::html::{escape, facts, fixed, number, table, Section};
use crate::accuracy::ErrorStats;
use crate::identify::tree::TreeEstimate;
use crate::model::sampling::random_joint_values;
use crate::model::tree::kinematics::{branch_kinematics, TreeData};
use crate::model::tree::Tree;
use crate::Error;
use nalgebra::Vector3;

/// Random configurations the 3D view shows after the zero configuration.
pub const VIEW_CONFIGURATIONS: usize = 8;
/// Their seed.
const VIEW_SEED: u64 = 32;
/// Radius (mm) a link segment is drawn with.
const LINK_RADIUS: f64 = 40.0;
/// Margin (mm) of the view's box around the tree.
const VIEW_MARGIN: f64 = 200.0;

/// The section of tree estimate `e`, labelled `label`, with id `id`.
pub(super) fn tree_estimate_section(
    id: &str,
    label: &str,
    e: &TreeEstimate,
) -> Result<Section, Error> {
    let mut s = Section::new(id, &format!("Tree estimate: {label}"));
    let sol = &e.solver;
    let solver = if sol.status.is_converged() {
        escape(&sol.status.to_string())
    } else {
        format!(
            "<span class=\"flag\">did not converge ({}): the parameters are not a least-squares solution</span>",
            escape(&sol.status.to_string())
        )
    };
    s.html(facts(&[
        ("tree cell", escape(&e.cell)),
        ("data", escape(&e.data)),
        (
            "fitted",
            format!(
                "{} measurements at {} configurations; {} free parameters, {} fixed at nominal",
                e.measurements,
                e.configurations,
                e.free.len(),
                e.fixed_reasons.len()
            ),
        ),
        (
            "solver",
            format!(
                "{}, {solver} — {} iterations",
                sol.method.words(),
                sol.iterations
            ),
        ),
        ("variance factor σ̂₀²", variance_factor(&e.uncertainty)),
        (
            "held out",
            if e.validation.is_empty() {
                "none".into()
            } else {
                escape(&e.validation)
            },
        ),
    ]));
    s.html("<h3>Fit per target (one per branch)</h3>\n");
    let stats = |x: &ErrorStats| -> [String; 2] {
        if x.count == 0 {
            ["—".into(), "—".into()]
        } else {
            [fixed(x.rms, 4), fixed(x.max, 4)]
        }
    };
    let rows: Vec<Vec<String>> = e
        .targets
        .iter()
        .map(|t| {
            let [fr, fm] = stats(&t.fitted);
            let [hr, hm] = stats(&t.held_out);
            let [or, _] = stats(&t.held_out_frames_only);
            vec![
                escape(&t.target),
                escape(&t.branch.join(" → ")),
                fr,
                fm,
                t.held_out.count.to_string(),
                hr,
                hm,
                or,
            ]
        })
        .collect();
    s.html(table(
        &[
            "target",
            "branch",
            "fitted RMS (mm)",
            "fitted max (mm)",
            "held-out rows",
            "held-out RMS (mm)",
            "held-out max (mm)",
            "frames only, held-out RMS (mm)",
        ],
        &rows,
        &[2, 3, 4, 5, 6, 7],
    ));
    if let Some(c) = &e.nongeometric_choice {
        s.html(format!(
            "<h3>Non-geometric terms chosen by {}-fold cross-validation</h3>\n",
            c.folds
        ));
        let rows: Vec<Vec<String>> = c
            .candidates
            .iter()
            .map(|k| {
                vec![
                    escape(k.candidate.words()),
                    k.terms.to_string(),
                    fixed(k.held_out.rms, 4),
                    fixed(k.standard_error, 4),
                    if k.candidate == c.chosen {
                        "chosen".into()
                    } else {
                        String::new()
                    },
                ]
            })
            .collect();
        s.html(table(
            &["candidate", "terms", "RMS (mm)", "± s.e. (mm)", ""],
            &rows,
            &[1, 2, 3],
        ));
        s.text(&format!("Rule: {}.", c.rule));
    }
    if !e.nongeometric.is_empty() {
        s.html("<h3>Compliance terms fitted (the identifiability gate)</h3>\n");
        let rows: Vec<Vec<String>> = e
            .nongeometric
            .iter()
            .map(|v| {
                vec![
                    escape(&v.name),
                    format!(
                        "{} ± {} {}",
                        fixed(v.estimate, 1),
                        fixed(v.sigma, 1),
                        escape(&v.unit)
                    ),
                    format!("{} %", fixed(100.0 * v.unabsorbed, 1)),
                    if v.separable {
                        "separable"
                    } else {
                        "not separable"
                    }
                    .into(),
                ]
            })
            .collect();
        s.html(table(
            &["term", "estimate ± σ", "not absorbed", "verdict"],
            &rows,
            &[],
        ));
    }
    s.html("<h3>Free parameters</h3>\n");
    let rows: Vec<Vec<String>> = e
        .parameters
        .iter()
        .filter(|p| p.free)
        .map(|p| {
            vec![
                escape(&p.name),
                number(p.nominal),
                number(p.estimate),
                p.sigma.map_or("—".into(), number),
                escape(&p.unit),
            ]
        })
        .collect();
    s.html(table(
        &["parameter", "nominal", "estimate", "σ", "unit"],
        &rows,
        &[1, 2, 3],
    ));
    if !e.fixed_reasons.is_empty() {
        let items: String = e
            .fixed_reasons
            .iter()
            .map(|(n, r)| format!("<li><code>{}</code>: {}</li>", escape(n), escape(r)))
            .collect();
        s.html(format!(
            "<details><summary>{} parameters fixed at nominal, with the reason</summary><ul>{items}</ul></details>\n",
            e.fixed_reasons.len()
        ));
    }
    s.html(tree_view(e)?);
    Ok(s)
}

/// The 3D view of the tree of `e` at its estimate (module notes).
fn tree_view(e: &TreeEstimate) -> Result<String, Error> {
    let tree = Tree::from_spec(&e.tree)?;
    view_section(
        &tree_scene(&tree, &e.cell)?,
        &format!("3D view of the tree at the estimate: {}", e.cell),
        &format!(
            "Every branch's links (orange) at the estimated parameters, the instrument and the \
             beam to each target (green), at the zero configuration and {VIEW_CONFIGURATIONS} \
             random ones within the joint limits (seed {VIEW_SEED}). Drag to orbit, wheel to \
             zoom, arrow keys or the slider to step through the configurations."
        ),
    )
}

/// The scene of `tree` at its own parameter values: one segment per link (a shared link
/// once), the targets and the instrument, at the zero and the random configurations.
fn tree_scene(tree: &Tree, name: &str) -> Result<Scene, Error> {
    let params = tree.nominal();
    let mut data = TreeData::new(tree);
    // each link once, as (branch, index of the link in the branch)
    let mut links: Vec<(usize, usize)> = Vec::new();
    let mut labels: Vec<String> = Vec::new();
    for (b, branch) in tree.branches.iter().enumerate() {
        for (k, l) in branch.model.links.iter().enumerate() {
            if !labels.contains(&l.spec.name) {
                labels.push(l.spec.name.clone());
                links.push((b, k));
            }
        }
    }
    let zero: Vec<f64> = tree
        .joints
        .iter()
        .map(|j| 0.0f64.clamp(j.lower, j.upper))
        .collect();
    let mut configurations = vec![zero];
    configurations.extend(random_joint_values(
        &tree.joints,
        VIEW_CONFIGURATIONS,
        VIEW_SEED,
    ));
    let display: Vec<f64> = tree
        .joints
        .iter()
        .map(|j| j.kind.unit().display_factor())
        .collect();
    let mut bounds = Bounds::default();
    let mut tracker: Option<Vector3<f64>> = None;
    let mut poses = Vec::with_capacity(configurations.len());
    for q in &configurations {
        let mut caps = Vec::with_capacity(links.len());
        for &(b, k) in &links {
            branch_kinematics(tree, &mut data, b, &params, q);
            let fk = &data.branches[b];
            // a link runs from the end of the one before it (the root frame's origin for
            // the first) to its own end
            let a = k
                .checked_sub(1)
                .map_or(Vector3::zeros(), |p| fk.frames[p].trans);
            let z = fk.frames[k].trans;
            bounds.add(&a, LINK_RADIUS);
            bounds.add(&z, LINK_RADIUS);
            caps.push([a.x, a.y, a.z, z.x, z.y, z.z].map(mm));
        }
        let mut targets = Vec::with_capacity(tree.targets.len());
        for &(_, b, k) in &tree.targets {
            branch_kinematics(tree, &mut data, b, &params, q);
            let fk = &data.branches[b];
            let world = fk.targets[k].trans;
            tracker = tracker.or(Some(fk.instrument.trans));
            bounds.add(&world, 0.0);
            targets.push([world.x, world.y, world.z].map(mm));
        }
        poses.push(PoseView {
            q: q.iter()
                .zip(&display)
                .map(|(v, f)| round_to(v * f, 100.0))
                .collect(),
            caps,
            targets,
            ok: true,
            clearance: None,
            incidence: None,
            violations: Vec::new(),
            below_required: Vec::new(),
            hit: Vec::new(),
            hit_obstacles: Vec::new(),
        });
    }
    if let Some(t) = &tracker {
        bounds.add(t, 0.0);
    }
    let ground = bounds.min.z;
    let mut focus = bounds.clone();
    focus.pad(VIEW_MARGIN);
    bounds.pad(VIEW_MARGIN);
    let corners = |b: &Bounds| {
        [
            [b.min.x, b.min.y, b.min.z].map(mm),
            [b.max.x, b.max.y, b.max.z].map(mm),
        ]
    };
    Ok(Scene {
        cell: name.to_string(),
        bounds: corners(&bounds),
        focus: corners(&focus),
        ground: mm(ground),
        robot: labels
            .into_iter()
            .map(|label| RobotCapsule {
                frame: label.clone(),
                label,
                r: LINK_RADIUS,
            })
            .collect(),
        obstacles: Vec::new(),
        boxes: Vec::new(),
        planes: Vec::new(),
        tracker: tracker.map(|t| [t.x, t.y, t.z].map(mm)),
        target_names: tree.targets.iter().map(|t| t.0.clone()).collect(),
        joints: joint_labels(&tree.joints),
        designs: vec![DesignView {
            name: "the zero and random configurations".into(),
            poses,
        }],
    })
}
