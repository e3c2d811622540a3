//! Completeness counts (book check 1) and the numerical identifiability analysis.

use crate::common;
use armcal::model::analyze;
use armcal::model::*;
use armcal::{Cell, IdentifiabilitySettings, JointKind, Measurement, Model};
use common::*;
use std::path::Path;

fn examples() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples")
}

#[test]
fn paper_cell_identifies_the_papers_27_parameters() {
    let cell = Cell::from_file(&examples().join("paper-cell.toml")).unwrap();
    let free: Vec<&str> = cell
        .model
        .registry
        .iter()
        .filter(|p| p.status.is_free())
        .map(|p| p.name.as_str())
        .collect();
    assert_eq!(free.len(), 27, "{free:?}");
    // Paper Table 2: j1 α, a; j2 θ a α β; j3–j5 θ d a α; tracker 6; reflector 3.
    for name in [
        "j1.a",
        "j1.alpha",
        "j2.beta",
        "j5.d",
        "tracker.rz",
        "smr1.z",
    ] {
        assert!(free.contains(&name), "{name} should be free");
    }
    let report = cell
        .identifiability(&cell.identifiability_settings())
        .unwrap();
    assert_eq!(report.rank_svd, 27);
    assert_eq!(report.rank_qr, 27);
    assert_eq!(report.identifiable.len(), 27);
    let excluded: Vec<&str> = report.excluded.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(
        excluded,
        ["j1.theta", "j1.d", "j6.theta", "j6.d", "j6.a", "j6.alpha"]
    );
    let reason = |n: &str| &report.excluded.iter().find(|e| e.name == n).unwrap().reason;
    assert!(
        reason("j1.theta").contains("`tracker.rz`"),
        "{}",
        reason("j1.theta")
    );
    assert!(reason("j1.d").contains("`tracker.z`"), "{}", reason("j1.d"));
    assert!(reason("j6.d").contains("`smr1.z`"), "{}", reason("j6.d"));
}

/// A random DH chain with base and tool frames, joints given by `kinds` ('R' / 'P').
fn random_chain(kinds: &str, seed: u64) -> Model {
    let mut r = rng(seed);
    let mut links = vec![LinkSpec {
        name: "base".into(),
        geometry: random_geometry(Convention::Frame6, None, &mut r),
        joint: None,
    }];
    for (i, k) in kinds.chars().enumerate() {
        let kind = if k == 'R' {
            JointKind::Revolute
        } else {
            JointKind::Prismatic
        };
        links.push(LinkSpec {
            name: format!("j{}", i + 1),
            geometry: random_geometry(Convention::Dh, Some(kind), &mut r),
            joint: Some(joint(&format!("q{}", i + 1), kind)),
        });
    }
    links.push(LinkSpec {
        name: "tool".into(),
        geometry: random_geometry(Convention::Frame6, None, &mut r),
        joint: None,
    });
    Model::from_spec(&ModelSpec {
        compliance: None,
        periodic: None,
        payloads: Vec::new(),
        name: kinds.into(),
        instrument: None,
        links,
        targets: vec![],
    })
    .unwrap()
}

#[test]
fn book_completeness_counts_hold_numerically() {
    // Book check 1: N = 4R + 2P + 6 — PUMA-like 6R 30, Stanford 5R1P 28, 3R 18, R 10, P 8.
    for (kinds, expected) in [
        ("RRRRRR", 30),
        ("RRPRRR", 28),
        ("RRR", 18),
        ("R", 10),
        ("P", 8),
    ] {
        let model = random_chain(kinds, 7);
        let opts = IdentifiabilitySettings {
            measurement: Measurement::Pose,
            ..Default::default()
        };
        let report = analyze(&model, &model.nominal(), &opts).unwrap();
        assert_eq!(report.completeness.complete_pose_model, expected, "{kinds}");
        assert_eq!(report.rank_svd, expected, "{kinds} SVD rank");
        assert_eq!(report.rank_qr, expected, "{kinds} QR rank");
        assert_eq!(report.identifiable.len(), expected, "{kinds} selection");
        assert_eq!(
            report.identifiable.len() + report.excluded.len(),
            model.param_count()
        );
    }
}

#[test]
fn position_and_distance_lose_orientation_and_placement() {
    let model = random_chain("RRRRRR", 11);
    for (m, expected) in [
        (Measurement::Pose, 30),
        (Measurement::Position, 27),
        (Measurement::Distance, 21),
    ] {
        let report = analyze(
            &model,
            &model.nominal(),
            &IdentifiabilitySettings {
                measurement: m,
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(report.identifiable.len(), expected, "{m:?}");
        assert_eq!(report.rank_svd, expected, "{m:?}");
        assert_eq!(report.completeness.expected_for_measurement, Some(expected));
    }
}

#[test]
fn identical_poses_are_rank_deficient() {
    let cell = Cell::from_file(&examples().join("paper-cell.toml")).unwrap();
    let q = vec![0.1, -0.3, 0.5, 0.2, 0.4, 0.1];
    let report = armcal::model::analyze_at(
        &cell.model,
        &cell.model.nominal(),
        &vec![q; 20],
        &cell.identifiability_settings(),
    )
    .unwrap();
    assert_eq!(report.rank_svd, 3, "one position seen 20 times has rank 3");
    assert_eq!(report.identifiable.len(), 3);
    assert!(report.excluded.len() >= 24);
}
