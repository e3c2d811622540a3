//! Issue 15, found #3: `armcal report` spun forever when a span overflowed to infinity (a
//! design's joint range of ±1e308, residuals of 1e308 and −1e308); now the figure, and with it
//! the document, is refused with an error. Each test passes only if the call returns.

use crate::common::example_cell;
use armcal::model::random_configurations;
use armcal::report::figures::{
    bar_figure, cdf_figure, histogram_figure, joint_figure, series_figure, JointTrace,
};
use armcal::report::{self, Document, Input, ReportContent};
use armcal::DesignRecord;

const HUGE: [f64; 3] = [1e308, -1e308, 0.0];

fn assert_too_wide<T: std::fmt::Debug>(r: Result<T, armcal::Error>) {
    let e = r.expect_err("an overflowing range is refused").to_string();
    assert!(e.contains("too wide to draw"), "{e}");
}

#[test]
fn overflowing_values_are_refused_by_every_figure() {
    let values = vec![("r".to_string(), HUGE.to_vec())];
    assert_too_wide(histogram_figure("h", "x", &values, 10));
    assert_too_wide(bar_figure(
        "b",
        "y",
        &["a".into(), "b".into(), "c".into()],
        &values,
        None,
        false,
    ));
    let pts = vec![("s".to_string(), HUGE.iter().map(|&v| (v, v)).collect())];
    assert_too_wide(series_figure("s", "x", "y", &pts, &[]));
    assert_too_wide(cdf_figure("c", "x", &[("e".into(), vec![0.0, 1.75e308])]));
    let joint = JointTrace {
        name: "q1".into(),
        unit: "deg".into(),
        lower: -1e308,
        upper: 1e308,
        values: vec![0.0],
    };
    assert_too_wide(joint_figure("j", &[joint]));
}

#[test]
fn a_design_with_an_overflowing_joint_range_is_refused() {
    let cell = example_cell("paper-cell.toml");
    let qs = random_configurations(&cell.model, 40, 7);
    let mut design = DesignRecord::new(&cell, None, "random poses", &qs, None, false).unwrap();
    design.joints[0].lower = -1e308;
    design.joints[0].upper = 1e308;
    let inputs = vec![Input {
        label: "design".into(),
        source: "design.json".into(),
        document: Document::Design(Box::new(design)),
    }];
    let e = report::page(&ReportContent {
        title: "t",
        subtitle: "s",
        inputs: &inputs,
        ..Default::default()
    })
    .map(|_| ())
    .expect_err("the design is refused")
    .to_string();
    assert!(
        e.starts_with("design.json: ") && e.contains("too wide to draw"),
        "{e}"
    );
}

/// Found by `fuzz/records`: a design whose joint value lies far outside the joint's limits
/// (finite: −6.1e17 deg) overflowed plotters' pixel coordinates (the axis was the limits alone).
#[test]
fn a_joint_value_far_past_its_limits_draws() {
    let joint = JointTrace {
        name: "q1".into(),
        unit: "deg".into(),
        lower: -180.0,
        upper: 180.0,
        values: vec![0.0, -6.1e17, 1e300, -45.0],
    };
    let svg = joint_figure("j", &[joint]).expect("the figure draws");
    // Every pose's dot lies inside the drawing (a wrapped pixel coordinate lies far out).
    let coordinate = |attr: &str| -> Vec<f64> {
        svg.split(&format!("{attr}=\""))
            .skip(1)
            .map(|rest| rest[..rest.find('"').unwrap()].parse().unwrap())
            .collect()
    };
    let (cx, cy) = (coordinate("cx"), coordinate("cy"));
    assert_eq!(cx.len(), 4, "{svg}");
    for (x, y) in cx.iter().zip(&cy) {
        assert!(
            (0.0..=2000.0).contains(x) && (0.0..=2000.0).contains(y),
            "dot at ({x}, {y})"
        );
    }
}
