//! Every design criterion's gradient w.r.t. all N×k joint values against central finite
//! differences, on the paper cell.

use armcal::cell::Cell;
use armcal::design::{Criterion, DesignModel, DesignObjective};
use armcal::model::random_configurations;
use std::path::Path;

#[test]
fn criterion_gradients_match_finite_differences() {
    let cell = Cell::from_file(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper-cell.toml"),
    )
    .unwrap();
    let d = DesignModel::from_cell(&cell).unwrap();
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
        // Check a spread of entries (all joints of several configurations).
        for idx in (0..q.len()).step_by(7) {
            let h = 1e-5;
            let mut qp = q.clone();
            qp[idx] += h;
            let mut qm = q.clone();
            qm[idx] -= h;
            let fd = (obj.value_and_gradient(&mut ws, &qp, None).unwrap()
                - obj.value_and_gradient(&mut ws, &qm, None).unwrap())
                / (2.0 * h);
            let err = (g[idx] - fd).abs();
            assert!(
                err <= 1e-6 * gmax.max(1e-12) + 1e-6 * fd.abs(),
                "{criterion:?} entry {idx}: analytic {} vs fd {fd} (max |g| {gmax})",
                g[idx]
            );
        }
    }
}
