//! A reflector that faces sideways (a frame target: `rpy_deg` gives its facing, the axis the
//! incidence limit is measured from) in a position-measuring cell (`measurement =
//! "position"`) is measured as a point: `simulate` writes no orientation columns, `plan`
//! takes the range noise model (it has no σ for rotation rows), and `identify` fits the
//! position rows its model analysis counted. Found in a new-user trial: the cell's
//! `measurement = "position"` was ignored and the fit of armcal's own simulation failed its
//! χ² test.

use crate::common::{armcal, scratch};

#[test]
fn a_facing_reflector_of_a_position_cell_is_measured_as_a_point() {
    let dir = scratch("facing-target");
    let paper = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/paper-cell.toml"
    ))
    .unwrap();
    let cell_text = paper
        .replace(
            "xyz_mm = [-89.58, -2.84, 327.03]   # reflector in the flange frame (paper Table 3)",
            "xyz_mm = [-89.58, -2.84, 327.03]\nrpy_deg = [0, 10, 0]",
        )
        .replace(
            "noise = { model = \"constant\", sigma_mm = 1.0 }",
            "noise = { model = \"range\", a_mm = 0.015, b_um_per_m = 6 }",
        );
    assert_ne!(cell_text, paper);
    let cell = dir.join("facing.toml");
    std::fs::write(&cell, &cell_text).unwrap();
    let (cell, design, data, est) = (
        cell.to_str().unwrap(),
        dir.join("design.csv"),
        dir.join("data.csv"),
        dir.join("estimate.json"),
    );
    let (ok, _, err) = armcal(&[
        "plan",
        "--cell",
        cell,
        "--poses",
        "30",
        "--out",
        design.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(ok, "{err}");
    let (ok, _, err) = armcal(&[
        "simulate",
        "--cell",
        cell,
        "--poses",
        design.to_str().unwrap(),
        "--out",
        data.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let header = std::fs::read_to_string(&data).unwrap();
    let header = header.lines().next().unwrap();
    assert!(!header.contains("roll"), "{header}");
    let (ok, out, err) = armcal(&[
        "identify",
        "--cell",
        cell,
        "--data",
        data.to_str().unwrap(),
        "--out",
        est.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(ok, "{err}");
    // 30 poses × 3 rows − 27 parameters.
    assert!(out.contains("63 dof"), "{out}");
    assert!(
        out.contains("the residuals agree with the stated σ"),
        "{out}"
    );
}
