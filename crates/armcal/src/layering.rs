//! The library's layering, checked on its sources: `report` only reads records, so no
//! module below it imports it; [`crate::workflow`] (and the CLI) compose a computation with
//! its report.

use std::path::Path;

/// Every `.rs` file under `dir` with its path relative to `src/`.
fn sources(dir: &Path, root: &Path, out: &mut Vec<(String, String)>) {
    for entry in std::fs::read_dir(dir).expect("readable src") {
        let path = entry.expect("dir entry").path();
        if path.is_dir() {
            sources(&path, root, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            let rel = path.strip_prefix(root).expect("under src");
            let text = std::fs::read_to_string(&path).expect("readable source");
            out.push((rel.display().to_string(), text));
        }
    }
}

#[test]
fn nothing_below_report_imports_it() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    sources(&root, &root, &mut files);
    assert!(files.len() > 50, "found {} sources", files.len());
    // Spelled in two pieces so that this file does not match itself.
    let needle = concat!("crate::", "report");
    let mut offenders = Vec::new();
    for (file, text) in &files {
        if file.starts_with("report") || file.starts_with("workflow") {
            continue;
        }
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            if code.contains(needle) {
                offenders.push(format!("{file}:{}: {}", n + 1, line.trim()));
            }
        }
    }
    assert!(
        offenders.is_empty(),
        "only `workflow` may import `report`:\n{}",
        offenders.join("\n")
    );
}
