//! The constraint set of the paper cell against central differences, parry, row subsets
//! and bad options.

use super::*;
use std::path::Path;

use crate::cell::builtin::PAPER_CELL_OBSTACLES as CELL;

fn cell() -> Cell {
    Cell::from_toml(CELL, "paper-cell-obstacles.toml", Path::new(".")).expect("paper cell")
}

fn random_q(set: &ConstraintSet, r: &mut rand_chacha::ChaCha8Rng) -> Vec<f64> {
    use rand::Rng;
    set.lower
        .iter()
        .zip(&set.upper)
        .map(|(lo, hi)| r.random_range(*lo..*hi))
        .collect()
}

/// Every constraint kind against central differences at random configurations.
#[test]
fn jacobian_matches_central_differences() {
    use rand::SeedableRng;
    let cell = cell();
    let set = ConstraintSet::new(&cell, &ConstraintSettings::default()).unwrap();
    let params = cell.model.nominal();
    let (n, dof) = (set.len(), set.dof());
    let mut ws = set.workspace();
    let mut values = vec![0.0; n];
    let mut jac = vec![0.0; n * dof];
    let (mut plus, mut minus) = (vec![0.0; n], vec![0.0; n]);
    let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let h = 1e-6;
    let mut checked = std::collections::HashMap::new();
    for _ in 0..200 {
        let q = random_q(&set, &mut r);
        set.evaluate(&mut ws, &params, &q, &mut values, Some(&mut jac));
        for j in 0..dof {
            let mut qp = q.clone();
            let mut qm = q.clone();
            qp[j] += h;
            qm[j] -= h;
            set.evaluate(&mut ws, &params, &qp, &mut plus, None);
            set.evaluate(&mut ws, &params, &qm, &mut minus, None);
            for i in 0..n {
                let fd = (plus[i] - minus[i]) / (2.0 * h);
                let an = jac[i * dof + j];
                // Kinks (closest-point switches, contact) are skipped: the one-sided
                // differences disagree there.
                let fwd = (plus[i] - values[i]) / h;
                let bwd = (values[i] - minus[i]) / h;
                if (fwd - bwd).abs() > 1e-3 * (1.0 + fwd.abs()) {
                    continue;
                }
                let tol = 1e-5 * (1.0 + an.abs());
                assert!(
                    (fd - an).abs() < tol,
                    "{} d/dq{}: analytic {an} fd {fd}",
                    set.name(i),
                    j + 1
                );
                *checked.entry(set.kind(i)).or_insert(0usize) += 1;
            }
        }
    }
    for kind in [
        ConstraintKind::Incidence,
        ConstraintKind::SelfCollision,
        ConstraintKind::Obstacle,
        ConstraintKind::HalfSpace,
        ConstraintKind::LineOfSight,
    ] {
        assert!(checked.get(&kind).copied().unwrap_or(0) > 100, "{kind:?}");
    }
    eprintln!("jacobian vs central differences, entries checked per kind: {checked:?}");
}

/// Capsule distances from the FK agree with parry: its closed-form segment–segment
/// distance minus the radii to 1e-9 mm, and its capsule–capsule distance (GJK, iterative,
/// ≈ 1e-7 relative accuracy) to 1e-6 relative.
#[test]
fn capsule_distances_agree_with_parry() {
    use parry3d_f64::math::{Pose, Vector};
    use parry3d_f64::query;
    use parry3d_f64::shape::{Capsule, Segment};
    use rand::SeedableRng;
    let cell = cell();
    let set = ConstraintSet::new(&cell, &ConstraintSettings::default()).unwrap();
    let params = cell.model.nominal();
    let mut ws = set.workspace();
    let mut values = vec![0.0; set.len()];
    let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(2);
    let v = |x: &Vector3<f64>| Vector::new(x[0], x[1], x[2]);
    let id = Pose::identity();
    let (mut compared, mut worst_seg, mut worst_gjk) = (0, 0.0f64, 0.0f64);
    for _ in 0..300 {
        let q = random_q(&set, &mut r);
        set.evaluate(&mut ws, &params, &q, &mut values, None);
        for (row, item) in set.items.iter().enumerate() {
            let (a, b) = match *item {
                Item::Pair { i, j } => (
                    (ws.ends[i], set.capsules[i].radius),
                    (ws.ends[j], set.capsules[j].radius),
                ),
                Item::Obstacle { i, o } => {
                    let ob = &set.obstacles[o];
                    (
                        (ws.ends[i], set.capsules[i].radius),
                        ([ob.a, ob.b], ob.radius),
                    )
                }
                _ => continue,
            };
            let s1 = Segment::new(v(&a.0[0]), v(&a.0[1]));
            let s2 = Segment::new(v(&b.0[0]), v(&b.0[1]));
            let seg = query::distance(&id, &s1, &id, &s2).unwrap().distance - a.1 - b.1;
            let err = (seg - values[row]).abs();
            worst_seg = worst_seg.max(err);
            assert!(
                err < 1e-9,
                "{}: ours {} parry {seg}",
                set.name(row),
                values[row]
            );
            let c1 = Capsule::new(v(&a.0[0]), v(&a.0[1]), a.1);
            let c2 = Capsule::new(v(&b.0[0]), v(&b.0[1]), b.1);
            let d = query::distance(&id, &c1, &id, &c2).unwrap().distance;
            if values[row] > 0.0 {
                let err = (d - values[row]).abs();
                worst_gjk = worst_gjk.max(err / (1.0 + d));
                assert!(
                    err < 1e-6 * (1.0 + d),
                    "{}: ours {} parry {d}",
                    set.name(row),
                    values[row]
                );
                compared += 1;
            } else {
                // parry reports 0 for overlapping capsules.
                assert!(
                    d < 1e-6,
                    "{}: ours {} parry {d}",
                    set.name(row),
                    values[row]
                );
            }
        }
    }
    eprintln!(
        "FK capsules vs parry: segments max |Δ| {worst_seg:.2e} mm, GJK capsules max \
         relative |Δ| {worst_gjk:.2e} ({compared} separated pairs)"
    );
    assert!(compared > 1000);
}

/// `evaluate_rows` gives the same values and Jacobian rows as `evaluate` and leaves the
/// other entries alone; the early-exit `feasible` agrees with the smallest margin.
#[test]
fn row_subsets_and_early_exit_agree_with_the_full_evaluation() {
    let c = cell();
    let set = ConstraintSet::new(&c, &ConstraintSettings::default()).unwrap();
    let params = c.model.nominal();
    let (m, dof) = (set.len(), set.dof());
    let mut ws = set.workspace();
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(11);
    let rows: Vec<usize> = (0..m).filter(|r| r % 3 == 1).collect();
    let (mut feasible, mut infeasible) = (0, 0);
    for _ in 0..300 {
        let q = random_q(&set, &mut rng);
        let (mut v, mut jac) = (vec![0.0; m], vec![0.0; m * dof]);
        set.evaluate(&mut ws, &params, &q, &mut v, Some(&mut jac));
        let (mut vs, mut js) = (vec![7.0; m], vec![7.0; m * dof]);
        set.evaluate_rows(&mut ws, &params, &q, &rows, &mut vs, Some(&mut js));
        for r in 0..m {
            if rows.contains(&r) {
                assert_eq!(vs[r], v[r]);
                assert_eq!(js[r * dof..(r + 1) * dof], jac[r * dof..(r + 1) * dof]);
            } else {
                assert_eq!(vs[r], 7.0);
            }
        }
        let ok = set.feasible(&mut ws, &params, &q);
        assert_eq!(ok, v.iter().all(|x| *x >= 0.0), "{q:?}");
        if ok {
            feasible += 1;
        } else {
            infeasible += 1;
        }
    }
    assert!(feasible > 0 && infeasible > 0, "{feasible} / {infeasible}");
}

#[test]
fn bad_options_are_rejected() {
    let cell = cell();
    let opts = ConstraintSettings {
        beam_radius: -1.0,
        ..Default::default()
    };
    assert!(ConstraintSet::new(&cell, &opts).is_err());
    let opts = ConstraintSettings {
        reflector: Some("nope".into()),
        ..Default::default()
    };
    assert!(ConstraintSet::new(&cell, &opts).is_err());
}

/// Every built-in robot can be planned for with collision avoidance: at least a fifth of
/// random configurations are free of self-collision, and no pair left in the set overlaps at
/// every one of them. The pairs in contact by construction are left out and named (the IRB
/// 120's upper arm and forearm meet at the short elbow link); before they were, 5 of the 10
/// robots had no self-collision-free configuration at all.
#[test]
fn every_builtin_robot_has_self_collision_free_configurations() {
    for (name, _) in crate::robots::list() {
        let text = format!("name = \"{name}\"\n[robot]\nbuiltin = \"{name}\"\n");
        let cell = Cell::from_toml(&text, "cell.toml", Path::new(".")).unwrap();
        let options = ConstraintSettings {
            incidence: false,
            line_of_sight: false,
            ..ConstraintSettings::default()
        };
        let set = ConstraintSet::new(&cell, &options).unwrap();
        let params = cell.model.nominal();
        let mut ws = set.workspace();
        let mut values = vec![0.0; set.len()];
        let draws = crate::model::random_configurations(&cell.model, 500, 11);
        let mut ever_apart = vec![false; set.len()];
        let mut free = 0;
        for q in &draws {
            set.evaluate(&mut ws, &params, q, &mut values, None);
            for (apart, v) in ever_apart.iter_mut().zip(&values) {
                *apart |= *v >= 0.0;
            }
            free += usize::from(values.iter().all(|&v| v >= 0.0));
        }
        assert!(
            5 * free >= draws.len(),
            "{name}: {free} of {} random configurations free of self-collision; in contact \
             everywhere: {:?}",
            draws.len(),
            set.pairs_in_contact()
        );
        for (i, apart) in ever_apart.iter().enumerate() {
            assert!(*apart, "{name}: `{}` overlaps at every draw", set.name(i));
        }
        if name == "irb120" {
            assert_eq!(set.pairs_in_contact(), ["capsule j2#0 / j4#0"]);
        }
    }
}
