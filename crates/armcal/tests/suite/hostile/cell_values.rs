//! Issue 15: a cell's values out of range are refused where they are read (file, line, field
//! and the range), never passed on to panic or overflow later.

use armcal::cell::Cell;
use std::path::Path;

fn parse(text: &str) -> Result<Cell, String> {
    Cell::from_toml(text, "cell.toml", Path::new(".")).map_err(|e| e.to_string())
}

fn assert_refused(text: &str, field: &str, range: &str) {
    let e = parse(text).err().expect("the cell is refused");
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
