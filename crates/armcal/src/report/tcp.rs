//! The TCP-precision section: C_s at the working pose for every design (predicted before
//! measuring) and every estimate (after identification), as a table and as the projections
//! of the 95 % confidence ellipsoids on the xy, xz and yz planes (paper Figure 7), in the
//! instrument frame and — a toggle that needs no script — in the robot base frame.

use super::ellipse::{confidence_scale, Plane};
use super::figures::{ellipse_figure, EllipseSeries};
use super::html::{escape, fixed, number, table, tagged, Figure, Section};
use crate::Error;
use nalgebra::Matrix3;

/// Probability held by the drawn confidence ellipsoids (the paper's Figure 7 uses 95 %).
pub const CONFIDENCE: f64 = 0.95;

/// One TCP covariance to compare.
#[derive(Clone, Debug)]
pub struct TcpItem {
    /// Label in the table and the figure legends (plain text).
    pub label: String,
    /// `true`: predicted by a design; `false`: from an identification.
    pub predicted: bool,
    /// The working pose's name.
    pub working: String,
    /// C_s (mm²), instrument frame.
    pub covariance: Matrix3<f64>,
    /// C_s (mm²) in the robot base frame, if the record holds it.
    pub covariance_base: Option<Matrix3<f64>>,
    /// The model floor C_floor (mm², instrument frame), if the record states one
    /// ([`crate::identify::model_floor`]): drawn as the ellipsoid of C_s + C_floor.
    pub floor: Option<Matrix3<f64>>,
    /// Palette index: the design's colour in every figure.
    pub colour: usize,
}

/// The section comparing `items`; `None` when there is nothing to compare.
pub fn tcp_section(id: &str, items: &[TcpItem]) -> Result<Option<Section>, Error> {
    if items.is_empty() {
        return Ok(None);
    }
    let k = confidence_scale(3, CONFIDENCE)?;
    let mut s = Section::new(id, "TCP precision at the working poses");
    s.html(format!(
        "<p class=\"note\">C_s is the covariance of the tool centre point at the working pose: predicted from the design before anything is measured (paper eq. 19 / appendix, C_s = G C_p Gᵀ), and from the identification afterwards. The figures show the projections of the {:.0} % confidence ellipsoid δᵀ C_s⁻¹ δ ≤ k² with k = √χ²₃({}) = {} onto the coordinate planes of the instrument frame, centred on the TCP (mm): dashed outlines are design predictions, solid ones identifications. The model floor C_floor is what the parameters held fixed add at their stated prior (the cell's <code>fixed_prior</code>); the outlines labelled \u{201c}C_s + model floor\u{201d} (dashed, instrument frame) are the ellipsoid of C_s + C_floor, the one the TCP's true error lies in.</p>\n",
        100.0 * CONFIDENCE,
        CONFIDENCE,
        fixed(k, 3)
    ));
    let rows: Vec<Vec<String>> = items
        .iter()
        .map(|t| {
            let c = &t.covariance;
            let kpi = c.trace() / 3.0;
            let largest = c.symmetric_eigen().eigenvalues.max().max(0.0).sqrt() * k;
            vec![
                escape(&t.label),
                if t.predicted {
                    "design prediction"
                } else {
                    "identification"
                }
                .into(),
                escape(&t.working),
                number(kpi),
                number(kpi.sqrt()),
                number(c[(0, 0)].sqrt()),
                number(c[(1, 1)].sqrt()),
                number(c[(2, 2)].sqrt()),
                number(largest),
                t.floor.map_or("–".into(), |f| number(f.trace() / 3.0)),
                t.floor
                    .map_or("–".into(), |f| number(((c + f).trace() / 3.0).sqrt())),
            ]
        })
        .collect();
    s.html(table(
        &[
            "",
            "source",
            "working pose",
            "(1/3) tr C_s (mm²)",
            "TCP σ (mm)",
            "σ_x (mm)",
            "σ_y (mm)",
            "σ_z (mm)",
            "largest 95 % semi-axis (mm)",
            "model floor (1/3) tr C_floor (mm²)",
            "TCP σ with the floor (mm)",
        ],
        &rows,
        &[3, 4, 5, 6, 7, 8, 9, 10],
    ));
    // One block of figures per working pose (in the order the inputs name them), each
    // comparing every input at that pose.
    let mut poses: Vec<&str> = Vec::new();
    for t in items {
        if !poses.contains(&t.working.as_str()) {
            poses.push(&t.working);
        }
    }
    for (g, pose) in poses.iter().enumerate() {
        let at: Vec<&TcpItem> = items.iter().filter(|t| t.working == *pose).collect();
        if poses.len() > 1 {
            s.html(format!(
                "<h3>Working pose <code>{}</code></h3>\n",
                escape(pose)
            ));
        }
        let gid = if g == 0 {
            id.to_string()
        } else {
            format!("{id}-{}", g + 1)
        };
        pose_figures(&mut s, &gid, pose, &at, k)?;
    }
    Ok(Some(s))
}

/// The ellipse figures of `items` (all at the working pose `pose`) in `s`: the instrument
/// frame, and with a pure-CSS toggle (radio buttons named after `id`) the robot base frame.
fn pose_figures(
    s: &mut Section,
    id: &str,
    pose: &str,
    items: &[&TcpItem],
    k: f64,
) -> Result<(), Error> {
    let series_of = |base: bool| -> Vec<EllipseSeries> {
        // C_s + C_floor, with its own legend entry; the floor is stated in the instrument
        // frame, so only in the instrument view
        let floors = items.iter().filter(|_| !base).filter_map(|t| {
            t.floor.map(|f| EllipseSeries {
                colour: t.colour,
                label: format!("{} (C_s + model floor)", t.label),
                covariance: t.covariance + f,
                dashed: true,
            })
        });
        items
            .iter()
            .map(|t| EllipseSeries {
                colour: t.colour,
                label: format!(
                    "{} ({})",
                    t.label,
                    if t.predicted {
                        "predicted"
                    } else {
                        "identified"
                    }
                ),
                covariance: if base {
                    t.covariance_base.unwrap_or(t.covariance)
                } else {
                    t.covariance
                },
                dashed: t.predicted,
            })
            .chain(floors)
            .collect()
    };
    let figures = |base: bool| -> Result<Vec<Figure>, Error> {
        let series = series_of(base);
        let frame = if base {
            "robot base frame"
        } else {
            "instrument frame"
        };
        Plane::ALL
            .iter()
            .map(|&plane| {
                let (a, b) = plane.axis_names();
                Ok(Figure {
                    svg: tagged(
                        ellipse_figure(plane, &series, k)?,
                        if base { "ellipse-base" } else { "ellipse-instrument" },
                    ),
                    caption: format!(
                        "{a}{b} projection, {frame}, of the {:.0} % confidence ellipsoid of the TCP at `{pose}` (δ{a}, δ{b} in mm).",
                        100.0 * CONFIDENCE
                    ),
                })
            })
            .collect()
    };
    if items.iter().all(|t| t.covariance_base.is_some()) {
        // Two views and a pure-CSS toggle (radio buttons): works offline, without scripts.
        s.html(format!(
            "<div class=\"frame-toggle\">\n<input type=\"radio\" class=\"instrument\" name=\"{id}-frame\" id=\"{id}-frame-instrument\" checked><label for=\"{id}-frame-instrument\">instrument frame</label>\n<input type=\"radio\" class=\"base\" name=\"{id}-frame\" id=\"{id}-frame-base\"><label for=\"{id}-frame-base\">robot base frame</label>\n<div class=\"frame-view frame-instrument\">\n"
        ));
        s.figure_row(figures(false)?);
        s.html("</div>\n<div class=\"frame-view frame-base\">\n<p class=\"note\">The TCP's confidence ellipsoids in the robot base (world) frame: C_base = G_w C_p G_wᵀ with G_w the derivative of the TCP's world position — where the robot's TCP is, without the uncertainty of the instrument's own pose that the instrument-frame C_s includes (so the two differ in size as well as orientation).</p>\n");
        s.figure_row(figures(true)?);
        s.html("</div>\n</div>\n");
    } else {
        s.html("<p class=\"note\">Instrument frame only: a record of an older armcal holds no base-frame C_s.</p>\n");
        s.figure_row(figures(false)?);
    }
    Ok(())
}
