//! Every analytic derivative against central finite differences, for every convention
//! (revolute and prismatic), rigid, with joint compliance (the lumped κ columns and the
//! chain rule through the deflected joints) and with compliance and periodic joint errors
//! together, on random configurations. Relative error < 1e-6.

use crate::common;
use armcal::model::*;
use armcal::Unit;
use common::*;
use nalgebra::DMatrix;

const TOL: f64 = 1e-6;

#[test]
fn identification_jacobian_matches_finite_differences() {
    for seed in 0..4 {
        for model in derivative_models(seed) {
            let mut r = rng(100 + seed);
            let params = model.nominal();
            let n = model.param_count();
            let columns: Vec<usize> = (0..n).collect();
            for _ in 0..3 {
                let q = random_q(&model, &mut r);
                let mut data = Data::new(&model);
                forward_kinematics(&model, &mut data, &params, &q);
                for obs in [Observed::Target(0), Observed::Target(1), Observed::Tool] {
                    let mut jac = DMatrix::zeros(6, n);
                    identification_jacobian(&model, &data, obs, Rows::Pose, &columns, &mut jac, 0);
                    for j in 0..n {
                        let fd = fd_pose(
                            |h| {
                                let mut p = params.clone();
                                p[j] += h;
                                measure(&model, &p, &q, obs)
                            },
                            1e-6,
                        );
                        let name = &model.registry.get(j).name;
                        for row in 0..6 {
                            assert_close(
                                jac[(row, j)],
                                fd[row],
                                TOL,
                                &format!("seed {seed} {obs:?} d(row {row})/d{name}"),
                            );
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn joint_jacobian_matches_finite_differences() {
    for seed in 0..4 {
        for model in derivative_models(seed) {
            let mut r = rng(200 + seed);
            let params = model.nominal();
            let q = random_q(&model, &mut r);
            let mut data = Data::new(&model);
            forward_kinematics(&model, &mut data, &params, &q);
            for obs in [Observed::Target(1), Observed::Tool] {
                let jq = joint_jacobian(&data, obs);
                for j in 0..model.dof() {
                    let fd = fd_pose(
                        |h| {
                            let mut qq = q.clone();
                            qq[j] += h;
                            let mut d = Data::new(&model);
                            forward_kinematics(&model, &mut d, &params, &qq);
                            // world frame: no instrument transform
                            *armcal::model::observed_world(&d, obs)
                        },
                        // poses of 10³ mm: at h = 1e-6 rounding (ε|x|/h ≈ 10⁻⁶) is the error
                        1e-5,
                    );
                    for row in 0..6 {
                        assert_close(
                            jq[(row, j)],
                            fd[row],
                            TOL,
                            &format!("seed {seed} dq{j} row {row}"),
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn calibrated_ik_steps_with_the_joint_jacobian_of_the_commanded_joints() {
    // Calibrated IK's task columns (position rows, rotation rows scaled by L) are the joint
    // Jacobian above, finite-difference checked: with compliance and periodic errors, the
    // chain rule through q + Δq(q) included (issue 14, compensation with the deflection).
    use armcal::compensate::task_jacobian_columns;
    use nalgebra::Vector6;
    let length = 800.0;
    for seed in 0..3 {
        for model in derivative_models(seed) {
            let mut r = rng(250 + seed);
            let q = random_q(&model, &mut r);
            let mut data = Data::new(&model);
            forward_kinematics(&model, &mut data, &model.nominal(), &q);
            let jq = joint_jacobian(&data, Observed::Tool);
            let n = model.dof();
            let (mut columns, mut corrected) =
                (vec![Vector6::zeros(); n], vec![Vector6::zeros(); n]);
            task_jacobian_columns(&data, length, &mut columns, &mut corrected);
            for (k, c) in columns.iter().enumerate() {
                for row in 0..6 {
                    let scale = if row < 3 { 1.0 } else { length };
                    assert_close(
                        c[row],
                        jq[(row, k)] * scale,
                        1e-12,
                        &format!("seed {seed} task column {k} row {row}"),
                    );
                }
            }
        }
    }
}

#[test]
fn mixed_derivative_matches_finite_differences_of_jacobian() {
    for seed in 0..3 {
        for model in derivative_models(seed) {
            let mut r = rng(300 + seed);
            let params = model.nominal();
            let n = model.param_count();
            let columns: Vec<usize> = (0..n).collect();
            let q = random_q(&model, &mut r);
            for rows in [Rows::Position, Rows::Pose] {
                let m = rows.count();
                let mut ws = MixedWorkspace::new(&model);
                let mut value = DMatrix::zeros(m, n);
                let mut dq = vec![DMatrix::zeros(m, n); model.dof()];
                identification_jacobian_dq(
                    &model,
                    &mut ws,
                    &params,
                    &q,
                    Observed::Target(0),
                    rows,
                    &columns,
                    &mut value,
                    &mut dq,
                );
                let jac_at = |qq: &[f64]| {
                    let mut d = Data::new(&model);
                    forward_kinematics(&model, &mut d, &params, qq);
                    let mut jac = DMatrix::zeros(m, n);
                    identification_jacobian(
                        &model,
                        &d,
                        Observed::Target(0),
                        rows,
                        &columns,
                        &mut jac,
                        0,
                    );
                    jac
                };
                let j0 = jac_at(&q);
                assert!(
                    (&value - &j0).abs().max() < 1e-12,
                    "the value equals the f64 Jacobian"
                );
                let h = 1e-6;
                for k in 0..model.dof() {
                    let mut qp = q.clone();
                    qp[k] += h;
                    let mut qm = q.clone();
                    qm[k] -= h;
                    let fd = (jac_at(&qp) - jac_at(&qm)) / (2.0 * h);
                    for (idx, (a, b)) in dq[k].iter().zip(fd.iter()).enumerate() {
                        // A κ column is a lever (~10³ mm) times a joint column: its finite
                        // difference rounds at eps·|column|/h, so compare it on its column's
                        // scale (the dual-number test below checks it exactly).
                        let c = idx / m;
                        let scale = if matches!(
                            model.registry.get(c).unit,
                            Unit::RadPerMm | Unit::RadPerNmm
                        ) {
                            j0.column(c).abs().max().max(1.0)
                        } else {
                            1.0
                        };
                        assert_close(
                            *a / scale,
                            *b / scale,
                            TOL,
                            &format!("seed {seed} dJ/dq{k} entry {idx}"),
                        );
                    }
                }
            }
        }
    }
}

/// The analytic mixed derivative against forward-mode dual numbers pushed through the
/// generic kinematics and identification Jacobian (exact to rounding, unlike finite
/// differences), for every observed frame, both row kinds and a column subset: the matrices
/// ∂J/∂q_k, and the weighted sums `∂/∂q_k ⟨Ω, J⟩` of [`identification_jacobian_dq_along`]
/// for a random Ω read at a row offset (Ω's other rows must not count; the sums are added
/// to what `out` holds).
#[test]
fn mixed_derivative_matches_dual_numbers() {
    use num_dual::Dual64;
    use rand::Rng;
    for seed in 0..3 {
        for model in derivative_models(seed) {
            let mut r = rng(500 + seed);
            let params = model.nominal();
            let n = model.param_count();
            let columns: Vec<usize> = (0..n).filter(|c| c % 3 != 1).collect();
            let q = random_q(&model, &mut r);
            let mut ws = MixedWorkspace::new(&model);
            let mut along_ws = AlongWorkspace::new(&model);
            let mut data = Data::new(&model);
            forward_kinematics(&model, &mut data, &params, &q);
            let mut dual_data = Data::<Dual64>::new(&model);
            for obs in [Observed::Target(0), Observed::Target(1), Observed::Tool] {
                for rows in [Rows::Position, Rows::Pose] {
                    let m = rows.count();
                    let mut value = DMatrix::zeros(m, columns.len());
                    let mut dq = vec![DMatrix::zeros(m, columns.len()); model.dof()];
                    identification_jacobian_dq(
                        &model, &mut ws, &params, &q, obs, rows, &columns, &mut value, &mut dq,
                    );
                    let weight =
                        DMatrix::from_fn(m + 3, columns.len(), |_, _| r.random_range(-1.0..1.0));
                    let mut along = vec![0.5; model.dof()];
                    identification_jacobian_dq_along(
                        &model,
                        &mut along_ws,
                        &data,
                        obs,
                        rows,
                        &columns,
                        &weight,
                        2,
                        &mut along,
                    );
                    for (k, dqk) in dq.iter().enumerate() {
                        let qd: Vec<Dual64> = q
                            .iter()
                            .enumerate()
                            .map(|(i, &x)| Dual64::new(x, if i == k { 1.0 } else { 0.0 }))
                            .collect();
                        forward_kinematics(&model, &mut dual_data, &params, &qd);
                        let mut jac = DMatrix::from_element(m, columns.len(), Dual64::from(0.0));
                        identification_jacobian(
                            &model, &dual_data, obs, rows, &columns, &mut jac, 0,
                        );
                        let scale = jac.iter().fold(1.0f64, |a, x| a.max(x.eps.abs()));
                        for (idx, (a, b)) in dqk.iter().zip(jac.iter()).enumerate() {
                            assert!(
                            (a - b.eps).abs() <= 1e-10 * scale,
                            "seed {seed} {obs:?} {rows:?} dJ/dq{k} entry {idx}: analytic {a}, dual {}",
                            b.eps
                        );
                            if k == 0 {
                                let v = value[idx];
                                assert!((v - b.re).abs() <= 1e-12 * scale.max(v.abs()));
                            }
                        }
                        let (mut expected, mut size) = (0.5, 1.0f64);
                        for (idx, x) in jac.iter().enumerate() {
                            let term = weight[(2 + idx % m, idx / m)] * x.eps;
                            expected += term;
                            size = size.max(term.abs());
                        }
                        assert!(
                            (along[k] - expected).abs() <= 1e-10 * size,
                            "seed {seed} {obs:?} {rows:?} joint {k}: weighted sum {}, dual {expected}",
                            along[k]
                        );
                    }
                }
            }
        }
    }
}
