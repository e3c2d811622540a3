//! The report's figures as SVG strings (plotters, SVG backend, the embedded font). Every
//! builder takes plain data and returns one `<svg>` element, ready to be placed inline in
//! an HTML page (no XML prolog, no namespace URL).
//!
//! (Over 600 lines: seven figure builders (two with explicit series colours) that share one style — palette, fonts, legend
//! strip, mesh — kept beside it so every figure of a report looks the same; each builder
//! is ~50–110 lines.)

use super::ellipse::{ellipse_points, Plane};
use super::font::{ensure_registered, FAMILY};
use crate::Error;
use nalgebra::Matrix3;
use plotters::chart::MeshStyle;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Series colours (Okabe–Ito, distinguishable with the common colour-vision deficiencies).
pub const PALETTE: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
];

/// Colour of series `i`.
pub fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Palette index of the nominal model in every figure (black); designs take the colours
/// before [`FRAMES_ONLY`] ([`design_colour`]).
pub const NOMINAL: usize = 6;

/// Palette index of the frames-only fit in every figure (sky blue).
pub const FRAMES_ONLY: usize = 5;

/// Palette index of the `k`-th design of a report: the first five colours in turn, so that
/// a design (and the estimate made from it) has one colour in every figure and never the
/// nominal model's or the frames-only fit's.
pub fn design_colour(k: usize) -> usize {
    k % FRAMES_ONLY
}

/// Width of the full-width figures (px; the page scales them to its column).
pub(super) const WIDE: u32 = 1100;

/// A drawing area of an SVG figure.
pub(super) type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

pub(super) fn drawing_error<E: std::fmt::Display>(e: E) -> Error {
    Error::Output(format!("drawing a figure: {e}"))
}

/// Draws into an SVG string of `size` px and strips what inline SVG does not need.
pub(super) fn svg(
    size: (u32, u32),
    draw: impl FnOnce(&Area) -> Result<(), Error>,
) -> Result<String, Error> {
    ensure_registered()?;
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, size).into_drawing_area();
        root.fill(&WHITE).map_err(drawing_error)?;
        draw(&root)?;
        root.present().map_err(drawing_error)?;
    }
    Ok(buf.replacen(" xmlns=\"http://www.w3.org/2000/svg\"", "", 1))
}

/// `[lo, hi]` covering `values` with a relative `pad`; a unit range around a single value
/// and `[0, 1]` when there is nothing finite.
fn range_of(values: impl Iterator<Item = f64>, pad: f64) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let span = hi - lo;
    if span <= 1e-12 * lo.abs().max(1e-12) {
        let w = (0.5 * lo.abs()).max(0.5);
        return (lo - w, hi + w);
    }
    (lo - pad * span, hi + pad * span)
}

/// A chart axis `lo..hi`, refused unless both ends and the span are finite: on an infinite
/// span plotters' tick search never ends (issue 15: a design's joint range of ±1e308, or
/// residuals of 1e308 and −1e308, froze `armcal report`).
pub(super) fn axis(lo: f64, hi: f64) -> Result<std::ops::Range<f64>, Error> {
    if lo.is_finite() && hi.is_finite() && (hi - lo).is_finite() {
        Ok(lo..hi)
    } else {
        Err(Error::Input(format!(
            "a chart axis from {lo} to {hi} is too wide to draw: the values it shows are out of \
             any physical range"
        )))
    }
}

/// Tick label text: integer positions get `names[i]`, others nothing.
pub(super) fn category_label(x: f64, names: &[String]) -> String {
    let i = x.round();
    if (x - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < names.len() {
        names[i as usize].clone()
    } else {
        String::new()
    }
}

/// Font sizes (plotters size; the SVG text is drawn at size/1.24 px).
pub(super) const TITLE: u32 = 20;
pub(super) const LABEL: u32 = 15;
pub(super) const DESC: u32 = 16;
const LEGEND: u32 = 15;

/// A tick label: up to six decimals, trailing zeros dropped, a true minus sign.
pub fn tick(v: &f64) -> String {
    if v.abs() < 1e-9 {
        return "0".into();
    }
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.replace('-', "−")
}

/// How a legend entry is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mark {
    Line,
    Dashed,
    Dot,
    Swatch,
}

/// Draws one legend mark of `colour` with its left end at `(x, y)` (pixels of `area`).
fn draw_mark(area: &Area, (x, y): (i32, i32), mark: Mark, c: RGBColor) -> Result<(), Error> {
    let style = c.stroke_width(2);
    match mark {
        Mark::Line => area.draw(&PathElement::new(vec![(x, y), (x + 24, y)], style)),
        Mark::Dashed => area
            .draw(&PathElement::new(vec![(x, y), (x + 9, y)], style))
            .and_then(|_| area.draw(&PathElement::new(vec![(x + 15, y), (x + 24, y)], style))),
        Mark::Dot => area.draw(&Circle::new((x + 12, y), 4, c.filled())),
        Mark::Swatch => area.draw(&Rectangle::new(
            [(x + 4, y - 6), (x + 20, y + 6)],
            c.filled(),
        )),
    }
    .map_err(drawing_error)
}

/// A legend in a strip of its own (never over the data): entries side by side, wrapping to
/// further rows, or one per row when `column`.
fn draw_legend(
    area: &Area,
    entries: &[(String, Mark, RGBColor)],
    column: bool,
) -> Result<(), Error> {
    let style =
        TextStyle::from((FAMILY, LEGEND).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    let (w, _) = area.dim_in_pixel();
    let (mut x, mut y) = (12i32, 11i32);
    for (label, mark, c) in entries {
        let (tw, _) = area
            .estimate_text_size(label, &style)
            .map_err(drawing_error)?;
        let width = 30 + tw as i32 + 24;
        if !column && x > 12 && x + width > w as i32 {
            x = 12;
            y += 22;
        }
        draw_mark(area, (x, y), *mark, *c)?;
        area.draw_text(label, &style, (x + 30, y))
            .map_err(drawing_error)?;
        if column {
            y += 20;
        } else {
            x += width;
        }
    }
    Ok(())
}

/// Height of a legend strip for `n` entries (one row of side-by-side entries, or a column).
fn legend_height(n: usize, column: bool) -> u32 {
    if column {
        8 + 20 * n as u32
    } else {
        24
    }
}

/// Draws `title` at the top of `root` and splits the rest into a legend strip of
/// `legend_h` px above the plot area; returns (legend strip, plot area).
fn titled_with_legend_strip<'a>(
    root: &Area<'a>,
    title: &str,
    legend_h: u32,
) -> Result<(Area<'a>, Area<'a>), Error> {
    let body = root.titled(title, (FAMILY, TITLE)).map_err(drawing_error)?;
    Ok(body.split_vertically(legend_h))
}

/// Starts `chart`'s mesh in the report's style: the embedded font for tick labels
/// ([`LABEL`]) and axis descriptions ([`DESC`]), a faint major grid and no minor one,
/// [`tick`] labels on both axes. Callers add the axis descriptions and label counts and may
/// override any of these.
pub(super) fn styled_mesh<'a, 'b, DB: DrawingBackend>(
    chart: &'b mut ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
) -> MeshStyle<'a, 'b, RangedCoordf64, RangedCoordf64, DB> {
    let mut mesh = chart.configure_mesh();
    mesh.label_style((FAMILY, LABEL))
        .axis_desc_style((FAMILY, DESC))
        .light_line_style(TRANSPARENT)
        .bold_line_style(BLACK.mix(0.08))
        .x_label_formatter(&tick)
        .y_label_formatter(&tick);
    mesh
}

/// One TCP covariance to draw as a confidence ellipse.
#[derive(Clone, Debug)]
pub struct EllipseSeries {
    /// Legend entry (plain text).
    pub label: String,
    /// C_s at the working pose (mm²).
    pub covariance: Matrix3<f64>,
    /// Dashed outline (predictions) instead of solid (estimates).
    pub dashed: bool,
    /// Index into [`PALETTE`] (series of one design share a colour).
    pub colour: usize,
}

/// The projections on `plane` of the confidence ellipsoids `δᵀ C_s⁻¹ δ ≤ k²` of every
/// series, overlaid, centred at the TCP, equal scales on both axes (paper Figure 7).
pub fn ellipse_figure(plane: Plane, series: &[EllipseSeries], k: f64) -> Result<String, Error> {
    let curves: Vec<Vec<(f64, f64)>> = series
        .iter()
        .map(|s| ellipse_points(plane.project(&s.covariance), k, 144))
        .collect();
    let extent = curves
        .iter()
        .flatten()
        .map(|p| p.0.abs().max(p.1.abs()))
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    let r = if extent > 0.0 { 1.3 * extent } else { 1.0 };
    let (xn, yn) = plane.axis_names();
    let legend_h = legend_height(series.len(), true);
    svg((380, 390 + legend_h), |root| {
        let area = root
            .titled(&format!("{xn}{yn} projection"), (FAMILY, TITLE))
            .map_err(drawing_error)?;
        let (_, h) = area.dim_in_pixel();
        let (plot_area, legend_area) = area.split_vertically(h.saturating_sub(legend_h));
        let (w, h) = plot_area.dim_in_pixel();
        let (margin, xl, yl) = (10u32, 44u32, 62u32);
        let (pw, ph) = (
            w.saturating_sub(yl + 2 * margin).max(1) as f64,
            h.saturating_sub(xl + 2 * margin).max(1) as f64,
        );
        // Equal scale: the y range follows the plot area's aspect ratio.
        let ry = r * ph / pw;
        let mut chart = ChartBuilder::on(&plot_area)
            .margin(margin)
            .x_label_area_size(xl)
            .y_label_area_size(yl)
            .build_cartesian_2d(axis(-r, r)?, axis(-ry, ry)?)
            .map_err(drawing_error)?;
        styled_mesh(&mut chart)
            .x_desc(format!("δ{xn} (mm)"))
            .y_desc(format!("δ{yn} (mm)"))
            .x_labels(5)
            .y_labels(5)
            .draw()
            .map_err(drawing_error)?;
        // Identified (solid) outlines first, predicted (dashed) ones on top: a prediction
        // that matches its identification stays visible.
        let mut order: Vec<usize> = (0..series.len()).collect();
        order.sort_by_key(|&i| series[i].dashed);
        for (s, c) in order.iter().map(|&i| (&series[i], &curves[i])) {
            let style = colour(s.colour).stroke_width(2);
            if s.dashed {
                chart
                    .draw_series(DashedLineSeries::new(c.clone(), 7, 4, style))
                    .map_err(drawing_error)?;
            } else {
                chart
                    .draw_series(LineSeries::new(c.clone(), style))
                    .map_err(drawing_error)?;
            }
        }
        let entries: Vec<(String, Mark, RGBColor)> = series
            .iter()
            .map(|s| {
                (
                    s.label.clone(),
                    if s.dashed { Mark::Dashed } else { Mark::Line },
                    colour(s.colour),
                )
            })
            .collect();
        draw_legend(&legend_area, &entries, true)
    })
}

/// Empirical cumulative distributions of non-negative errors, one step line per series:
/// F(x) = #{eᵢ ≤ x}/n, in %.
pub fn cdf_figure(
    title: &str,
    x_label: &str,
    series: &[(String, Vec<f64>)],
) -> Result<String, Error> {
    let colours: Vec<usize> = (0..series.len()).collect();
    cdf_figure_coloured(title, x_label, series, &colours)
}

/// [`cdf_figure`] with series `i` drawn in palette colour `colours[i]`.
pub fn cdf_figure_coloured(
    title: &str,
    x_label: &str,
    series: &[(String, Vec<f64>)],
    colours: &[usize],
) -> Result<String, Error> {
    let pick = |i: usize| colour(colours.get(i).copied().unwrap_or(i));
    let (_, hi) = range_of(series.iter().flat_map(|s| s.1.iter().copied()), 0.05);
    svg((WIDE, 420), |root| {
        let (legend_area, plot_area) =
            titled_with_legend_strip(root, title, legend_height(series.len(), false))?;
        let mut chart = ChartBuilder::on(&plot_area)
            .margin(12)
            .x_label_area_size(46)
            .y_label_area_size(64)
            .build_cartesian_2d(axis(0.0, hi.max(1e-9))?, 0.0..100.0)
            .map_err(drawing_error)?;
        styled_mesh(&mut chart)
            .x_desc(x_label)
            .y_desc("poses with error ≤ x (%)")
            .draw()
            .map_err(drawing_error)?;
        let mut entries = Vec::new();
        for (i, (label, values)) in series.iter().enumerate() {
            let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
            v.sort_by(f64::total_cmp);
            let n = v.len().max(1) as f64;
            let mut pts = vec![(0.0, 0.0)];
            for (k, x) in v.iter().enumerate() {
                pts.push((*x, 100.0 * k as f64 / n));
                pts.push((*x, 100.0 * (k + 1) as f64 / n));
            }
            chart
                .draw_series(LineSeries::new(pts, pick(i).stroke_width(2)))
                .map_err(drawing_error)?;
            entries.push((label.clone(), Mark::Line, pick(i)));
        }
        draw_legend(&legend_area, &entries, false)
    })
}

/// Grouped vertical bars: one group per category, one bar per series, each labelled with
/// its value. `highlight` = (series, category) draws that bar in the warning colour.
/// `log`: a logarithmic value axis (bars from the lowest decade), used when every value
/// is positive, so that margins of 0.05 mm and 200 mm are both readable.
pub fn bar_figure(
    title: &str,
    y_label: &str,
    categories: &[String],
    series: &[(String, Vec<f64>)],
    highlight: Option<(usize, usize)>,
    log: bool,
) -> Result<String, Error> {
    let colours: Vec<usize> = (0..series.len()).collect();
    bar_figure_coloured(title, y_label, categories, series, &colours, highlight, log)
}

/// [`bar_figure`] with series `i` drawn in palette colour `colours[i]`.
pub fn bar_figure_coloured(
    title: &str,
    y_label: &str,
    categories: &[String],
    series: &[(String, Vec<f64>)],
    colours: &[usize],
    highlight: Option<(usize, usize)>,
    log: bool,
) -> Result<String, Error> {
    let n = categories.len().max(1);
    let values = || {
        series
            .iter()
            .flat_map(|s| s.1.iter().copied())
            .filter(|v| v.is_finite())
    };
    let log = log && values().count() > 0 && values().all(|v| v > 0.0);
    // Bar heights in axis units: log10 of the value on a log axis.
    let height = |v: f64| if log { v.log10() } else { v };
    let (lo, hi) = if log {
        let (a, b) = range_of(values().map(f64::log10), 0.0);
        (a.floor(), b.ceil().max(a.floor() + 1.0) + 0.15)
    } else {
        let (a, b) = range_of(values().chain([0.0]), 0.12);
        (a.min(0.0), b)
    };
    let base = if log { lo } else { 0.0 };
    let m = series.len().max(1) as f64;
    let width = 0.8 / m;
    let with_legend = series.len() > 1;
    let y_tick = |t: &f64| {
        if !log {
            tick(t)
        } else if (t - t.round()).abs() < 1e-9 {
            tick(&10f64.powf(t.round()))
        } else {
            String::new()
        }
    };
    svg((WIDE, 400), |root| {
        let (legend_area, plot_area) = titled_with_legend_strip(
            root,
            title,
            if with_legend {
                legend_height(series.len(), false)
            } else {
                0
            },
        )?;
        let mut chart = ChartBuilder::on(&plot_area)
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(-0.5..(n as f64 - 0.5), axis(lo, hi)?)
            .map_err(drawing_error)?;
        let x_tick = |x: &f64| category_label(*x, categories);
        let mut mesh = styled_mesh(&mut chart);
        mesh.disable_x_mesh()
            .x_labels(n + 1)
            .x_label_formatter(&x_tick)
            .y_label_formatter(&y_tick)
            .y_desc(y_label)
            .label_style((FAMILY, DESC));
        if log {
            mesh.y_labels((hi - lo).ceil() as usize + 1);
        }
        mesh.draw().map_err(drawing_error)?;
        let warn = colour(1);
        let mut entries = Vec::new();
        for (s, (label, values)) in series.iter().enumerate() {
            let fill = colour(colours.get(s).copied().unwrap_or(s));
            let bars: Vec<(f64, f64, bool)> = values
                .iter()
                .enumerate()
                .filter(|(_, v)| v.is_finite())
                .map(|(c, v)| {
                    (
                        c as f64 - 0.4 + width * s as f64,
                        *v,
                        highlight == Some((s, c)),
                    )
                })
                .collect();
            chart
                .draw_series(bars.iter().map(|(x0, v, hl)| {
                    let c = if *hl { warn } else { fill };
                    Rectangle::new([(*x0, base), (x0 + 0.92 * width, height(*v))], c.filled())
                }))
                .map_err(drawing_error)?;
            chart
                .draw_series(bars.iter().map(|(x0, v, hl)| {
                    let up = height(*v) >= base;
                    let label = if *hl {
                        format!("{} (smallest)", super::html::number(*v))
                    } else {
                        super::html::number(*v)
                    };
                    Text::new(
                        label,
                        (x0 + 0.46 * width, height(*v)),
                        TextStyle::from((FAMILY, LABEL).into_font())
                            .color(if *hl { &warn } else { &BLACK })
                            .pos(Pos::new(
                                HPos::Center,
                                if up { VPos::Bottom } else { VPos::Top },
                            )),
                    )
                }))
                .map_err(drawing_error)?;
            entries.push((label.clone(), Mark::Swatch, fill));
        }
        if with_legend {
            draw_legend(&legend_area, &entries, false)?;
        }
        Ok(())
    })
}

/// Histograms side by side, one panel per series, on a common range with `bins` bins.
pub fn histogram_figure(
    title: &str,
    x_label: &str,
    panels: &[(String, Vec<f64>)],
    bins: usize,
) -> Result<String, Error> {
    let bins = bins.max(1);
    let (lo, hi) = range_of(panels.iter().flat_map(|p| p.1.iter().copied()), 0.02);
    let width = (hi - lo) / bins as f64;
    let counts: Vec<Vec<usize>> = panels
        .iter()
        .map(|(_, v)| {
            let mut c = vec![0usize; bins];
            for x in v.iter().filter(|x| x.is_finite()) {
                c[(((x - lo) / width) as usize).min(bins - 1)] += 1;
            }
            c
        })
        .collect();
    let top = counts.iter().flatten().copied().max().unwrap_or(0).max(1) as f64 * 1.1;
    svg((WIDE, 340), |root| {
        let body = root.titled(title, (FAMILY, TITLE)).map_err(drawing_error)?;
        let cells = body.split_evenly((1, panels.len().max(1)));
        for (i, ((name, _), area)) in panels.iter().zip(&cells).enumerate() {
            let mut chart = ChartBuilder::on(area)
                .caption(name, (FAMILY, DESC))
                .margin(8)
                .x_label_area_size(44)
                .y_label_area_size(48)
                .build_cartesian_2d(axis(lo, hi)?, 0.0..top)
                .map_err(drawing_error)?;
            styled_mesh(&mut chart)
                .x_desc(x_label)
                .y_desc("count")
                .x_labels(5)
                .y_labels(5)
                .draw()
                .map_err(drawing_error)?;
            let fill = colour(i);
            chart
                .draw_series(counts[i].iter().enumerate().map(|(b, c)| {
                    let x0 = lo + width * b as f64;
                    Rectangle::new([(x0, 0.0), (x0 + width, *c as f64)], fill.mix(0.8).filled())
                }))
                .map_err(drawing_error)?;
        }
        Ok(())
    })
}

/// A horizontal reference line drawn dashed across a [`series_figure`].
#[derive(Clone, Debug)]
pub struct Reference {
    /// Legend entry (plain text).
    pub label: String,
    /// Where the line is drawn, in the units of the figure's y axis.
    pub value: f64,
}

/// Line-and-point series over a common x axis (e.g. pose number), with optional dashed
/// horizontal reference lines (e.g. zero, or a published value).
pub fn series_figure(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[(String, Vec<(f64, f64)>)],
    references: &[Reference],
) -> Result<String, Error> {
    let (x0, x1) = range_of(series.iter().flat_map(|s| s.1.iter().map(|p| p.0)), 0.02);
    let (y0, y1) = range_of(
        series
            .iter()
            .flat_map(|s| s.1.iter().map(|p| p.1))
            .chain(references.iter().map(|r| r.value)),
        0.08,
    );
    svg((WIDE, 420), |root| {
        let (legend_area, plot_area) =
            titled_with_legend_strip(root, title, legend_height(series.len(), false))?;
        let mut chart = ChartBuilder::on(&plot_area)
            .margin(12)
            .x_label_area_size(46)
            .y_label_area_size(70)
            .build_cartesian_2d(axis(x0, x1)?, axis(y0, y1)?)
            .map_err(drawing_error)?;
        styled_mesh(&mut chart)
            .x_desc(x_label)
            .y_desc(y_label)
            .draw()
            .map_err(drawing_error)?;
        for (k, r) in references.iter().enumerate() {
            let style = BLACK.mix(0.55).stroke_width(1);
            chart
                .draw_series(DashedLineSeries::new(
                    vec![(x0, r.value), (x1, r.value)],
                    6,
                    4,
                    style,
                ))
                .map_err(drawing_error)?;
            chart
                .draw_series(std::iter::once(Text::new(
                    r.label.clone(),
                    (x0 + 0.01 * (x1 - x0), r.value),
                    TextStyle::from((FAMILY, LABEL).into_font())
                        .color(&BLACK.mix(0.7))
                        .pos(Pos::new(
                            HPos::Left,
                            if k % 2 == 0 { VPos::Bottom } else { VPos::Top },
                        )),
                )))
                .map_err(drawing_error)?;
        }
        let mut entries = Vec::new();
        for (i, (label, pts)) in series.iter().enumerate() {
            let c = colour(i);
            chart
                .draw_series(LineSeries::new(pts.clone(), c.mix(0.5).stroke_width(1)))
                .map_err(drawing_error)?;
            chart
                .draw_series(pts.iter().map(|p| Circle::new(*p, 3, c.filled())))
                .map_err(drawing_error)?;
            entries.push((label.clone(), Mark::Dot, c));
        }
        draw_legend(&legend_area, &entries, false)
    })
}

/// One joint of a design: its values at every pose and its limits (display units).
#[derive(Clone, Debug)]
pub struct JointTrace {
    /// Joint name (panel title).
    pub name: String,
    /// Display unit of the values and limits (e.g. `deg`, `mm`).
    pub unit: String,
    /// Lower joint limit (display units).
    pub lower: f64,
    /// Upper joint limit (display units).
    pub upper: f64,
    /// The joint's value at each pose, in pose order (display units).
    pub values: Vec<f64>,
}

/// The design's joint values pose by pose, one panel per joint, the joint limits drawn as
/// red lines (at the panel's edges when every value is within them).
pub fn joint_figure(title: &str, joints: &[JointTrace]) -> Result<String, Error> {
    let cols = 3usize;
    let rows = joints.len().div_ceil(cols).max(1);
    svg((WIDE, 40 + 250 * rows as u32), |root| {
        let body = root.titled(title, (FAMILY, TITLE)).map_err(drawing_error)?;
        let cells = body.split_evenly((rows, cols));
        for (i, (j, area)) in joints.iter().zip(&cells).enumerate() {
            let n = j.values.len().max(1) as f64;
            // The axis spans the limits and every value: a value past a limit is drawn
            // where it is (and a far one cannot map outside plotters' pixel range).
            let (lo, hi) = j
                .values
                .iter()
                .fold((j.lower, j.upper), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
            let pad = 0.06 * (hi - lo).abs().max(1e-9);
            let mut chart = ChartBuilder::on(area)
                .caption(format!("{} ({})", j.name, j.unit), (FAMILY, DESC))
                .margin(8)
                .x_label_area_size(40)
                .y_label_area_size(56)
                .build_cartesian_2d(0.5..(n + 0.5), axis(lo - pad, hi + pad)?)
                .map_err(drawing_error)?;
            styled_mesh(&mut chart)
                .x_desc("pose")
                .y_desc(j.unit.as_str())
                .x_labels(6)
                .y_labels(5)
                .draw()
                .map_err(drawing_error)?;
            for limit in [j.lower, j.upper] {
                chart
                    .draw_series(LineSeries::new(
                        vec![(0.5, limit), (n + 0.5, limit)],
                        RGBColor(200, 30, 30).stroke_width(2),
                    ))
                    .map_err(drawing_error)?;
            }
            let c = colour(i);
            let pts: Vec<(f64, f64)> = j
                .values
                .iter()
                .enumerate()
                .map(|(k, v)| ((k + 1) as f64, *v))
                .collect();
            chart
                .draw_series(LineSeries::new(pts.clone(), c.mix(0.4).stroke_width(1)))
                .map_err(drawing_error)?;
            chart
                .draw_series(pts.iter().map(|p| Circle::new(*p, 3, c.filled())))
                .map_err(drawing_error)?;
        }
        Ok(())
    })
}
