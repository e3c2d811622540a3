//! Circle point analysis on simulated sweeps: exact and noisy axes, the rebuilt models,
//! planned sweeps and the trust warnings.

use super::*;
use crate::geometry::fit::principal_axes;
use crate::geometry::fit::tests::noisy_arc;
use crate::model::kinematics::{forward_kinematics, tool_pose, Data};
use crate::robots;
use crate::sim::{perturbed_truth, Perturbation};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// The paper robot with a point target 300 mm off the flange and off axis 6.
fn paper_with_target() -> Model {
    let mut spec = robots::robot("paper").unwrap().spec;
    spec.targets.push(LinkSpec {
        name: "smr".into(),
        geometry: LinkGeometry::point([120.0, -80.0, 300.0]),
        joint: None,
    });
    Model::from_spec(&spec).unwrap()
}

/// Sweeps every joint over ±`half_span` (deg, clamped to its limits) in 15 steps, others
/// at 0.
fn sweeps(model: &Model, truth: &[f64], half_span: f64, sigma: f64, seed: u64) -> Vec<JointSweep> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let normal = Normal::new(0.0, 1.0).unwrap();
    let mut data = Data::<f64>::new(model);
    let (lo, hi) = model.joint_limits();
    (0..model.dof())
        .map(|j| {
            let a = lo[j].max(-half_span.to_radians());
            let b = hi[j].min(half_span.to_radians());
            let mut s = JointSweep {
                joint: j,
                q: vec![],
                points: vec![],
            };
            for i in 0..15 {
                let mut q = vec![0.0; model.dof()];
                q[j] = a + (b - a) * i as f64 / 14.0;
                forward_kinematics(model, &mut data, truth, &q);
                let noise = Vector3::from_fn(|_, _| sigma * normal.sample(&mut rng));
                s.points.push(data.targets[0].trans + noise);
                s.q.push(q);
            }
            s
        })
        .collect()
}

/// True axes at q = 0: direction `w`, point `w × v / |w|²`.
fn true_axes(model: &Model, truth: &[f64]) -> Vec<(Vector3<f64>, Vector3<f64>)> {
    let mut data = Data::<f64>::new(model);
    forward_kinematics(model, &mut data, truth, &vec![0.0; model.dof()]);
    data.joint_twists
        .iter()
        .map(|t| {
            let n2 = t.w.norm_squared();
            (t.w / n2.sqrt(), t.w.cross(&t.v) / n2)
        })
        .collect()
}

/// (angle between directions, distance of the fitted point from the true line).
fn axis_errors(a: &JointAxis, t: &(Vector3<f64>, Vector3<f64>)) -> (f64, f64) {
    let angle = a.direction.cross(&t.0).norm().atan2(a.direction.dot(&t.0));
    let dist = (a.point - t.1).cross(&t.0).norm();
    (angle, dist)
}

fn target_at_zero(model: &Model, truth: &[f64]) -> Pose<f64> {
    let mut data = Data::<f64>::new(model);
    forward_kinematics(model, &mut data, truth, &vec![0.0; model.dof()]);
    data.targets[0]
}

/// Largest FK difference (mm; rotation matrices, Frobenius ≈ √2 × angle) between `spec`'s tool and the truth's target.
fn fk_error(model: &Model, truth: &[f64], spec: &ModelSpec) -> (f64, f64) {
    let m = Model::from_spec(spec).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let (lo, hi) = model.joint_limits();
    let mut data = Data::<f64>::new(model);
    let (mut dp, mut dr) = (0.0f64, 0.0f64);
    for _ in 0..50 {
        let q: Vec<f64> = (0..model.dof())
            .map(|j| rng.random_range(lo[j]..=hi[j]))
            .collect();
        forward_kinematics(model, &mut data, truth, &q);
        let t = data.targets[0];
        let p = tool_pose(&m, &m.nominal(), &q);
        dp = dp.max((p.trans - t.trans).norm());
        // Frobenius norm: `rotation_angle_to` (an arccos) bottoms out near 1e-8.
        dr = dr.max((p.rot - t.rot).norm());
    }
    (dp, dr)
}

fn truth(model: &Model) -> Vec<f64> {
    let p = Perturbation {
        all: true,
        ..Default::default()
    };
    perturbed_truth(model, &p, 11)
}

#[test]
fn noise_free_axes_are_exact_and_rebuild_the_robot() {
    let model = paper_with_target();
    let truth = truth(&model);
    let result = identify_axes(&model, &sweeps(&model, &truth, 30.0, 0.0, 1)).unwrap();
    let t = true_axes(&model, &truth);
    for (a, t) in result.axes.iter().zip(&t) {
        let (angle, dist) = axis_errors(a, t);
        eprintln!(
            "noise-free {}: angle {angle:.2e} rad, distance {dist:.2e} mm, r {:.1} mm, rms {:.1e}",
            a.link, a.radius, a.rms
        );
        assert!(angle < 1e-9 && dist < 1e-9, "{}: {angle} {dist}", a.link);
    }
    let tool = target_at_zero(&model, &truth);
    let zrp = axes_to_zrp(&result, &tool).unwrap();
    let (dp, dr) = fk_error(&model, &truth, &zrp);
    eprintln!("noise-free ZRP FK error: {dp:.2e} mm, {dr:.2e} rad");
    assert!(dp < 1e-6 && dr < 1e-9, "{dp} {dr}");
    let nominal = robots::robot("paper").unwrap().spec;
    let dh = axes_to_dh(&result, &tool, Some(&nominal)).unwrap();
    let (dp, dr) = fk_error(&model, &truth, &dh);
    eprintln!("noise-free DH FK error: {dp:.2e} mm, {dr:.2e} rad");
    assert!(dp < 1e-6 && dr < 1e-9, "{dp} {dr}");
    let sm = axes_to_s_model(&result, &tool).unwrap();
    let (dp, dr) = fk_error(&model, &truth, &sm);
    eprintln!("noise-free S-model FK error: {dp:.2e} mm, {dr:.2e} rad");
    assert!(dp < 1e-6 && dr < 1e-9, "{dp} {dr}");
}

/// Linearised precision of a circle fit with n points of noise σ per coordinate on an
/// arc: the plane tilts about the chord by ≈ σ/s₂ and the centre moves along the arc's
/// bisector by ≈ σ r/s₂, where s₂ = √n × (RMS in-plane spread of the points across the
/// chord) is the second singular value of the centred points (the centre and radius
/// columns of the geometric Jacobian differ only by that spread). For ±30°, 15 points,
/// r = 300 mm: s₂ ≈ 45 mm, σ = 0.01 → 2e-4 rad, 0.07 mm. The test allows 5 of these
/// (and √2 for the distance, which has a tilt and an in-plane part).
#[test]
fn noisy_axes_are_within_their_precision() {
    let model = paper_with_target();
    let truth = truth(&model);
    let sigma = 0.01;
    let sw = sweeps(&model, &truth, 30.0, sigma, 2);
    let result = identify_axes(&model, &sw).unwrap();
    let t = true_axes(&model, &truth);
    for ((a, t), s) in result.axes.iter().zip(&t).zip(&sw) {
        let (_, _, sv) = principal_axes(&s.points);
        let (angle, dist) = axis_errors(a, t);
        let angle_bound = 5.0 * sigma / sv[1];
        let dist_bound = 5.0 * 2f64.sqrt() * sigma * a.radius / sv[1];
        eprintln!(
            "σ = {sigma} mm {}: angle {angle:.2e} rad (bound {angle_bound:.2e}), distance \
             {dist:.2e} mm (bound {dist_bound:.2e}), rms {:.2e} mm",
            a.link, a.rms
        );
        assert!(angle < angle_bound, "{}: angle {angle}", a.link);
        assert!(dist < dist_bound, "{}: distance {dist}", a.link);
        assert!(a.rms < 3.0 * sigma, "{}: rms {}", a.link, a.rms);
    }
    let tool = target_at_zero(&model, &truth);
    let nominal = robots::robot("paper").unwrap().spec;
    for (what, spec) in [
        ("ZRP", axes_to_zrp(&result, &tool).unwrap()),
        ("DH", axes_to_dh(&result, &tool, Some(&nominal)).unwrap()),
        ("S-model", axes_to_s_model(&result, &tool).unwrap()),
    ] {
        let (dp, dr) = fk_error(&model, &truth, &spec);
        eprintln!("σ = {sigma} mm {what} FK error (exact tool at 0): {dp:.3} mm, {dr:.2e}");
    }
}

#[test]
fn suggested_span_reaches_the_limits() {
    let (r, n, sigma) = (300.0, 13, 1.0);
    let span = span_for_limits(r, n, sigma).unwrap();
    // The warning's sweep, made with the same noise: the RMS errors of the axes fitted
    // to it meet the tighter of the two limits.
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    let (_, c, normal) = noisy_arc(r, span, n, 0.0, &mut rng);
    let (mut angle2, mut dist2) = (0.0, 0.0);
    let runs = 300;
    for _ in 0..runs {
        let f = fit_circle(&noisy_arc(r, span, n, sigma, &mut rng).0).unwrap();
        angle2 += f.normal.angle(&normal).powi(2);
        dist2 += (f.centre - c).cross(&normal).norm_squared();
    }
    let k_dir = (angle2 / runs as f64).sqrt().to_degrees() / MAX_SIGMA_DIRECTION_DEG;
    let k_point = (dist2 / runs as f64).sqrt() / MAX_SIGMA_POINT_MM;
    eprintln!(
        "r {r} mm, {n} points, σ {sigma} mm: sweep {:.1}° gives σ direction {k_dir:.3} and σ \
         point {k_point:.3} × their limits (Monte Carlo)",
        span.to_degrees()
    );
    assert!(
        (0.85..1.1).contains(&k_dir.max(k_point)),
        "{k_dir} {k_point}"
    );
    // Shorter sweeps do not reach them; a full turn at 50 mm noise does not either.
    let planned = planned_circle_covariance(r, n, 0.95 * span, sigma).unwrap();
    assert!(
        planned.sigma_direction().to_degrees() > MAX_SIGMA_DIRECTION_DEG
            || planned.sigma_point() > MAX_SIGMA_POINT_MM
    );
    assert!(span_for_limits(r, n, 50.0).is_none());
}

#[test]
fn untrustworthy_axes_are_warned_about() {
    let model = paper_with_target();
    let truth = truth(&model);
    // A long clean sweep: every axis trusted, with small σ's.
    let clean = identify_axes(&model, &sweeps(&model, &truth, 60.0, 0.01, 3)).unwrap();
    for a in &clean.axes {
        let cov = a.covariance.as_ref().unwrap();
        eprintln!(
            "±60°, σ 0.01 mm {}: σ direction {:.4}°, σ point {:.4} mm, σ̂ {:.4} mm",
            a.link,
            cov.sigma_direction().to_degrees(),
            cov.sigma_point(),
            cov.sigma_noise
        );
        assert!(a.warning.is_none(), "{:?}", a.warning);
    }
    assert_eq!(clean.warnings().count(), 0);
    // σ = 1 mm on ±12°: every axis warned about, with its numbers and remedies.
    let noisy = identify_axes(&model, &sweeps(&model, &truth, 12.0, 1.0, 3)).unwrap();
    let t = true_axes(&model, &truth);
    for (a, t) in noisy.axes.iter().zip(&t) {
        let w = a.warning.as_deref().expect("a warning");
        eprintln!("{w}");
        let cov = a.covariance.as_ref().unwrap();
        let sd = cov.sigma_direction().to_degrees();
        assert!(sd > MAX_SIGMA_DIRECTION_DEG, "{}: {sd}", a.link);
        assert!(w.starts_with(&a.joint.name), "{w}");
        for needle in [
            "over 24.0°",
            &format!("σ direction {sd:.3}°"),
            "shorter than 30°",
            "a sweep of ",
            "° with as many points",
            "points (σ ∝ 1/√n)",
        ] {
            assert!(w.contains(needle), "{needle}: {w}");
        }
        // The σ's say how far off the axis is: the actual error is within 4 σ.
        let (angle, dist) = axis_errors(a, t);
        assert!(angle < 4.0 * cov.sigma_direction(), "{}: {angle}", a.link);
        assert!(dist < 4.0 * cov.sigma_point(), "{}: {dist}", a.link);
    }
    // Three points: an exact fit, no σ, a warning asking for more points.
    let mut few = sweeps(&model, &truth, 30.0, 0.01, 3);
    for s in &mut few {
        s.q.truncate(3);
        s.points.truncate(3);
    }
    let r = identify_axes(&model, &few).unwrap();
    let w = r.axes[0].warning.as_deref().unwrap();
    assert!(r.axes[0].covariance.is_none());
    assert!(
        w.contains("fit a circle exactly") && w.contains("at least 7 points"),
        "{w}"
    );
}

#[test]
fn prismatic_axis_and_zero_reference_check() {
    let spec = ModelSpec {
        compliance: None,
        periodic: None,
        payloads: Vec::new(),
        name: "rp".into(),
        instrument: None,
        links: vec![
            LinkSpec {
                name: "base".into(),
                geometry: LinkGeometry::frame6([0.0; 3], [0.0; 3]),
                joint: None,
            },
            LinkSpec {
                name: "j1".into(),
                geometry: LinkGeometry::zrp([0.1, 0.0, 1.0], [10.0, 20.0, 0.0], 0.0),
                joint: Some(Joint {
                    name: "q1".into(),
                    kind: JointKind::Revolute,
                    lower: -3.0,
                    upper: 3.0,
                }),
            },
            LinkSpec {
                name: "j2".into(),
                geometry: LinkGeometry::zrp([1.0, 0.2, 0.1], [0.0; 3], 0.0),
                joint: Some(Joint {
                    name: "d2".into(),
                    kind: JointKind::Prismatic,
                    lower: -500.0,
                    upper: 500.0,
                }),
            },
            LinkSpec {
                name: "tool".into(),
                geometry: LinkGeometry::frame6([300.0, 50.0, 40.0], [0.1, 0.2, 0.3]),
                joint: None,
            },
        ],
        targets: vec![],
    };
    let model = Model::from_spec(&spec).unwrap();
    let params = model.nominal();
    let sweep = |j: usize, vals: &[f64], other: f64| {
        let q: Vec<Vec<f64>> = vals
            .iter()
            .map(|&v| {
                let mut q = vec![other; 2];
                q[j] = v;
                q
            })
            .collect();
        let points = q
            .iter()
            .map(|q| tool_pose(&model, &params, q).trans)
            .collect();
        JointSweep {
            joint: j,
            q,
            points,
        }
    };
    // Joint values out of order: the sign comes from the joint values, not the order.
    let sw = vec![
        sweep(0, &[0.2, -0.3, 0.0, 0.4], 0.0),
        sweep(1, &[50.0, -20.0, 10.0], 0.0),
    ];
    let r = identify_axes(&model, &sw).unwrap();
    let t = true_axes(&model, &params);
    assert!(axis_errors(&r.axes[0], &t[0]).0 < 1e-12);
    assert!(axis_errors(&r.axes[0], &t[0]).1 < 1e-9);
    let d = r.axes[1].direction;
    assert!((d - Vector3::new(1.0, 0.2, 0.1).normalize()).norm() < 1e-12);
    let zrp = axes_to_zrp(&r, &tool_pose(&model, &params, &[0.0, 0.0])).unwrap();
    let m = Model::from_spec(&zrp).unwrap();
    let s = Model::from_spec(&axes_to_s_model(&r, &tool_pose(&model, &params, &[0.0; 2])).unwrap())
        .unwrap();
    for q in [[0.5, 100.0], [-1.0, -30.0]] {
        let a = tool_pose(&m, &m.nominal(), &q);
        let b = tool_pose(&model, &params, &q);
        assert!((a.trans - b.trans).norm() < 1e-9);
        let c = tool_pose(&s, &s.nominal(), &q);
        assert!((c.trans - b.trans).norm() < 1e-9 && (c.rot - b.rot).norm() < 1e-12);
    }
    // Swept with the other joint away from zero: axes come out, a ZRP build refuses.
    let sw = vec![
        sweep(0, &[0.2, -0.3, 0.0], 0.0),
        sweep(1, &[50.0, -20.0, 10.0], 0.5),
    ];
    let r = identify_axes(&model, &sw).unwrap();
    assert!(axes_to_zrp(&r, &Pose::identity()).is_err());
    assert!(axes_to_s_model(&r, &Pose::identity()).is_err());
    // Another joint moving within a sweep, a missing joint.
    let mut bad = sweep(0, &[0.2, -0.3, 0.0], 0.0);
    bad.q[1][1] = 1.0;
    assert!(identify_axes(&model, &[bad, sweep(1, &[1.0, 2.0], 0.0)]).is_err());
    assert!(identify_axes(&model, &[sweep(1, &[1.0, 2.0], 0.0)]).is_err());
}
