//! Robust estimation with gross errors, and bad input: clear errors, never a panic.

use armcal::identify::*;
use armcal::measure::{csv, MeasurementKind};
use armcal::model::random_configurations;
use armcal::{
    identify, perturbed_truth, simulate, Cell, ErrorStats, Estimate, IdentifySettings, Loss,
    Method, Perturbation, Silent, Status,
};
use nalgebra::Vector3;
use std::path::Path;

fn paper_cell() -> Cell {
    Cell::from_file(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper-cell.toml"))
        .unwrap()
}

#[test]
fn robust_fit_rejects_gross_errors_and_lists_them() {
    let cell = paper_cell();
    let model = &cell.model;
    let noise = cell.instrument.as_ref().unwrap().noise.clone();
    let truth = perturbed_truth(model, &Perturbation::default(), 9);
    let qs = random_configurations(model, 200, 31);
    let clean = simulate(model, &truth, &qs, Some(&noise), 5).unwrap();
    // 5 % of the measurements get a 50 σ error in a random direction.
    let mut dirty = clean.clone();
    let corrupted: Vec<usize> = (0..clean.measurements.len())
        .filter(|i| i % 20 == 7)
        .collect();
    for &i in &corrupted {
        if let MeasurementKind::Position { value, .. } = &mut dirty.measurements[i].kind {
            let d = Vector3::new((i as f64).sin(), (i as f64 * 1.7).cos(), 0.5).normalize();
            *value += d * 50.0;
        }
    }
    let holdout = |data: &armcal::Dataset, robust: Option<Loss>| {
        let opts = IdentifySettings {
            robust,
            holdout: 0.3,
            seed: 2,
            ..Default::default()
        };
        identify(&cell, data, &opts, &mut Silent).unwrap()
    };
    let clean_est = holdout(&clean, None);
    let plain = holdout(&dirty, None);
    let robust = holdout(&dirty, Some(Loss::Huber));
    let cauchy = holdout(&dirty, Some(Loss::Cauchy));
    // Held-out error against the clean measurements of the test configurations.
    let (train, test) = holdout_split(qs.len(), 0.3, 2);
    let clean_test = clean.subset(&test);
    let rms = |e: &Estimate| {
        let problem = Problem::new(model, &clean_test, &noise).unwrap();
        let mut ws = problem.workspace();
        ErrorStats::of(&problem.errors(&mut ws, &e.params_for(model).unwrap())).rms
    };
    eprintln!(
        "held-out RMS: clean {:.3}, plain LM on dirty {:.3}, Huber {:.3}, Cauchy {:.3} mm",
        rms(&clean_est),
        rms(&plain),
        rms(&robust),
        rms(&cauchy)
    );
    assert!(
        rms(&plain) > 1.5 * rms(&clean_est),
        "the gross errors must hurt a plain fit"
    );
    assert!(
        rms(&robust) <= 1.5 * rms(&clean_est),
        "Huber: {} vs clean {}",
        rms(&robust),
        rms(&clean_est)
    );
    assert!(
        rms(&cauchy) <= 1.5 * rms(&clean_est),
        "Cauchy: {} vs clean {}",
        rms(&cauchy),
        rms(&clean_est)
    );
    // Every corrupted measurement in the training split is listed, and nothing else.
    let expected: Vec<String> = corrupted
        .iter()
        .filter(|&&i| train.contains(&clean.measurements[i].config))
        .map(|&i| clean.config_ids[clean.measurements[i].config].clone())
        .collect();
    let mut listed: Vec<String> = robust
        .outliers
        .iter()
        .map(|o| o.configuration.clone())
        .collect();
    listed.sort();
    let mut exp = expected.clone();
    exp.sort();
    assert_eq!(listed, exp);
}

const HEADER: &str = "pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg,x_mm,y_mm,z_mm\n";

fn read(text: &str) -> Result<armcal::Dataset, String> {
    let cell = paper_cell();
    csv::read_str(text, "data.csv", &cell.model, None)
        .map(|d| d.0)
        .map_err(|e| e.to_string())
}

/// `#` lines are comments (armcal writes one on outputs made with an unconverged estimate),
/// and line numbers in errors still count every line of the file.
#[test]
fn data_files_may_carry_comment_lines() {
    let row = "1,0,-10,20,0,10,0,100,200,300\n";
    let d = read(&format!("# armcal: a note\n{HEADER}{row}")).unwrap();
    assert_eq!(d.measurements.len(), 1);
    let e = read(&format!(
        "# armcal: a note\n{HEADER}{row}# another\n2,0,-10,NaN,0,10,0,100,200,300\n"
    ))
    .unwrap_err();
    assert!(e.contains("line 5") && e.contains("q3_deg"), "{e}");
}

#[test]
fn bad_data_files_give_clear_errors() {
    let row = "1,0,-10,20,0,10,0,100,200,300\n";
    assert!(read(&format!("{HEADER}{row}")).is_ok());
    let e = read(&format!("{HEADER}{row}2,0,-10,NaN,0,10,0,100,200,300\n")).unwrap_err();
    assert!(
        e.contains("data.csv")
            && e.contains("line 3")
            && e.contains("q3_deg")
            && e.contains("not finite"),
        "{e}"
    );
    let e = read(&format!("{HEADER}{row}2,0,-10,20,0,10,0,,200,300\n")).unwrap_err();
    assert!(
        e.contains("line 3") && e.contains("x_mm") && e.contains("missing"),
        "{e}"
    );
    let e = read(&format!("{HEADER}{row}2,0,-10,20,0,10,0,100,200\n")).unwrap_err();
    assert!(e.contains("line 3"), "wrong column count: {e}");
    let e = read(&HEADER.replace("x_mm", "x_ft").to_string()).unwrap_err();
    assert!(
        e.contains("x_ft") && e.contains("unknown unit suffix `ft`"),
        "{e}"
    );
    let e = read(&HEADER.replace("q2_deg", "q2_grad").to_string()).unwrap_err();
    assert!(
        e.contains("q2_grad") && e.contains("unknown unit suffix"),
        "{e}"
    );
    let e = read(
        &HEADER
            .replace("q4_deg,", "")
            .replace(",0,10,0,100", ",10,0,100"),
    )
    .unwrap_err();
    assert!(e.contains("no column for joint `q4`"), "{e}");
    let e = read(HEADER).unwrap_err();
    assert!(e.contains("no data rows"), "{e}");
    let e = read(&format!(
        "{HEADER}1,0,-10,20,0,10,0,1,2,3\n1,5,-10,20,0,10,0,1,2,3\n"
    ))
    .unwrap_err();
    assert!(
        e.contains("pose_id `1` appears with different joint values"),
        "{e}"
    );
    // Units: metres and radians are converted.
    let d = read("q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad,x_m,y_m,z_m\n0,0,0,0,0,0,1.5,0,0\n")
        .unwrap();
    match &d.measurements[0].kind {
        MeasurementKind::Position { value, .. } => assert_eq!(value[0], 1500.0),
        k => panic!("{k:?}"),
    }
}

#[test]
fn too_few_or_degenerate_measurements_are_refused_with_reasons() {
    let cell = paper_cell();
    let model = &cell.model;
    let qs = random_configurations(model, 5, 1);
    let data = simulate(model, &model.nominal(), &qs, None, 0).unwrap();
    let e = identify(&cell, &data, &IdentifySettings::default(), &mut Silent)
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.contains("15 residual rows") && e.contains("27 parameters"),
        "{e}"
    );
    // 20 measurements of one configuration: rank 3. With `free = "auto"` the estimate
    // names everything these data cannot identify.
    let same = vec![qs[0].clone(); 20];
    let noise = cell.instrument.as_ref().unwrap().noise.clone();
    let data = simulate(model, &model.nominal(), &same, Some(&noise), 0).unwrap();
    let est = identify(&cell, &data, &IdentifySettings::default(), &mut Silent).unwrap();
    assert_eq!(est.free.len(), 3);
    let from_data: Vec<&str> = est
        .fixed_reasons
        .iter()
        .filter(|(_, r)| r.starts_with("from these data"))
        .map(|(n, _)| n.as_str())
        .collect();
    assert_eq!(from_data.len(), 24, "{from_data:?}");
    assert!(from_data.contains(&"j2.beta"));
    // With an explicit free list the rank deficiency is an error naming the parameters.
    let mut fixed_list = cell.clone();
    fixed_list.auto_free = false;
    let e = identify(
        &fixed_list,
        &data,
        &IdentifySettings::default(),
        &mut Silent,
    )
    .err()
    .unwrap()
    .to_string();
    assert!(
        e.contains("not all identifiable") && e.contains("`j"),
        "{e}"
    );
}

#[test]
fn a_fit_that_cannot_converge_reports_its_status() {
    let cell = paper_cell();
    let model = &cell.model;
    let truth = perturbed_truth(
        model,
        &Perturbation {
            length: 20.0,
            angle: 0.1,
            ..Default::default()
        },
        3,
    );
    let qs = random_configurations(model, 60, 1);
    let data = simulate(
        model,
        &truth,
        &qs,
        Some(&cell.instrument.as_ref().unwrap().noise),
        0,
    )
    .unwrap();
    let mut opts = IdentifySettings::default();
    opts.lm.tolerances.max_iterations = 2;
    let est = identify(&cell, &data, &opts, &mut Silent).unwrap();
    assert_eq!(est.solver.status, Status::IterationLimit);
    // Undamped Gauss–Newton from a start far away: diverges or stops, with a reason.
    let far = perturbed_truth(
        model,
        &Perturbation {
            length: 2000.0,
            angle: 2.0,
            ..Default::default()
        },
        3,
    );
    let data = simulate(model, &far, &qs, None, 0).unwrap();
    let opts = IdentifySettings {
        method: Method::GaussNewton,
        ..Default::default()
    };
    match identify(&cell, &data, &opts, &mut Silent) {
        Ok(est) => assert!(
            !est.solver.status.is_converged() || est.uncertainty.verdict.contains("too large"),
            "{:?}",
            est.solver.status
        ),
        Err(e) => assert!(!e.to_string().is_empty()),
    }
}
