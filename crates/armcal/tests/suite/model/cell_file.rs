//! Cell files: a full inline example loads; every kind of mistake gives file, line and field.

use armcal::cell::Obstacle;
use armcal::measure::NoiseModel;
use armcal::{Cell, ParameterStatus};
use std::path::Path;

fn parse(text: &str) -> Result<Cell, String> {
    Cell::from_toml(text, "cell.toml", Path::new(".")).map_err(|e| e.to_string())
}

const INLINE: &str = r#"
name = "two-link"

[robot]
name = "planar-2r"
[[robot.links]]
name = "j1"
convention = "dh"
joint = "revolute"
limits = [-170, 170]
theta_deg = 0
d_mm = 400
a_mm = 500
alpha_deg = 0
[[robot.links]]
name = "j2"
convention = "mdh"
joint = "prismatic"
limits = [0, 300]
alpha_deg = 90
a_m = 0.1
theta_deg = 0
d_mm = 0

[instrument]
xyz_m = [2, 0, 0]
rpy_deg = [0, 0, 180]
noise = { model = "range", a_mm = 0.015, b_um_per_m = 6 }

[[targets]]
name = "ball"
xyz_mm = [0, 0, 50]

[parameters]
free = ["j1", "j2.a", "tracker", "ball"]
priors = { "j1.alpha" = { sigma_deg = 0.1 } }

[[working]]
joints_deg = [10, 150]

[[obstacles]]
kind = "half-space"
normal = [0, 0, 2]
offset_mm = -100
"#;

#[test]
fn inline_robot_with_units_loads() {
    let cell = parse(INLINE).unwrap();
    let m = &cell.model;
    assert_eq!(m.dof(), 2);
    let get = |n: &str| m.registry.get(m.registry.index_of(n).unwrap());
    assert_eq!(get("j2.a").nominal, 100.0, "0.1 m is 100 mm");
    assert!((get("j2.alpha").nominal - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    assert_eq!(get("tracker.x").nominal, 2000.0);
    assert_eq!(
        get("j2.alpha").status,
        ParameterStatus::Fixed,
        "not in the free list"
    );
    assert_eq!(get("j2.a").status, ParameterStatus::Free);
    match get("j1.alpha").status {
        ParameterStatus::Prior { sigma } => assert!((sigma - 0.1f64.to_radians()).abs() < 1e-15),
        s => panic!("expected a prior, got {s:?}"),
    }
    // Prismatic working value stays in mm; revolute in degrees → rad.
    assert!((cell.working[0].q[0] - 10f64.to_radians()).abs() < 1e-15);
    assert_eq!(cell.working[0].q[1], 150.0);
    let inst = cell.instrument.as_ref().unwrap();
    assert_eq!(
        inst.noise,
        NoiseModel::Range {
            a: 0.015,
            b_per_m: 0.006
        }
    );
    match &cell.obstacles[0] {
        Obstacle::HalfSpace { normal, offset, .. } => {
            assert_eq!(*normal, [0.0, 0.0, 1.0]);
            assert_eq!(*offset, -100.0);
        }
        o => panic!("{o:?}"),
    }
    assert!(!cell.auto_free);
}

fn expect_error(text: &str, needles: &[&str]) {
    let e = parse(text).expect_err("must fail");
    for n in needles {
        assert!(e.contains(n), "error `{e}` should mention `{n}`");
    }
}

#[test]
fn errors_name_file_line_and_field() {
    // Unit suffix missing: the field and the line of the link.
    let bad = INLINE.replace("a_mm = 500", "a = 500");
    expect_error(&bad, &["cell.toml", "line 6", "robot.links[0]", "a_mm"]);
    // Unknown convention.
    let bad = INLINE.replace("convention = \"mdh\"", "convention = \"dhx\"");
    expect_error(
        &bad,
        &["line 15", "robot.links[1]", "unknown convention `dhx`"],
    );
    // Unknown built-in robot.
    expect_error(
        "[robot]\nbuiltin = \"kr9000\"\n",
        &["line 1", "robot.builtin", "kr9000"],
    );
    // Typo in a top-level key: toml's own error with line.
    expect_error(
        "[robot]\nbuiltin = \"paper\"\n[instrumnet]\n",
        &["cell.toml", "instrumnet"],
    );
    // Wrong number of working joints.
    let bad = INLINE.replace("joints_deg = [10, 150]", "joints_deg = [10]");
    expect_error(&bad, &["working[0].joints_deg", "1 values", "2 joints"]);
    // Unknown parameter pattern.
    let bad = INLINE.replace("\"j2.a\"", "\"j2.q\"");
    expect_error(
        &bad,
        &["parameters", "unknown parameter `j2.q`", "j2.alpha"],
    );
    // Noise model.
    let bad = INLINE.replace("model = \"range\"", "model = \"gauss\"");
    expect_error(&bad, &["instrument.noise", "unknown noise model `gauss`"]);
    // Limits reversed.
    let bad = INLINE.replace("limits = [-170, 170]", "limits = [170, -170]");
    expect_error(&bad, &["lower limit"]);
    // Two robot sources.
    expect_error(
        "[robot]\nbuiltin = \"paper\"\nurdf = \"x.urdf\"\n",
        &["exactly one of"],
    );
    // Capsule on a frame the robot does not have.
    let bad = format!("{INLINE}\n[[tool_capsules]]\nframe = \"j9\"\na_mm = [0,0,0]\nb_mm = [0,0,1]\nradius_mm = 5\n");
    expect_error(&bad, &["j9"]);
}

/// A link written with `limits` but without `joint` was silently a fixed link (two of them in
/// a row failed as "frame name `j0` is used twice"): the user meant a joint.
#[test]
fn limits_without_a_joint_kind_are_an_error_and_fixed_links_get_their_own_names() {
    let bad = INLINE.replace("joint = \"revolute\"\n", "");
    expect_error(
        &bad,
        &[
            "cell.toml",
            "robot.links[0]",
            "`limits` without `joint`",
            "joint = \"revolute\"",
        ],
    );
    // Two unnamed fixed links (a mounting plate and an adapter) before two unnamed joints:
    // each gets a name of its own, and the joints keep j1, j2.
    let fixed = "[[robot.links]]\nconvention = \"dh\"\ntheta_deg = 0\nd_mm = 100\na_mm = 0\nalpha_deg = 0\n";
    let joint = "[[robot.links]]\nconvention = \"dh\"\njoint = \"revolute\"\nlimits = [-90, 90]\ntheta_deg = 0\nd_mm = 0\na_mm = 300\nalpha_deg = 0\n";
    let text = format!(
        "name = \"plated\"\n[robot]\nname = \"plated-2r\"\n{fixed}{fixed}{joint}{joint}[[targets]]\nname = \"smr\"\nxyz_mm = [50, 0, 0]\n"
    );
    let cell = parse(&text).unwrap();
    assert_eq!(cell.model.dof(), 2);
    for name in ["fixed1.d", "fixed2.d", "j1.a", "j2.a"] {
        assert!(
            cell.model.registry.index_of(name).is_some(),
            "no parameter `{name}`"
        );
    }
}

#[test]
fn working_pose_outside_limits_is_kept_with_a_warning() {
    let text = INLINE.replace("joints_deg = [10, 150]", "joints_deg = [10, 400]");
    let cell = parse(&text).unwrap();
    assert_eq!(cell.warnings.len(), 1);
    assert!(
        cell.warnings[0].contains("outside its limits"),
        "{}",
        cell.warnings[0]
    );
}

#[test]
fn a_cell_can_use_a_urdf_robot() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("urdf-cell");
    std::fs::create_dir_all(&dir).unwrap();
    // The paper robot exported to URDF, then used by a cell next to it.
    let paper = armcal::robots::robot("paper").unwrap();
    std::fs::write(
        dir.join("arm.urdf"),
        armcal::model::urdf::to_urdf(&paper.spec).unwrap(),
    )
    .unwrap();
    let text =
        "[robot]\nurdf = \"arm.urdf\"\n\n[[targets]]\nname = \"smr1\"\nxyz_mm = [0, 0, 100]\n";
    std::fs::write(dir.join("cell.toml"), text).unwrap();
    let cell = Cell::from_file(&dir.join("cell.toml")).unwrap();
    assert_eq!(cell.model.dof(), 6);
    assert!(
        (cell.model.joints[1].upper - 31f64.to_radians()).abs() < 1e-12,
        "limits kept"
    );
    let e = Cell::from_toml("[robot]\nurdf = \"missing.urdf\"\n", "c.toml", &dir)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("robot.urdf") && e.contains("missing.urdf"),
        "{e}"
    );
}

#[test]
fn a_misspelt_key_is_named_as_unknown_not_as_a_missing_field() {
    // A wrong unit suffix or a typo in a required field: the error names the key the user
    // wrote (the missing field is its consequence), at the link's line.
    for (from, to, unknown) in [
        ("d_mm = 400", "d_in = 400", "`d_in`"),
        (
            "alpha_deg = 0\n[[robot.links]]",
            "alpah_deg = 0\n[[robot.links]]",
            "`alpah_deg`",
        ),
        ("xyz_mm = [0, 0, 50]", "xyz_cm = [0, 0, 5]", "`xyz_cm`"),
        ("offset_mm = -100", "offset_in = -4", "`offset_in`"),
        ("a_mm = 0.015", "a_um = 15", "`a_um`"),
        ("sigma_deg = 0.1", "sigma_arcmin = 6", "`sigma_arcmin`"),
    ] {
        assert!(INLINE.contains(from), "{from}");
        let bad = INLINE.replacen(from, to, 1);
        expect_error(&bad, &["cell.toml", "unknown field", unknown, "valid here"]);
    }
    // Without a stray key, a missing field is still reported as missing.
    let bad = INLINE.replace("d_mm = 400\n", "");
    expect_error(&bad, &["line 6", "robot.links[0]", "missing `d_mm`"]);
}

#[test]
fn duplicate_names_and_an_unknown_instrument_kind_are_errors() {
    let twice = |section: &str| format!("{INLINE}\n{section}\n{section}\n");
    expect_error(
        &twice("[[working]]\nname = \"w\"\njoints_deg = [0, 10]"),
        &[
            "working[2]",
            "working pose name `w` is used twice",
            "first at line",
        ],
    );
    expect_error(
        &twice("[[working_path]]\nname = \"p\"\njoints_deg = [[0, 10]]"),
        &["working_path[1]", "working path name `p` is used twice"],
    );
    expect_error(
        &twice("[[obstacles]]\nname = \"wall\"\nkind = \"half-space\"\nnormal = [1, 0, 0]\noffset_mm = -900"),
        &["obstacles[2]", "obstacle name `wall` is used twice"],
    );
    // The unnamed default names count too: `obstacle1` is the first obstacle's.
    expect_error(
        &twice("[[obstacles]]\nname = \"obstacle1\"\nkind = \"half-space\"\nnormal = [1, 0, 0]\noffset_mm = -900"),
        &["obstacles[1]", "obstacle name `obstacle1` is used twice"],
    );
    expect_error(
        &twice("[[targets]]\nname = \"ball\"\nxyz_mm = [0, 0, 9]"),
        &[
            "line 46",
            "targets[1]",
            "target name `ball` is used twice (first at line 30)",
        ],
    );
    let bad = INLINE.replace("[instrument]\n", "[instrument]\nkind = \"laser-traker\"\n");
    expect_error(
        &bad,
        &[
            "instrument.kind",
            "unknown instrument kind `laser-traker`",
            "laser-tracker",
        ],
    );
    for kind in ["laser-tracker", "cmm"] {
        let good = INLINE.replace(
            "[instrument]\n",
            &format!("[instrument]\nkind = \"{kind}\"\n"),
        );
        assert_eq!(parse(&good).unwrap().instrument.unwrap().kind, kind);
    }
}
