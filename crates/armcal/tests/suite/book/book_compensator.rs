//! The book's optimal (LQR) compensator and CMAC (Mooring, Roth, Driels 1991, §5.3 and
//! §5.4.2; book checks 9 and 10 of docs/book-notes.md).

use crate::common;
use armcal::compensate::cmac::{book_memory_words, Cmac, CmacSettings};
use armcal::compensate::lqr::{
    operation_count, optimal_compensation, pose_error_map, reduced_order_weight, relative_weights,
    OperationCount,
};
use armcal::compensate::{damped_step, task_jacobian_columns};
use armcal::model::random_configurations;
use armcal::model::{forward_kinematics, joint_jacobian, tool_pose, Data, Observed, Pose};
use armcal::{perturbed_truth, robots, Model, Perturbation, PolynomialCorrection};
use common::rng;
use nalgebra::{DMatrix, DVector, Matrix3, Matrix4, Rotation3, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

fn random_matrix(rows: usize, cols: usize, r: &mut ChaCha8Rng) -> DMatrix<f64> {
    DMatrix::from_fn(rows, cols, |_, _| r.random_range(-1.0..1.0))
}

fn random_vector(n: usize, r: &mut ChaCha8Rng) -> DVector<f64> {
    DVector::from_fn(n, |_, _| r.random_range(-1.0..1.0))
}

fn random_rotation(r: &mut ChaCha8Rng) -> Matrix3<f64> {
    let axis = Vector3::new(
        r.random_range(-1.0..1.0),
        r.random_range(-1.0..1.0),
        r.random_range(-1.0..1.0),
    );
    Rotation3::new(axis * 2.5).into_inner()
}

/// `u = −(BᵀQB + Γ)⁻¹ BᵀQ x_c`, solved directly.
fn batch_solution(
    b: &DMatrix<f64>,
    q: &DMatrix<f64>,
    gammas: &[f64],
    x: &DVector<f64>,
) -> DVector<f64> {
    let mut a = b.transpose() * q * b;
    for (k, g) in gammas.iter().enumerate() {
        a[(k, k)] += g;
    }
    -a.cholesky().unwrap().solve(&(b.transpose() * q * x))
}

/// `x_{N+1}ᵀ Q x_{N+1} + Σ γ_k u_k²` with `x_{N+1} = x_c + B u` (book eq. 5.83).
fn direct_cost(
    b: &DMatrix<f64>,
    q: &DMatrix<f64>,
    gammas: &[f64],
    x: &DVector<f64>,
    u: &DVector<f64>,
) -> f64 {
    let end = x + b * u;
    end.dot(&(q * &end))
        + gammas
            .iter()
            .zip(u.iter())
            .map(|(g, v)| g * v * v)
            .sum::<f64>()
}

fn relative(a: &DVector<f64>, b: &DVector<f64>) -> f64 {
    (a - b).norm() / b.norm()
}

#[test]
fn lqr_recursion_equals_batch_damped_least_squares() {
    // Book check 9, bullet 1: the recursion 5.85–5.87 gives u = −(BᵀQB + Γ)⁻¹BᵀQ x_c and
    // J* = x_cᵀ P_N x_c (eq. 5.88) = the cost of eq. 5.83 evaluated directly.
    let mut r = rng(91);
    for (state, stages) in [(6, 6), (6, 12), (12, 6), (12, 12)] {
        for trial in 0..20 {
            let mut b = random_matrix(state, stages, &mut r);
            if trial == 0 {
                // Rank-deficient B (a zero and a repeated column): γ > 0 keeps u finite.
                b.column_mut(0).fill(0.0);
                let c = b.column(1).into_owned();
                b.column_mut(2).copy_from(&c);
            }
            let a = random_matrix(state, state, &mut r);
            let q = &a * a.transpose() + DMatrix::identity(state, state) * 0.1;
            let gammas: Vec<f64> = (0..stages).map(|_| r.random_range(0.01..2.0)).collect();
            let x = random_vector(state, &mut r);
            let sol = optimal_compensation(&b, &q, &gammas, &x).unwrap();
            let direct = batch_solution(&b, &q, &gammas, &x);
            let err = relative(&sol.controls, &direct);
            assert!(err < 1e-10, "{state}×{stages} trial {trial}: {err:e}");
            let j_direct = direct_cost(&b, &q, &gammas, &x, &sol.controls);
            let j_p = x.dot(&(&sol.p_final * &x));
            assert!(
                (sol.cost - j_direct).abs() < 1e-10 * j_direct,
                "{}",
                sol.cost
            );
            assert!((j_p - j_direct).abs() < 1e-10 * j_direct);
            assert!(relative(&sol.terminal_error, &(&x + &b * &sol.controls)) < 1e-12);
            // Optimality: any other control costs more.
            let du = random_vector(stages, &mut r) * 1e-3;
            assert!(direct_cost(&b, &q, &gammas, &x, &(&sol.controls + du)) > sol.cost);
            // The feedback law u_k = k_kᵀ x_k (eq. 5.84) along the optimal trajectory.
            let mut xk = x.clone();
            for k in 0..stages {
                let u = sol.gains.row(k).transpose().dot(&xk);
                assert!((u - sol.controls[k]).abs() < 1e-12 * (1.0 + u.abs()));
                xk += b.column(k) * u;
            }
        }
    }
}

#[test]
fn lqr_rejects_bad_input() {
    let b = DMatrix::from_element(6, 3, 1.0);
    let q = DMatrix::identity(6, 6);
    let x = DVector::from_element(6, 1.0);
    let msg = |r: armcal::Result<_>| r.expect_err("an error").to_string();
    assert!(msg(optimal_compensation(&b, &q, &[1.0, 0.0, 1.0], &x)).contains("γ_2"));
    assert!(msg(optimal_compensation(&b, &q, &[1.0, 1.0], &x)).contains("2 control weights"));
    assert!(msg(optimal_compensation(
        &b,
        &DMatrix::identity(5, 5),
        &[1.0; 3],
        &x
    ))
    .contains("Q is 5×5"));
    assert!(msg(optimal_compensation(&b, &q, &[1.0; 3], &DVector::zeros(4))).contains("x_c"));
    let mut asym = q.clone();
    asym[(0, 1)] = 0.5;
    assert!(msg(optimal_compensation(&b, &asym, &[1.0; 3], &x)).contains("symmetric"));
    let mut nan = x.clone();
    nan[2] = f64::NAN;
    assert!(msg(optimal_compensation(&b, &q, &[1.0; 3], &nan)).contains("non-finite"));
}

fn puma() -> Model {
    Model::from_spec(&robots::robot("puma560").unwrap().spec).unwrap()
}

/// Position error (mm) and small rotation vector (rad) of `actual` relative to `reference`,
/// both in the world frame.
fn world_pose_error(actual: &Pose<f64>, reference: &Pose<f64>) -> DVector<f64> {
    let d = actual.trans - reference.trans;
    let w = Rotation3::from_matrix_unchecked(actual.rot * reference.rot.transpose()).scaled_axis();
    DVector::from_column_slice(&[d.x, d.y, d.z, w.x, w.y, w.z])
}

#[test]
fn lqr_is_the_one_step_damped_step_on_the_puma560() {
    // Book §5.3 / check 9: with Q = diag(1, 1, 1, L², L², L²) (mm and rad·L) and Γ = γ² I,
    // the N-stage recursion gives exactly the one-step damped least-squares correction of
    // `compensate::ik::damped_step`, on the PUMA 560 world-frame Jacobian.
    let model = puma();
    let nominal = model.nominal();
    let truth = perturbed_truth(&model, &Perturbation::default(), 7);
    let length = 500.0;
    let weight = DMatrix::from_diagonal(&DVector::from_column_slice(&[
        1.0,
        1.0,
        1.0,
        length * length,
        length * length,
        length * length,
    ]));
    let mut data = Data::new(&model);
    let mut ratios = Vec::new();
    for (i, q0) in random_configurations(&model, 20, 8).iter().enumerate() {
        forward_kinematics(&model, &mut data, &nominal, q0);
        let reference = *data.tool();
        let b = joint_jacobian(&data, Observed::Tool);
        let mut jw = [nalgebra::Vector6::zeros(); 6];
        task_jacobian_columns(&data, length, &mut jw, &mut []);
        // Initial error x_c: the truth robot's pose at q0 minus the nominal pose (eq. 5.140).
        let x_c = world_pose_error(&tool_pose(&model, &truth, q0), &reference);
        for gamma2 in [1e-4, 1.0, 1e3] {
            let sol = optimal_compensation(&b, &weight, &[gamma2; 6], &x_c).unwrap();
            let mut wx = x_c.clone();
            for r in 3..6 {
                wx[r] *= length;
            }
            let mut step = [0.0; 6];
            let ew = nalgebra::Vector6::from_column_slice((-wx).as_slice());
            assert!(damped_step::<6>(&jw, &ew, gamma2, &mut step));
            let step = DVector::from_column_slice(&step);
            let err = relative(&sol.controls, &step);
            assert!(err < 1e-10, "config {i}, γ² = {gamma2}: {err:e}");
        }
        // Applying the correction on the truth robot removes most of the pose error
        // (eq. 5.129: q_act = q0 + Δq_c).
        let sol = optimal_compensation(&b, &weight, &[1e-4; 6], &x_c).unwrap();
        let q_act: Vec<f64> = q0
            .iter()
            .zip(sol.controls.iter())
            .map(|(a, b)| a + b)
            .collect();
        let after = world_pose_error(&tool_pose(&model, &truth, &q_act), &reference);
        let weighted = |e: &DVector<f64>| e.dot(&(&weight * e)).sqrt();
        ratios.push(weighted(&after) / weighted(&x_c));
    }
    // One linear step: near a wrist singularity the corrections grow (up to ~0.1 rad,
    // Δθ4 ≈ −Δθ6 as in book Table 5.7) and the linearisation leaves more behind.
    ratios.sort_by(f64::total_cmp);
    let (median, worst) = (ratios[ratios.len() / 2], ratios[ratios.len() - 1]);
    eprintln!(
        "PUMA 560, 20 poses: compensated/initial weighted pose error median {median:.2e}, \
         worst {worst:.2e}"
    );
    assert!(median < 0.02 && worst < 0.25, "{ratios:?}");
}

/// `[n; o; a; p]` of a pose (book eq. 5.109 / vector f).
fn f12(pose: &Pose<f64>) -> DVector<f64> {
    let mut f = DVector::zeros(12);
    for c in 0..3 {
        f.rows_mut(3 * c, 3).copy_from(&pose.rot.column(c));
    }
    f.rows_mut(9, 3).copy_from(&pose.trans);
    f
}

#[test]
fn redundant_and_reduced_order_weights_are_equivalent() {
    // Book check 9, bullet 2 (eqs. 5.135, 5.161–5.170): x = [dn; do; da; dp] of
    // dT = T δT (eq. 5.142) is M y for y = [dx, dy, dz, δx, δy, δz] of δT (eq. 5.143), so
    // xᵀ Q_x x = yᵀ Q_y y with Q_y = Mᵀ Q_x M.
    let mut r = rng(92);
    for _ in 0..20 {
        let rot = random_rotation(&mut r);
        let p = Vector3::new(
            r.random_range(-900.0..900.0),
            r.random_range(-900.0..900.0),
            r.random_range(-900.0..900.0),
        );
        let mut t = Matrix4::identity();
        t.fixed_view_mut::<3, 3>(0, 0).copy_from(&rot);
        t.fixed_view_mut::<3, 1>(0, 3).copy_from(&p);
        let y = random_vector(6, &mut r);
        // δT of eq. 5.143, then dT = T δT and x = its 12 non-trivial entries column-wise.
        let mut delta = Matrix4::zeros();
        delta[(0, 1)] = -y[5];
        delta[(0, 2)] = y[4];
        delta[(1, 0)] = y[5];
        delta[(1, 2)] = -y[3];
        delta[(2, 0)] = -y[4];
        delta[(2, 1)] = y[3];
        delta[(0, 3)] = y[0];
        delta[(1, 3)] = y[1];
        delta[(2, 3)] = y[2];
        let dt = t * delta;
        let x = DVector::from_fn(12, |i, _| dt[(i % 3, i / 3)]);
        let m = pose_error_map(&rot);
        assert!((&x - m * nalgebra::Vector6::from_column_slice(y.as_slice())).norm() < 1e-12);

        // General diagonal Q_x: the closed form equals Mᵀ Q_x M.
        let q_x: [f64; 12] = std::array::from_fn(|_| r.random_range(0.1..3.0));
        let q_y = reduced_order_weight(&rot, &q_x);
        let exact = m.transpose()
            * nalgebra::SMatrix::<f64, 12, 12>::from_diagonal(
                &nalgebra::SVector::<f64, 12>::from_column_slice(&q_x),
            )
            * m;
        assert!(
            (q_y - exact).norm() < 1e-12 * exact.norm(),
            "{q_y} vs {exact}"
        );
        // The diagonal of eq. 5.164 as printed pairs each block with the other vector
        // (e.g. Qˡ₁₁ = oᵀQ₄₋₆o + aᵀQ₇₋₉a); with a general diagonal Q_x it is not Mᵀ Q_x M.
        let (o, a) = (rot.column(1), rot.column(2));
        let form = |block: usize, u: &Vector3<f64>| {
            (0..3)
                .map(|i| u[i] * u[i] * q_x[3 * block + i])
                .sum::<f64>()
        };
        let printed_11 = form(1, &o.into_owned()) + form(2, &a.into_owned());
        assert!((printed_11 - exact[(3, 3)]).abs() > 1e-6, "{printed_11}");

        // Eq. 5.170: the book's relative weights (eq. 5.135) give a diagonal Q_y.
        let (k1, k2) = (r.random_range(0.1..10.0), r.random_range(0.1..10.0));
        let (q_x_rel, q_y_rel) = relative_weights(k1, k2, p.norm());
        assert!((q_y_rel[0] - k2 / p.norm_squared()).abs() < 1e-15 * q_y_rel[0]);
        assert_eq!(q_y_rel[3], 2.0 * k1);
        assert_eq!(q_x_rel[..9], [k1; 9]);
        assert_eq!(q_x_rel[9..], [q_y_rel[0]; 3]);
        let q_y = reduced_order_weight(&rot, &q_x_rel);
        for i in 0..6 {
            for j in 0..6 {
                let want = if i == j { q_y_rel[i] } else { 0.0 };
                assert!((q_y[(i, j)] - want).abs() < 1e-12 * (k1 + k2), "{q_y}");
            }
        }
    }
}

#[test]
fn redundant_and_reduced_order_compensations_agree_on_the_puma560() {
    // Book check 9, bullet 2 and §5.3.5 ("the outputs of the two algorithms match
    // closely"): the redundant 12-state model with Q_x = diag(k1 ×9, k2/‖p‖² ×3) and the
    // reduced 6-state model with Q_y = diag(k2/‖p‖² ×3, 2k1 ×3) give the same corrections
    // and costs.
    let model = puma();
    let nominal = model.nominal();
    let truth = perturbed_truth(&model, &Perturbation::default(), 11);
    let mut data = Data::new(&model);
    let mut r = rng(93);
    let (k1, k2) = (1.0, 1.0);
    let mut worst_exact_difference: f64 = 0.0;
    for q0 in random_configurations(&model, 10, 12) {
        forward_kinematics(&model, &mut data, &nominal, &q0);
        let tool = *data.tool();
        let rot = tool.rot;
        let j = joint_jacobian(&data, Observed::Tool);
        // B_f = ∂f/∂q (eq. 5.115): columns [ω×n; ω×o; ω×a; v] ...
        let mut b_f = DMatrix::zeros(12, 6);
        for c in 0..6 {
            let w = Vector3::new(j[(3, c)], j[(4, c)], j[(5, c)]);
            for k in 0..3 {
                b_f.fixed_view_mut::<3, 1>(3 * k, c)
                    .copy_from(&w.cross(&rot.column(k).into_owned()));
            }
            b_f.fixed_view_mut::<3, 1>(9, c).copy_from(&Vector3::new(
                j[(0, c)],
                j[(1, c)],
                j[(2, c)],
            ));
        }
        // ... checked against central differences of the forward kinematics.
        let h = 1e-6;
        for c in 0..6 {
            let (mut qp, mut qm) = (q0.clone(), q0.clone());
            qp[c] += h;
            qm[c] -= h;
            let fd = (f12(&tool_pose(&model, &nominal, &qp))
                - f12(&tool_pose(&model, &nominal, &qm)))
                / (2.0 * h);
            let col = b_f.column(c).into_owned();
            assert!(
                (&fd - &col).norm() < 1e-6 * (1.0 + col.norm()),
                "column {c}"
            );
        }
        // B_g (eqs. 5.151–5.155): the tool-frame Jacobian [Rᵀv; Rᵀω]; B_f = M B_g.
        let mut b_g = DMatrix::zeros(6, 6);
        for c in 0..6 {
            let v = Vector3::new(j[(0, c)], j[(1, c)], j[(2, c)]);
            let w = Vector3::new(j[(3, c)], j[(4, c)], j[(5, c)]);
            b_g.fixed_view_mut::<3, 1>(0, c)
                .copy_from(&(rot.transpose() * v));
            b_g.fixed_view_mut::<3, 1>(3, c)
                .copy_from(&(rot.transpose() * w));
        }
        let m = pose_error_map(&rot);
        let m = DMatrix::from_column_slice(12, 6, m.as_slice());
        assert!((&b_f - &m * &b_g).norm() < 1e-10 * b_f.norm());

        let (q_x, q_y) = relative_weights(k1, k2, tool.trans.norm());
        let q_x = DMatrix::from_diagonal(&DVector::from_column_slice(&q_x));
        let q_y = DMatrix::from_diagonal(&DVector::from_column_slice(&q_y));
        let gammas: Vec<f64> = (0..6).map(|_| r.random_range(1e-8..1e-6)).collect();

        // Linearised errors (eq. 5.117 / 5.148): x_c = M y_c exactly, so the two
        // compensations and costs are equal.
        let y_c = DVector::from_fn(6, |i, _| {
            if i < 3 {
                r.random_range(-1.0..1.0)
            } else {
                r.random_range(-2e-3..2e-3)
            }
        });
        let x_c = &m * &y_c;
        let sx = optimal_compensation(&b_f, &q_x, &gammas, &x_c).unwrap();
        let sy = optimal_compensation(&b_g, &q_y, &gammas, &y_c).unwrap();
        assert!(relative(&sx.controls, &sy.controls) < 1e-9);
        assert!((sx.cost - sy.cost).abs() < 1e-9 * sy.cost);
        let jx0 = x_c.dot(&(&q_x * &x_c));
        let jy0 = y_c.dot(&(&q_y * &y_c));
        assert!((jx0 - jy0).abs() < 1e-12 * jy0);
        assert!(sx.cost < 1e-3 * jx0, "{} vs {jx0}", sx.cost);

        // Exact differences of a perturbed robot (eqs. 5.140, 5.145–5.146): x_c is the
        // difference of the 12-vectors, y_c comes from δT = T⁻¹ dT; they agree to first
        // order, and so do the corrections.
        let actual = tool_pose(&model, &truth, &q0);
        let x_c = f12(&actual) - f12(&tool);
        let d_rot = rot.transpose() * actual.rot - Matrix3::identity();
        let d_p = rot.transpose() * (actual.trans - tool.trans);
        let y_c = DVector::from_column_slice(&[
            d_p.x,
            d_p.y,
            d_p.z,
            d_rot[(2, 1)],
            d_rot[(0, 2)],
            d_rot[(1, 0)],
        ]);
        let sx = optimal_compensation(&b_f, &q_x, &gammas, &x_c).unwrap();
        let sy = optimal_compensation(&b_g, &q_y, &gammas, &y_c).unwrap();
        worst_exact_difference = worst_exact_difference.max(relative(&sx.controls, &sy.controls));
    }
    eprintln!(
        "PUMA 560: redundant vs reduced corrections from exact differences differ by ≤ {:.2e} (relative)",
        worst_exact_difference
    );
    assert!(worst_exact_difference < 1e-2, "{worst_exact_difference}");
}

#[test]
fn operation_counts_of_eq_5_173() {
    // Book check 9, bullet 3: N = 6 joints, diagonal Q.
    let count = |n, stages, diagonal| operation_count(n, stages, diagonal).unwrap();
    assert_eq!(
        count(12, 6, true),
        OperationCount {
            multiplications: 1596,
            additions: 2316
        }
    );
    assert_eq!(
        count(6, 6, true),
        OperationCount {
            multiplications: 474,
            additions: 654
        }
    );
    // Eq. 5.172 (full Q) costs more than 5.173 by one k and one P evaluation.
    let full = count(12, 6, false);
    assert_eq!((full.multiplications, full.additions), (1860, 2724));
    assert!(operation_count(12, 1, true).is_err());
    assert!(operation_count(12, 0, false).is_err());
}

#[test]
fn cmac_memory_of_the_book_example() {
    // Book §5.4.2.3 (check 10): two inputs of R = 120 units, Q = 10 quantising functions.
    assert_eq!(book_memory_words(120, 10, 2), 1440);
    assert_eq!(book_memory_words(120, 1, 2), 14_400);
    let settings = |levels| CmacSettings {
        lower: vec![2.0, 2.0],
        upper: vec![13.9, 13.9],
        resolution: 120,
        levels,
        outputs: 1,
    };
    // The one-to-one table is the book's 14 400 words; the offset subtables of
    // eq. 5.209 need 13 cells per axis for K = 1..9 and 12 for K = 10: 9·169 + 144.
    assert_eq!(Cmac::new(&settings(1)).unwrap().memory_words(), 14_400);
    let cmac = Cmac::new(&settings(10)).unwrap();
    assert_eq!(cmac.memory_words(), 1665);
    // Every input addresses a valid word in each subtable, and the highest input uses the
    // last cell of subtable 1 (so the 13th cell is needed).
    let top = cmac.active_words(&[13.9, 13.9]).unwrap();
    assert_eq!(top[0], 13 * 13 - 1);
    assert!(top.iter().all(|&w| w < cmac.memory_words()));
    // Bad layouts are errors.
    assert!(Cmac::new(&settings(0)).is_err());
    assert!(Cmac::new(&settings(120)).is_err());
    let mut inverted = settings(10);
    inverted.upper[1] = 1.0;
    assert!(Cmac::new(&inverted)
        .unwrap_err()
        .to_string()
        .contains("axis 1"));
}

/// A two-input CMAC whose `resolution` units per axis are the integers 0..resolution − 1.
fn unit_grid_cmac(resolution: usize, levels: usize, outputs: usize) -> Cmac {
    let top = (resolution - 1) as f64;
    Cmac::new(&CmacSettings {
        lower: vec![0.0, 0.0],
        upper: vec![top, top],
        resolution,
        levels,
        outputs,
    })
    .unwrap()
}

#[test]
fn cmac_output_of_table_5_8() {
    // Book Table 5.8: the output is the sum of the Q = 4 selected weights, 34.1.
    let table = include_str!("../../data/book/table_5_8_cmac_weights.csv");
    let mut weights = Vec::new();
    let mut printed_sum = None;
    for line in table.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let v: f64 = f[2].parse().unwrap();
        if f[0] == "output" {
            printed_sum = Some(v);
        } else {
            weights.push(v);
        }
    }
    assert_eq!(weights.len(), 4);
    // Units 0..8 per axis (R = 9): every one of the Q = 4 subtables has 3 × 3 cells, as
    // the letters A–L / a–l of Table 5.8 imply (three per quantising function).
    let mut cmac = unit_grid_cmac(9, 4, 1);
    assert_eq!(cmac.memory_words(), 4 * 9);
    let words = cmac.active_words(&[3.0, 5.0]).unwrap();
    // Cell letters of eq. 5.209: subtable K uses letters 3(K − 1) + cell along x (A–L)
    // and y (a–l). Subtables 1–3 give Bc, Ee, Hh as in Table 5.8; subtable 4 gives Jk
    // where the book prints Kl (Figure 5.5, which fixes the offsets, is missing).
    let letters: Vec<String> = words
        .iter()
        .enumerate()
        .map(|(k, w)| {
            let cell = w - 9 * k;
            let (cx, cy) = (cell % 3, cell / 3);
            format!(
                "{}{}",
                (b'A' + (3 * k + cx) as u8) as char,
                (b'a' + (3 * k + cy) as u8) as char
            )
        })
        .collect();
    assert_eq!(letters, ["Bc", "Ee", "Hh", "Jk"]);
    for (w, v) in words.iter().zip(&weights) {
        cmac.set_weight(*w, 0, *v).unwrap();
    }
    let out = cmac.predict(&[3.0, 5.0]).unwrap()[0];
    assert!((out - 34.1).abs() < 1e-12, "{out}");
    assert!((out - printed_sum.unwrap()).abs() < 1e-12);
    assert!(cmac.set_weight(36, 0, 1.0).is_err());
}

#[test]
fn cmac_learning_rule_of_eq_5_200() {
    // Δ = g (desired − output)/Q on each of the Q selected weights, nothing else changes.
    let mut cmac = unit_grid_cmac(100, 5, 2);
    let x = [40.0, 61.0];
    let (g, desired) = (0.8, [10.0, -4.0]);
    let squared = cmac.train(&x, &desired, g).unwrap();
    assert_eq!(squared, 116.0);
    let words = cmac.active_words(&x).unwrap();
    for (out, d) in desired.iter().enumerate() {
        for w in 0..cmac.memory_words() {
            let want = if words.contains(&w) { g * d / 5.0 } else { 0.0 };
            assert!((cmac.weight(w, out).unwrap() - want).abs() < 1e-15);
        }
    }
    // The output moved by g of its error; a second experience with the same data again
    // removes the fraction g of what is left.
    let o = cmac.predict(&x).unwrap();
    assert!((o[0] - 8.0).abs() < 1e-12 && (o[1] + 3.2).abs() < 1e-12);
    cmac.train(&x, &desired, g).unwrap();
    let o = cmac.predict(&x).unwrap();
    assert!((o[0] - 9.6).abs() < 1e-12, "{o:?}");
    // Generalisation: a neighbour one unit away shares Q − 1 = 4 of its 5 weights.
    let near = cmac.predict(&[41.0, 61.0]).unwrap();
    assert!((near[0] - 9.6 * 4.0 / 5.0).abs() < 1e-12, "{near:?}");
    // A far input shares none.
    assert_eq!(cmac.predict(&[80.0, 10.0]).unwrap(), vec![0.0, 0.0]);
    // Bad input.
    assert!(cmac.train(&x, &desired, 0.0).is_err());
    assert!(cmac.train(&x, &desired, 2.5).is_err());
    assert!(cmac.train(&x, &[1.0], 1.0).is_err());
    assert!(cmac.predict(&[1.0]).is_err());
    assert!(cmac.predict(&[f64::NAN, 1.0]).is_err());
    let mut out = [0.0; 3];
    assert!(cmac.predict_into(&x, &mut out).is_err());
}

fn rms(v: &[Vector3<f64>]) -> f64 {
    (v.iter().map(|e| e.norm_squared()).sum::<f64>() / v.len() as f64).sqrt()
}

#[test]
fn cmac_and_polynomial_correct_a_smooth_3d_error_field() {
    // A smooth error field: the tool-position error (mm) of a perturbed PUMA 560 relative
    // to its nominal model, as a function of q1..q3 (wrist at rest). Both approximators are
    // trained on 3000 configurations and evaluated on 500 held-out ones.
    let model = puma();
    let nominal = model.nominal();
    let truth = perturbed_truth(&model, &Perturbation::default(), 31);
    let sample = |seed: u64, count: usize| -> (Vec<Vec<f64>>, Vec<Vector3<f64>>) {
        let configs = random_configurations(&model, count, seed);
        let inputs: Vec<Vec<f64>> = configs.iter().map(|q| q[..3].to_vec()).collect();
        let errors = inputs
            .iter()
            .map(|arm| {
                let q = [arm[0], arm[1], arm[2], 0.0, 0.0, 0.0];
                tool_pose(&model, &truth, &q).trans - tool_pose(&model, &nominal, &q).trans
            })
            .collect();
        (inputs, errors)
    };
    let (train_x, train_e) = sample(32, 3000);
    let (test_x, test_e) = sample(33, 500);
    let before = rms(&test_e);

    let (lo, hi) = model.joint_limits();
    let mut cmac = Cmac::new(&CmacSettings {
        lower: lo[..3].to_vec(),
        upper: hi[..3].to_vec(),
        resolution: 64,
        levels: 8,
        outputs: 3,
    })
    .unwrap();
    let desired: Vec<Vec<f64>> = train_e.iter().map(|e| e.as_slice().to_vec()).collect();
    let training = cmac.train_epochs(&train_x, &desired, 0.5, 30).unwrap();
    let mut out = [0.0; 3];
    let cmac_after: Vec<Vector3<f64>> = test_x
        .iter()
        .zip(&test_e)
        .map(|(x, e)| {
            cmac.predict_into(x, &mut out).unwrap();
            e - Vector3::from_column_slice(&out)
        })
        .collect();
    let cmac_rms = rms(&cmac_after);

    let poly_rms = |degree| {
        let poly = PolynomialCorrection::fit(&train_x, &train_e, degree).unwrap();
        let after: Vec<Vector3<f64>> = test_x
            .iter()
            .zip(&test_e)
            .map(|(x, e)| e - poly.predict(x))
            .collect();
        rms(&after)
    };
    let (poly4, poly6) = (poly_rms(4), poly_rms(6));
    eprintln!(
        "held-out RMS of the PUMA position error: {before:.4} mm; CMAC (R = 64, Q = 8, {} \
         words × 3 outputs, last-epoch training RMS {training:.4} mm) leaves {cmac_rms:.4} mm; \
         polynomial of degree 4 (35 terms × 3) leaves {poly4:.4} mm, degree 6 (84 terms × 3) \
         {poly6:.4} mm",
        cmac.memory_words()
    );
    assert!(before > 0.5, "{before}");
    assert!(cmac_rms < before / 5.0, "{cmac_rms} vs {before}");
    assert!(poly4 < before / 3.0, "{poly4} vs {before}");
    assert!(poly6 < poly4, "{poly6} vs {poly4}");
}
