//! Page assembly: escaping, number formatting, tables, figures with captions, sections and
//! the self-contained page (inline CSS, inline SVG, no external resources).

/// Escapes text for HTML element content and attribute values.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

/// A number with four significant digits (fixed notation between 10⁻³ and 10⁶, scientific
/// outside), "–" when not finite.
pub fn number(x: f64) -> String {
    if !x.is_finite() {
        return "–".into();
    }
    if x == 0.0 {
        return "0".into();
    }
    let a = x.abs();
    let s = if (1e-3..1e6).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.3e}")
    };
    s.replace('-', "−")
}

/// A number with a fixed count of decimals, "–" when not finite.
pub fn fixed(x: f64, decimals: usize) -> String {
    if x.is_finite() {
        format!("{x:.decimals$}").replace('-', "−")
    } else {
        "–".into()
    }
}

/// An HTML table in a wrapper that scrolls sideways on a screen narrower than the table.
/// `rows` hold HTML (escape text first); the columns listed in `numeric` are
/// right-aligned; a row whose first cell starts with `!` is highlighted (the `!` dropped).
pub fn table(head: &[&str], rows: &[Vec<String>], numeric: &[usize]) -> String {
    let mut s = String::from("<div class=\"table-wrap\"><table>\n<thead><tr>");
    for (i, h) in head.iter().enumerate() {
        let class = if numeric.contains(&i) {
            " class=\"num\""
        } else {
            ""
        };
        s.push_str(&format!("<th{class}>{h}</th>"));
    }
    s.push_str("</tr></thead>\n<tbody>\n");
    for row in rows {
        let highlighted = row.first().is_some_and(|c| c.starts_with('!'));
        s.push_str(if highlighted {
            "<tr class=\"highlight\">"
        } else {
            "<tr>"
        });
        for (i, c) in row.iter().enumerate() {
            let c = if i == 0 && highlighted { &c[1..] } else { c };
            let class = if numeric.contains(&i) {
                " class=\"num\""
            } else {
                ""
            };
            s.push_str(&format!("<td{class}>{c}</td>"));
        }
        s.push_str("</tr>\n");
    }
    s.push_str("</tbody>\n</table></div>\n");
    s
}

/// A key–value table (two columns, the keys as row headers), scrolling like [`table`].
pub fn facts(rows: &[(&str, String)]) -> String {
    let mut s = String::from("<div class=\"table-wrap\"><table class=\"facts\">\n<tbody>\n");
    for (k, v) in rows {
        s.push_str(&format!("<tr><th>{k}</th><td>{v}</td></tr>\n"));
    }
    s.push_str("</tbody>\n</table></div>\n");
    s
}

/// `svg` (one `<svg …>` element) marked with `data-figure="kind"`, so that a reader of the
/// page (a test, a script) finds each kind of figure.
pub fn tagged(svg: String, kind: &str) -> String {
    match svg.strip_prefix("<svg ") {
        Some(rest) => format!("<svg data-figure=\"{}\" {rest}", escape(kind)),
        None => svg,
    }
}

/// One inline SVG figure and its caption (HTML).
#[derive(Clone, Debug)]
pub struct Figure {
    /// The figure as an inline `<svg>` element.
    pub svg: String,
    /// Caption below the figure (HTML).
    pub caption: String,
}

#[derive(Clone, Debug)]
enum Block {
    Html(String),
    Figures(Vec<Figure>),
}

/// A section of the report: a heading and, in order, HTML blocks and figures.
#[derive(Clone, Debug)]
pub struct Section {
    /// HTML id of the section, the target of its table-of-contents link (plain text, escaped).
    pub id: String,
    /// Heading and table-of-contents entry (plain text, escaped).
    pub title: String,
    blocks: Vec<Block>,
    /// A complete fragment with its own `<section>` and heading (e.g. the 3D view), placed
    /// as it is inside `<div id="…">`.
    framed_by_fragment: bool,
}

impl Section {
    /// `id` is the anchor (letters, digits, `-`); `title` is plain text.
    pub fn new(id: &str, title: &str) -> Section {
        Section {
            id: id.into(),
            title: title.into(),
            blocks: Vec::new(),
            framed_by_fragment: false,
        }
    }

    /// A section that is a complete HTML fragment with its own `<section>` element and
    /// heading; `title` names it in the contents.
    pub fn fragment(id: &str, title: &str, html: String) -> Section {
        Section {
            id: id.into(),
            title: title.into(),
            blocks: vec![Block::Html(html)],
            framed_by_fragment: true,
        }
    }

    /// Appends HTML.
    pub fn html(&mut self, html: impl Into<String>) {
        self.blocks.push(Block::Html(html.into()));
    }

    /// Appends a paragraph of plain text.
    pub fn text(&mut self, text: &str) {
        self.html(format!("<p>{}</p>\n", escape(text)));
    }

    /// Appends a full-width figure.
    pub fn figure(&mut self, svg: String, caption: String) {
        self.blocks
            .push(Block::Figures(vec![Figure { svg, caption }]));
    }

    /// Appends figures side by side.
    pub fn figure_row(&mut self, figures: Vec<Figure>) {
        if !figures.is_empty() {
            self.blocks.push(Block::Figures(figures));
        }
    }

    /// Number of figures in the section.
    pub fn figure_count(&self) -> usize {
        self.blocks
            .iter()
            .map(|b| match b {
                Block::Figures(f) => f.len(),
                Block::Html(_) => 0,
            })
            .sum()
    }
}

/// The page: title, a short description, sections, and extra HTML fragments (e.g. the 3D
/// cell view) placed after the section named in `after` or at the end.
#[derive(Clone, Debug, Default)]
pub struct Page {
    /// Page title, in `<title>` and the top heading (plain text).
    pub title: String,
    /// Plain text below the title.
    pub subtitle: String,
    /// The sections in page order.
    pub sections: Vec<Section>,
}

const CSS: &str = r#"
:root { --ink: #1d2630; --muted: #5b6770; --line: #d5dbe0; --accent: #0072b2; --warn: #d55e00;
  --ok: #009e73; --caution: #e69f00; }
* { box-sizing: border-box; }
body { margin: 0; color: var(--ink); background: #f4f6f8;
  font: 15px/1.5 "DejaVu Sans", "Helvetica Neue", Arial, sans-serif; }
header { background: #16324f; color: #fff; padding: 28px 0 22px; }
header .wrap, main, nav, footer { max-width: 1160px; margin: 0 auto; padding: 0 20px; }
header h1 { margin: 0 0 6px; font-size: 26px; font-weight: 600; }
header p { margin: 0; color: #c9d6e3; }
nav { margin-top: 18px; }
nav ol { margin: 0; padding: 10px 16px 10px 36px; background: #fff; border: 1px solid var(--line);
  border-radius: 6px; columns: 2; }
nav a { color: var(--accent); text-decoration: none; }
section { background: #fff; border: 1px solid var(--line); border-radius: 6px;
  margin: 18px 0; padding: 6px 22px 16px; }
section h2 { font-size: 20px; font-weight: 600; border-bottom: 2px solid var(--accent);
  padding-bottom: 4px; }
section h3 { font-size: 16px; font-weight: 600; margin: 20px 0 6px; }
p.note { color: var(--muted); font-size: 13.5px; }
table { border-collapse: collapse; margin: 8px 0 14px; font-size: 13.5px; }
th, td { padding: 3px 10px; border-bottom: 1px solid var(--line); text-align: left;
  vertical-align: top; }
thead th { background: #eef2f5; font-weight: 600; }
td.num, th.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
tbody tr:nth-child(even) { background: #fafbfc; }
tr.highlight, tr.highlight:nth-child(even) { background: #fde8dc; }
table.facts th { background: none; font-weight: 600; color: var(--muted); white-space: nowrap; }
.flag { color: var(--warn); font-weight: 600; }
.scroll { max-height: 560px; overflow: auto; border: 1px solid var(--line); }
.scroll table { margin: 0; }
.table-wrap { max-width: 100%; overflow-x: auto; }
.table-wrap table { margin: 8px 0 14px; }
.verdicts { display: flex; flex-wrap: wrap; gap: 12px; }
.verdict-panel { flex: 1 1 420px; min-width: 0; border: 1px solid var(--line); border-left: 6px solid var(--ok);
  border-radius: 6px; padding: 4px 14px 8px; }
.verdict-panel.check { border-left-color: var(--caution); }
.verdict-panel.bad { border-left-color: var(--warn); }
.verdict-panel h3 { margin: 8px 0 4px; }
.verdict-panel .headline { font-weight: 600; margin: 4px 0 6px; }
.frame-toggle > input { margin-left: 0; }
.frame-toggle > label { margin-right: 16px; cursor: pointer; }
.frame-toggle > .frame-base { display: none; }
.frame-toggle > input.base:checked ~ .frame-base { display: block; }
.frame-toggle > input.base:checked ~ .frame-instrument { display: none; }
.figrow { display: flex; gap: 12px; flex-wrap: wrap; }
.figrow figure { flex: 1 1 340px; }
figure.armcal-figure { margin: 10px 0 16px; }
figure.armcal-figure svg { display: block; width: 100%; height: auto; border: 1px solid var(--line); }
figcaption { color: var(--muted); font-size: 13.5px; margin-top: 4px; }
footer { color: var(--muted); font-size: 12.5px; padding-bottom: 30px; }
"#;

impl Page {
    /// Number of inline SVG figures.
    pub fn figure_count(&self) -> usize {
        self.sections.iter().map(Section::figure_count).sum()
    }

    /// The self-contained HTML document. `<meta name="armcal-figures">` gives the number of
    /// inline SVG figures, each wrapped in `<figure class="armcal-figure">`.
    pub fn render(&self) -> String {
        let mut s = String::new();
        s.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
        s.push_str("<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n");
        s.push_str(&format!(
            "<meta name=\"armcal-figures\" content=\"{}\">\n",
            self.figure_count()
        ));
        s.push_str(&format!("<title>{}</title>\n", escape(&self.title)));
        s.push_str(&format!("<style>{CSS}</style>\n</head>\n<body>\n"));
        s.push_str(&format!(
            "<header><div class=\"wrap\"><h1>{}</h1><p>{}</p></div></header>\n",
            escape(&self.title),
            escape(&self.subtitle)
        ));
        s.push_str("<nav><ol>\n");
        for sec in &self.sections {
            s.push_str(&format!(
                "<li><a href=\"#{}\">{}</a></li>\n",
                escape(&sec.id),
                escape(&sec.title)
            ));
        }
        s.push_str("</ol></nav>\n<main>\n");
        for sec in &self.sections {
            if sec.framed_by_fragment {
                s.push_str(&format!("<div id=\"{}\">\n", escape(&sec.id)));
            } else {
                s.push_str(&format!(
                    "<section id=\"{}\">\n<h2>{}</h2>\n",
                    escape(&sec.id),
                    escape(&sec.title)
                ));
            }
            for b in &sec.blocks {
                match b {
                    Block::Html(h) => s.push_str(h),
                    Block::Figures(figs) => {
                        let row = figs.len() > 1;
                        if row {
                            s.push_str("<div class=\"figrow\">\n");
                        }
                        for f in figs {
                            s.push_str("<figure class=\"armcal-figure\">\n");
                            s.push_str(&f.svg);
                            s.push_str(&format!(
                                "\n<figcaption>{}</figcaption>\n</figure>\n",
                                f.caption
                            ));
                        }
                        if row {
                            s.push_str("</div>\n");
                        }
                    }
                }
            }
            s.push_str(if sec.framed_by_fragment {
                "</div>\n"
            } else {
                "</section>\n"
            });
        }
        s.push_str(&format!(
            "</main>\n<footer>Written by armcal {}. One self-contained file: figures are inline SVG, nothing is fetched from the network.</footer>\n</body>\n</html>\n",
            env!("CARGO_PKG_VERSION")
        ));
        s
    }
}
