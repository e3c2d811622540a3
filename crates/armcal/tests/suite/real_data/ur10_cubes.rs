//! ISO 9283 on the real cubes of the UR10 data, Series D (`data/ipa-ur10-leica/`, Landgraf
//! et al., IEEE CASE 2021): the structure `accuracy` finds in the file, and AP/RP before
//! (nominal robot, frames fitted) and after calibration (a stand-in: Series D identified
//! on 70 % of its own rows) within plausible bounds.
//!
//! The file holds 70 blocks of 9 rows — a cube centre, then its 8 corners — plus 2 rows: each
//! cube centre is measured with cubes of 400, 250 and 100 mm edge, so a centre is approached
//! three times (the first five times), the first 400 mm cube's corners three times, and every
//! other corner once. One cube is repeated 0.9 mm lower (rows 73–99): its corners stay poses
//! of their own.

use armcal::measure::csv;
use armcal::{
    commanded_poses, identify, performance, Calibrated, Cell, IdentifySettings,
    PerformanceSettings, SamePose, Silent,
};
use std::path::Path;

#[test]
fn series_d_cubes_before_and_after() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let cell = Cell::from_file(&root.join("examples/ur10-leica-cell.toml")).unwrap();
    let file = root.join("data/ipa-ur10-leica/Series_D/measurements_iso_cubes.csv");
    let (data, _) = csv::read_with(&file, &cell.model, &cell.data_format()).unwrap();
    let found = commanded_poses(
        &cell.model,
        &data.configurations,
        &data.config_ids,
        &SamePose::default(),
    );
    let s = &found.summary;
    // 632 rows; 31 poses approached more than once: 25 centres and the first cube's corners.
    assert_eq!((s.configurations, s.poses), (632, 574));
    assert_eq!(s.approaches, vec![[1, 543], [2, 6], [3, 24], [5, 1]]);
    let five = found.groups.iter().find(|g| g.len() == 5).unwrap();
    // The first centre: rows 1, 10, 19, 28 and 37 (pose ids are file lines here: 2, 11, …).
    assert_eq!(
        five.iter()
            .map(|&c| data.config_ids[c].as_str())
            .collect::<Vec<_>>(),
        ["1", "10", "19", "28", "37"]
    );
    assert!(
        s.largest_spread_mm < 0.25 && s.largest_spread_deg < 0.05,
        "{s:?}"
    );
    let close = s.closest.as_ref().unwrap();
    assert!(
        close.distance_mm > 0.5 && close.distance_mm < 1.0,
        "{close:?}"
    );

    let est = identify(
        &cell,
        &data,
        &IdentifySettings {
            holdout: 0.3,
            ..Default::default()
        },
        &mut Silent,
    )
    .unwrap();
    let params = est.params_for(&cell.model).unwrap();
    let rec = performance(
        &cell,
        &data,
        Some(Calibrated {
            name: "Series D, 70 % identified".into(),
            params: &params,
        }),
        &PerformanceSettings::default(),
        &mut Silent,
    )
    .unwrap();
    let (before, after) = (
        &rec.before.report.summary,
        &rec.after.as_ref().unwrap().report.summary,
    );
    eprintln!("before {before:?}\nafter {after:?}");
    // The UR10's repeatability is ±0.1 mm by its datasheet; RP_l = l̄ + 3 S_l of three
    // approaches scatters around that. AP of the nominal robot: under a few millimetres
    // once its frames are fitted; the calibration must shrink it.
    let (rb, ra) = (before.rp.as_ref().unwrap(), after.rp.as_ref().unwrap());
    assert!(rb.mean > 0.02 && rb.max < 0.3, "{rb:?}");
    assert!(
        (rb.max - ra.max).abs() < 1e-9,
        "RP does not depend on the model"
    );
    assert!(
        before.ap.mean > 0.3 && before.ap.max < 3.0,
        "{:?}",
        before.ap
    );
    assert!(
        after.ap.mean < 0.7 * before.ap.mean,
        "{:?} vs {:?}",
        after.ap,
        before.ap
    );
    let (ob, oa) = (
        before.ap_abc_max_deg.unwrap(),
        after.ap_abc_max_deg.unwrap(),
    );
    assert!(ob.iter().all(|&v| v < 0.5) && oa.iter().sum::<f64>() < ob.iter().sum::<f64>());
    assert!(before
        .rp_abc_max_deg
        .unwrap()
        .iter()
        .all(|&v| v > 0.001 && v < 0.1));
    assert_eq!((before.repeated, before.iso_cycles), (31, 0));
}
