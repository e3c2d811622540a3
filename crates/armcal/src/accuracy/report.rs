//! Accuracy of a model against measurements, and ISO 9283 figures per commanded pose.

use crate::accuracy::iso9283::{
    position_accuracy, position_repeatability, Accuracy, Repeatability,
};
use crate::accuracy::ErrorStats;
use crate::measure::{Dataset, MeasurementKind};
use crate::model::{forward_kinematics, observed_position, Data, Model};
use serde::{Deserialize, Serialize};

/// ISO 9283 figures of one commanded pose (a configuration measured several times).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PoseFigures {
    /// Configuration id (from the dataset) of the first measurement of the pose.
    pub pose_id: String,
    /// RP of the positions attained at this pose; `None` if measured only once.
    pub repeatability: Option<Repeatability>,
    /// AP against the model's prediction (the commanded position).
    pub accuracy: Accuracy,
}

/// Accuracy of a model on a dataset of position measurements.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct AccuracyReport {
    /// |measured − predicted| of every position measurement (mm).
    pub errors: ErrorStats,
    /// ISO 9283 figures per commanded pose and observed point.
    pub poses: Vec<PoseFigures>,
    /// Largest RP over poses measured at least twice (mm).
    pub worst_rp: Option<f64>,
}

/// Joint distance (rad or mm, largest over the joints) within which two configurations
/// count as the same commanded pose: repeated approaches read slightly different encoder
/// values.
pub const SAME_POSE: f64 = 1e-3;

/// Groups configurations that are the same commanded pose: each configuration joins the
/// first group whose first configuration is within [`SAME_POSE`] in every joint, else starts
/// a group.
///
/// Linear in the number of configurations for measured data: the groups' first
/// configurations are indexed by buckets of width [`SAME_POSE`] of the joint with the widest
/// range, so a configuration is compared only with those in its own and the two neighbouring
/// buckets (any group it can join is there). Hand-written because the query, "the earliest
/// point within a box", is not what the k-d tree crates answer, and the buckets are ten lines.
fn commanded_poses(data: &Dataset) -> Vec<Vec<usize>> {
    let qs = &data.configurations;
    let joints = qs.first().map_or(0, Vec::len);
    let range = |j: usize| {
        let (lo, hi) = qs
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), q| {
                (lo.min(q[j]), hi.max(q[j]))
            });
        hi - lo
    };
    let key = (0..joints)
        .max_by(|&a, &b| range(a).total_cmp(&range(b)))
        .unwrap_or(0);
    // Bucket of a joint value; finite joint values (checked on reading) keep it in range.
    let bucket = |q: &[f64]| q.get(key).map_or(0, |v| (v / SAME_POSE).floor() as i64);
    let mut groups: Vec<Vec<usize>> = Vec::new();
    let mut firsts: std::collections::HashMap<i64, Vec<usize>> = Default::default();
    for (c, q) in qs.iter().enumerate() {
        let b = bucket(q);
        let same = |g: &usize| {
            qs[groups[*g][0]]
                .iter()
                .zip(q)
                .all(|(a, b)| (a - b).abs() <= SAME_POSE)
        };
        let joined = (b - 1..=b + 1)
            .filter_map(|k| firsts.get(&k))
            .flat_map(|gs| gs.iter().filter(|g| same(g)))
            .min()
            .copied();
        match joined {
            Some(g) => groups[g].push(c),
            None => {
                firsts.entry(b).or_default().push(groups.len());
                groups.push(vec![c]);
            }
        }
    }
    groups
}

/// Compares the model with parameters `params` with every position measurement of `data`;
/// configurations within [`SAME_POSE`] of each other are one commanded pose (ISO 9283 RP
/// and AP, the command being the model's prediction at the first of them).
pub fn accuracy_report(model: &Model, params: &[f64], data: &Dataset) -> AccuracyReport {
    let mut fk = Data::new(model);
    let mut errors = Vec::new();
    let mut poses = Vec::new();
    let groups = commanded_poses(data);
    // The measurements of each group, in the data's order (one pass, not one per group).
    let mut group_of = vec![0; data.configurations.len()];
    for (g, group) in groups.iter().enumerate() {
        for &c in group {
            group_of[c] = g;
        }
    }
    let mut measurements = vec![Vec::new(); groups.len()];
    for m in &data.measurements {
        measurements[group_of[m.config]].push(m);
    }
    for (group, measured) in groups.iter().zip(measurements) {
        let c = group[0];
        forward_kinematics(model, &mut fk, params, &data.configurations[c]);
        let mut by_target: Vec<(crate::model::Observed, Vec<nalgebra::Vector3<f64>>)> = Vec::new();
        for m in measured {
            let value = match &m.kind {
                MeasurementKind::Position { value, .. } => *value,
                MeasurementKind::Pose { value, .. } => value.trans,
                _ => continue,
            };
            errors.push((value - observed_position(&fk, m.observed)).norm());
            match by_target.iter_mut().find(|(o, _)| *o == m.observed) {
                Some((_, v)) => v.push(value),
                None => by_target.push((m.observed, vec![value])),
            }
        }
        for (obs, pts) in by_target {
            let commanded = observed_position(&fk, obs);
            if let Some(accuracy) = position_accuracy(&commanded, &pts) {
                poses.push(PoseFigures {
                    pose_id: data.config_ids[c].clone(),
                    repeatability: position_repeatability(&pts),
                    accuracy,
                });
            }
        }
    }
    let worst_rp = poses
        .iter()
        .filter_map(|p| p.repeatability.as_ref().map(|r| r.rp))
        .fold(None, |a: Option<f64>, b| Some(a.map_or(b, |a| a.max(b))));
    AccuracyReport {
        errors: ErrorStats::of(&errors),
        poses,
        worst_rp,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// The grouping as first written: every configuration against every group (quadratic).
    fn commanded_poses_by_scan(data: &Dataset) -> Vec<Vec<usize>> {
        let mut groups: Vec<Vec<usize>> = Vec::new();
        for (c, q) in data.configurations.iter().enumerate() {
            let same = |g: &Vec<usize>| {
                data.configurations[g[0]]
                    .iter()
                    .zip(q)
                    .all(|(a, b)| (a - b).abs() <= SAME_POSE)
            };
            match groups.iter_mut().find(|g| same(g)) {
                Some(g) => g.push(c),
                None => groups.push(vec![c]),
            }
        }
        groups
    }

    #[test]
    fn bucketed_grouping_is_the_scan() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for round in 0..20 {
            let mut data = Dataset::default();
            // Commanded poses on a coarse grid (so some lie within a few SAME_POSE of each
            // other), each approached several times with encoder noise around SAME_POSE.
            let commanded: Vec<Vec<f64>> = (0..30)
                .map(|_| {
                    (0..6)
                        .map(|_| rng.random_range(0..4) as f64 * 1.5e-3)
                        .collect()
                })
                .collect();
            for k in 0..200 {
                let base = &commanded[rng.random_range(0..commanded.len())];
                let spread = if round % 2 == 0 { 0.6e-3 } else { 2e-3 };
                let q = base
                    .iter()
                    .map(|v| v + rng.random_range(-spread..spread))
                    .collect();
                data.push_configuration(format!("p{k}"), q);
            }
            assert_eq!(commanded_poses(&data), commanded_poses_by_scan(&data));
        }
    }
}
