//! Running the `armcal` binary from the repository root.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// Runs `armcal` with `args`; returns (success, stdout, stderr).
pub fn armcal(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_armcal"))
        .args(args)
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .output()
        .expect("run armcal");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A fresh scratch directory `name` under the test target directory.
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `armcal simulate` of the paper cell at the 60 planned example poses (measurable) with
/// noise `seed`, written to `out`.
pub fn simulate_paper_cell<'a>(seed: &'a str, out: &'a str) -> [&'a str; 9] {
    [
        "simulate",
        "--cell",
        "examples/paper-cell.toml",
        "--poses",
        "examples/paper-poses-planned-60.csv",
        "--seed",
        seed,
        "--out",
        out,
    ]
}

/// `armcal identify` of the paper cell from `data` with the `options`, written to `out`.
pub fn identify_paper_cell<'a>(data: &'a str, options: &[&'a str], out: &'a str) -> Vec<&'a str> {
    identify_cell("examples/paper-cell.toml", data, options, out)
}

/// `armcal identify` of `cell` from `data` with the `options`, written to `out`.
pub fn identify_cell<'a>(
    cell: &'a str,
    data: &'a str,
    options: &[&'a str],
    out: &'a str,
) -> Vec<&'a str> {
    let mut args = vec!["identify", "--cell", cell, "--data", data];
    args.extend_from_slice(options);
    args.extend(["--out", out]);
    args
}

/// The paper cell simulated at its 60 planned poses with seed 3 ([`simulate_paper_cell`])
/// and the estimate `identify` fits to them at the defaults: (data, estimate) paths, made
/// once per test run in the scratch directory `paper-seed-3`. Tests only read them.
pub fn paper_estimate() -> &'static (String, String) {
    static MADE: OnceLock<(String, String)> = OnceLock::new();
    MADE.get_or_init(|| {
        let dir = scratch("paper-seed-3");
        let path = |f: &str| dir.join(f).to_str().unwrap().to_string();
        let (data, est) = (path("data.csv"), path("estimate.json"));
        let (ok, _, err) = armcal(&simulate_paper_cell("3", &data));
        assert!(ok, "{err}");
        let (ok, _, err) = armcal(&identify_paper_cell(&data, &[], &est));
        assert!(ok, "{err}");
        (data, est)
    })
}

/// `examples/paper-cell.toml` without its zero incidence and line-of-sight margins (the
/// defaults apply), written to `dir`.
pub fn cell_with_default_margins(dir: &Path) -> PathBuf {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
    let text = std::fs::read_to_string(Path::new(root).join("examples/paper-cell.toml")).unwrap();
    let kept: Vec<&str> = text
        .lines()
        .filter(|l| *l != "incidence_margin_deg = 0" && *l != "line_of_sight_margin_mm = 0")
        .collect();
    assert_eq!(
        kept.len() + 2,
        text.lines().count(),
        "the paper cell's margins"
    );
    let path = dir.join("real-cell.toml");
    std::fs::write(&path, kept.join("\n") + "\n").unwrap();
    path
}

/// A variant of the paper cell, `text`, written to `dir/cell.toml`, simulated at the 60
/// planned example poses (noise `seed`; `--allow-unmeasurable` if `unmeasurable`) into
/// `dir/data.csv` and identified into `dir/estimate.json`; returns the three paths.
pub fn simulate_and_identify_variant(
    dir: &Path,
    text: &str,
    seed: &str,
    unmeasurable: bool,
) -> [String; 3] {
    let path = |f: &str| dir.join(f).to_str().unwrap().to_string();
    let [cell, data, est] = [path("cell.toml"), path("data.csv"), path("estimate.json")];
    std::fs::write(&cell, text).unwrap();
    let mut simulate = vec!["simulate", "--cell", &cell, "--poses"];
    simulate.extend(["examples/paper-poses-planned-60.csv", "--seed", seed]);
    if unmeasurable {
        simulate.push("--allow-unmeasurable");
    }
    simulate.extend(["--out", &data]);
    let (ok, _, err) = armcal(&simulate);
    assert!(ok, "{err}");
    let (ok, _, err) = armcal(&["identify", "--cell", &cell, "--data", &data, "--out", &est]);
    assert!(ok, "{err}");
    [cell, data, est]
}
