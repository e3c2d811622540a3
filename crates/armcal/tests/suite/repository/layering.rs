//! The library's top-level modules form layers: no import cycle between them, and `report`
//! (which only reads records) is imported by nothing below it. The test reads the `crate::…`
//! paths of every source file (code only: comments, `#[cfg(test)]` modules and `tests.rs`
//! files, which may use any fixture, are skipped) and fails on a cycle or a forbidden import, naming the files.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Modules allowed to import `report`: the ones above it.
const ABOVE_REPORT: &[&str] = &["workflow"];

/// The layers of docs/DESIGN.md, bottom first: a module imports only from lower layers.
const LAYERS: &[&[&str]] = &[
    &[
        "solve",
        "progress",
        "error",
        "json",
        "input",
        "table",
        "toml_text",
        "linalg",
    ],
    &["model", "geometry"],
    &["robots", "measure"],
    &["cell", "sim", "accuracy"],
    &["identify", "compensate"],
    &["design", "performance"],
    &["campaign"],
    &["study"],
    &["report"],
    &["workflow"],
];

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The top-level module a file under `src/` belongs to (`src/model/chain.rs` → `model`,
/// `src/error.rs` → `error`); `None` for `lib.rs`.
fn top_module(src: &Path, file: &Path) -> Option<String> {
    let rel = file.strip_prefix(src).unwrap();
    let first = rel.components().next()?.as_os_str().to_str()?.to_string();
    if first == "lib.rs" {
        return None;
    }
    Some(first.trim_end_matches(".rs").to_string())
}

/// The top-level modules named by `crate::X` paths in the code of `text`, up to its first
/// `#[cfg(test)]`.
fn imports(text: &str) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    for line in text.lines() {
        let code = line.trim_start();
        if code.starts_with("#[cfg(test)]") {
            break;
        }
        if code.starts_with("//") {
            continue;
        }
        let code = code.split("//").next().unwrap_or("");
        let mut rest = code;
        while let Some(at) = rest.find("crate::") {
            let after = &rest[at + "crate::".len()..];
            // `crate::{a::X, b::{Y, Z}}`: the first name of each top-level item in the braces.
            let heads: Vec<&str> = match after.strip_prefix('{') {
                Some(group) => top_level_items(group),
                None => vec![after],
            };
            for head in heads {
                let name: String = head
                    .trim_start()
                    .chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                    .collect();
                if name.chars().next().is_some_and(|c| c.is_ascii_lowercase()) {
                    found.insert(name);
                }
            }
            rest = after;
        }
    }
    found
}

/// The items of a brace group up to its closing brace, split at its top-level commas.
fn top_level_items(group: &str) -> Vec<&str> {
    let (mut depth, mut start, mut items) = (0usize, 0, Vec::new());
    for (i, c) in group.char_indices() {
        match c {
            '{' => depth += 1,
            '}' if depth == 0 => {
                items.push(&group[start..i]);
                return items;
            }
            '}' => depth -= 1,
            ',' if depth == 0 => {
                items.push(&group[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    items.push(&group[start..]);
    items
}

/// The edges between top-level modules, each with the files that make it.
fn module_graph() -> BTreeMap<String, BTreeMap<String, Vec<String>>> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    files.sort();
    let mut graph: BTreeMap<String, BTreeMap<String, Vec<String>>> = BTreeMap::new();
    for file in files {
        let Some(from) = top_module(&src, &file) else {
            continue;
        };
        if file.file_name().is_some_and(|n| n == "tests.rs") {
            continue;
        }
        let text = std::fs::read_to_string(&file).unwrap();
        let node = graph.entry(from.clone()).or_default();
        for to in imports(&text) {
            if to != from {
                let shown = file.strip_prefix(&src).unwrap().display().to_string();
                node.entry(to).or_default().push(shown);
            }
        }
    }
    graph
}

#[test]
fn no_import_cycle_between_top_level_modules() {
    let graph = module_graph();
    // Depth-first search for a back edge; reports the first cycle with the files of each edge.
    fn visit(
        m: &str,
        graph: &BTreeMap<String, BTreeMap<String, Vec<String>>>,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(at) = path.iter().position(|p| p == m) {
            let mut cycle = path[at..].to_vec();
            cycle.push(m.to_string());
            return Some(cycle);
        }
        if done.contains(m) {
            return None;
        }
        path.push(m.to_string());
        for next in graph
            .get(m)
            .map(|e| e.keys().cloned().collect::<Vec<_>>())
            .unwrap_or_default()
        {
            if let Some(c) = visit(&next, graph, path, done) {
                return Some(c);
            }
        }
        path.pop();
        done.insert(m.to_string());
        None
    }
    let mut done = BTreeSet::new();
    for m in graph.keys() {
        if let Some(cycle) = visit(m, &graph, &mut Vec::new(), &mut done) {
            let edges: Vec<String> = cycle
                .windows(2)
                .map(|w| format!("{} → {} ({})", w[0], w[1], graph[&w[0]][&w[1]].join(", ")))
                .collect();
            panic!(
                "import cycle between top-level modules:\n  {}",
                edges.join("\n  ")
            );
        }
    }
}

#[test]
fn every_import_goes_down_the_layers() {
    let layer = |m: &str| LAYERS.iter().position(|l| l.contains(&m));
    let graph = module_graph();
    let mut wrong = Vec::new();
    for (from, edges) in &graph {
        let Some(lf) = layer(from) else {
            wrong.push(format!(
                "`{from}` is in no layer of docs/DESIGN.md: add it to LAYERS"
            ));
            continue;
        };
        for (to, files) in edges {
            match layer(to) {
                Some(lt) if lt < lf => {}
                _ => wrong.push(format!(
                    "{from} → {to} goes up or sideways ({})",
                    files.join(", ")
                )),
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "imports against the layers:\n  {}",
        wrong.join("\n  ")
    );
}

#[test]
fn nothing_below_report_imports_it() {
    let graph = module_graph();
    let offenders: Vec<String> = graph
        .iter()
        .filter(|(from, _)| !ABOVE_REPORT.contains(&from.as_str()) && from.as_str() != "report")
        .filter_map(|(from, edges)| {
            edges
                .get("report")
                .map(|files| format!("{from} ({})", files.join(", ")))
        })
        .collect();
    assert!(
        offenders.is_empty(),
        "`report` only reads records; these modules import it: {}",
        offenders.join("; ")
    );
}

#[test]
fn the_import_reader_sees_paths_and_skips_comments_and_tests() {
    let text = "use crate::model::Model;\nuse crate::{design::{a, b}, measure::X};\n// crate::report is only mentioned\nfn f() { crate::cell::Cell::load(\"x\"); } // crate::sim\n#[cfg(test)]\nmod tests { use crate::robots; }\n";
    let found: Vec<String> = imports(text).into_iter().collect();
    assert_eq!(found, ["cell", "design", "measure", "model"]);
}
