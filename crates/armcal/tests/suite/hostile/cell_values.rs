//! Issue 15: a cell's values out of range are refused where they are read (file, line, field
//! and the range), never passed on to panic or overflow later.

use armcal::Cell;
use std::path::Path;

fn parse(text: &str) -> Result<Cell, String> {
    Cell::from_toml(text, "cell.toml", Path::new(".")).map_err(|e| e.to_string())
}

fn assert_refused(text: &str, field: &str, range: &str) {
    let Err(e) = parse(text) else {
        panic!("the cell was not refused")
    };
    assert!(e.contains("cell.toml") && e.contains("line "), "{e}");
    assert!(e.contains(&format!("`{field}`")), "{e}");
    assert!(e.contains(range), "{e}");
}

/// Found #1: an infinite (or NaN) limit override panicked in the configuration sampler.
#[test]
fn infinite_limit_override_is_a_cell_error() {
    for v in ["inf", "-inf", "nan"] {
        let text = format!("[robot]\nbuiltin = \"paper\"\nlimits = {{ q1 = [0, {v}] }}\n");
        assert_refused(&text, "robot.limits.q1", "|x| ≤ 3600 deg");
    }
}

/// Found #2: huge link lengths overflowed the conversions (and emptied the identifiability
/// partners list).
#[test]
fn huge_builtin_lengths_are_a_cell_error() {
    assert_refused(
        "[robot]\nbuiltin = \"paper-1e155-1\"\n",
        "robot.builtin",
        "|x| ≤ 1000000 mm",
    );
}

/// Also: `x_m = 1e306` is finite but infinite in mm; the range is checked after converting.
#[test]
fn inline_lengths_are_checked_after_unit_conversion() {
    let text = r#"
[robot]
[[robot.links]]
name = "j1"
convention = "dh"
joint = "revolute"
limits = [-170, 170]
theta_deg = 0
d_m = 1e306
a_mm = 500
alpha_deg = 0
"#;
    assert_refused(text, "robot.links[0]", "|x| ≤ 1000000 mm");
}

/// Also: the instrument's placement and frames are checked after converting too.
#[test]
fn instrument_and_target_placements_are_checked_after_unit_conversion() {
    assert_refused(
        "[robot]\nbuiltin = \"paper\"\n[instrument]\nxyz_m = [1e306, 0, 0]\n",
        "instrument",
        "|x| ≤ 1000000 mm",
    );
    assert_refused(
        "[robot]\nbuiltin = \"paper\"\n[[targets]]\nxyz_m = [1e306, 0, 0]\n",
        "targets[0]",
        "|x| ≤ 1000000 mm",
    );
}

/// Also: a prior pattern over parameters of different units took the first one's unit.
#[test]
fn a_prior_pattern_over_mixed_units_is_an_error_naming_them() {
    let text =
        "[robot]\nbuiltin = \"paper\"\n[parameters]\npriors = { \"j2.*\" = { sigma_mm = 0.1 } }\n";
    let Err(e) = parse(text) else {
        panic!("the cell was not refused")
    };
    assert!(e.contains("`parameters.priors.j2.*`"), "{e}");
    assert!(
        e.contains("different units") && e.contains("(deg)") && e.contains("(mm)"),
        "{e}"
    );
}
