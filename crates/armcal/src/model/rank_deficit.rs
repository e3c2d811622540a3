//! Why a model identifies fewer parameters than the generic count (book §2.3 and §4.7:
//! `4R + 2P + 6` for full poses, 3 fewer for the position of one point, 6 fewer again for
//! distances), in one sentence per cause with its fix. The causes armcal checks:
//!
//! * a point target on the last joint axis (book Prop. 4.7.3: the PUMA's tool origin on
//!   axis 6 leaves 25 of 27): that joint's rotation does not move it;
//! * nearly parallel consecutive axes in a DH or modified-DH link (book §2.6): no parameter
//!   for the tilt between them ([`crate::model::complete`]);
//! * a prismatic joint along the axis of a neighbouring revolute joint: its offset and the
//!   revolute link's offset along that axis move the tool alike;
//! * the data: the configurations given separate fewer parameters than random ones do
//!   (too few, or too similar, poses), with the joints that barely move;
//! * parameters the cell fixed that the count needs.

use crate::model::chain::Model;
use crate::model::complete::{self, NEAR_PARALLEL_DEG};
use crate::model::convert::axes_at_zero;
use crate::model::identifiability::{self, expected_count, IdentifiabilitySettings, Measurement};
use crate::model::kinematics::{forward_kinematics, Data};
use crate::model::link::JointKind;
use crate::model::registry::ParameterStatus;
use crate::Error;
use serde::{Deserialize, Serialize};

/// Below this distance (mm) a point target lies on a joint axis for the rank test.
pub const ON_AXIS_MM: f64 = 1e-3;

/// The distance (mm) of every point target of `model` at `params` (the tool origin when
/// there is none) from its last joint axis, if that joint is revolute: `(what, joint, mm)`,
/// e.g. ``("target `smr1`", "q6", 0.97)``. A point on that axis does not move when the
/// joint turns (book Prop. 4.7.3).
pub fn last_axis_distances(model: &Model, params: &[f64]) -> Vec<(String, String, f64)> {
    let (axes, _) = axes_at_zero(model, params);
    let Some(last) = axes.last().filter(|a| a.kind == JointKind::Revolute) else {
        return Vec::new();
    };
    let joint = model.joints[axes.len() - 1].name.clone();
    let mut data = Data::new(model);
    forward_kinematics(model, &mut data, params, &vec![0.0; model.dof()]);
    let points: Vec<(String, nalgebra::Vector3<f64>)> = if model.targets.is_empty() {
        vec![("the tool origin".into(), data.tool().trans)]
    } else {
        (0..model.targets.len())
            .filter(|&k| !model.target_is_frame(k))
            .map(|k| {
                (
                    format!("target `{}`", model.targets[k].spec.name),
                    data.targets[k].trans,
                )
            })
            .collect()
    };
    points
        .into_iter()
        .map(|(what, p)| {
            let off = p - last.point;
            let dist = (off - last.dir * off.dot(&last.dir)).norm();
            (what, joint.clone(), dist)
        })
        .collect()
}

/// A rank below the generic count, and why.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RankDeficit {
    /// Measurement type the rank was computed for.
    pub measurement: Measurement,
    /// The generic count for the measurement type.
    pub expected: usize,
    /// Size of the identifiable set found numerically (below `expected`).
    pub identifiable: usize,
    /// One sentence per cause found, each with its fix.
    pub causes: Vec<String>,
}

impl std::fmt::Display for RankDeficit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} of the {} parameters a complete model identifies from {} measurements: {}",
            self.identifiable,
            self.expected,
            self.measurement.words(),
            self.causes.join("; ")
        )
    }
}

/// The rank deficit of `model` (its free parameters, at `params`) when `identifiable`
/// geometric parameters ([`identifiability::IdentifiableCount`]) were found identifiable for measurement type `m`, or `None` when that is the
/// generic count (or the measurement type has none, e.g. several point targets).
/// `configurations`: the data's joint values, if the count came from data.
pub fn rank_deficit(
    model: &Model,
    params: &[f64],
    identifiable: usize,
    m: Measurement,
    configurations: Option<&[Vec<f64>]>,
) -> Result<Option<RankDeficit>, Error> {
    let Some(expected) = expected_count(model, m) else {
        return Ok(None);
    };
    if identifiable >= expected {
        return Ok(None);
    }
    let mut causes = Vec::new();
    let (axes, _) = axes_at_zero(model, params);
    let joint_name = |i: usize| model.joints[i].name.clone();

    // A point target (or the tool origin) on the last joint axis.
    if m != Measurement::Pose {
        for (what, joint, dist) in last_axis_distances(model, params) {
            if dist < ON_AXIS_MM {
                causes.push(format!(
                    "{what} lies on the axis of {joint} ({dist:.4} mm from it), so that joint's \
                     rotation does not move it and its link parameters have no effect; give \
                     the target's offset from the flange, even a rough one (the fit refines \
                     it), or measure a second target off that axis"
                ));
            }
        }
    }

    // Nearly parallel axes in DH / modified-DH links.
    let formed = complete::complete_minimal(&model.spec_at(params))?;
    for c in &formed.changes {
        causes.push(format!(
            "the axes of {} and {} are {:.2}° apart and link `{}` is plain {}, with no parameter \
             for a tilt between them; use `[robot] convention = \"auto\"` (the default), which \
             gives it the {} form (book §2.6)",
            c.joints[0], c.joints[1], c.angle_deg, c.link, c.from, c.to
        ));
    }
    causes.extend(formed.incomplete.iter().cloned());

    // A prismatic joint along a neighbouring revolute axis.
    for (i, a) in axes.iter().enumerate() {
        if a.kind != JointKind::Prismatic {
            continue;
        }
        for j in [i.wrapping_sub(1), i + 1] {
            let Some(b) = axes.get(j).filter(|b| b.kind == JointKind::Revolute) else {
                continue;
            };
            let angle = a.dir.dot(&b.dir).abs().min(1.0).acos().to_degrees();
            if angle < NEAR_PARALLEL_DEG {
                causes.push(format!(
                    "prismatic joint {} moves along the axis of revolute joint {} ({angle:.2}° \
                     apart), so its offset and that link's offset along the axis move the tool \
                     alike; fix one of the two in `[parameters] fixed`",
                    joint_name(i),
                    joint_name(j)
                ));
            }
        }
    }

    let opts = IdentifiabilitySettings {
        measurement: m,
        ..Default::default()
    };
    // The data: fewer than random configurations of the same model separate.
    if let Some(qs) = configurations {
        // geometric against geometric: `identifiable` counts no non-geometric term
        let generic = identifiability::analyze(model, params, &opts)?
            .count(model)
            .geometric;
        if generic > identifiable {
            let still: Vec<String> = (0..model.dof())
                .filter_map(|k| {
                    let (lo, hi) = qs.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, q| {
                        (a.0.min(q[k]), a.1.max(q[k]))
                    });
                    let j = &model.joints[k];
                    let range = (j.upper - j.lower).max(f64::EPSILON);
                    let (f, unit) = (j.kind.unit().display_factor(), j.kind.unit().display_name());
                    ((hi - lo) < 0.05 * range)
                        .then(|| format!("{} spans {:.2} {unit}", j.name, (hi - lo) * f))
                })
                .collect();
            causes.push(format!(
                "these {} configurations separate {} geometric parameters where spread-out poses \
                 separate {}: too few or too similar poses{}; measure more poses spread over every \
                 joint's range (armcal plan chooses them)",
                qs.len(),
                identifiable,
                generic,
                if still.is_empty() {
                    String::new()
                } else {
                    format!(" ({})", still.join(", "))
                }
            ));
        }
    }

    // Parameters the cell fixed.
    let fixed: Vec<usize> = (0..model.param_count())
        .filter(|&i| model.registry.get(i).status == ParameterStatus::Fixed)
        .collect();
    if causes.is_empty() && !fixed.is_empty() {
        let mut all = model.clone();
        for &i in &fixed {
            all.registry.set_status(i, ParameterStatus::Free);
        }
        let unfixed = identifiability::analyze(&all, params, &opts)?;
        if unfixed.count(&all).geometric > identifiable {
            let names: Vec<&str> = fixed
                .iter()
                .map(|&i| model.registry.get(i).name.as_str())
                .filter(|n| unfixed.identifiable.iter().any(|u| u == n))
                .collect();
            causes.push(format!(
                "the cell fixes parameters the count needs ({}); free them, or keep them fixed \
                 if you know their values",
                names.join(", ")
            ));
        }
    }
    if causes.is_empty() {
        causes.push(
            "none of the known causes applies (a target on a joint axis, parallel axes in a DH \
             or modified-DH link, a prismatic joint along a revolute axis, too few or too \
             similar poses, fixed parameters); the parameters listed as not identifiable show \
             which effects coincide"
                .into(),
        );
    }
    Ok(Some(RankDeficit {
        measurement: m,
        expected,
        identifiable,
        causes,
    }))
}
