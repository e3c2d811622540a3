//! Which poses the instrument can measure (issue 12, item 4): the incidence angle recomputed
//! from the forward kinematics (paper eq. 4: the flange z axis against the beam to the
//! tracker) picks out the same poses of the README's old random pose file as
//! `unmeasurable_poses`; the planned example poses are all measurable.

use crate::common::example_cell;
use armcal::design::ConstraintKind;
use armcal::measure::csv::read_configurations;
use armcal::model::{forward_kinematics, Data};
use armcal::unmeasurable_poses;
use std::path::Path;

fn example(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name)
}

#[test]
fn the_random_example_poses_are_mostly_unmeasurable() {
    let cell = example_cell("paper-cell.toml");
    let poses =
        read_configurations(&example("paper-poses-random-60.csv"), &cell.model, None).unwrap();
    let found = unmeasurable_poses(&cell, &poses).unwrap();
    let model = &cell.model;
    let mut data = Data::new(model);
    let mut beyond_30 = Vec::new();
    for (id, q) in &poses {
        forward_kinematics(model, &mut data, &model.nominal(), q);
        let p = data.targets[0].trans;
        let z = data.tool().rot.column(2).into_owned();
        let g = (data.instrument.trans - p).normalize();
        let beta = z.dot(&g).clamp(-1.0, 1.0).acos().to_degrees();
        if beta > 30.0 {
            beyond_30.push((id.clone(), beta));
        }
    }
    let with_incidence: Vec<(String, f64)> = found
        .iter()
        .filter_map(|u| {
            u.violations
                .iter()
                .find(|v| v.kind == ConstraintKind::Incidence)
                .map(|v| (u.id.clone(), v.value))
        })
        .collect();
    assert_eq!(with_incidence.len(), beyond_30.len());
    for ((a, ba), (b, bb)) in with_incidence.iter().zip(&beyond_30) {
        assert_eq!(a, b);
        assert!((ba - bb).abs() < 1e-9, "pose {a}: {ba} vs {bb}");
    }
    // Most random poses face away from the tracker (≈ 6 % of uniform draws meet the limit).
    assert!(found.len() > 40, "{} unmeasurable", found.len());
    let text = found[0].to_string();
    assert!(
        text.starts_with(&format!("pose {}: incidence ", found[0].id)) && text.contains("° > 30°"),
        "{text}"
    );
}

#[test]
fn the_planned_example_poses_are_measurable() {
    for cell in ["paper-cell.toml", "paper-cell-obstacles.toml"] {
        let cell = example_cell(cell);
        let poses =
            read_configurations(&example("paper-poses-planned-60.csv"), &cell.model, None).unwrap();
        let found = unmeasurable_poses(&cell, &poses).unwrap();
        if cell.obstacles.is_empty() {
            assert!(found.is_empty(), "{:?}", found);
        } else {
            // Planned without the car: some poses reach into it or behind it, and are named.
            for u in &found {
                assert!(u
                    .violations
                    .iter()
                    .all(|v| v.kind != ConstraintKind::Incidence));
            }
        }
    }
}
