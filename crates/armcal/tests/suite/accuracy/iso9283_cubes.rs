//! ISO 9283 on simulated test cubes: known bias and scatter in position and orientation,
//! the figures checked against a computation written here (ISO 9283 §7.2–7.3 from the
//! attained world poses this test made), the grouping of repeated approaches (rows
//! shuffled, no pose ids, near-duplicate poses of different corners), and bad input.

use armcal::measure::{Covariates, Measurement, MeasurementKind};
use armcal::model::{rot_axis, rotation_log};
use armcal::model::{tool_pose, Observed, Pose};
use armcal::{
    accuracy_report, commanded_poses, AccuracyOrientation, Cell, Dataset, Model, SamePose,
};
use nalgebra::{Matrix3, Vector3};
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;

fn cell() -> Cell {
    Cell::from_file(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/ur10-leica-cell.toml"),
    )
    .unwrap()
}

/// The tracker somewhere in the cell (mm, deg), so that the world frame is not the
/// instrument's.
fn params(model: &Model) -> Vec<f64> {
    let mut p = model.nominal();
    for (name, v) in [
        ("tracker.x", 2500.0),
        ("tracker.y", -900.0),
        ("tracker.z", 300.0),
        ("tracker.rz", 101f64.to_radians()),
        ("tracker.rx", 0.3f64.to_radians()),
    ] {
        p[model.registry.index_of(name).unwrap()] = v;
    }
    p
}

fn exp(v: &Vector3<f64>) -> Matrix3<f64> {
    let a = v.norm();
    if a == 0.0 {
        Matrix3::identity()
    } else {
        rot_axis(&(v / a), a)
    }
}

/// A test cube in joint space: a centre and 8 corners, the corners' joints ±0.15 rad from
/// the centre's on joints 1–3 (a few hundred millimetres apart).
fn cube() -> Vec<Vec<f64>> {
    let centre = [0.9, -1.8, 1.5, 0.27, 0.93, -1.57];
    let mut poses = vec![centre.to_vec()];
    for k in 0..8 {
        let mut q = centre.to_vec();
        for (j, v) in q.iter_mut().enumerate().take(3) {
            *v += if k >> j & 1 == 1 { 0.15 } else { -0.15 };
        }
        poses.push(q);
    }
    poses
}

/// One approach: the attained world pose and its measurement in the tracker frame.
struct Approach {
    config: Vec<f64>,
    pose: usize,
    attained: Pose<f64>,
}

/// `cycles` approaches of every pose at the commanded joints exactly, attained at the
/// nominal pose moved by `bias` (mm) and turned by `tilt` (rad, world frame), with uniform
/// scatter of ±`scatter` mm and ±`scatter_rad` per axis.
fn approaches(
    model: &Model,
    poses: &[Vec<f64>],
    cycles: usize,
    bias: Vector3<f64>,
    tilt: Vector3<f64>,
    (scatter, scatter_rad): (f64, f64),
    rng: &mut ChaCha8Rng,
) -> Vec<Approach> {
    let nominal = model.nominal();
    let mut out = Vec::new();
    for _ in 0..cycles {
        for (k, q) in poses.iter().enumerate() {
            let c = tool_pose(model, &nominal, q);
            let mut u = |s: f64| Vector3::from_fn(|_, _| rng.random_range(-s..s));
            let (dp, dr) = (u(scatter), u(scatter_rad));
            out.push(Approach {
                config: q.clone(),
                pose: k,
                attained: Pose {
                    rot: exp(&(tilt + dr)) * c.rot,
                    trans: c.trans + bias + dp,
                },
            });
        }
    }
    out
}

/// The data set of the approaches, in the given order, with a pose measurement (or only
/// the position) in the tracker frame.
fn dataset(model: &Model, params: &[f64], a: &[&Approach], pose: bool) -> Dataset {
    let mut fk = armcal::model::Data::new(model);
    armcal::model::forward_kinematics(model, &mut fk, params, &a[0].config);
    let tracker = fk.instrument;
    let mut data = Dataset {
        source: "simulated cubes".into(),
        ..Default::default()
    };
    for (i, x) in a.iter().enumerate() {
        let c = data.push_configuration(String::new(), x.config.clone());
        let value = tracker.inverse().compose(&x.attained);
        let kind = if pose {
            MeasurementKind::Pose { value, sigma: None }
        } else {
            MeasurementKind::Position {
                value: value.trans,
                sigma: None,
            }
        };
        data.measurements.push(Measurement {
            config: c,
            observed: Observed::Tool,
            kind,
            line: i + 2,
            covariates: Covariates::default(),
        });
    }
    data
}

/// Sample standard deviation with n − 1.
fn std(v: &[f64]) -> f64 {
    let m = v.iter().sum::<f64>() / v.len() as f64;
    (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() as f64 - 1.0)).sqrt()
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

#[test]
fn cube_figures_are_iso_9283_of_the_attained_poses() {
    let cell = cell();
    let model = &cell.model;
    let p = params(model);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let poses = cube();
    let (bias, tilt) = (
        Vector3::new(0.3, -0.2, 0.1),
        Vector3::new(0.02, -0.01, 0.03).map(f64::to_radians),
    );
    let (scatter, scatter_rad) = (0.03, 0.005f64.to_radians());
    let mut all = approaches(
        model,
        &poses,
        30,
        bias,
        tilt,
        (scatter, scatter_rad),
        &mut rng,
    );
    all.shuffle(&mut rng);
    let refs: Vec<&Approach> = all.iter().collect();
    let data = dataset(model, &p, &refs, true);
    let found = commanded_poses(
        model,
        &data.configurations,
        &data.config_ids,
        &SamePose::default(),
    );
    assert_eq!(found.summary.poses, 9);
    assert_eq!(found.summary.approaches, vec![[30, 9]]);
    let rep = accuracy_report(model, &p, &data, &found, AccuracyOrientation::Required).unwrap();
    assert_eq!(rep.summary.iso_cycles, 9);
    let nominal = model.nominal();
    for fig in &rep.poses {
        // The pose of this entry: the one commanded where the entry says (no ids to go by).
        let command = Vector3::from(fig.command_mm);
        let pose = (0..poses.len())
            .find(|&k| (tool_pose(model, &nominal, &poses[k]).trans - command).norm() < 1e-9)
            .expect("the command is a pose's nominal position");
        let mine: Vec<&Approach> = all.iter().filter(|a| a.pose == pose).collect();
        let c = tool_pose(model, &nominal, &mine[0].config);
        // §7.2.1: AP_x = x̄ − x_c …, AP_P = √(AP_x² + AP_y² + AP_z²).
        let d: Vec<Vector3<f64>> = mine.iter().map(|a| a.attained.trans - c.trans).collect();
        let ap: Vec<f64> = (0..3)
            .map(|i| mean(&d.iter().map(|v| v[i]).collect::<Vec<_>>()))
            .collect();
        let a = &fig.accuracy;
        for (got, want) in [a.apx, a.apy, a.apz].iter().zip(&ap) {
            assert!((got - want).abs() < 1e-9, "{got} vs {want}");
        }
        assert!((a.ap - (ap[0] * ap[0] + ap[1] * ap[1] + ap[2] * ap[2]).sqrt()).abs() < 1e-9);
        // The known bias, within the scatter's standard error.
        assert!(
            (a.ap - bias.norm()).abs() < 0.02,
            "AP_P {} vs bias {}",
            a.ap,
            bias.norm()
        );
        // §7.3.1: l_j = |x_j − x̄|, RP_l = l̄ + 3 S_l.
        let bary = mine
            .iter()
            .fold(Vector3::zeros(), |s, a| s + a.attained.trans)
            / 30.0;
        let l: Vec<f64> = mine
            .iter()
            .map(|a| (a.attained.trans - bary).norm())
            .collect();
        let r = fig.repeatability.as_ref().unwrap();
        assert!((r.rp - (mean(&l) + 3.0 * std(&l))).abs() < 1e-9 && r.n == 30);
        // §7.2.2 / §7.3.2 on the deviation angles about the world axes.
        let dev: Vec<Vector3<f64>> = mine
            .iter()
            .map(|a| rotation_log(&(a.attained.rot * c.rot.transpose())))
            .collect();
        let o = fig.orientation.as_ref().unwrap();
        let ro = o.repeatability.as_ref().unwrap();
        for (i, (apx, rpx)) in [
            (o.accuracy.apa_deg, ro.rpa_deg),
            (o.accuracy.apb_deg, ro.rpb_deg),
            (o.accuracy.apc_deg, ro.rpc_deg),
        ]
        .into_iter()
        .enumerate()
        {
            let v: Vec<f64> = dev.iter().map(|d| d[i].to_degrees()).collect();
            assert!((apx - mean(&v)).abs() < 1e-9 && (rpx - 3.0 * std(&v)).abs() < 1e-9);
            assert!(
                (apx - tilt[i].to_degrees()).abs() < 0.002,
                "{apx} vs {}",
                tilt[i].to_degrees()
            );
        }
    }
}

#[test]
fn repeated_approaches_are_found_in_any_order_and_close_corners_kept_apart() {
    let cell = cell();
    let model = &cell.model;
    let p = params(model);
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    // The cube, and a second cube whose corners are 1 mm from the first's (joint 1 turned by
    // 1 mm at the tool's radius), approached 5 times each with joint jitter of ±1e-5 rad.
    let mut poses = cube();
    let radius = tool_pose(model, &model.nominal(), &poses[0])
        .trans
        .xy()
        .norm();
    let shifted: Vec<Vec<f64>> = cube()
        .into_iter()
        .map(|mut q| {
            q[0] += 1.0 / radius;
            q
        })
        .collect();
    poses.extend(shifted);
    let mut all = approaches(
        model,
        &poses,
        5,
        Vector3::zeros(),
        Vector3::zeros(),
        (0.01, 1e-5),
        &mut rng,
    );
    for a in &mut all {
        for v in &mut a.config {
            *v += rng.random_range(-1e-5..1e-5);
        }
    }
    for round in 0..5 {
        all.shuffle(&mut rng);
        let refs: Vec<&Approach> = all.iter().collect();
        let data = dataset(model, &p, &refs, round % 2 == 0);
        let found = commanded_poses(
            model,
            &data.configurations,
            &data.config_ids,
            &SamePose::default(),
        );
        assert_eq!(found.summary.approaches, vec![[5, 18]], "round {round}");
        for g in &found.groups {
            let pose = refs[g[0]].pose;
            assert!(
                g.iter().all(|&c| refs[c].pose == pose),
                "one group mixes two poses"
            );
        }
        let close = found
            .summary
            .closest
            .as_ref()
            .expect("the two cubes are 1 mm apart");
        assert!(
            (close.distance_mm - 1.0).abs() < 0.2,
            "{}",
            close.distance_mm
        );
        let spread = found.summary.largest_spread_mm;
        assert!(spread > 0.0 && spread < 0.15, "{spread}");
        // With a tolerance above the 1 mm, each corner's two poses are one.
        let coarse = SamePose {
            position_mm: 2.0,
            ..SamePose::default()
        };
        let merged = commanded_poses(model, &data.configurations, &data.config_ids, &coarse);
        assert_eq!(merged.summary.approaches, vec![[10, 9]]);
    }
}

#[test]
fn a_pose_approached_once_has_no_rp_and_positions_give_no_orientation() {
    let cell = cell();
    let model = &cell.model;
    let p = params(model);
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let all = approaches(
        model,
        &cube(),
        1,
        Vector3::zeros(),
        Vector3::zeros(),
        (0.01, 1e-5),
        &mut rng,
    );
    let refs: Vec<&Approach> = all.iter().collect();
    let data = dataset(model, &p, &refs, true);
    let found = commanded_poses(
        model,
        &data.configurations,
        &data.config_ids,
        &SamePose::default(),
    );
    let rep = accuracy_report(model, &p, &data, &found, AccuracyOrientation::IfMeasured).unwrap();
    assert_eq!(rep.summary.repeated, 0);
    assert!(rep.summary.rp.is_none() && rep.summary.rp_abc_max_deg.is_none());
    assert!(rep.poses.iter().all(|f| f.repeatability.is_none()
        && f.orientation
            .as_ref()
            .is_some_and(|o| o.repeatability.is_none())));
    // Positions only: orientation figures are absent, and refused when required.
    let positions = dataset(model, &p, &refs, false);
    let rep = accuracy_report(
        model,
        &p,
        &positions,
        &found,
        AccuracyOrientation::IfMeasured,
    )
    .unwrap();
    assert!(rep.poses.iter().all(|f| f.orientation.is_none()) && rep.orientation_errors.is_none());
    let err = accuracy_report(model, &p, &positions, &found, AccuracyOrientation::Required)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("simulated cubes")
            && err.contains("need pose measurements")
            && err.contains("positions only"),
        "{err}"
    );
    // A tolerance that is no number is refused with the caller's name for it.
    let bad = SamePose {
        position_mm: f64::NAN,
        ..SamePose::default()
    };
    let err = bad
        .check(["--same-pose-mm", "--same-pose-deg"])
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("--same-pose-mm") && err.contains("positive"),
        "{err}"
    );
}
