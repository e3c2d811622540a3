//! Finding the commanded poses of an ISO 9283 test in a data set: which configurations are
//! repeated approaches of one pose (ISO 9283 §7.1: each pose of the test cube approached in
//! cycles).
//!
//! Two configurations are the same commanded pose when the robot's nominal model puts its
//! tool at the same place there: positions within [`SamePose::position_mm`] and orientations
//! within [`SamePose::orientation_deg`]. The test is on the pose, not on the joints, because
//! repeated approaches read different joints at one pose (encoder and servo spread) and, near
//! a wrist singularity, joints 4 and 6 may trade turns at the same tool pose (UR10 Series D:
//! 0.11° apart at one cube centre, 0.04 mm and 0.014° between the poses). It needs no pose id
//! and no order: the data's rows may come in any order, and any user's ISO 9283 data — or
//! data that never meant to repeat a pose — group the same way. The nominal model is the
//! controller's view, so a calibration does not change which rows are one pose.

use crate::model::{forward_kinematics, Data, Model, Pose};
use crate::Error;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

/// The tolerance within which two configurations are one commanded pose.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SamePose {
    /// Largest distance between the nominal tool positions (mm).
    pub position_mm: f64,
    /// Largest angle between the nominal tool orientations (deg).
    pub orientation_deg: f64,
}

impl Default for SamePose {
    /// 0.5 mm and 0.1°: well above the spread of repeated approaches of an industrial arm
    /// (UR10 Series D: 0.18 mm, 0.015° at most between the nominal poses of one pose's
    /// approaches) and well below the distance between the poses of a test cube (tens of
    /// millimetres; the closest two distinct commanded poses in Series D are 0.9 mm apart).
    fn default() -> Self {
        SamePose {
            position_mm: 0.5,
            orientation_deg: 0.1,
        }
    }
}

impl SamePose {
    /// Refuses a tolerance that is not a positive finite number, naming `what` each is
    /// called by the caller (e.g. its option names).
    pub fn check(&self, what: [&str; 2]) -> Result<(), Error> {
        for (v, name, unit) in [
            (self.position_mm, what[0], "mm"),
            (self.orientation_deg, what[1], "deg"),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::Input(format!(
                    "{name}: the same-pose tolerance must be a positive number of {unit}, not {v}"
                )));
            }
        }
        Ok(())
    }
}

/// The commanded poses found in a data set.
#[derive(Clone, Debug)]
pub struct CommandedPoses {
    /// The configurations of each commanded pose (indices into the dataset's
    /// configurations), in data order; poses in the order of their first configuration.
    pub groups: Vec<Vec<usize>>,
    /// How well apart the groups are.
    pub summary: GroupingSummary,
}

/// How the commanded poses were found and how well they separate (a record field).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct GroupingSummary {
    /// The tolerance used.
    pub tolerance: SamePose,
    /// Number of configurations.
    pub configurations: usize,
    /// Number of commanded poses found.
    pub poses: usize,
    /// Number of poses by number of approaches: `[approaches, poses]`, ascending.
    pub approaches: Vec<[usize; 2]>,
    /// Largest distance of an approach's nominal position from its pose's first (mm).
    pub largest_spread_mm: f64,
    /// Largest angle of an approach's nominal orientation from its pose's first (deg).
    pub largest_spread_deg: f64,
    /// The two distinct poses closest to each other, if any two are within three times
    /// the tolerance (in position and orientation): poses that close may be one pose split
    /// or two poses merged, and the tolerance is then worth a look.
    pub closest: Option<ClosePoses>,
}

/// Two distinct commanded poses close to each other.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ClosePoses {
    /// `pose_id` of the first configuration of one pose.
    pub a: String,
    /// `pose_id` of the first configuration of the other.
    pub b: String,
    /// Distance between their nominal positions (mm).
    pub distance_mm: f64,
    /// Angle between their nominal orientations (deg).
    pub angle_deg: f64,
}

/// Grid cell of side `h` holding a point.
fn cell(p: &Vector3<f64>, h: f64) -> [i64; 3] {
    // FK of finite joints (checked on reading) is finite: the cast saturates at worst.
    [0, 1, 2].map(|k| (p[k] / h).floor() as i64)
}

/// The 27 cells around and including `c`.
fn neighbours(c: [i64; 3]) -> impl Iterator<Item = [i64; 3]> {
    (-1..=1).flat_map(move |i| {
        (-1..=1).flat_map(move |j| (-1..=1).map(move |k| [c[0] + i, c[1] + j, c[2] + k]))
    })
}

/// The nominal tool pose of every configuration.
pub fn nominal_poses(model: &Model, configurations: &[Vec<f64>]) -> Vec<Pose<f64>> {
    let nominal = model.nominal();
    let mut fk = Data::new(model);
    configurations
        .iter()
        .map(|q| {
            forward_kinematics(model, &mut fk, &nominal, q);
            *fk.tool()
        })
        .collect()
}

/// Groups configurations into commanded poses: each configuration joins the earliest pose
/// whose first configuration is within `tol` (nominal tool position and orientation), else
/// starts a pose. With approaches of one pose closer to each other than `tol` and distinct
/// poses farther than twice `tol`, the grouping does not depend on the order of the rows.
///
/// Linear in the number of configurations for measured data: the poses' first
/// configurations are indexed by grid cells of side `tol.position_mm`, so a configuration is
/// compared only with those in the 27 cells around its own (any pose it can join is there).
pub fn commanded_poses(
    model: &Model,
    configurations: &[Vec<f64>],
    ids: &[String],
    tol: &SamePose,
) -> CommandedPoses {
    let poses = nominal_poses(model, configurations);
    let h = tol.position_mm;
    let max_angle = tol.orientation_deg.to_radians();
    let mut groups: Vec<Vec<usize>> = Vec::new();
    let mut firsts: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    let (mut spread_mm, mut spread_rad) = (0.0f64, 0.0f64);
    for (c, p) in poses.iter().enumerate() {
        let near = |g: &usize| {
            let f = &poses[groups[*g][0]];
            (f.trans - p.trans).norm() <= h && f.rotation_angle_to(p) <= max_angle
        };
        let joined = neighbours(cell(&p.trans, h))
            .filter_map(|k| firsts.get(&k))
            .flat_map(|gs| gs.iter().filter(|g| near(g)))
            .min()
            .copied();
        match joined {
            Some(g) => {
                let f = &poses[groups[g][0]];
                spread_mm = spread_mm.max((f.trans - p.trans).norm());
                spread_rad = spread_rad.max(f.rotation_angle_to(p));
                groups[g].push(c);
            }
            None => {
                firsts
                    .entry(cell(&p.trans, h))
                    .or_default()
                    .push(groups.len());
                groups.push(vec![c]);
            }
        }
    }
    let closest = closest_poses(&poses, &groups, tol).map(|(a, b, d, r)| ClosePoses {
        a: ids[groups[a][0]].clone(),
        b: ids[groups[b][0]].clone(),
        distance_mm: d,
        angle_deg: r.to_degrees(),
    });
    let mut counts: std::collections::BTreeMap<usize, usize> = Default::default();
    for g in &groups {
        *counts.entry(g.len()).or_default() += 1;
    }
    CommandedPoses {
        summary: GroupingSummary {
            tolerance: *tol,
            configurations: configurations.len(),
            poses: groups.len(),
            approaches: counts.into_iter().map(|(a, n)| [a, n]).collect(),
            largest_spread_mm: spread_mm,
            largest_spread_deg: spread_rad.to_degrees(),
            closest,
        },
        groups,
    }
}

/// The two poses (by their first configurations) nearest each other in the scaled distance
/// `max(d / tol_mm, θ / tol_deg)`, if below 3: (pose, pose, d mm, θ rad). Cells of side three
/// times the tolerance, so only neighbouring cells can hold such a pair.
fn closest_poses(
    poses: &[Pose<f64>],
    groups: &[Vec<usize>],
    tol: &SamePose,
) -> Option<(usize, usize, f64, f64)> {
    const WITHIN: f64 = 3.0;
    let h = WITHIN * tol.position_mm;
    let mut cells: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    for (g, members) in groups.iter().enumerate() {
        cells
            .entry(cell(&poses[members[0]].trans, h))
            .or_default()
            .push(g);
    }
    let mut best: Option<(f64, usize, usize, f64, f64)> = None;
    for (g, members) in groups.iter().enumerate() {
        let p = &poses[members[0]];
        for other in neighbours(cell(&p.trans, h)).filter_map(|k| cells.get(&k)) {
            for &o in other.iter().filter(|&&o| o > g) {
                let f = &poses[groups[o][0]];
                let (d, r) = ((f.trans - p.trans).norm(), f.rotation_angle_to(p));
                let scaled = (d / tol.position_mm).max(r.to_degrees() / tol.orientation_deg);
                if scaled < WITHIN && best.is_none_or(|b| scaled < b.0) {
                    best = Some((scaled, g, o, d, r));
                }
            }
        }
    }
    best.map(|(_, a, b, d, r)| (a, b, d, r))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// The grouping as first written: every configuration against every pose (quadratic).
    fn by_scan(poses: &[Pose<f64>], tol: &SamePose) -> Vec<Vec<usize>> {
        let mut groups: Vec<Vec<usize>> = Vec::new();
        for (c, p) in poses.iter().enumerate() {
            let same = |g: &Vec<usize>| {
                let f = &poses[g[0]];
                (f.trans - p.trans).norm() <= tol.position_mm
                    && f.rotation_angle_to(p) <= tol.orientation_deg.to_radians()
            };
            match groups.iter_mut().find(|g| same(g)) {
                Some(g) => g.push(c),
                None => groups.push(vec![c]),
            }
        }
        groups
    }

    #[test]
    fn gridded_grouping_is_the_scan() {
        let model = Model::from_spec(&crate::robots::robot("ur10").unwrap().spec).unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for round in 0..10 {
            // Commanded joints on a coarse grid (some poses within a few tolerances of each
            // other), each approached several times with jitter around the tolerance.
            let commanded: Vec<Vec<f64>> = (0..30)
                .map(|_| {
                    (0..6)
                        .map(|_| 0.3 + rng.random_range(0..4) as f64 * 4e-4)
                        .collect()
                })
                .collect();
            let spread = if round % 2 == 0 { 1e-4 } else { 5e-4 };
            let qs: Vec<Vec<f64>> = (0..200)
                .map(|_| {
                    commanded[rng.random_range(0..commanded.len())]
                        .iter()
                        .map(|v| v + rng.random_range(-spread..spread))
                        .collect()
                })
                .collect();
            let ids: Vec<String> = (0..qs.len()).map(|k| format!("p{k}")).collect();
            let tol = SamePose::default();
            let found = commanded_poses(&model, &qs, &ids, &tol);
            assert_eq!(found.groups, by_scan(&nominal_poses(&model, &qs), &tol));
        }
    }
}
