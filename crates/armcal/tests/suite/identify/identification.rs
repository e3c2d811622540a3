//! Identification against known truth in simulation: exact recovery, agreement of the
//! solvers, honest covariance (Monte Carlo), both C_s formulas.

use crate::common;
use armcal::identify::*;
use armcal::model::random_configurations;
use armcal::{
    identify, perturbed_truth, simulate, Cell, Estimate, IdentifySettings, Method, Perturbation,
    Silent,
};
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;
use std::path::Path;

fn paper_cell() -> Cell {
    Cell::from_file(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper-cell.toml"))
        .unwrap()
}

#[test]
fn noise_free_identification_recovers_the_truth() {
    let cell = paper_cell();
    let model = &cell.model;
    let truth = perturbed_truth(model, &Perturbation::default(), 11);
    let qs = random_configurations(model, 60, 5);
    let data = simulate(model, &truth, &qs, None, 0).unwrap();
    let noise = cell.instrument.as_ref().unwrap().noise.clone();
    for method in [Method::Lm, Method::GaussNewton, Method::Kalman] {
        let mut problem = Problem::new(model, &data, &noise).unwrap();
        let opts = IdentifySettings {
            method,
            ..Default::default()
        };
        let (sol, _, _) = solve(&mut problem, &model.nominal(), &opts, &mut Silent).unwrap();
        assert!(sol.status.is_converged(), "{method:?}: {:?}", sol.status);
        for &i in &problem.free {
            let (est, tru) = (sol.params[i], truth[i]);
            assert!(
                (est - tru).abs() <= 1e-8 * tru.abs().max(1.0),
                "{method:?} {}: {est} vs truth {tru}",
                model.registry.get(i).name
            );
        }
    }
}

#[test]
fn gauss_newton_kalman_and_lm_agree_on_noisy_data() {
    let cell = paper_cell();
    let model = &cell.model;
    let truth = perturbed_truth(model, &Perturbation::default(), 3);
    let qs = random_configurations(model, 60, 8);
    let noise = cell.instrument.as_ref().unwrap().noise.clone();
    let data = simulate(model, &truth, &qs, Some(&noise), 21).unwrap();
    let run = |method| {
        let mut problem = Problem::new(model, &data, &noise).unwrap();
        let opts = IdentifySettings {
            method,
            ..Default::default()
        };
        let (sol, _, _) = solve(&mut problem, &model.nominal(), &opts, &mut Silent).unwrap();
        assert!(sol.status.is_converged(), "{method:?}: {:?}", sol.status);
        (problem.free.clone(), sol.params)
    };
    let (free, lm) = run(Method::Lm);
    let (_, gn) = run(Method::GaussNewton);
    let (_, kf) = run(Method::Kalman);
    let problem = Problem::new(model, &data, &noise).unwrap();
    let sol_sigma = problem.uncertainty_at(&lm).unwrap().sigma;
    for (c, &i) in free.iter().enumerate() {
        // Agreement to a tiny fraction of the parameter's standard deviation.
        assert!(
            (lm[i] - gn[i]).abs() < 1e-6 * sol_sigma[c],
            "GN {}",
            model.registry.get(i).name
        );
        assert!(
            (lm[i] - kf[i]).abs() < 1e-6 * sol_sigma[c],
            "Kalman {}",
            model.registry.get(i).name
        );
    }
}

#[test]
fn constrained_tcp_covariance_equals_propagated_covariance() {
    // Paper eq. 19 (KKT form) against C_s = G C_p Gᵀ (paper appendix).
    let cell = paper_cell();
    let model = &cell.model;
    let qs = random_configurations(model, 60, 2);
    let data = simulate(model, &model.nominal(), &qs, None, 0).unwrap();
    let noise = cell.instrument.as_ref().unwrap().noise.clone();
    let problem = Problem::new(model, &data, &noise).unwrap();
    let (_, j) = problem.residual_and_jacobian(&model.nominal());
    let cp = problem.uncertainty_at(&model.nominal()).unwrap().covariance;
    let work: Vec<Vec<f64>> = cell.working.iter().map(|w| w.q.clone()).collect();
    let g = tcp_jacobian(model, &model.nominal(), &problem.free, &work);
    let cs = tcp_covariance(&g, &cp, &["w".into()]);
    let cc = tcp_covariance_constrained(&j, &g).unwrap();
    let diff = (cs[0].covariance - cc.fixed_view::<3, 3>(0, 0)).abs().max();
    assert!(
        diff < 1e-9 * cs[0].covariance.abs().max(),
        "eq. 19 vs G C_p Gᵀ differ by {diff}"
    );
    // The paper's KPI for 60 random poses lands near its heuristic figures (0.5–0.8 mm²).
    assert!(
        cs[0].kpi > 0.2 && cs[0].kpi < 2.0,
        "(1/3) tr C_s = {}",
        cs[0].kpi
    );
}

#[test]
fn predicted_tcp_covariance_matches_monte_carlo() {
    tcp_covariance_matches_monte_carlo(&paper_cell(), 60);
}

/// The same with joint compliance and periodic joint errors identified with the geometry
/// (issue 14): C_p and C_s include the non-geometric terms.
#[test]
fn predicted_tcp_covariance_with_nongeometric_terms_matches_monte_carlo() {
    let cell = super::compliance::paper_cell_with(
        "compliance = [\"q2\", \"q3\"]\n\
         periodic = { joints = [\"q1\", \"q2\", \"q3\"], harmonics = [1, 2] }",
        "monte-carlo",
    )
    .unwrap();
    assert!(cell.model.joint_corrections().count() == 15);
    tcp_covariance_matches_monte_carlo(&cell, 120);
}

/// 300 seeded re-identifications of `cell` from noisy data at the same `poses` random
/// configurations: the empirical covariance of the TCP at the first working pose against the
/// predicted C_s at the truth, traces within ±15 %.
fn tcp_covariance_matches_monte_carlo(cell: &Cell, poses: usize) {
    let model = &cell.model;
    let truth = perturbed_truth(model, &Perturbation::default(), 4);
    let qs = random_configurations(model, poses, 17);
    let noise = cell.instrument.as_ref().unwrap().noise.clone();
    let work = cell.working[0].q.clone();
    let tcp_at = |params: &[f64]| -> Vector3<f64> {
        let mut d = armcal::model::Data::new(model);
        armcal::model::forward_kinematics(model, &mut d, params, &work);
        armcal::model::observed_position(&d, armcal::model::Observed::Tool)
    };
    let estimates: Vec<Vector3<f64>> = (0..300u64)
        .into_par_iter()
        .map(|seed| {
            let data = simulate(model, &truth, &qs, Some(&noise), 1000 + seed).unwrap();
            let mut problem = Problem::new(model, &data, &noise).unwrap();
            let (sol, _, _) = solve(
                &mut problem,
                &model.nominal(),
                &IdentifySettings::default(),
                &mut Silent,
            )
            .unwrap();
            assert!(sol.status.is_converged());
            tcp_at(&sol.params)
        })
        .collect();
    let n = estimates.len() as f64;
    let mean = estimates.iter().fold(Vector3::zeros(), |a, b| a + b) / n;
    let emp = estimates.iter().fold(Matrix3::zeros(), |a, e| {
        a + (e - mean) * (e - mean).transpose()
    }) / (n - 1.0);
    // Prediction at the truth.
    let data = simulate(model, &truth, &qs, None, 0).unwrap();
    let problem = Problem::new(model, &data, &noise).unwrap();
    let cp = problem.uncertainty_at(&truth).unwrap().covariance;
    let g = tcp_jacobian(model, &truth, &problem.free, std::slice::from_ref(&work));
    let cs = tcp_covariance(&g, &cp, &["w".into()]);
    let ratio = emp.trace() / cs[0].covariance.trace();
    eprintln!(
        "Monte Carlo ({poses} poses, {} non-geometric terms): empirical (1/3) tr = {:.4} mm², \
         predicted {:.4} mm², ratio {ratio:.3}",
        model.joint_corrections().count(),
        emp.trace() / 3.0,
        cs[0].kpi
    );
    assert!(
        (0.85..=1.15).contains(&ratio),
        "empirical / predicted trace = {ratio:.3} (emp {:.4}, pred {:.4})",
        emp.trace(),
        cs[0].covariance.trace()
    );
}

/// Identifies `cell` from `data` with each method; returns the estimates (LM first).
fn every_method(cell: &Cell, data: &armcal::Dataset) -> Vec<Estimate> {
    [Method::Lm, Method::GaussNewton, Method::Kalman]
        .into_iter()
        .map(|method| {
            let opts = IdentifySettings {
                method,
                ..Default::default()
            };
            let est = identify(cell, data, &opts, &mut Silent).unwrap();
            assert!(
                est.solver.status.is_converged(),
                "{method:?}: {}",
                est.solver.status
            );
            est
        })
        .collect()
}

#[test]
fn every_method_from_an_unplaced_tracker_reaches_lms_estimate_on_precise_data() {
    // Tracker noise σ = 0.05 mm; the cell's tracker is not placed (nominal at the base).
    let noise = armcal::measure::NoiseModel::Constant {
        sigma: [0.05; 3],
        sigma_angle: 1e-3,
    };
    for frames_only in [true, false] {
        let (mut cell, truth) = common::unplaced_tracker_paper_cell(frames_only, 5);
        cell.instrument.as_mut().unwrap().noise = noise.clone();
        let qs = random_configurations(&cell.model, 60, 7);
        let data = simulate(&cell.model, &truth, &qs, Some(&noise), 3).unwrap();
        let est = every_method(&cell, &data);
        let lm = &est[0];
        // Gauss–Newton without the frames-first start: converged only at LM's cost.
        let (model, _) = identifiable_model(&cell, &data, &cell.model.nominal()).unwrap();
        let mut problem = Problem::new(&model, &data, &noise).unwrap();
        let opts = IdentifySettings {
            method: Method::GaussNewton,
            ..Default::default()
        };
        let (gn, _, _) = solve(&mut problem, &model.nominal(), &opts, &mut Silent).unwrap();
        let lm_cost = 0.5 * lm.uncertainty.chi2;
        assert!(
            !gn.status.is_converged() || gn.cost() <= lm_cost * (1.0 + 1e-9),
            "frames only {frames_only}: GN from the nominal {} at cost {} (LM {lm_cost})",
            gn.status,
            gn.cost()
        );
        for other in &est[1..] {
            for (a, b) in lm.parameters.iter().zip(&other.parameters) {
                if let Some(sigma) = a.sigma {
                    // Levenberg–Marquardt stops within 1e-4 σ of the minimum (its σ rule),
                    // the others tighter
                    assert!(
                        (a.estimate - b.estimate).abs() <= 1e-4 * sigma,
                        "frames only {frames_only}, {:?} {}: {} vs LM {} (σ {sigma})",
                        other.solver.method,
                        a.name,
                        b.estimate,
                        a.estimate
                    );
                }
            }
        }
    }
}
