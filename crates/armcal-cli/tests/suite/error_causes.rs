//! Errors that say the real cause (issue 12, item 7): each input below used to fail with a
//! misleading message, pass silently, or refuse what it should only warn about.

use crate::common::{armcal, scratch, simulate_paper_cell};
use std::path::Path;

/// The paper cell's text with `[[working]]` removed.
fn paper_cell_without_working_pose() -> String {
    let text = std::fs::read_to_string("../../examples/paper-cell.toml").unwrap();
    let start = text.find("[[working]]").unwrap();
    let end = text[start + 1..]
        .find("\n[")
        .map_or(text.len(), |e| start + 1 + e);
    format!("{}{}", &text[..start], &text[end..])
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

#[test]
fn the_exchange_names_the_cause_it_hit() {
    let dir = scratch("errors-exchange");
    let cell = write(&dir, "no-work.toml", &paper_cell_without_working_pose());
    let out = dir.join("d.csv").display().to_string();
    let (ok, _, err) = armcal(&[
        "plan",
        "--cell",
        &cell,
        "--criterion",
        "kpi",
        "--poses",
        "30",
        "--out",
        &out,
    ]);
    assert!(!ok);
    assert!(
        err.contains(
            "KPI criteria need at least one [[working]] configuration or [[working_path]]"
        ),
        "{err}"
    );
    assert!(!err.contains("no random set"), "{err}");
    // Below the minimum: the minimum is stated (27 free parameters, 3 rows per pose).
    let (ok, _, err) = armcal(&[
        "plan",
        "--cell",
        "examples/paper-cell.toml",
        "--poses",
        "3",
        "--out",
        &out,
    ]);
    assert!(!ok);
    assert!(err.contains("at least 9 poses are needed"), "{err}");
}

#[test]
fn a_bound_that_says_nothing_is_not_printed_as_an_efficiency() {
    let dir = scratch("errors-bound");
    let out = dir.join("d.csv").display().to_string();
    // With the fewest poses the bound found is weak; whatever it is, no negative efficiency.
    let (ok, stdout, err) = armcal(&[
        "plan",
        "--cell",
        "examples/paper-cell.toml",
        "--poses",
        "9",
        "--out",
        &out,
    ]);
    assert!(ok, "{err}");
    let line = stdout
        .lines()
        .find(|l| l.starts_with("optimality bound"))
        .unwrap();
    match line.split("efficiency ").nth(1) {
        Some(e) => assert!(e.trim().parse::<f64>().unwrap() > 0.0, "{line}"),
        None => assert!(line.contains("says nothing"), "{line}"),
    }
}

/// The paper cell's 60 example poses simulated, as lines of armcal's CSV.
fn simulated_lines(dir: &Path) -> Vec<String> {
    let data = dir.join("sim.csv").display().to_string();
    let (ok, _, err) = armcal(&simulate_paper_cell("1", &data));
    assert!(ok, "{err}");
    std::fs::read_to_string(&data)
        .unwrap()
        .lines()
        .map(String::from)
        .collect()
}

fn identify(dir: &Path, data: &str) -> (bool, String) {
    let out = dir.join(format!("{data}.json")).display().to_string();
    let data = dir.join(data).display().to_string();
    let (ok, _, err) = armcal(&[
        "identify",
        "--cell",
        "examples/paper-cell.toml",
        "--data",
        &data,
        "--out",
        &out,
        "--quiet",
    ]);
    (ok, err)
}

#[test]
fn sigma_columns_are_checked_and_a_noise_model_that_ignores_them_says_so() {
    let dir = scratch("errors-sigma");
    let lines = simulated_lines(&dir);
    let with_sigma = |bad_row: Option<usize>| -> String {
        let mut out = vec![format!("{},sigma_x_mm,sigma_y_mm,sigma_z_mm", lines[0])];
        for (i, l) in lines[1..].iter().enumerate() {
            let s = if Some(i) == bad_row {
                "0.1,-0.1,0.1"
            } else {
                "0.1,0.1,0.1"
            };
            out.push(format!("{l},{s}"));
        }
        out.join("\n") + "\n"
    };
    write(&dir, "bad.csv", &with_sigma(Some(2)));
    let (ok, err) = identify(&dir, "bad.csv");
    assert!(!ok);
    assert!(
        err.contains("bad.csv: line 4: `sigma_y_mm` = -0.1") && err.contains("cannot be negative"),
        "{err}"
    );
    // The paper cell's noise model is constant: the σ columns are read but not used, and
    // the user is told.
    write(&dir, "good.csv", &with_sigma(None));
    let (ok, err) = identify(&dir, "good.csv");
    assert!(ok, "{err}");
    assert!(
        err.contains("60 of the 60 measurements") && err.contains("not used"),
        "{err}"
    );
}

#[test]
fn data_joints_past_a_limit_warn_a_little_and_refuse_far_naming_file_line_and_joint() {
    let dir = scratch("errors-limits");
    let lines = simulated_lines(&dir);
    let with_q1 = |value: &str| -> String {
        let mut out = lines.clone();
        let mut fields: Vec<&str> = out[5].split(',').collect();
        fields[1] = value;
        out[5] = fields.join(",");
        out.join("\n") + "\n"
    };
    // q1's limits are ±82°.
    write(&dir, "near.csv", &with_q1("82.5"));
    let (ok, err) = identify(&dir, "near.csv");
    // The changed row no longer matches its measured point: the fit checks (issue 30 item 4)
    // name it as a blunder and refuse the fit; the limit warning comes first.
    assert!(!ok && err.contains("blunders: line 6 (pose `5`)"), "{err}");
    assert!(
        err.contains("warning: ")
            && err.contains(
                "near.csv: line 6: joint `q1` = 82.5000 deg is 0.5000 deg past its limits"
            ),
        "{err}"
    );
    write(&dir, "far.csv", &with_q1("120"));
    let (ok, err) = identify(&dir, "far.csv");
    assert!(!ok);
    assert!(
        err.contains("far.csv: line 6: joint `q1` = 120.0000 deg is 38.0000 deg past")
            && err.contains("unit"),
        "{err}"
    );
}

#[test]
fn cell_and_model_inputs_that_were_missing_checks() {
    let dir = scratch("errors-inputs");
    let (ok, _, err) = armcal(&["model", "paper", "--poses", "0"]);
    assert!(!ok && err.contains("--poses"), "{err}");
    let cell = write(
        &dir,
        "w.toml",
        "[robot]\nbuiltin = \"paper\"\n[[working]]\nname = \"w\"\njoints_deg = \"0 0 0 0 0 0\"\n",
    );
    let (ok, _, err) = armcal(&["model", &cell]);
    assert!(
        !ok && err.contains("`working[0].joints_deg`: must be an array of 6 numbers"),
        "{err}"
    );
    let cell = write(
        &dir,
        "inv.toml",
        "[robot]\nbuiltin = \"paper\"\nlimits = { q1 = [50, -50] }\n",
    );
    let (ok, _, err) = armcal(&["model", &cell]);
    assert!(
        !ok && err.contains("inv.toml: line 1: `robot.limits.q1`")
            && err.contains("lower limit 50 deg is above the upper limit -50 deg"),
        "{err}"
    );
    let joint = |parent: &str, child: &str| {
        format!(
            "<joint name=\"j\" type=\"revolute\"><parent link=\"{parent}\"/><child link=\"{child}\"/>\
             <origin xyz=\"0 0 0.1\" rpy=\"0 0 0\"/><axis xyz=\"0 0 1\"/>\
             <limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint>"
        )
    };
    write(&dir, "dup.urdf", &format!(
        "<robot name=\"dup\"><link name=\"base\"/><link name=\"l1\"/><link name=\"l2\"/>{}{}</robot>",
        joint("base", "l1"),
        joint("l1", "l2")
    ));
    let cell = write(&dir, "dup.toml", "[robot]\nurdf = \"dup.urdf\"\n");
    let (ok, _, err) = armcal(&["model", &cell]);
    assert!(!ok && err.contains("two joints are named `j`"), "{err}");
}

/// A URDF the XML parser under urdf-rs panics on (found by fuzz/urdf, issue 15) gives
/// armcal's error and nothing of the parser's panic.
#[test]
fn a_urdf_the_parser_panics_on_gives_only_the_error() {
    let dir = scratch("error-causes-urdf-panic");
    write(
        &dir,
        "bad.urdf",
        "<robot name=\"r\"><link name=\"a\"/><link name=\"b\"/><joint name=\"q1\" type=\"revolute\">\
         <parent link=\"a\"/><child link=\"b\"/><limit xmlns=\"0\" upper=\"0\" effort=\"0\":velocity=\"0\"/>\
         </joint></robot>",
    );
    let cell = write(&dir, "bad.toml", "[robot]\nurdf = \"bad.urdf\"\n");
    let (ok, _, err) = armcal(&["model", &cell]);
    assert!(!ok && err.contains("not a valid URDF document"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

/// A pose to simulate beyond a joint limit is refused with the file, line, pose and joint.
#[test]
fn a_pose_beyond_a_limit_names_its_file_and_line() {
    let dir = scratch("error-causes-pose-limits");
    let poses = write(
        &dir,
        "poses.csv",
        "pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\n\
         a,0,-30,30,0,-60,0\nb,100,-30,30,0,-60,0\n",
    );
    let out = dir.join("data.csv");
    let (ok, _, err) = armcal(&[
        "simulate",
        "--cell",
        "examples/paper-cell.toml",
        "--poses",
        &poses,
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        !ok && err.contains(
            "poses.csv: line 3 (pose `b`): joint `q1` = 100.0000 deg is outside its limits"
        ),
        "{err}"
    );
    assert!(!out.exists());
}
