//! Real data: the Motoman dual-arm robot as ONE kinematic tree (issue 32;
//! `examples/motoman-tree-cell.toml`: the torso axis E, one tracker frame, both arms), the
//! right and left grids fitted together, against the two serial fits, held out per arm with
//! the serial fits' splits (a third of each grid, seed 1). Figures in the guide
//! (docs/src/case-motoman-tree.md) from
//! `cargo test --release -p armcal --test suite real_data::motoman_tree -- --nocapture`:
//! kinematic, and with `--nongeometric auto` (the compliant tree of
//! `examples/motoman-tree-nongeometric-cell.toml` against the serial non-geometric cells).

use super::motoman_calibration::motoman;
use armcal::{identify, identify_tree, IdentifySettings, NonGeometric, Silent, TreeCell};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn motoman_arms_fitted_as_one_tree_against_the_serial_fits() {
    fitted_together("tree-cell", "cell", NonGeometric::AsCell);
}

/// With `--nongeometric auto`: the compliant tree (shoulders and elbows of both arms)
/// cross-validated against the rigid one, the serial non-geometric cells' own choice
/// (compliance and periodic terms) beside it.
#[test]
fn motoman_arms_fitted_as_one_tree_with_nongeometric_auto() {
    fitted_together(
        "tree-nongeometric-cell",
        "nongeometric-cell",
        NonGeometric::Auto { folds: 5 },
    );
}

/// The tree of `examples/motoman-<tree>.toml` fitted to both grids, and each arm's serial
/// fit of `examples/motoman-<arm>-<serial>.toml`, with `nongeometric`; held out per arm with
/// the same splits.
fn fitted_together(tree_cell: &str, serial: &str, nongeometric: NonGeometric) {
    let cell =
        TreeCell::from_file(&root().join(format!("examples/motoman-{tree_cell}.toml"))).unwrap();
    let mut data = armcal::Dataset::default();
    for (arm, target) in [("right", "smr1"), ("left", "smr2")] {
        let file = root().join(format!("data/motoman-leica/{arm}_arm_grid_6x6x6.csv"));
        data.append(&cell.read_data(&file, Some(target)).unwrap());
    }
    data.source = "right and left grids".into();
    let opts = IdentifySettings {
        holdout: 1.0 / 3.0,
        seed: 1,
        nongeometric,
        ..Default::default()
    };
    let t0 = std::time::Instant::now();
    let tree = identify_tree(&cell, &data, &opts, &mut Silent).unwrap();
    let elapsed = t0.elapsed().as_secs_f64();
    assert!(tree.solver.status.is_converged(), "{}", tree.solver.status);
    eprintln!(
        "tree ({tree_cell}): {} free parameters, {} iterations, σ̂₀² = {:.3}, {elapsed:.2} s{}",
        tree.free.len(),
        tree.solver.iterations,
        tree.uncertainty.variance_factor,
        chosen(tree.nongeometric_choice.as_ref())
    );
    for (t, arm) in tree.targets.iter().zip(["right", "left"]) {
        let (serial_cell, serial_data) = motoman(&format!("{arm}-{serial}"), arm);
        let t0 = std::time::Instant::now();
        let est = identify(&serial_cell, &serial_data, &opts, &mut Silent).unwrap();
        let serial_s = t0.elapsed().as_secs_f64();
        let serial_choice = chosen(est.nongeometric_choice.as_ref());
        let v = est.validation.unwrap();
        eprintln!(
            "{arm}: held-out {} poses; tree mean {:.4} RMS {:.4} max {:.4} p95 {:.4}, frames only RMS {:.4}; serial ({} free, {serial_s:.2} s{serial_choice}) mean {:.4} RMS {:.4} max {:.4} p95 {:.4} (mm)",
            t.held_out.count,
            t.held_out.mean,
            t.held_out.rms,
            t.held_out.max,
            t.held_out.p95,
            t.held_out_frames_only.rms,
            est.free.len(),
            v.calibrated.mean,
            v.calibrated.rms,
            v.calibrated.max,
            v.calibrated.p95
        );
        // the same split: the poses a serial fit of this arm holds out
        assert_eq!(t.held_out.count, v.test_configurations, "{arm}");
        assert!(t.held_out.rms < t.held_out_frames_only.rms, "{arm}: {t:?}");
    }
}

/// `, auto chose <candidate> (<RMS> / <RMS> mm)` of a cross-validated fit; empty otherwise.
fn chosen(choice: Option<&armcal::NonGeometricChoice>) -> String {
    choice.map_or(String::new(), |c| {
        let scores: Vec<String> = c
            .candidates
            .iter()
            .map(|s| {
                format!(
                    "{} {:.4} ± {:.4}",
                    s.candidate.words(),
                    s.held_out.rms,
                    s.standard_error
                )
            })
            .collect();
        format!(
            ", auto chose {} ({} mm)",
            c.chosen.words(),
            scores.join(" / ")
        )
    })
}
