//! An estimate knows how its fit went and what it was identified on (issue #10 items 4, 5):
//! the χ² verdict states what a wrong σ means for the reported σ's, an unconverged or
//! unverified estimate is refused, and a cell that differs from the estimate's is an error
//! naming the difference.

use crate::common;
use armcal::identify::*;
use armcal::measure::NoiseModel;
use armcal::model::random_configurations;
use armcal::{
    identify, perturbed_truth, simulate, Acceptance, Cell, Dataset, Estimate, IdentifySettings,
    Perturbation, Silent, Status,
};
use common::example_cell;
use std::path::Path;

/// Acceptance in the CLI's words, as the CLI passes it.
fn cli(accepted: bool) -> Acceptance<'static> {
    Acceptance {
        accepted,
        accept: "--accept-unconverged",
        raise_iterations: "--max-iterations",
    }
}

fn constant(sigma: f64) -> NoiseModel {
    NoiseModel::Constant {
        sigma: [sigma; 3],
        sigma_angle: 1e-5,
    }
}

/// The paper cell stating σ = `stated` mm, and 80 configurations measured with σ = `actual`.
fn paper_campaign(stated: f64, actual: f64, seed: u64) -> (Cell, Dataset) {
    let mut cell = example_cell("paper-cell.toml");
    cell.instrument.as_mut().unwrap().noise = constant(stated);
    let model = &cell.model;
    let truth = perturbed_truth(model, &Perturbation::default(), seed);
    let qs = random_configurations(model, 80, seed + 1);
    let data = simulate(model, &truth, &qs, Some(&constant(actual)), seed + 2).unwrap();
    (cell, data)
}

fn sigmas(e: &Estimate) -> Vec<f64> {
    e.parameters.iter().filter_map(|p| p.sigma).collect()
}

/// σ stated 1 mm but measured with 3 mm (and with 0.3 mm): the verdict says the σ's are
/// about 3× too small (too large), and the σ's reported with the right σ stated are indeed
/// √σ̂₀² times those reported with the wrong one.
#[test]
fn chi2_verdict_says_what_a_wrong_sigma_means_for_the_reported_sigmas() {
    for (actual, outcome, words) in [
        (3.0, Chi2Outcome::SigmaTooSmall, "too small"),
        (0.3, Chi2Outcome::SigmaTooLarge, "too large"),
    ] {
        let (cell, data) = paper_campaign(1.0, actual, 40);
        let wrong = identify(&cell, &data, &IdentifySettings::default(), &mut Silent).unwrap();
        let v = wrong.verdicts.as_ref().unwrap();
        assert_eq!(v.chi2.outcome, outcome, "{}", v.chi2.meaning);
        let k = v.chi2.sigma_ratio.unwrap();
        // σ̂₀ estimates σ_true/σ_stated from 240 − 27 degrees of freedom (±5 % at 1σ).
        assert!(
            (k / actual - 1.0).abs() < 0.15,
            "√σ̂₀² = {k}, actual {actual}"
        );
        assert!(
            v.chi2.meaning.contains(words)
                && v.chi2.meaning.contains(&format!("√σ̂₀² = {k:.2}"))
                && v.chi2.meaning.contains("not scaled by σ̂₀²"),
            "{}",
            v.chi2.meaning
        );
        let usable = wrong.check_usable(&cli(false)).unwrap();
        assert!(
            usable.overridden.is_none() && usable.notes.iter().any(|n| n.contains(words)),
            "{usable:?}"
        );

        // Stating the true σ: consistent, and every reported σ is k times the wrong one's.
        let mut right_cell = cell.clone();
        right_cell.instrument.as_mut().unwrap().noise = constant(actual);
        let right = identify(
            &right_cell,
            &data,
            &IdentifySettings::default(),
            &mut Silent,
        )
        .unwrap();
        let rv = right.verdicts.as_ref().unwrap();
        assert_eq!(
            rv.chi2.outcome,
            Chi2Outcome::Consistent,
            "{}",
            rv.chi2.meaning
        );
        assert!(right.check_usable(&cli(false)).unwrap().notes.is_empty());
        for (s_wrong, s_right) in sigmas(&wrong).iter().zip(sigmas(&right)) {
            let ratio = s_right / (k * s_wrong);
            assert!(
                (ratio - 1.0).abs() < 0.15,
                "σ with the true σ stated {s_right} vs √σ̂₀² × σ reported {}",
                k * s_wrong
            );
        }
    }
}

/// An estimate whose solver stopped at the iteration limit is refused, naming the status,
/// unless accepted; then the line every output must carry says so. A file of an older
/// armcal (no verdicts) is unverified and refused the same way.
#[test]
fn unconverged_and_unverified_estimates_are_refused_unless_accepted() {
    let (cell, data) = paper_campaign(1.0, 1.0, 50);
    let mut opts = IdentifySettings::default();
    opts.lm.tolerances.max_iterations = 1;
    let est = identify(&cell, &data, &opts, &mut Silent).unwrap();
    let v = est.verdicts.as_ref().unwrap();
    assert_eq!(v.solver, Status::IterationLimit);
    let e = est.check_usable(&cli(false)).unwrap_err().to_string();
    assert!(
        e.contains("did not converge")
            && e.contains("stopped at the iteration limit")
            && e.contains("--accept-unconverged"),
        "{e}"
    );
    let accepted = est.check_usable(&cli(true)).unwrap();
    let line = accepted.overridden.unwrap();
    assert!(
        line.contains("did not converge (stopped at the iteration limit)")
            && line.contains("used with --accept-unconverged"),
        "{line}"
    );

    // The same estimate as an older armcal wrote it: no verdicts, no fingerprint.
    let mut json: serde_json::Value = serde_json::to_value(&est).unwrap();
    let obj = json.as_object_mut().unwrap();
    obj.remove("verdicts");
    obj.remove("fingerprint");
    let path = Path::new(env!("CARGO_TARGET_TMPDIR")).join("old-estimate.json");
    std::fs::write(&path, serde_json::to_string(&json).unwrap()).unwrap();
    let old = Estimate::from_file(&path).unwrap();
    assert!(old.verdicts.is_none() && old.fingerprint.is_none());
    let e = old.check_usable(&cli(false)).unwrap_err().to_string();
    assert!(
        e.contains("older armcal") && e.contains("--accept-unconverged"),
        "{e}"
    );
    assert!(old
        .check_usable(&cli(true))
        .unwrap()
        .overridden
        .unwrap()
        .contains("unverified"));
    // Its parameter names still belong to the cell (JSON keeps values to the last bit or so).
    let (a, b) = (
        old.params_for(&cell.model).unwrap(),
        est.params_for(&cell.model).unwrap(),
    );
    assert!(a
        .iter()
        .zip(&b)
        .all(|(x, y)| (x - y).abs() <= 1e-12 * x.abs().max(1.0)));
}

fn paper_cell_text() -> String {
    std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper-cell.toml"),
    )
    .unwrap()
}

fn cell_from(text: &str) -> Cell {
    Cell::from_toml(text, "changed-cell.toml", Path::new(".")).unwrap()
}

/// The same parameter names, another model: λ = 700 instead of 650, a moved reflector, a
/// changed free set. Each is an error naming what differs; a cell equal to 1e-12 relative is not.
#[test]
fn a_cell_that_differs_from_the_estimates_is_named() {
    let (cell, data) = paper_campaign(1.0, 1.0, 60);
    let est = identify(&cell, &data, &IdentifySettings::default(), &mut Silent).unwrap();
    assert!(est.params_for(&cell.model).is_ok());
    let text = paper_cell_text();
    let cases = [
        (
            text.replace("builtin = \"paper-650-600\"", "builtin = \"paper-700-600\""),
            "link 3 `j2` a: 650 mm in the estimate's cell, 700 mm in this cell",
        ),
        (
            text.replace("-89.58, -2.84", "-89.08, -2.84"),
            "target `smr1` x: -89.58 mm in the estimate's cell, -89.08 mm in this cell",
        ),
        (
            text.replace(
                "fixed = [\"base\", \"tool\"]",
                "fixed = [\"base\", \"tool\", \"j1.a\"]",
            ),
            "free set: the estimate's cell frees `j1.a` that this cell fixes",
        ),
    ];
    for (changed, needle) in cases {
        let other = cell_from(&changed);
        let e = est.params_for(&other.model).unwrap_err().to_string();
        assert!(
            e.contains(needle) && e.contains("identified on another model"),
            "{needle}\n{e}"
        );
        assert_eq!(est.check_model(&other.model).unwrap_err().to_string(), e);
    }
    // Not bitwise: a reflector 1e-10 mm (1e-12 relative) away is the same cell.
    let same = cell_from(&text.replace("-89.58, -2.84", "-89.5800000001, -2.84"));
    assert!(est.check_model(&same.model).is_ok());
}
