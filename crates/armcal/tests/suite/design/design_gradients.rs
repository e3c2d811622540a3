//! Every design criterion's gradient w.r.t. all N×k joint values against central finite
//! differences, on the paper cell (position rows) and on the UR10 full-pose cell (position
//! and rotation rows).

use crate::common::{example_cell, ur10_pose_cell};
use armcal::design::{DesignModel, DesignObjective};
use armcal::model::random_configurations;
use armcal::{Cell, Criterion};

#[test]
fn criterion_gradients_match_finite_differences() {
    check_gradients(&example_cell("paper-cell.toml"));
}

#[test]
fn pose_criterion_gradients_match_finite_differences() {
    check_gradients(&ur10_pose_cell());
}

fn check_gradients(cell: &Cell) {
    let d = DesignModel::from_cell(cell).unwrap();
    let qs = random_configurations(&d.model, 40, 9);
    let measured = random_configurations(&d.model, 3, 10);
    let q: Vec<f64> = qs.concat();
    for criterion in Criterion::ALL {
        let obj = DesignObjective::new(&d, criterion, &measured);
        let mut ws = obj.workspace(qs.len());
        let mut g = vec![0.0; q.len()];
        let f0 = obj.value_and_gradient(&mut ws, &q, Some(&mut g)).unwrap();
        let f1 = obj.value_and_gradient(&mut ws, &q, None).unwrap();
        assert_eq!(f0, f1);
        let gmax = g.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        let tolerance = |fd: f64| 1e-6 * gmax.max(1e-12) + 1e-6 * fd.abs();
        // Check a spread of entries (all joints of several configurations) against central
        // differences at the step that suits the criterion: truncation error grows as h², the
        // rounding error of φ over h, and φ's rounding error is large for a criterion of an
        // ill-conditioned M (E = 1/λ_min of the full-pose cell, whose M spans 10⁸: its
        // differences are rounding noise at 1e-5 and agree to 1e-9 at 1e-4). A wrong
        // derivative matches at no step.
        for idx in (0..q.len()).step_by(7) {
            let mut central = |h: f64| {
                let mut qp = q.clone();
                qp[idx] += h;
                let mut qm = q.clone();
                qm[idx] -= h;
                (obj.value_and_gradient(&mut ws, &qp, None).unwrap()
                    - obj.value_and_gradient(&mut ws, &qm, None).unwrap())
                    / (2.0 * h)
            };
            let fds = [1e-5, 1e-4, 1e-6].map(&mut central);
            assert!(
                fds.iter().any(|fd| (g[idx] - fd).abs() <= tolerance(*fd)),
                "{criterion:?} entry {idx}: analytic {} vs fd {fds:?} at h = 1e-5, 1e-4, 1e-6 (max |g| {gmax})",
                g[idx]
            );
        }
    }
}
