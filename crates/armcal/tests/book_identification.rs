use armcal::model::pose::{rot_axis, rotation_log};
use armcal::model::*;
use armcal::robots;
use nalgebra::{DMatrix, DVector, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const IN: f64 = 25.4;

fn ik(m: &Model, params: &[f64], target: &Pose<f64>, seed: &[f64]) -> Option<Vec<f64>> {
    let mut q = seed.to_vec();
    let mut d = Data::new(m);
    for _ in 0..200 {
        forward_kinematics(m, &mut d, params, &q);
        let t = d.tool();
        let ep = target.trans - t.trans;
        let er = rotation_log(&(target.rot * t.rot.transpose()));
        if ep.norm() < 1e-7 && er.norm() < 1e-10 {
            // wrap into limits
            for (v, j) in q.iter_mut().zip(&m.joints) {
                let w = (*v + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI)
                    - std::f64::consts::PI;
                *v = w;
                if *v < j.lower {
                    *v += 2.0 * std::f64::consts::PI;
                }
                if *v > j.upper {
                    *v -= 2.0 * std::f64::consts::PI;
                }
                if *v < j.lower || *v > j.upper {
                    return None;
                }
            }
            return Some(q);
        }
        let j = joint_jacobian(&d, Observed::Tool);
        let s = 1.0 / 100.0; // mm → rad-like
        let mut js = j.clone();
        for c in 0..6 {
            for r in 0..3 {
                js[(r, c)] *= s;
            }
        }
        let e = DVector::from_vec(vec![ep.x * s, ep.y * s, ep.z * s, er.x, er.y, er.z]);
        let a = &js * js.transpose() + DMatrix::identity(6, 6) * 1e-6;
        let dq = js.transpose() * a.cholesky()?.solve(&e);
        let n = dq.norm();
        let f = if n > 0.3 { 0.3 / n } else { 1.0 };
        for k in 0..6 {
            q[k] += dq[k] * f;
        }
    }
    None
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Class {
    right: bool,
    up: bool,
}

/// (class, margins ok)
fn classify(m: &Model, params: &[f64], q: &[f64]) -> (Class, [f64; 3]) {
    let mut d = Data::new(m);
    forward_kinematics(m, &mut d, params, q);
    let u1 = d.frames[0].rot.column(2).into_owned();
    let z1 = d.frames[1].rot.column(2).into_owned();
    let h = z1.cross(&u1);
    let s = d.frames[1].trans;
    let e = d.frames[2].trans - s;
    let w = d.frames[4].trans - s;
    let (wx, wy, ex, ey) = (w.dot(&h), w.dot(&u1), e.dot(&h), e.dot(&u1));
    let cross = wx * ey - wy * ex;
    let fx = wx - ex;
    let fy = wy - ey;
    let elbow_sin =
        (ex * fy - ey * fx).abs() / ((ex * ex + ey * ey).sqrt() * (fx * fx + fy * fy).sqrt());
    let z4 = d.frames[3].rot.column(2).into_owned();
    let z6 = d.frames[5].rot.column(2).into_owned();
    let wrist_sin = z4.cross(&z6).norm();
    (
        Class {
            right: wx < 0.0,
            up: cross * wx.signum() > 0.0,
        },
        [wx.abs() / IN, elbow_sin, wrist_sin],
    )
}

fn random_rot(r: &mut ChaCha8Rng) -> nalgebra::Matrix3<f64> {
    let q = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
        r.random_range(-1.0..1.0f64),
        r.random_range(-1.0..1.0),
        r.random_range(-1.0..1.0),
        r.random_range(-1.0..1.0),
    ));
    *q.to_rotation_matrix().matrix()
}

fn random_q(m: &Model, r: &mut ChaCha8Rng) -> Vec<f64> {
    m.joints
        .iter()
        .map(|j| r.random_range(j.lower..j.upper))
        .collect()
}

fn solve_class(
    m: &Model,
    p: &[f64],
    pos: Vector3<f64>,
    want: Class,
    r: &mut ChaCha8Rng,
) -> Option<Vec<f64>> {
    for _ in 0..20 {
        let target = Pose {
            rot: random_rot(r),
            trans: pos,
        };
        for _ in 0..30 {
            let seed = random_q(m, r);
            if let Some(q) = ik(m, p, &target, &seed) {
                let (c, mg) = classify(m, p, &q);
                if c == want && mg[0] > 4.0 && mg[1] > 0.34 && mg[2] > 0.34 {
                    return Some(q);
                }
            }
        }
    }
    None
}

#[test]
fn explore() {
    let spec = robots::robot("puma560").unwrap().spec;
    let m = Model::from_spec(&spec).unwrap();
    let p = m.nominal();
    let _ = rot_axis(&Vector3::x(), 0.0);
    let axis1 = Vector3::new(-15.591, 14.681, 32.878);
    let dir = Vector3::new(15.591, 0.0, -32.878).normalize();
    for seed in [1, 2, 3] {
        let mut r = ChaCha8Rng::seed_from_u64(seed);
        for (rr, dy, sp) in [
            (24.0, 9.0, 6.0),
            (24.0, 8.0, 6.0),
            (22.0, 10.0, 6.0),
            (24.0, 9.0, 8.0),
        ] {
            let c = axis1 + dir * rr + Vector3::y() * dy;
            let mut ok = 0;
            for i in 0..3 {
                for j in 0..2 {
                    for k in 0..2 {
                        let pos = (c + Vector3::new(
                            sp * (i as f64 - 1.0),
                            sp * (j as f64 - 0.5),
                            sp * (k as f64 - 0.5),
                        )) * IN;
                        for right in [false, true] {
                            for up in [false, true] {
                                if solve_class(&m, &p, pos, Class { right, up }, &mut r).is_some() {
                                    ok += 1;
                                }
                            }
                        }
                    }
                }
            }
            eprintln!(
                "seed {seed} r {rr} dy {dy} sp {sp}: center {:.1?} {ok}/48",
                c.as_slice()
            );
        }
    }
}
