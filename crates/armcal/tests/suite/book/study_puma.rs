//! `armcal study puma` (the book's Chapter 6 case, `armcal::study::puma`): simulated CMM
//! measurements of the Table 6.5 robot with Table 6.4 noise, identified with the
//! modified-DH (Table 6.1) and the zero-reference (Table 6.2 / eq. 6.11) models.
//!
//! Tolerances, from the noise. The CMM σ is 0.044–0.057 mm (≈ 0.002 in) per axis and
//! 0.58 mrad (0.033°) per rotation axis; a held-out pose error against a *measured* pose is
//! at least that noise (RMS √(σx² + σy² + σz²) ≈ 0.087 mm = 0.0034 in and √3 σ ≈ 0.057°),
//! while the nominal model is off by about an inch and a few degrees. The calibrated
//! errors are thus ≳ 100 times below the nominal; ≥ 10 times (the book's "at least a factor
//! of 10") is asserted. Both calibrated models are complete and minimal (30 parameters)
//! for full-pose measurements, so they fit the same data equally well: their held-out
//! errors must agree within a factor of 2 (they coincide here, because the two models are
//! exact reparametrisations of each other). The converted DH parameters equal the
//! modified-DH estimate to far below the estimate's standard deviation σ (0.0003–0.002 in,
//! 0.003–0.005° from the Table 6.4 noise): the test asks 0.1 σ; and both lie within 5 σ of
//! the truth (Table 6.5).

use armcal::study::puma::{run, PumaStudy};
use armcal::{PumaSettings, Silent};
use std::sync::OnceLock;

fn study() -> &'static PumaStudy {
    static S: OnceLock<PumaStudy> = OnceLock::new();
    S.get_or_init(|| run(&PumaSettings::default(), &mut Silent).unwrap())
}

#[test]
fn both_fits_converge_with_the_books_30_parameters() {
    let s = study();
    assert_eq!((s.identification_poses, s.held_out_poses), (50, 10));
    for f in [&s.mdh, &s.zrp] {
        assert!(f.converged, "{}", f.model);
        assert_eq!(f.free, 30, "{}: {:?}", f.model, f.unidentifiable);
        assert_eq!(f.rows, 300);
        // SSQ ~ χ²(270): variance factor within 1 ± 3·√(2/270) ≈ [0.74, 1.26].
        assert!(
            (0.74..=1.26).contains(&f.variance_factor),
            "{}: {}",
            f.model,
            f.variance_factor
        );
    }
    assert!(
        s.mdh.unidentifiable.is_empty(),
        "{:?}",
        s.mdh.unidentifiable
    );
}

#[test]
fn calibrated_models_are_far_more_accurate_than_the_nominal() {
    let s = study();
    let m = &s.held_out_mean;
    eprintln!("{m:?}\nbook: {:?}", s.book_mean);
    for (what, nominal, mdh, zrp) in [
        ("δr", m.nominal_dr_in, m.mdh_dr_in, m.zrp_dr_in),
        (
            "δθ",
            m.nominal_dtheta_deg,
            m.mdh_dtheta_deg,
            m.zrp_dtheta_deg,
        ),
    ] {
        assert!(
            mdh * 10.0 <= nominal,
            "{what}: mdh {mdh} vs nominal {nominal}"
        );
        assert!(
            zrp * 10.0 <= nominal,
            "{what}: zrp {zrp} vs nominal {nominal}"
        );
        let ratio = mdh / zrp;
        assert!((0.5..=2.0).contains(&ratio), "{what}: mdh / zrp = {ratio}");
    }
    // Per pose too.
    for r in &s.held_out {
        assert!(r.mdh_dr_in * 10.0 <= r.nominal_dr_in, "{r:?}");
        assert!(r.zrp_dr_in * 10.0 <= r.nominal_dr_in, "{r:?}");
    }
    // At or below the book's calibrated levels (Table 6.13 means 0.020–0.022 in,
    // 0.22–0.24°), which include non-geometric errors the simulation does not have.
    assert!(m.mdh_dr_in <= s.book_mean.mdh_dr_in, "{m:?}");
    assert!(m.mdh_dtheta_deg <= s.book_mean.mdh_dtheta_deg, "{m:?}");
    // Table 6.13 is embedded as transcribed.
    assert!((s.book_mean.nominal_dr_in - 1.1444).abs() < 1e-9);
    assert!((s.book_mean.mdh_dtheta_deg - 0.222).abs() < 1e-9);
}

#[test]
fn converted_zero_reference_matches_the_identified_modified_dh() {
    let s = study();
    assert_eq!(s.conversion.len(), 6);
    for r in &s.conversion {
        for j in 0..3 {
            let sigma = r.identified_sigma[j];
            assert!(sigma.is_finite() && sigma > 0.0, "{r:?}");
            // Floor: a near-zero σ (e.g. a length of a nearly parallel pair) still admits
            // rounding of the conversion.
            let tol = (0.1 * sigma).max(1e-6);
            assert!(
                (r.converted[j] - r.identified[j]).abs() <= tol,
                "{} {}: converted {} vs identified {} (σ {sigma})",
                r.transform,
                r.fields[j],
                r.converted[j],
                r.identified[j]
            );
            assert!(
                (r.identified[j] - r.truth[j]).abs() <= 5.0 * sigma,
                "{} {}: identified {} vs truth {} (σ {sigma})",
                r.transform,
                r.fields[j],
                r.identified[j],
                r.truth[j]
            );
        }
    }
    // The book's Table 6.9 identified columns are Table 6.5 (the truth here) to print
    // precision, except its sign slip in row 6's α (see tests/data/book/README.md).
    for r in &s.conversion[..5] {
        for j in 0..3 {
            assert!((r.book_identified[j] - r.truth[j]).abs() <= 0.0015, "{r:?}");
        }
    }
}
