//! The user guide's links are not broken (issue 31): every relative link of README.md and of the
//! guide's Markdown pages (`docs/src/`, and the developer notes they include) reaches a file of
//! the repository, and every `#anchor` a heading of the page it points into; and, once the
//! guide is built (`mdbook build docs`, which `.ci/run` does before the tests and where it sets
//! `ARMCAL_REQUIRE_BOOK=1` so this part cannot be skipped), every relative `href`/`src` of the
//! built HTML reaches a file and every `#anchor` an `id` of the page it points into.
//!
//! Why a test of our own and not mdbook-linkcheck: mdbook-linkcheck (0.7.7) is built on
//! mdBook 0.4 and does not run as a backend of the pinned mdBook 0.5; its maintained fork
//! (mdbook-linkcheck2) refuses links that leave the book's `src/` (the guide's links to
//! `examples/…` and `data/…`, which resolve both on a repository browser and from the built
//! book in `docs/book/`), does not read README.md, and would add a second install to CI. This
//! test needs no install, checks the ids mdBook really generated, and runs in well under a
//! second.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The repository's root.
fn root() -> PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .canonicalize()
        .expect("the repository's root")
}

/// Every file under `dir` whose name ends in `ext`, sorted.
fn files(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).expect("a folder") {
        let path = entry.expect("a folder entry").path();
        if path.is_dir() {
            out.extend(files(&path, ext));
        } else if path.to_string_lossy().ends_with(ext) {
            out.push(path);
        }
    }
    out.sort();
    out
}

/// mdBook's id of a heading's text (mdBook's `normalize_id`, which GitHub's README anchors
/// follow too for the text armcal's headings use): alphanumerics, `_` and `-` kept (ASCII
/// letters lower-cased), white space turned into `-`, everything else dropped.
fn heading_id(text: &str) -> String {
    text.chars()
        .filter_map(|c| {
            if c.is_alphanumeric() || c == '_' || c == '-' {
                Some(c.to_ascii_lowercase())
            } else if c.is_whitespace() {
                Some('-')
            } else {
                None
            }
        })
        .collect()
}

/// The text of a Markdown page with `{{#include FILE}}` lines replaced by that file (as mdBook
/// does), the included file's path relative to `page`.
fn with_includes(page: &Path) -> String {
    let text = std::fs::read_to_string(page).expect("a Markdown page");
    let mut out = String::new();
    for line in text.lines() {
        match line
            .trim()
            .strip_prefix("{{#include ")
            .and_then(|l| l.strip_suffix("}}"))
        {
            Some(file) => {
                let included = page.parent().expect("a folder").join(file.trim());
                out.push_str(&std::fs::read_to_string(&included).unwrap_or_else(|e| {
                    panic!("{}: {{{{#include {file}}}}}: {e}", page.display())
                }));
            }
            None => out.push_str(line),
        }
        out.push('\n');
    }
    out
}

/// The lines of `text` outside fenced code blocks, with their line numbers (1-based) and inline
/// code spans blanked.
fn prose_lines(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut fenced = false;
    for (i, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        let mut prose = String::new();
        let mut in_code = false;
        for c in line.chars() {
            if c == '`' {
                in_code = !in_code;
            } else if !in_code {
                prose.push(c);
            }
        }
        out.push((i + 1, prose));
    }
    out
}

/// The ids mdBook gives the headings of a Markdown page (a repeated id gets `-1`, `-2`, …).
fn markdown_ids(text: &str) -> BTreeSet<String> {
    let mut ids = BTreeSet::new();
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        let Some(title) = line
            .strip_prefix('#')
            .map(|l| l.trim_start_matches('#'))
            .and_then(|l| l.strip_prefix(' '))
            .filter(|_| !fenced)
        else {
            continue;
        };
        let id = heading_id(&title.replace('`', ""));
        let n = seen.entry(id.clone()).or_insert(0);
        ids.insert(if *n == 0 { id } else { format!("{id}-{n}") });
        *n += 1;
    }
    ids
}

/// The targets of the Markdown links `[text](target)` and images of a prose line.
fn markdown_links(prose: &str) -> Vec<String> {
    prose
        .match_indices("](")
        .filter_map(|(k, _)| {
            let rest = &prose[k + 2..];
            rest.find(')').map(|end| rest[..end].trim().to_string())
        })
        .collect()
}

/// Whether `target` leaves the repository (a URL, mail) rather than naming a file of it.
fn is_external(target: &str) -> bool {
    target.contains("://") || target.starts_with("mailto:")
}

/// The problems of the relative links of the Markdown file `page`: a file that does not exist,
/// or an anchor that is no heading of the page it points into.
fn markdown_problems(page: &Path, root: &Path) -> Vec<String> {
    let text = with_includes(page);
    let name = page
        .strip_prefix(root)
        .unwrap_or(page)
        .display()
        .to_string();
    let mut problems = Vec::new();
    for (line, prose) in prose_lines(&text) {
        for target in markdown_links(&prose) {
            if is_external(&target) {
                continue;
            }
            let (path, anchor) = match target.split_once('#') {
                Some((p, a)) => (p, Some(a)),
                None => (target.as_str(), None),
            };
            let file = if path.is_empty() {
                page.to_path_buf()
            } else {
                page.parent().expect("a folder").join(path)
            };
            if !file.exists() {
                problems.push(format!("{name} line {line}: `{target}`: no such file"));
                continue;
            }
            if let Some(anchor) = anchor {
                let ids = markdown_ids(&with_includes(&file));
                if !ids.contains(anchor) {
                    problems.push(format!(
                        "{name} line {line}: `{target}`: no heading with the id `{anchor}`"
                    ));
                }
            }
        }
    }
    problems
}

/// The values of the attribute `attribute` (`href`, `src`, `id`) in an HTML text.
fn attribute_values<'a>(html: &'a str, attribute: &str) -> Vec<&'a str> {
    let key = format!(" {attribute}=\"");
    html.match_indices(&key)
        .filter_map(|(k, _)| {
            let rest = &html[k + key.len()..];
            rest.find('"').map(|end| &rest[..end])
        })
        .collect()
}

/// The problems of the built guide's relative links: each `href`/`src` of every HTML page
/// reaches a file (in the book, or of the repository two levels up), and each anchor an `id`
/// of its page.
fn html_problems(book: &Path, root: &Path) -> Vec<String> {
    let mut ids: BTreeMap<PathBuf, BTreeSet<String>> = BTreeMap::new();
    let pages = files(book, ".html");
    for page in &pages {
        let html = std::fs::read_to_string(page).expect("a built page");
        let page_ids = attribute_values(&html, "id")
            .into_iter()
            .map(str::to_string)
            .collect();
        ids.insert(page.canonicalize().expect("a page"), page_ids);
    }
    let mut problems = Vec::new();
    for page in &pages {
        let html = std::fs::read_to_string(page).expect("a built page");
        let name = page
            .strip_prefix(root)
            .unwrap_or(page)
            .display()
            .to_string();
        let links = attribute_values(&html, "href")
            .into_iter()
            .chain(attribute_values(&html, "src"));
        for target in links {
            if is_external(target) || target.starts_with("javascript:") {
                continue;
            }
            let (path, anchor) = match target.split_once('#') {
                Some((p, a)) => (p, Some(a)),
                None => (target, None),
            };
            let path = path.split('?').next().unwrap_or_default();
            let file = if path.is_empty() {
                page.clone()
            } else {
                page.parent().expect("a folder").join(path)
            };
            let Ok(file) = file.canonicalize() else {
                problems.push(format!("{name}: `{target}`: no such file"));
                continue;
            };
            if let Some(anchor) = anchor.filter(|a| !a.is_empty()) {
                let found = ids.get(&file).is_some_and(|ids| ids.contains(anchor));
                if !found {
                    problems.push(format!(
                        "{name}: `{target}`: no element with the id `{anchor}`"
                    ));
                }
            }
        }
    }
    problems
}

#[test]
fn readme_and_guide_links_reach_files_and_headings() {
    let root = root();
    let mut pages = vec![root.join("README.md")];
    pages.extend(files(&root.join("docs/src"), ".md"));
    assert!(pages.len() > 20, "the guide's pages: {pages:?}");
    let problems: Vec<String> = pages
        .iter()
        .flat_map(|p| markdown_problems(p, &root))
        .collect();
    assert!(
        problems.is_empty(),
        "broken links:\n{}",
        problems.join("\n")
    );
}

#[test]
fn the_built_guide_has_no_broken_link() {
    let root = root();
    let book = root.join("docs/book");
    if !book.join("index.html").exists() {
        assert!(
            std::env::var_os("ARMCAL_REQUIRE_BOOK").is_none(),
            "ARMCAL_REQUIRE_BOOK is set but the guide is not built: run `mdbook build docs`"
        );
        eprintln!("the guide is not built (docs/book/): its HTML links are not checked");
        return;
    }
    let problems = html_problems(&book, &root);
    assert!(
        problems.is_empty(),
        "broken links in the built guide:\n{}",
        problems.join("\n")
    );
}

#[test]
fn the_link_checker_finds_broken_links() {
    let dir = super::common::scratch("guide-links");
    let page = dir.join("page.md");
    std::fs::write(
        dir.join("other.md"),
        "# Other page\n\n## The `model` floor\n\n## The `model` floor\n",
    )
    .unwrap();
    std::fs::write(
        &page,
        "# Page\n\n[ok](other.md#the-model-floor) [ok](other.md#the-model-floor-1) [ok](#page)\n\
         [bad](missing.md) [bad](other.md#nowhere)\n`[in code](missing.md)`\n\
         ```text\n[in a block](missing.md)\n```\n",
    )
    .unwrap();
    let problems = markdown_problems(&page, &dir);
    assert_eq!(problems.len(), 2, "{problems:?}");
    assert!(
        problems[0].contains("line 4: `missing.md`: no such file"),
        "{problems:?}"
    );
    assert!(problems[1].contains("`nowhere`"), "{problems:?}");

    let book = dir.join("book");
    std::fs::create_dir_all(&book).unwrap();
    std::fs::write(
        book.join("a.html"),
        "<h1 id=\"top\">A</h1><a href=\"b.html#x\">b</a><a href=\"#top\">top</a>\
         <a href=\"c.html\">c</a><a href=\"b.html#y\">b</a><img src=\"https://example.org/i.png\">",
    )
    .unwrap();
    std::fs::write(book.join("b.html"), "<h2 id=\"x\">B</h2>").unwrap();
    let problems = html_problems(&book, &dir);
    assert_eq!(problems.len(), 2, "{problems:?}");
    assert!(
        problems[0].contains("`c.html`: no such file"),
        "{problems:?}"
    );
    assert!(problems[1].contains("`b.html#y`"), "{problems:?}");
    assert_eq!(
        heading_id("The model floor: C_s + C_floor (mm²)"),
        "the-model-floor-c_s--c_floor-mm²"
    );
}
