//! Periodic joint errors (issue 14 item 2) with joint compliance: the paper cell with
//! `periodic = { joints = […], harmonics = […] }`. The cell names the terms and refuses what
//! it cannot model; noise-free data with a compliant and periodic truth recover every
//! parameter; a term that is the same function as another (the first harmonic of `q2` and
//! its compliance under the elbow mass) or as the geometry over the measured range is named
//! and dropped, and the fit is redone without it.

use super::compliance::{assert_recovered, fit, paper_cell_with};
use armcal::model::random_configurations;
use armcal::{
    identify, perturbed_truth, simulate, IdentifySettings, ParameterStatus, Perturbation, Silent,
    Unit,
};

const BOTH: &str = "compliance = [\"q2\", \"q3\"]\n\
                    periodic = { joints = [\"q1\", \"q2\", \"q3\"], harmonics = [1, 2] }";

#[test]
fn the_cell_names_the_periodic_terms() {
    let cell = paper_cell_with(
        "periodic = { joints = [\"q3\", \"q1\"], harmonics = [2, 1] }",
        "periodic-names",
    )
    .unwrap();
    let declared = cell.declared_model();
    let terms: Vec<(&str, bool)> = declared
        .registry
        .iter()
        .filter(|p| p.unit == Unit::Arcsec)
        .map(|p| (p.name.as_str(), p.status.is_free()))
        .collect();
    let names: Vec<&str> = terms.iter().map(|t| t.0).collect();
    assert_eq!(
        names,
        [
            "q1.periodic.sin1",
            "q1.periodic.cos1",
            "q1.periodic.sin2",
            "q1.periodic.cos2",
            "q3.periodic.sin1",
            "q3.periodic.cos1",
            "q3.periodic.sin2",
            "q3.periodic.cos2"
        ]
    );
    assert!(terms.iter().all(|t| t.1), "every term is free: {terms:?}");
    // a prior in arcsec
    let cell = paper_cell_with(
        "periodic = { joints = [\"q1\"], harmonics = [1] }\n\
         priors = { \"q1.periodic.sin1\" = { sigma_arcsec = 30 } }",
        "periodic-prior",
    )
    .unwrap();
    let i = cell.model.registry.index_of("q1.periodic.sin1").unwrap();
    let ParameterStatus::Prior { sigma } = cell.model.registry.get(i).status else {
        panic!("a prior: {:?}", cell.model.registry.get(i).status)
    };
    assert!((sigma * Unit::Arcsec.display_factor() - 30.0).abs() < 1e-9);
}

#[test]
fn the_cell_refuses_what_it_cannot_model_with_the_line() {
    for (extra, words) in [
        (
            "periodic = { joints = [\"q9\"], harmonics = [1] }",
            "unknown joint `q9`",
        ),
        (
            "periodic = { joints = [\"q1\"], harmonics = [0] }",
            "harmonic 0",
        ),
        (
            "periodic = { joints = [\"q1\", \"q1\"], harmonics = [1] }",
            "listed twice",
        ),
        (
            "periodic = { joints = [], harmonics = [1] }",
            "at least one",
        ),
    ] {
        let e = paper_cell_with(extra, "periodic-bad")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(words) && e.contains("parameters.periodic") && e.contains("line"),
            "{extra}: {e}"
        );
    }
    let e = paper_cell_with(
        "periodic = { joints = [\"q1\"], harmonic = [1] }",
        "periodic-field",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("harmonic") && e.contains("line"), "{e}");
}

#[test]
fn noise_free_data_recover_geometry_compliance_and_periodic_errors() {
    let cell = paper_cell_with(BOTH, "periodic-both").unwrap();
    let model = &cell.model;
    let kinds = |u: Unit| {
        model
            .registry
            .free()
            .into_iter()
            .filter(|&i| model.registry.get(i).unit == u)
            .count()
    };
    // the cell's identifiable set keeps compliance and periodic terms alike
    assert!(kinds(Unit::RadPerMm) >= 2 && kinds(Unit::Arcsec) >= 10);
    let truth = perturbed_truth(model, &Perturbation::default(), 14);
    let qs = random_configurations(model, 120, 6);
    let data = simulate(model, &truth, &qs, None, 0).unwrap();
    let noise = cell.instrument.as_ref().unwrap().noise.clone();
    let est = fit(&cell, &data, &noise);
    assert_recovered(model, &est, &truth);
}

/// The first harmonic of `q2` and the compliance of `q2` under the elbow mass are the same
/// function (the elbow's lever is `a₂ cos(q₂ + φ)`): one of them is left out, with its reason.
#[test]
fn the_first_harmonic_and_the_elbow_compliance_are_one_function() {
    let cell = paper_cell_with(
        "compliance = [\"q2\"]\nperiodic = { joints = [\"q2\"], harmonics = [1] }",
        "periodic-elbow",
    )
    .unwrap();
    let truth = perturbed_truth(&cell.model, &Perturbation::default(), 3);
    let qs = random_configurations(&cell.model, 60, 2);
    let data = simulate(&cell.model, &truth, &qs, None, 0).unwrap();
    let e = identify(&cell, &data, &IdentifySettings::default(), &mut Silent).unwrap();
    let group = [
        "q2.compliance.elbow",
        "q2.periodic.sin1",
        "q2.periodic.cos1",
    ];
    let out: Vec<&(String, String)> = e
        .fixed_reasons
        .iter()
        .filter(|(n, _)| group.contains(&n.as_str()))
        .collect();
    eprintln!("left out: {out:?}");
    assert_eq!(
        out.len(),
        1,
        "exactly one of the three is left out: {out:?}"
    );
    assert!(
        e.nongeometric.iter().all(|v| v.separable),
        "{:?}",
        e.nongeometric
    );
}

/// Over a narrow range of `q2` (±6°) its harmonics are nearly the joint offset and a linear
/// function of it: the gate finds them not separable, the fit drops them one by one (each
/// named with its unabsorbed share) and what it keeps is separable.
#[test]
fn terms_the_data_cannot_separate_are_dropped_and_the_fit_redone() {
    let cell = paper_cell_with(
        "periodic = { joints = [\"q2\", \"q3\"], harmonics = [1, 2] }",
        "periodic-narrow",
    )
    .unwrap();
    let model = &cell.model;
    let q2 = model.joints.iter().position(|j| j.name == "q2").unwrap();
    let qs: Vec<Vec<f64>> = random_configurations(model, 80, 9)
        .into_iter()
        .enumerate()
        .map(|(k, mut q)| {
            q[q2] = 0.1 * ((k as f64) * 0.37).sin();
            q
        })
        .collect();
    let truth = perturbed_truth(model, &Perturbation::default(), 4);
    let noise = cell.instrument.as_ref().unwrap().noise.clone();
    let data = simulate(model, &truth, &qs, Some(&noise), 1).unwrap();
    let e = identify(&cell, &data, &IdentifySettings::default(), &mut Silent).unwrap();
    let dropped: Vec<&(String, String)> = e
        .fixed_reasons
        .iter()
        .filter(|(n, r)| n.starts_with("q2.periodic") && r.contains("not separable"))
        .collect();
    eprintln!("dropped: {dropped:?}\nkept: {:?}", e.nongeometric);
    assert!(!dropped.is_empty(), "{:?}", e.fixed_reasons);
    assert!(
        e.nongeometric.iter().all(|v| v.separable),
        "{:?}",
        e.nongeometric
    );
    assert!(
        e.nongeometric
            .iter()
            .any(|v| v.name.starts_with("q3.periodic")),
        "q3 moves over its range: its terms stay"
    );
    assert!(e.solver.status.is_converged(), "{:?}", e.solver.status);
}
