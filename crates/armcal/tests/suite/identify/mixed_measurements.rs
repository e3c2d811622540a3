//! Measurement blocks of every kind mixed in one problem: residual-row derivatives against
//! finite differences, and exact recovery of the truth from noise-free mixed data.

use crate::common;
use armcal::identify::*;
use armcal::measure::{Measurement, MeasurementKind, NoiseModel};
use armcal::model::random_configurations;
use armcal::model::*;
use armcal::{perturbed_truth, simulate, Dataset, IdentifySettings, Model, Perturbation, Silent};
use nalgebra::{DMatrix, DVector, Vector3};

/// The every-convention chain measured by a point target (positions, distances between
/// poses, distance to a pivot, a plane) and a frame target (poses).
fn mixed(model: &Model, truth: &[f64], qs: &[Vec<f64>]) -> Dataset {
    let mut data = simulate(model, truth, qs, None, 0).unwrap();
    let mut d = Data::new(model);
    let pos = |d: &mut Data<f64>, q: &[f64]| {
        forward_kinematics(model, d, truth, q);
        observed_position(d, Observed::Target(0))
    };
    let pivot = Vector3::new(100.0, -50.0, 30.0);
    let normal = Vector3::new(0.3, -0.4, 0.866).normalize();
    for c in 0..qs.len() {
        let p = pos(&mut d, &qs[c]);
        let other = (c + 1) % qs.len();
        let po = pos(&mut d, &qs[other]);
        data.measurements.push(Measurement {
            config: c,
            observed: Observed::Target(0),
            kind: MeasurementKind::Distance {
                other,
                value: (p - po).norm(),
                sigma: None,
            },
            line: 0,
            covariates: Default::default(),
        });
        data.measurements.push(Measurement {
            config: c,
            observed: Observed::Target(0),
            kind: MeasurementKind::DistanceToPoint {
                point: pivot,
                value: (p - pivot).norm(),
                sigma: None,
            },
            line: 0,
            covariates: Default::default(),
        });
        if c % 3 == 0 {
            // A plane through the point (a probe touching a surface).
            data.measurements.push(Measurement {
                config: c,
                observed: Observed::Target(0),
                kind: MeasurementKind::OnPlane {
                    normal,
                    offset: normal.dot(&p),
                    sigma: None,
                },
                line: 0,
                covariates: Default::default(),
            });
        }
    }
    data
}

#[test]
fn mixed_residual_jacobian_matches_finite_differences() {
    let model = common::every_convention_model(2);
    let mut r = common::rng(5);
    let qs: Vec<Vec<f64>> = (0..6).map(|_| common::random_q(&model, &mut r)).collect();
    let params = model.nominal();
    // Measured values from other parameters so that residuals are non-zero.
    let mut other = params.clone();
    for (i, p) in other.iter_mut().enumerate() {
        *p += 1e-3 * ((i % 7) as f64 - 3.0);
    }
    let data = mixed(&model, &other, &qs);
    let noise = NoiseModel::Constant {
        sigma: [0.1, 0.2, 0.3],
        sigma_angle: 1e-3,
    };
    let problem = Problem::new(&model, &data, &noise).unwrap();
    let mut ws = problem.workspace();
    let (m, n) = (problem.rows(), problem.columns());
    let mut res = DVector::zeros(m);
    let mut jac = DMatrix::zeros(m, n);
    problem.evaluate(&mut ws, &params, &mut res, Some(&mut jac));
    let jmax = jac.abs().max();
    for c in 0..n {
        let h = 1e-6;
        let mut pp = params.clone();
        pp[problem.free[c]] += h;
        let mut pm = params.clone();
        pm[problem.free[c]] -= h;
        let (mut rp, mut rm) = (DVector::zeros(m), DVector::zeros(m));
        problem.evaluate(&mut ws, &pp, &mut rp, None);
        problem.evaluate(&mut ws, &pm, &mut rm, None);
        let fd = (rp - rm) / (2.0 * h);
        for row in 0..m {
            let err = (jac[(row, c)] - fd[row]).abs();
            assert!(
                err <= 1e-6 * jmax.max(1.0) + 1e-6 * fd[row].abs(),
                "row {row} col {c}: {} vs {}",
                jac[(row, c)],
                fd[row]
            );
        }
    }
}

#[test]
fn noise_free_mixed_data_recover_the_truth() {
    let cell = armcal::Cell::from_file(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper-cell.toml"),
    )
    .unwrap();
    let model = &cell.model;
    let truth = perturbed_truth(model, &Perturbation::default(), 21);
    let qs = random_configurations(model, 40, 6);
    let data = mixed(model, &truth, &qs);
    let noise = NoiseModel::Constant {
        sigma: [1.0; 3],
        sigma_angle: 1e-3,
    };
    let mut problem = Problem::new(model, &data, &noise).unwrap();
    let (sol, _, _) = solve(
        &mut problem,
        &model.nominal(),
        &IdentifySettings::default(),
        &mut Silent,
    )
    .unwrap();
    assert!(sol.status.is_converged(), "{}", sol.status);
    for &i in &problem.free {
        assert!(
            (sol.params[i] - truth[i]).abs() <= 1e-8 * truth[i].abs().max(1.0),
            "{}",
            model.registry.get(i).name
        );
    }
}
