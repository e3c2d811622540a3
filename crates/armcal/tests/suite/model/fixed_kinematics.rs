//! Forward kinematics at fixed parameters (`model::fixed_kinematics`, the planner's
//! constraint evaluation) against the full forward kinematics: every frame, target, the
//! instrument and every joint twist and axis point, for every convention (revolute and
//! prismatic), with two instrument stations, and with joint corrections (which take the full
//! pass); alternating parameter vectors, so that every recompilation and the memoised
//! sines and cosines of the full pass are exercised.

use crate::common;
use armcal::model::fixed_kinematics::{fixed_forward_kinematics, FixedKinematics};
use armcal::model::*;
use armcal::Model;
use common::*;
use rand::Rng;

fn assert_same(a: &Data<f64>, b: &Data<f64>, what: &str) {
    let close = |x: f64, y: f64| (x - y).abs() <= 1e-9 * (1.0 + x.abs().max(y.abs()));
    let poses = |p: &Pose<f64>, r: &Pose<f64>, name: String| {
        for (x, y) in p
            .rot
            .iter()
            .chain(p.trans.iter())
            .zip(r.rot.iter().chain(r.trans.iter()))
        {
            assert!(close(*x, *y), "{what}: {name}: {x} vs {y}");
        }
    };
    poses(&a.instrument, &b.instrument, "instrument".into());
    for (i, (p, r)) in a.frames.iter().zip(&b.frames).enumerate() {
        poses(p, r, format!("frame {i}"));
    }
    for (i, (p, r)) in a.targets.iter().zip(&b.targets).enumerate() {
        poses(p, r, format!("target {i}"));
    }
    for (j, (t, u)) in a.joint_twists.iter().zip(&b.joint_twists).enumerate() {
        for (x, y) in
            t.w.iter()
                .chain(t.v.iter())
                .zip(u.w.iter().chain(u.v.iter()))
        {
            assert!(close(*x, *y), "{what}: joint twist {j}: {x} vs {y}");
        }
    }
    for (j, (p, r)) in a.joint_points.iter().zip(&b.joint_points).enumerate() {
        for (x, y) in p.iter().zip(r.iter()) {
            assert!(close(*x, *y), "{what}: joint point {j}: {x} vs {y}");
        }
    }
}

/// Two parameter vectors: the nominal one and every parameter moved by up to 0.05 (mm or
/// rad).
fn two_parameter_vectors(model: &Model, seed: u64) -> [Vec<f64>; 2] {
    let mut r = rng(seed);
    let nominal = model.nominal();
    let moved = nominal
        .iter()
        .map(|p| p + r.random_range(-0.05..0.05))
        .collect();
    [nominal, moved]
}

fn check(model: &Model, seed: u64, what: &str) {
    let params = two_parameter_vectors(model, seed);
    let mut r = rng(seed + 1);
    let mut fixed = FixedKinematics::new(model);
    let mut data = Data::new(model);
    let mut full = Data::new(model);
    for step in 0..12 {
        let p = &params[step % 3 % 2];
        let q = random_q(model, &mut r);
        let station = if model.stations.len() > 1 {
            step % 2
        } else {
            0
        };
        data.station = station;
        full.station = station;
        fixed_forward_kinematics(model, &mut fixed, &mut data, p, &q);
        forward_kinematics(model, &mut full, p, &q);
        assert_same(&data, &full, &format!("{what}, evaluation {step}"));
        // The full pass with its memo agrees with a fresh one.
        let mut fresh = Data::new(model);
        fresh.station = station;
        forward_kinematics(model, &mut fresh, p, &q);
        assert_eq!(
            full.tool().trans,
            fresh.tool().trans,
            "{what}: memoised pass"
        );
        for (a, b) in full.param_twists.iter().zip(&fresh.param_twists) {
            assert_eq!((a.w, a.v), (b.w, b.v), "{what}: memoised parameter twists");
        }
    }
}

#[test]
fn fixed_parameter_kinematics_match_the_full_pass() {
    for seed in 0..4 {
        check(
            &every_convention_model(seed),
            seed,
            &format!("every convention, seed {seed}"),
        );
        let stationed = every_convention_model(seed)
            .with_stations(&["east".to_string(), "west".to_string()])
            .expect("two stations");
        check(&stationed, seed, &format!("two stations, seed {seed}"));
        for (i, model) in derivative_models(seed).iter().enumerate() {
            check(model, seed, &format!("derivative model {i}, seed {seed}"));
        }
    }
}
