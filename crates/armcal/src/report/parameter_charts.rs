//! Figures of per-parameter values, in the style of [`super::figures`]: horizontal bars
//! with the parameter names beside them (change / σ, estimate − truth) and a heatmap of a
//! correlation matrix.

use super::figures::{
    axis, category_label, colour, drawing_error, styled_mesh, svg, tick, DESC, LABEL, TITLE, WIDE,
};
use super::font::FAMILY;
use crate::Error;
use nalgebra::DMatrix;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Height of one bar or one heatmap row (px).
const ROW: u32 = 22;

/// One bar per item `(name, value)`, the names down the left, drawn in palette colour
/// `fill`; dashed vertical guides at `±g` for every `g` in `guides` (e.g. ±2 σ).
pub fn hbar_figure(
    title: &str,
    x_label: &str,
    items: &[(String, f64)],
    fill: usize,
    guides: &[f64],
) -> Result<String, Error> {
    let n = items.len().max(1);
    let extent = items
        .iter()
        .map(|(_, v)| v.abs())
        .chain(guides.iter().map(|g| g.abs()))
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    let r = if extent > 0.0 { 1.12 * extent } else { 1.0 };
    let names: Vec<String> = items.iter().rev().map(|(n, _)| n.clone()).collect();
    svg((WIDE, 110 + ROW * n as u32), |root| {
        let body = root.titled(title, (FAMILY, TITLE)).map_err(drawing_error)?;
        let mut chart = ChartBuilder::on(&body)
            .margin(12)
            .x_label_area_size(44)
            .y_label_area_size(150)
            .build_cartesian_2d(axis(-r, r)?, -0.5..(n as f64 - 0.5))
            .map_err(drawing_error)?;
        let y_tick = |y: &f64| category_label(*y, &names);
        styled_mesh(&mut chart)
            .disable_y_mesh()
            .y_labels(n + 1)
            .y_label_formatter(&y_tick)
            .x_desc(x_label)
            .draw()
            .map_err(drawing_error)?;
        for g in guides {
            for x in [-g, *g] {
                chart
                    .draw_series(DashedLineSeries::new(
                        vec![(x, -0.5), (x, n as f64 - 0.5)],
                        6,
                        4,
                        BLACK.mix(0.45).stroke_width(1),
                    ))
                    .map_err(drawing_error)?;
            }
        }
        let c = colour(fill);
        chart
            .draw_series(
                items
                    .iter()
                    .rev()
                    .enumerate()
                    .filter(|(_, (_, v))| v.is_finite())
                    .map(|(i, (_, v))| {
                        let y = i as f64;
                        Rectangle::new([(0.0, y - 0.36), (*v, y + 0.36)], c.filled())
                    }),
            )
            .map_err(drawing_error)?;
        chart
            .draw_series(
                items
                    .iter()
                    .rev()
                    .enumerate()
                    .filter(|(_, (_, v))| v.is_finite())
                    .map(|(i, (_, v))| {
                        let right = *v >= 0.0;
                        Text::new(
                            format!(" {} ", tick(&((v * 100.0).round() / 100.0))),
                            (*v, i as f64),
                            TextStyle::from((FAMILY, LABEL).into_font()).pos(Pos::new(
                                if right { HPos::Left } else { HPos::Right },
                                VPos::Center,
                            )),
                        )
                    }),
            )
            .map_err(drawing_error)?;
        Ok(())
    })
}

/// The colour of a correlation ρ ∈ [−1, 1]: white at 0, the palette's blue at −1 and its
/// vermillion at +1, linear in between.
pub fn correlation_colour(rho: f64) -> RGBColor {
    let t = rho.clamp(-1.0, 1.0);
    let end = if t < 0.0 { colour(0) } else { colour(1) };
    let a = t.abs();
    let mix = |e: u8| (255.0 + (e as f64 - 255.0) * a).round() as u8;
    RGBColor(mix(end.0), mix(end.1), mix(end.2))
}

/// A heatmap of the symmetric matrix `m` (entries in [−1, 1]) with row `i` named
/// `names[i]`: rows are labelled "k name", columns by k; a colour scale below.
pub fn heatmap_figure(title: &str, names: &[String], m: &DMatrix<f64>) -> Result<String, Error> {
    let n = names.len();
    if m.nrows() != n || m.ncols() != n {
        return Err(Error::Input(format!(
            "a {}×{} matrix for {n} names cannot be drawn as a heatmap",
            m.nrows(),
            m.ncols()
        )));
    }
    let n = n.max(1);
    let side = (ROW * n as u32).clamp(240, 900);
    let labels: Vec<String> = names
        .iter()
        .enumerate()
        .rev()
        .map(|(k, s)| format!("{} {s}", k + 1))
        .collect();
    let numbers: Vec<String> = (1..=n).map(|k| k.to_string()).collect();
    svg((side + 260, side + 150), |root| {
        let body = root.titled(title, (FAMILY, TITLE)).map_err(drawing_error)?;
        let (plot, scale) = body.split_vertically(side + 70);
        let mut chart = ChartBuilder::on(&plot)
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(170)
            .build_cartesian_2d(-0.5..(n as f64 - 0.5), -0.5..(n as f64 - 0.5))
            .map_err(drawing_error)?;
        let x_tick = |x: &f64| category_label(*x, &numbers);
        let y_tick = |y: &f64| category_label(*y, &labels);
        styled_mesh(&mut chart)
            .disable_mesh()
            .x_labels(n + 1)
            .y_labels(n + 1)
            .x_label_formatter(&x_tick)
            .y_label_formatter(&y_tick)
            .x_desc("parameter number")
            .label_style((FAMILY, LABEL.min(13)))
            .draw()
            .map_err(drawing_error)?;
        chart
            .draw_series((0..n.min(m.nrows())).flat_map(|i| {
                (0..n.min(m.ncols())).map(move |j| {
                    // Row i at the top: y = n − 1 − i.
                    let y = (n - 1 - i) as f64;
                    let x = j as f64;
                    Rectangle::new(
                        [(x - 0.5, y - 0.5), (x + 0.5, y + 0.5)],
                        correlation_colour(m[(i, j)]).filled(),
                    )
                })
            }))
            .map_err(drawing_error)?;
        // The colour scale: −1 … 1 in 21 steps.
        let (w, _) = scale.dim_in_pixel();
        let (x0, width) = (180i32, (w as i32 - 260).max(100));
        let steps = 21;
        for k in 0..steps {
            let rho = -1.0 + 2.0 * k as f64 / (steps - 1) as f64;
            let a = x0 + width * k / steps;
            let b = x0 + width * (k + 1) / steps;
            scale
                .draw(&Rectangle::new(
                    [(a, 8), (b, 26)],
                    correlation_colour(rho).filled(),
                ))
                .map_err(drawing_error)?;
        }
        let style =
            TextStyle::from((FAMILY, DESC).into_font()).pos(Pos::new(HPos::Center, VPos::Top));
        for (rho, label) in [(-1.0, "ρ = −1"), (0.0, "0"), (1.0, "+1")] {
            let x = x0 + ((rho + 1.0) / 2.0 * width as f64) as i32;
            scale
                .draw_text(label, &style, (x, 30))
                .map_err(drawing_error)?;
        }
        Ok(())
    })
}
