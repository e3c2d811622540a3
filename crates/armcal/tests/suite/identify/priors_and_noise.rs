//! MAP estimation with priors, and noise models (per-measurement σ from a data file, range).

use armcal::identify::*;
use armcal::measure::{csv, NoiseModel};
use armcal::model::random_configurations;
use armcal::{
    perturbed_truth, simulate, Cell, IdentifySettings, ParameterStatus, Perturbation, Silent,
};
use std::path::Path;

fn root() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn a_prior_pulls_a_weak_parameter_toward_its_nominal_value() {
    let cell = Cell::from_file(&root().join("examples/paper-cell.toml")).unwrap();
    let noise = cell.instrument.as_ref().unwrap().noise.clone();
    let truth = perturbed_truth(&cell.model, &Perturbation::default(), 5);
    let qs = random_configurations(&cell.model, 40, 3);
    let data = simulate(&cell.model, &truth, &qs, Some(&noise), 8).unwrap();
    let i = cell.model.registry.index_of("j5.d").unwrap();
    let fit = |status: ParameterStatus| {
        let mut model = cell.model.clone();
        model.registry.set_status(i, status);
        let mut problem = Problem::new(&model, &data, &noise).unwrap();
        let (sol, _, _) = solve(
            &mut problem,
            &model.nominal(),
            &IdentifySettings::default(),
            &mut Silent,
        )
        .unwrap();
        assert!(sol.status.is_converged());
        sol.params[i]
    };
    let nominal = cell.model.registry.get(i).nominal;
    let free = fit(ParameterStatus::Free);
    let loose = fit(ParameterStatus::Prior { sigma: 1e6 });
    let tight = fit(ParameterStatus::Prior { sigma: 1e-6 });
    assert!(
        (loose - free).abs() < 1e-6,
        "a very loose prior changes nothing"
    );
    assert!(
        (tight - nominal).abs() < 1e-4,
        "a very tight prior holds the nominal value"
    );
    let medium = fit(ParameterStatus::Prior { sigma: 0.3 });
    assert!(
        (medium - nominal).abs() < (free - nominal).abs(),
        "a prior shrinks toward nominal"
    );
}

#[test]
fn per_measurement_sigma_comes_from_the_data_file_with_a_floor() {
    let cell = Cell::from_file(&root().join("examples/motoman-right-cell.toml")).unwrap();
    let cols = cell.data_columns.as_ref().unwrap().joints.clone();
    let (data, report) = csv::read(
        &root().join("data/motoman-leica/right_arm_grid_6x6x6.csv"),
        &cell.model,
        Some(&cols),
    )
    .unwrap();
    assert!(report.ignored.contains(&"u_total_m".to_string()));
    let noise = NoiseModel::PerMeasurement { floor: 0.002 };
    let problem = Problem::new(&cell.model, &data, &noise).unwrap();
    // First row: u_x = 1 µm (raised to the 2 µm floor), u_y = 3 µm, u_z = 6 µm.
    assert_eq!(&problem.sigmas[..3], &[0.002, 0.003, 0.006]);
    // The constant model ignores the file's σ; the range model grows with distance.
    let range = NoiseModel::Range {
        a: 0.015,
        b_per_m: 0.006,
    };
    let p = Problem::new(&cell.model, &data, &range).unwrap();
    let m = &data.measurements[0];
    let dist = match &m.kind {
        armcal::measure::MeasurementKind::Position { value, .. } => value.norm(),
        _ => unreachable!(),
    };
    assert!((p.sigmas[0] - (0.015 + 0.006 * dist / 1000.0)).abs() < 1e-15);
    // A per-measurement model needs σ columns.
    let sim = simulate(
        &cell.model,
        &cell.model.nominal(),
        &data.configurations[..3],
        None,
        0,
    )
    .unwrap();
    let e = Problem::new(&cell.model, &sim, &noise)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("no σ columns"), "{e}");
}
