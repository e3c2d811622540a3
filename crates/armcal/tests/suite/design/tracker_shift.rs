//! The worst tracker displacement (issue 30 item 2) is exact: on the obstacle cell (car body,
//! roof and mount beam in the beam's way) with the tracker moved 50 mm, and on the same cell
//! with the tracker brought to 1.8 m of the robot, no displacement of 1 000 spread over the
//! sphere and its inside gives any incidence or line-of-sight constraint a smaller value than
//! `evaluate_shifted`, and the best of them comes within the sampling's resolution of it. The
//! beam's part, the distance of a segment to the hull of a point and a ball, is checked
//! against its definition on random geometry.

use crate::common::example_cell;
use armcal::design::ConstraintKind;
use armcal::design::{ConstraintSet, ConstraintSettings};
use armcal::geometry::{point_segment_distance, segment_cone_distance, segment_distance};
use armcal::measure::csv::read_configurations;
use armcal::model::{forward_kinematics, Data};
use armcal::Cell;
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;

/// `n` directions spread over the unit sphere (a Fibonacci lattice).
fn sphere(n: usize) -> Vec<Vector3<f64>> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|k| {
            let z = 1.0 - 2.0 * (k as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let phi = golden * k as f64;
            Vector3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

fn check(cell: &Cell, shift: f64) {
    let model = &cell.model;
    let poses = read_configurations(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper-poses-planned-60.csv"),
        model,
        None,
    )
    .unwrap();
    let set = ConstraintSet::new(cell, &ConstraintSettings::default()).unwrap();
    assert!(
        set.count(ConstraintKind::LineOfSight) > 0 && set.count(ConstraintKind::Incidence) == 1
    );
    let nominal = model.nominal();
    let xyz: Vec<usize> = ["tracker.x", "tracker.y", "tracker.z"]
        .iter()
        .map(|n| model.registry.index_of(n).unwrap())
        .collect();
    let mut data = Data::new(model);
    forward_kinematics(model, &mut data, &nominal, &poses[0].1);
    let origin = data.instrument.trans;
    // Offsets: 800 on the sphere, 200 inside it.
    let offsets: Vec<Vector3<f64>> = sphere(800)
        .into_iter()
        .map(|d| d * shift)
        .chain(
            sphere(200)
                .into_iter()
                .enumerate()
                .map(|(k, d)| d * shift * (k as f64 / 200.0)),
        )
        .collect();
    let moved: Vec<Vec<f64>> = offsets
        .iter()
        .map(|d| {
            let mut p = nominal.clone();
            for (a, &i) in xyz.iter().enumerate() {
                p[i] += d[a];
            }
            // The tracker's parameters x, y, z are its origin in the world.
            forward_kinematics(model, &mut data, &p, &poses[0].1);
            assert!((data.instrument.trans - origin - d).norm() < 1e-9);
            p
        })
        .collect();
    let mut ws = set.workspace();
    let (mut exact, mut values) = (vec![0.0; set.len()], vec![0.0; set.len()]);
    let mut sampled = vec![0.0; set.len()];
    let mut attained = 0;
    for (_, q) in poses.iter().take(30) {
        set.evaluate_shifted(&mut ws, &nominal, q, shift, &mut exact);
        sampled.fill(f64::INFINITY);
        for p in &moved {
            set.evaluate(&mut ws, p, q, &mut values, None);
            for (s, v) in sampled.iter_mut().zip(&values) {
                *s = s.min(*v);
            }
        }
        for i in 0..set.len() {
            let (e, s) = (exact[i], sampled[i]);
            match set.kind(i) {
                // cos β − cos β_max: 800 directions resolve the worst to about 1e-4.
                ConstraintKind::Incidence => {
                    assert!(
                        s >= e - 1e-12 && s - e < 2e-4,
                        "{}: {s} vs {e}",
                        set.name(i)
                    );
                    attained += 1;
                }
                // mm: a beam point moves at most `shift` (the sampling misses < 1.5 mm).
                ConstraintKind::LineOfSight => {
                    assert!(s >= e - 1e-9 && s - e < 1.5, "{}: {s} vs {e}", set.name(i));
                    attained += 1;
                }
                // The robot's own constraints do not move with the tracker.
                _ => assert!((s - e).abs() < 1e-9, "{}: {s} vs {e}", set.name(i)),
            }
        }
    }
    assert!(attained > 30);
}

#[test]
fn the_worst_tracker_displacement_is_exact() {
    let cell = example_cell("paper-cell-obstacles.toml");
    check(&cell, 50.0);
    // The tracker 1.8 m from the base, beside the car: the beam passes the robot at larger
    // fractions of its length, where a displacement moves it more.
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper-cell-obstacles.toml"),
    )
    .unwrap()
    .replace(
        "xyz_mm = [2730.88, 4554.68, 1397.67]",
        "xyz_mm = [900.0, 1700.0, 1200.0]",
    );
    let near = Cell::from_toml(&text, "near.toml", Path::new(".")).unwrap();
    check(&near, 80.0);
}

fn random_point(rng: &mut ChaCha8Rng, scale: f64) -> Vector3<f64> {
    Vector3::new(
        rng.random_range(-scale..scale),
        rng.random_range(-scale..scale),
        rng.random_range(-scale..scale),
    )
}

/// Against the definition: no beam `p → t + δ` with `|δ| ≤ D` comes closer to the segment
/// than the cone distance (600 random offsets, inside and on the sphere), and the offset
/// built from the minimiser attains it (so the value is exact, not a bound).
#[test]
fn no_shifted_beam_comes_closer_and_the_worst_one_attains_it() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for case in 0..200 {
        let p = random_point(&mut rng, 500.0);
        let t = p + random_point(&mut rng, 3000.0);
        let (a0, a1) = (
            random_point(&mut rng, 1500.0),
            random_point(&mut rng, 1500.0),
        );
        let radius = rng.random_range(0.0..200.0);
        let (d, s) = segment_cone_distance(&p, &t, radius, &a0, &a1);
        for k in 0..600 {
            let dir = random_point(&mut rng, 1.0).normalize();
            let len = if k % 2 == 0 {
                radius
            } else {
                radius * rng.random::<f64>()
            };
            let beam = segment_distance(&p, &(t + dir * len), &a0, &a1).distance;
            assert!(beam >= d - 1e-9, "case {case}: a beam at {beam} < {d}");
        }
        if d > 1e-6 {
            let c = p + (t - p) * s;
            let (_, u) = point_segment_distance(&c, &a0, &a1);
            let x = a0 + (a1 - a0) * u;
            let worst = t + (x - c).normalize() * radius;
            let beam = segment_distance(&p, &worst, &a0, &a1).distance;
            assert!(
                (beam - d).abs() < 1e-6,
                "case {case}: worst beam {beam} vs {d}"
            );
        }
    }
}

/// Without a ball the cone is the segment `pt`: the segment–segment distance.
#[test]
fn without_a_ball_it_is_the_segment_distance() {
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    for _ in 0..200 {
        let (p, t) = (
            random_point(&mut rng, 1000.0),
            random_point(&mut rng, 1000.0),
        );
        let (a0, a1) = (
            random_point(&mut rng, 1000.0),
            random_point(&mut rng, 1000.0),
        );
        let (d, _) = segment_cone_distance(&p, &t, 0.0, &a0, &a1);
        let exact = segment_distance(&p, &t, &a0, &a1).distance;
        assert!((d - exact).abs() < 1e-7 * (1.0 + exact), "{d} vs {exact}");
    }
}
