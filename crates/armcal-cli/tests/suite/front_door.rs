//! The CLI uses only the library's front door (issue 34): a command file names root items
//! (`armcal::identify`, `armcal::Dataset`, …), never `armcal::<module>::…` (the budget of
//! such paths, once 81, is 0).

use std::path::Path;

/// Every `armcal::<module>::` in `text` (the re-exported `nalgebra` crate is a root item).
fn module_paths(text: &str) -> Vec<String> {
    let mut found = Vec::new();
    for (at, _) in text.match_indices("armcal::") {
        let rest = &text[at + "armcal::".len()..];
        // `armcal::{a::X, b}`: each top-level item of the group.
        if let Some(group) = rest.strip_prefix('{') {
            let mut depth = 0;
            let mut item = String::new();
            for c in group.chars() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => item.clear(),
                    _ if depth == 0 => item.push(c),
                    _ => {}
                }
                let head = item.trim();
                if let Some(name) = head.strip_suffix("::") {
                    if name.starts_with(|c: char| c.is_ascii_lowercase()) && name != "nalgebra" {
                        found.push(format!("armcal::{name}::"));
                    }
                    item.clear();
                    item.push('!');
                }
            }
            continue;
        }
        let name: String = rest
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect();
        let lower = name.chars().next().is_some_and(|c| c.is_ascii_lowercase());
        if lower && name != "nalgebra" && rest[name.len()..].starts_with("::") {
            found.push(format!("armcal::{name}::"));
        }
    }
    found
}

#[test]
fn commands_name_only_root_items() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/commands");
    let mut all = Vec::new();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        all.extend(
            module_paths(&text)
                .into_iter()
                .map(|p| format!("{name}: {p}")),
        );
    }
    all.sort();
    println!("{} module paths in the command files", all.len());
    assert!(
        all.is_empty(),
        "the command files name {} `armcal::<module>::` paths: call the front door (a root \
         item of crates/armcal/src/lib.rs) instead:\n{}",
        all.len(),
        all.join("\n")
    );
}

#[test]
fn a_module_path_is_found() {
    assert_eq!(
        module_paths(
            "use armcal::measure::csv; armcal::Dataset armcal::nalgebra::Vector3 \
             use armcal::{sim::{a, b}, Cell, model::X};"
        ),
        ["armcal::measure::", "armcal::sim::", "armcal::model::"]
    );
}

/// `ARMCAL_MAX_INPUT_MIB` is the command line's default of the library's input caps
/// ([`armcal::set_input_limits`]): 0 MiB refuses any cell file, and the message says how to
/// raise the cap.
#[test]
fn the_environment_sets_the_input_caps() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_armcal"))
        .args(["model", "examples/paper-cell.toml"])
        .env("ARMCAL_MAX_INPUT_MIB", "0")
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("larger than 0 MiB") && stderr.contains("ARMCAL_MAX_INPUT_MIB"),
        "{stderr}"
    );
    let (ok, _, stderr) = crate::common::armcal(&["model", "examples/paper-cell.toml"]);
    assert!(ok, "{stderr}");
}
