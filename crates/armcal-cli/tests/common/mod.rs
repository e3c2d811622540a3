//! Running the `armcal` binary from the repository root.
#![allow(dead_code)]

use std::process::Command;

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
