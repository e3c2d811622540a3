//! Every export format of a calibrated model re-imports to the same forward kinematics
//! (1e-6 mm): cell TOML in the model's own convention and as DH, modified DH and
//! zero-reference; JSON; URDF through urdf-rs.

use armcal::model::random_configurations;
use armcal::model::{
    convert, export, forward_kinematics, observed_pose, urdf, Data, ModelSpec, Observed,
};
use armcal::{perturbed_truth, Cell, Model, Perturbation};
use std::path::Path;

fn calibrated() -> (Model, ModelSpec) {
    let cell = Cell::from_file(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper-cell.toml"),
    )
    .unwrap();
    let p = perturbed_truth(
        &cell.model,
        &Perturbation {
            all: true,
            ..Default::default()
        },
        9,
    );
    let spec = cell.model.spec_at(&p);
    (Model::from_spec(&spec).unwrap(), spec)
}

/// Largest difference of the measured target and of the tool, in and out of the instrument.
fn max_difference(a: &Model, b: &Model, with_instrument: bool) -> f64 {
    let (pa, pb) = (a.nominal(), b.nominal());
    let (mut da, mut db) = (Data::new(a), Data::new(b));
    let mut worst: f64 = 0.0;
    for q in random_configurations(a, 50, 3) {
        forward_kinematics(a, &mut da, &pa, &q);
        forward_kinematics(b, &mut db, &pb, &q);
        worst = worst.max((da.tool().trans - db.tool().trans).norm());
        worst = worst.max((da.tool().rot - db.tool().rot).norm() * 1000.0);
        if with_instrument {
            let (ta, tb) = (
                observed_pose(&da, Observed::Target(0)),
                observed_pose(&db, Observed::Target(0)),
            );
            worst = worst.max((ta.trans - tb.trans).norm());
        }
    }
    worst
}

fn reload_cell(text: &str) -> Model {
    Cell::from_toml(text, "export.toml", Path::new("."))
        .unwrap()
        .model
}

#[test]
fn cell_exports_in_every_convention_round_trip() {
    let (model, spec) = calibrated();
    let zrp = convert::to_zrp(&model, &model.nominal());
    let dh = convert::zrp_to_dh(&zrp, Some(&spec)).unwrap();
    // Modified DH from a pure DH chain (the nominal's Hayati link cannot be regrouped).
    let mdh = convert::dh_to_mdh(&convert::zrp_to_dh(&zrp, None).unwrap()).unwrap();
    for (name, s) in [("own", &spec), ("zrp", &zrp), ("dh", &dh), ("mdh", &mdh)] {
        let back = reload_cell(&export::to_cell_toml(s).unwrap());
        let d = max_difference(&model, &back, true);
        assert!(d < 1e-6, "{name}: {d} mm");
        assert!(export::to_table_csv(s).lines().count() > model.param_count() / 2);
    }
}

#[test]
fn json_and_urdf_exports_round_trip() {
    let (model, spec) = calibrated();
    let json = serde_json::to_string(&spec).unwrap();
    let back: ModelSpec = serde_json::from_str(&json).unwrap();
    assert!(max_difference(&model, &Model::from_spec(&back).unwrap(), true) < 1e-9);
    // URDF carries the robot (no instrument, no targets): compare the tool frame.
    let mut robot_only = spec.clone();
    robot_only.instrument = None;
    robot_only.targets.clear();
    let xml = urdf::to_urdf(&robot_only).unwrap();
    let robot = urdf_rs::read_from_string(&xml).unwrap();
    let imported = urdf::from_urdf_robot(&robot, None).unwrap();
    let m = Model::from_spec(&imported).unwrap();
    let reference = Model::from_spec(&robot_only).unwrap();
    assert!(max_difference(&reference, &m, false) < 1e-6);
    // Joint limits are kept.
    for (a, b) in reference.joints.iter().zip(&m.joints) {
        assert!((a.lower - b.lower).abs() < 1e-12 && (a.upper - b.upper).abs() < 1e-12);
    }
}
