//! README and user-guide transcripts are real (issue 12 item 11, issue 31): every
//! ```` ```text ```` block of README.md and of every page of the guide (`docs/src/`, the pages
//! in `SUMMARY.md` order) whose lines start with `$ ` is run, and each command's output
//! (stdout and stderr, as a terminal shows them) must be what the page prints under it.
//!
//! README runs in a scratch folder of its own (a newcomer's first commands); the guide's pages
//! run one after another in one shared scratch folder, in `SUMMARY.md` order, as a reader who
//! goes through the guide: a page may use what an earlier page wrote (`out/estimate.json` of
//! "Identify" in "Compensation and exports"), as the tutorial always has, and no page repeats
//! the setup of the pages before it. Each folder sees the repository's `examples/` and `data/`.
//!
//! A page may leave out lines: a line that is only `…` stands for any number of lines, and a
//! line ending in ` …` for a line that begins with what precedes the `…`. Durations
//! (`0.55 s`, `0.9 ms`) are compared as "a duration", since they change from run to run.

use super::common::scratch;
use std::path::Path;
use std::process::Command;

/// One `$ command` of a page's text block and the lines the page shows under it.
struct Transcript {
    /// Line of the command.
    line: usize,
    command: String,
    expected: Vec<String>,
}

/// The transcripts of a page's text blocks, in document order.
fn transcripts(readme: &str) -> Vec<Transcript> {
    let mut out: Vec<Transcript> = Vec::new();
    let mut in_text_block = false;
    // Whether the last transcript of `out` is the one the current line belongs to.
    let mut collecting = false;
    for (i, line) in readme.lines().enumerate() {
        if line.starts_with("```") {
            in_text_block = line == "```text" && !in_text_block;
            collecting = false;
        } else if let Some(command) = line.strip_prefix("$ ").filter(|_| in_text_block) {
            out.push(Transcript {
                line: i + 1,
                command: command.to_string(),
                expected: Vec::new(),
            });
            collecting = true;
        } else if let Some(t) = out.last_mut().filter(|_| collecting) {
            t.expected.push(line.to_string());
        }
    }
    for t in &mut out {
        while t.expected.last().is_some_and(|l| l.trim().is_empty()) {
            t.expected.pop();
        }
    }
    out
}

/// `line` with every duration (a number followed by ` s` or ` ms`) replaced by `<duration>`.
fn without_durations(line: &str) -> String {
    let chars: Vec<char> = line.chars().collect();
    let mut out = String::with_capacity(line.len());
    let mut i = 0;
    while i < chars.len() {
        let starts_number =
            chars[i].is_ascii_digit() && (i == 0 || !chars[i - 1].is_alphanumeric());
        if starts_number {
            let mut j = i;
            while j < chars.len() && (chars[j].is_ascii_digit() || chars[j] == '.') {
                j += 1;
            }
            let rest: String = chars[j..].iter().take(4).collect();
            let unit = [" ms", " s"].into_iter().find(|u| {
                rest.starts_with(u)
                    && chars
                        .get(j + u.chars().count())
                        .is_none_or(|c| !c.is_alphanumeric())
            });
            if let Some(u) = unit {
                out.push_str("<duration>");
                i = j + u.chars().count();
                continue;
            }
            out.extend(&chars[i..j]);
            i = j;
            continue;
        }
        out.push(chars[i]);
        i += 1;
    }
    out
}

/// Whether the page's `expected` line stands for the printed line `actual`.
fn line_matches(expected: &str, actual: &str) -> bool {
    let (e, a) = (without_durations(expected), without_durations(actual));
    match e.strip_suffix(" …") {
        Some(prefix) => a.starts_with(prefix),
        None => e == a,
    }
}

/// Whether `segment` matches `actual` line by line from its start.
fn segment_at(segment: &[String], actual: &[String]) -> bool {
    segment.len() <= actual.len() && segment.iter().zip(actual).all(|(e, a)| line_matches(e, a))
}

/// Whether the `expected` transcript (with `…` lines standing for any lines) is `actual`.
fn transcript_matches(expected: &[String], actual: &[String]) -> bool {
    let segments: Vec<&[String]> = expected.split(|l| l == "…").collect();
    let (first, rest) = segments
        .split_first()
        .expect("split gives one segment at least");
    if !segment_at(first, actual) {
        return false;
    }
    if rest.is_empty() {
        return first.len() == actual.len();
    }
    let (last, middle) = rest.split_last().expect("rest is not empty");
    let mut at = first.len();
    for segment in middle {
        match (at..=actual.len()).find(|&k| segment_at(segment, &actual[k..])) {
            Some(k) => at = k + segment.len(),
            None => return false,
        }
    }
    actual.len() >= at + last.len() && segment_at(last, &actual[actual.len() - last.len()..])
}

/// The repository's root.
fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

/// The guide's pages (paths relative to `docs/src/`) in the order `SUMMARY.md` lists them.
fn summary_pages() -> Vec<String> {
    let summary =
        std::fs::read_to_string(root().join("docs/src/SUMMARY.md")).expect("docs/src/SUMMARY.md");
    let mut pages: Vec<String> = Vec::new();
    for line in summary.lines() {
        for (k, _) in line.match_indices("](") {
            let rest = &line[k + 2..];
            let Some(end) = rest.find(')') else { continue };
            let page = rest[..end].to_string();
            if page.ends_with(".md") && !pages.contains(&page) {
                pages.push(page);
            }
        }
    }
    pages
}

/// Every Markdown file under `dir`, relative to `base`, sorted.
fn markdown_files(base: &Path, dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).expect("a folder of the guide") {
        let path = entry.expect("a folder entry").path();
        if path.is_dir() {
            out.extend(markdown_files(base, &path));
        } else if path.extension().is_some_and(|e| e == "md") {
            let relative = path.strip_prefix(base).expect("under the base");
            out.push(relative.to_string_lossy().into_owned());
        }
    }
    out.sort();
    out
}

/// The documents whose transcripts run, each as (name shown in failures, text): README.md
/// alone, then the guide's pages with a `$ armcal` line in `SUMMARY.md` order. A page with
/// such a line that `SUMMARY.md` does not list (so the reader would never see it, and its place
/// in the shared folder's order is undefined) or a listed page that does not exist is an error.
fn guide_documents() -> Vec<(String, String)> {
    let src = root().join("docs/src");
    let listed = summary_pages();
    let has_transcript = |text: &str| !transcripts(text).is_empty();
    let mut problems = Vec::new();
    for page in markdown_files(&src, &src) {
        let text = std::fs::read_to_string(src.join(&page)).expect("a guide page");
        if has_transcript(&text) && !listed.contains(&page) {
            problems.push(format!(
                "docs/src/{page} has `$ ` transcripts but is not in docs/src/SUMMARY.md"
            ));
        }
    }
    let mut documents = Vec::new();
    for page in &listed {
        match std::fs::read_to_string(src.join(page)) {
            Ok(text) if has_transcript(&text) => documents.push((format!("docs/src/{page}"), text)),
            Ok(_) => {}
            Err(e) => problems.push(format!("docs/src/SUMMARY.md lists {page}: {e}")),
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    documents
}

/// A scratch folder `name` with `bin/armcal`, `out/` and links to the repository's `examples/`
/// and `data/`; returns it and the `PATH` that finds `armcal` there.
fn transcript_folder(name: &str) -> (std::path::PathBuf, String) {
    let dir = scratch(name);
    let bin = dir.join("bin");
    std::fs::create_dir_all(dir.join("out")).expect("out/");
    std::fs::create_dir_all(&bin).expect("bin/");
    std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_armcal"), bin.join("armcal")).expect("armcal");
    for folder in ["examples", "data"] {
        std::os::unix::fs::symlink(
            root().join(folder).canonicalize().unwrap(),
            dir.join(folder),
        )
        .expect("a link to the repository's folder");
    }
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    (dir, path)
}

/// Runs the transcripts of `documents` in order in the folder `name`; returns a message per
/// transcript whose output differs, naming the document and line.
fn run_transcripts(name: &str, documents: &[(String, String)]) -> Vec<String> {
    let (dir, path) = transcript_folder(name);
    let mut failures = Vec::new();
    for (document, text) in documents {
        let start = std::time::Instant::now();
        for t in transcripts(text) {
            let out = Command::new("sh")
                .arg("-c")
                .arg(format!("{} 2>&1", t.command))
                .current_dir(&dir)
                .env("PATH", &path)
                .output()
                .expect("run sh");
            let text = String::from_utf8_lossy(&out.stdout);
            let mut actual: Vec<String> = text.lines().map(str::to_string).collect();
            while actual.last().is_some_and(|l| l.trim().is_empty()) {
                actual.pop();
            }
            if !transcript_matches(&t.expected, &actual) {
                failures.push(format!(
                    "{document} line {}: `$ {}`\n--- the page shows:\n{}\n--- the command prints:\n{}",
                    t.line,
                    t.command,
                    t.expected.join("\n"),
                    actual.join("\n")
                ));
            }
        }
        eprintln!("{document}: {:.1} s", start.elapsed().as_secs_f64());
    }
    failures
}

#[test]
fn readme_and_guide_transcripts_are_what_the_commands_print() {
    let readme = std::fs::read_to_string(root().join("README.md")).expect("README.md");
    assert!(
        transcripts(&readme)
            .iter()
            .any(|t| t.command.starts_with("armcal ")),
        "README has a worked example"
    );
    let guide = guide_documents();
    let commands: Vec<String> = guide
        .iter()
        .flat_map(|(_, text)| transcripts(text).into_iter().map(|t| t.command))
        .collect();
    assert!(
        commands.iter().any(|c| c == "armcal demo")
            && commands.iter().any(|c| c.starts_with("armcal model ")),
        "the guide has the demo's and the model's transcripts"
    );
    eprintln!(
        "transcripts: README.md and {} guide pages: {}",
        guide.len(),
        guide
            .iter()
            .map(|(name, _)| name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    );
    // README and the guide in two threads: the two folders share nothing.
    let readme_run = std::thread::spawn(move || {
        run_transcripts("readme-transcripts", &[("README.md".to_string(), readme)])
    });
    let mut failures = run_transcripts("guide-transcripts", &guide);
    failures.extend(readme_run.join().expect("README's transcripts"));
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

#[test]
fn the_transcript_matcher_checks_what_it_should() {
    let lines = |s: &str| -> Vec<String> { s.lines().map(str::to_string).collect() };
    let actual = lines("a\nb in 0.55 s\nc\nd\ne");
    assert!(transcript_matches(
        &lines("a\nb in 3.1 s\nc\nd\ne"),
        &actual
    ));
    assert!(transcript_matches(&lines("a\n…\nd\ne"), &actual));
    assert!(transcript_matches(&lines("a\n…\nc\n…"), &actual));
    assert!(transcript_matches(&lines("a\nb …\n…\ne"), &actual));
    assert!(
        !transcript_matches(&lines("a\nb in 0.55 s\nc"), &actual),
        "a missing tail"
    );
    assert!(
        !transcript_matches(&lines("a\n…\nc\nb …"), &actual),
        "out of order"
    );
    assert!(
        !transcript_matches(&lines("b …\n…"), &actual),
        "a missing first line"
    );
    assert!(
        !transcript_matches(&lines("a\n…\nx\n…"), &actual),
        "a line not printed"
    );
    assert_eq!(
        without_durations("v2 60 poses (0.6 s), 9 ms, 3 sweeps"),
        "v2 60 poses (<duration>), <duration>, 3 sweeps"
    );
}

/// The joint names the non-geometric examples of README and the guide use (`compliance = ["q2", "q3"]`,
/// `periodic = { joints = [...] }`, `"q2.compliance.elbow"`) are joints of a built-in robot:
/// a user who copies an example into a cell of a built-in robot gets a cell that loads (a
/// tree's examples: joints of a shipped tree cell, `examples/*tree-cell.toml`).
#[test]
fn readme_joint_names_are_real_joints() {
    let src = root().join("docs/src");
    let mut documents = vec![(
        "README.md".to_string(),
        std::fs::read_to_string(root().join("README.md")).expect("README.md"),
    )];
    for page in markdown_files(&src, &src) {
        let text = std::fs::read_to_string(src.join(&page)).expect("a guide page");
        documents.push((format!("docs/src/{page}"), text));
    }
    let mut joints: Vec<String> = armcal::Cell::robots()
        .into_iter()
        .flat_map(|(name, _)| armcal::robots::robot(&name).expect("built-in").spec.links)
        .filter_map(|l| l.joint.map(|j| j.name))
        .collect();
    // a tree's examples name the joints of the shipped tree cells (`examples/*tree-cell.toml`)
    for entry in std::fs::read_dir(root().join("examples")).expect("examples/") {
        let path = entry.expect("an examples/ entry").path();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        if name.ends_with("tree-cell.toml") {
            let cell = armcal::TreeCell::from_file(&path).expect("a shipped tree cell loads");
            joints.extend(cell.tree.joints.iter().map(|j| j.name.clone()));
        }
    }
    // The quoted names inside `compliance = [...]` and `joints = [...]`, and the joint of every
    // `"<joint>.compliance.…"` / `<joint>.periodic.…` term.
    let mut named = Vec::new();
    for (document, text) in &documents {
        for (i, line) in text.lines().enumerate() {
            let at = format!("{document} line {}", i + 1);
            for key in ["compliance = [", "periodic = { joints = ["] {
                for (_, rest) in line
                    .match_indices(key)
                    .map(|(k, _)| line.split_at(k + key.len()))
                {
                    let list = rest.split(']').next().unwrap_or("");
                    named.extend(
                        list.split(',')
                            .map(|n| (at.clone(), n.trim().trim_matches('"').to_string())),
                    );
                }
            }
            for term in [".compliance.", ".periodic."] {
                for (k, _) in line.match_indices(term) {
                    let start = line[..k]
                        .rfind(|c: char| !(c.is_alphanumeric() || c == '_'))
                        .map_or(0, |s| s + 1);
                    named.push((at.clone(), line[start..k].to_string()));
                }
            }
        }
    }
    named.retain(|(_, n)| !n.is_empty() && !n.contains('<') && !n.contains('…'));
    assert!(
        named.len() >= 10,
        "the non-geometric examples of README and the guide were found: {named:?}"
    );
    let unknown: Vec<String> = named
        .iter()
        .filter(|(_, n)| !joints.contains(n))
        .map(|(at, n)| format!("{at}: `{n}`"))
        .collect();
    assert!(
        unknown.is_empty(),
        "not a joint of any built-in robot: {unknown:?}"
    );
}
