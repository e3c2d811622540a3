//! Self-contained HTML reports: figures as inline SVG (plotters, embedded font) and a 3D
//! view of the cell drawn in the browser from inline data. One file, no network fetches.
//!
//! `documents` recognises armcal's JSON results; the page opens with the [`verdict`]
//! panels, then one module per kind builds its section (`estimate` with
//! [`parameter_view`] and `held_out`, `design`, `study`, `tcp` for the Figure 7
//! comparison, `demo_summary` and [`compensation`], `tree` for a tree's estimate);
//! [`figures`] and [`parameter_charts`] draw plain data to SVG; [`html`] assembles the page. A design (and
//! the estimate made from it) keeps one colour in every figure ([`design_key`]).

pub(crate) mod campaign;
pub mod cell_view;
pub(crate) mod check;
pub mod compensation;
pub(crate) mod decimate;
pub(crate) mod demo_summary;
pub(crate) mod design;
pub(crate) mod documents;
pub mod ellipse;
pub(crate) mod estimate;
pub mod figures;
pub(crate) mod files;
pub(crate) mod font;
pub(crate) mod held_out;
pub mod html;
pub mod parameter_charts;
pub mod parameter_view;
pub(crate) mod study;
pub(crate) mod tcp;
pub(crate) mod temperature;
pub(crate) mod tree;
pub mod verdict;

pub use documents::Document;

use crate::cell::Cell;
use crate::sim::TruthRecord;
use crate::study::demo::DemoSummary;
use crate::study::paper::StudyRecord;
use crate::Error;
use html::{escape, table, Page, Section};
use tcp::TcpItem;

/// One input of a report.
#[derive(Clone, Debug)]
pub struct Input {
    /// Its name in headings and legends (plain text).
    pub label: String,
    /// Where it came from (file name), for the inputs table.
    pub source: String,
    /// The document read from the file.
    pub document: Document,
}

/// What a report shows.
#[derive(Clone, Debug, Default)]
pub struct ReportContent<'a> {
    /// Page title (plain text).
    pub title: &'a str,
    /// Text below the title (plain text).
    pub subtitle: &'a str,
    /// The documents to show, in order.
    pub inputs: &'a [Input],
    /// The demo's summary, shown first (else the first demo summary among the inputs).
    pub demo: Option<&'a DemoSummary>,
    /// The 3D view fragment ([`cell_view::cell_view_section`]), placed after the designs.
    pub cell_view: Option<String>,
    /// Notes for the reader (plain text), e.g. why the 3D view is missing.
    pub notes: &'a [String],
}

fn inputs_section(inputs: &[Input], notes: &[String]) -> Section {
    let mut s = Section::new("inputs", "Inputs");
    let rows: Vec<Vec<String>> = inputs
        .iter()
        .map(|i| {
            let about = match &i.document {
                Document::Estimate(e) => format!(
                    "cell <em>{}</em>, data {}",
                    escape(&e.cell),
                    escape(&e.data)
                ),
                Document::Design(d) => format!(
                    "cell <em>{}</em>, {} poses, {}",
                    escape(&d.cell),
                    d.poses.len(),
                    escape(&d.method)
                ),
                Document::Study(st) => format!(
                    "study <em>{}</em>, {} robots, collision avoidance {}",
                    escape(&st.study),
                    st.rows.len(),
                    if st.collisions { "on" } else { "off" }
                ),
                Document::Demo(d) => format!("{} poses per design, seed {}", d.poses, d.seed),
                Document::Truth(t) => format!(
                    "true parameters of cell <em>{}</em> ({} parameters, seed {})",
                    escape(&t.cell),
                    t.parameters.len(),
                    t.seed
                ),
                Document::Campaign(c) => format!(
                    "campaign on cell <em>{}</em>, {} poses in {} steps, {}",
                    escape(&c.cell),
                    c.measured(),
                    c.steps.len(),
                    escape(c.decision.words())
                ),
                Document::Check(c) => format!(
                    "drift check of cell <em>{}</em>, {} poses, {}",
                    escape(&c.cell),
                    c.poses,
                    escape(c.verdict.words())
                ),
                Document::TreeEstimate(e) => format!(
                    "tree cell <em>{}</em>, data {}",
                    escape(&e.cell),
                    escape(&e.data)
                ),
            };
            vec![
                escape(&i.label),
                i.document.kind().into(),
                about,
                escape(&i.source),
            ]
        })
        .collect();
    s.html(table(&["name", "kind", "about", "file"], &rows, &[]));
    for n in notes {
        s.html(format!("<p class=\"note\">{}</p>\n", escape(n)));
    }
    s
}

/// What names one design across a report's inputs: the label in lower case without the
/// words "design" and "estimate" and without separators, so that `design-kpi` (a design
/// file), `estimate-kpi` (the estimate from its data), "KPI design" (the demo's label) and
/// `kpi` (the demo summary's campaign) are one design.
pub fn design_key(label: &str) -> String {
    label
        .to_lowercase()
        .split(|c: char| !c.is_alphanumeric())
        .filter(|w| !w.is_empty() && *w != "design" && *w != "estimate")
        .collect::<Vec<_>>()
        .join("-")
}

/// The palette index of every design of a report, by [`design_key`] in the order the
/// designs and estimates first appear.
struct Colours(Vec<String>);

impl Colours {
    fn of_inputs(inputs: &[Input]) -> Colours {
        let mut keys: Vec<String> = Vec::new();
        for i in inputs {
            if matches!(i.document, Document::Design(_) | Document::Estimate(_)) {
                let k = design_key(&i.label);
                if !keys.contains(&k) {
                    keys.push(k);
                }
            }
        }
        Colours(keys)
    }

    /// The colour of the design named `label` (a design not among the inputs takes the
    /// next colour after them, the same for the same name).
    fn of(&self, label: &str) -> usize {
        let k = design_key(label);
        figures::design_colour(self.0.iter().position(|x| *x == k).unwrap_or(self.0.len()))
    }
}

/// The page for `c`: the verdict panels, the demo summary and its compensated program, the
/// inputs, the TCP comparison (Figure 7), each design, the 3D view, each estimate, each campaign, the
/// studies.
pub fn page(c: &ReportContent) -> Result<Page, Error> {
    let mut sections = Vec::new();
    // A document that cannot be drawn (e.g. values out of any physical range) is named.
    let of = |i: &Input| {
        let file = i.source.clone();
        move |e: Error| Error::File {
            file,
            message: e.to_string(),
        }
    };
    let demo = c.demo.or_else(|| {
        c.inputs.iter().find_map(|i| match &i.document {
            Document::Demo(d) => Some(d.as_ref()),
            _ => None,
        })
    });
    let colours = Colours::of_inputs(c.inputs);
    let estimates: Vec<(&str, &crate::identify::Estimate)> = c
        .inputs
        .iter()
        .filter_map(|i| match &i.document {
            Document::Estimate(e) => Some((i.label.as_str(), e.as_ref())),
            _ => None,
        })
        .collect();
    let designs: Vec<(&str, &crate::design::DesignRecord)> = c
        .inputs
        .iter()
        .filter_map(|i| match &i.document {
            Document::Design(d) => Some((i.label.as_str(), d.as_ref())),
            _ => None,
        })
        .collect();
    sections.extend(verdict::verdict_section("verdict", &estimates, &designs)?);
    // The true robot, where known: the demo's, or a truth record among the inputs.
    let truths: Vec<&TruthRecord> = demo
        .and_then(|d| d.truth.as_ref())
        .into_iter()
        .chain(c.inputs.iter().filter_map(|i| match &i.document {
            Document::Truth(t) => Some(t),
            _ => None,
        }))
        .collect();
    if let Some(d) = demo {
        sections.push(demo_summary::demo_section("summary", d, &|l| {
            colours.of(l)
        })?);
        if let Some(p) = &d.program {
            sections.push(compensation::compensation_section(
                "compensation",
                p,
                &format!(
                    "The demo's working program of {} poses (<code>program.csv</code>), compensated with the KPI design's estimate (<code>program-corrected.csv</code>): on the true robot its largest miss falls from {} mm with the nominal joints to {} mm with the compensated ones.",
                    p.rows.len(),
                    html::fixed(d.program_miss_nominal, 3),
                    html::fixed(d.program_miss_compensated, 3)
                ),
            )?);
        }
    }
    if !c.inputs.is_empty() {
        sections.push(inputs_section(c.inputs, c.notes));
    }
    let mut items = Vec::new();
    for i in c.inputs {
        let (tcp, predicted, floor): (&[_], bool, _) = match &i.document {
            Document::Design(d) => (&d.assessment.tcp, true, &d.assessment.model_floor),
            Document::Estimate(e) => (&e.tcp, false, &e.model_floor),
            Document::Study(_)
            | Document::Demo(_)
            | Document::Truth(_)
            | Document::Campaign(_)
            | Document::Check(_)
            | Document::TreeEstimate(_) => (&[], false, &None),
        };
        // every working pose, not only the first
        for t in tcp {
            items.push(TcpItem {
                label: i.label.clone(),
                predicted,
                working: t.name.clone(),
                covariance: t.covariance,
                covariance_base: t.covariance_base,
                floor: floor
                    .as_ref()
                    .and_then(|f| f.at(&t.name))
                    .map(|f| f.covariance),
                colour: colours.of(&i.label),
            });
        }
    }
    sections.extend(tcp::tcp_section("tcp", &items)?);
    for (k, i) in c.inputs.iter().enumerate() {
        if let Document::Design(d) = &i.document {
            sections.push(
                design::design_section(&format!("design-{}", k + 1), &i.label, d).map_err(of(i))?,
            );
        }
    }
    if let Some(view) = &c.cell_view {
        sections.push(Section::fragment(
            "cell-view",
            "3D view of the cell",
            view.clone(),
        ));
    }
    for (k, i) in c.inputs.iter().enumerate() {
        if let Document::Estimate(e) = &i.document {
            let mut section =
                estimate::estimate_section(&format!("estimate-{}", k + 1), &i.label, e)
                    .map_err(of(i))?;
            let fill = colours.of(&i.label);
            held_out::held_out_axes_block(&mut section, &i.label, e, fill).map_err(of(i))?;
            temperature::temperature_block(&mut section, &i.label, e).map_err(of(i))?;
            let truth = truths.iter().copied().find(|t| t.cell == e.cell);
            parameter_view::parameter_blocks(&mut section, &i.label, e, truth, fill)
                .map_err(of(i))?;
            sections.push(section);
        }
    }
    for (k, i) in c.inputs.iter().enumerate() {
        if let Document::TreeEstimate(e) = &i.document {
            sections.push(
                tree::tree_estimate_section(&format!("tree-estimate-{}", k + 1), &i.label, e)
                    .map_err(of(i))?,
            );
        }
    }
    for (k, i) in c.inputs.iter().enumerate() {
        if let Document::Campaign(st) = &i.document {
            sections.push(
                campaign::campaign_section(&format!("campaign-{}", k + 1), &i.label, st)
                    .map_err(of(i))?,
            );
        }
    }
    for (k, i) in c.inputs.iter().enumerate() {
        if let Document::Check(d) = &i.document {
            sections.push(check::check_section(
                &format!("check-{}", k + 1),
                &i.label,
                d,
            ));
        }
    }
    let studies: Vec<(String, &StudyRecord)> = c
        .inputs
        .iter()
        .filter_map(|i| match &i.document {
            Document::Study(s) => Some((i.label.clone(), s)),
            _ => None,
        })
        .collect();
    if !studies.is_empty() {
        sections.push(study::study_section("study", &studies)?);
    }
    Ok(Page {
        title: c.title.into(),
        subtitle: c.subtitle.into(),
        sections,
    })
}

/// The self-contained HTML report.
pub fn render(c: &ReportContent) -> Result<String, Error> {
    Ok(page(c)?.render())
}

/// The 3D view of the designs among `inputs` that were made for `cell` (same cell name);
/// `None` if there are none.
pub fn cell_view_of(cell: &Cell, inputs: &[Input]) -> Result<Option<String>, Error> {
    let mut designs = Vec::new();
    for i in inputs {
        if let Document::Design(d) = &i.document {
            if d.cell == cell.name {
                designs.push((i.label.as_str(), d.design_for(&cell.model)?));
            }
        }
    }
    if designs.is_empty() {
        return Ok(None);
    }
    let refs: Vec<(&str, &[Vec<f64>])> = designs.iter().map(|(n, q)| (*n, q.as_slice())).collect();
    cell_view::cell_view_section(cell, &refs).map(Some)
}
