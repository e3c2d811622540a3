//! The book's Chapter 6 case (Mooring, Roth, Driels 1991, §6.2–6.5) in simulation: the
//! PUMA 560 identified with the modified-DH model (Table 6.1 → Table 6.5) and with the
//! zero-reference model (Table 6.2 / eq. 6.11), the zero-reference result converted to DH
//! (Tables 6.9/6.10), and the held-out accuracy of nominal vs calibrated models (Table 6.13).
//!
//! * Truth: the identified robot of Table 6.5; the CMM measures the full end-effector pose
//!   with the σ of Table 6.4 (seeded noise).
//! * Poses (§6.2, Figs. 6.9–6.10, `poses`): [`book_poses`], 50 on a 3 × 2 × 2 grid in the four arm
//!   configurations with random orientations, plus 10 held-out poses in the grid box.
//! * Errors (eqs. 6.41–6.42): [`pose_errors`], δr = |translation of Pm⁻¹Pp|,
//!   δθ = rotation angle of Pm⁻¹Pp.
//!
//! **Units.** armcal works in mm and rad; the book's Chapter 6 in inches and degrees
//! (Table 6.4 in mm and rad). The study's tables are in the book's units.

pub(crate) mod book;
pub(crate) mod poses;
pub(crate) mod record;
pub(crate) mod settings;

pub use book::*;
pub use poses::*;
pub(crate) use settings::PumaSettings;

use crate::identify::{solve, IdentifySettings, Problem};
use crate::measure::{Dataset, NoiseModel};
use crate::model::convert::zrp_to_dh;
use crate::model::identifiability::{analyze_at, IdentifiabilitySettings, Measurement};
use crate::model::{Convention, LinkGeometry, Model, ModelSpec, ParameterStatus};
use crate::progress::Observer;
use crate::robots::puma560::{book_dh_spec, book_zrp_spec, MM_PER_IN};
use crate::sim::simulate;
use crate::Error;
use serde::{Deserialize, Serialize};

/// One identification.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FitSummary {
    /// The model identified: `modified DH (Table 6.1)` or
    /// `zero reference (Table 6.2, eq. 6.11)`.
    pub model: String,
    /// Free parameters estimated.
    pub free: usize,
    /// Parameters fixed at the start value as unidentifiable (with the reason).
    pub unidentifiable: Vec<(String, String)>,
    /// Iterations of the identification solver.
    pub iterations: usize,
    /// Whether the identification converged.
    pub converged: bool,
    /// Whitened sum of squares at the solution (≈ residual rows − free parameters).
    pub ssq: f64,
    /// A-posteriori variance factor σ̂₀² = SSQ / (rows − free); ≈ 1.
    pub variance_factor: f64,
    /// Residual rows of the identification data (the `rows` of σ̂₀²).
    pub rows: usize,
    /// Identification data, RMS δr (in) and δθ (deg) of the calibrated model.
    pub fit_rms_dr_in: f64,
    /// RMS δθ (deg) of the calibrated model on the identification data.
    pub fit_rms_dtheta_deg: f64,
}

/// One row of Tables 6.9/6.10: parameters 1–3 of a transform, in the book's units (in,
/// deg), converted from the zero-reference estimate beside those identified with the
/// modified-DH model, the truth (Table 6.5), and the book's Table 6.9.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ConversionRow {
    /// The book's transform, `B->0` … `4->5`.
    pub transform: String,
    /// The armcal link of that transform (`base`, `j1` … `j5`).
    pub link: String,
    /// Names of parameters 1–3: `d, a, alpha` (Type 1, `dh`), `a, alpha, beta` (Type 2,
    /// `hayati`) or `dx, dy, dz` (Type 3).
    pub fields: [String; 3],
    /// Parameters 1–3 of the zero-reference estimate converted to DH (in, deg).
    pub converted: [f64; 3],
    /// Parameters 1–3 identified with the modified-DH model (in, deg).
    pub identified: [f64; 3],
    /// Standard deviations of the modified-DH estimate implied by the Table 6.4 noise
    /// (`C_p = (FᵀF)⁻¹` at the estimate).
    pub identified_sigma: [f64; 3],
    /// Parameters 1–3 of the truth, Table 6.5 (in, deg).
    pub truth: [f64; 3],
    /// The book's converted values, Table 6.9 (in, deg; NaN where the table has no row).
    pub book_converted: [f64; 3],
    /// The book's identified values, Table 6.9 (in, deg; NaN where the table has no row).
    pub book_identified: [f64; 3],
}

/// One held-out pose (Table 6.13): δr (in) and δθ (deg) of the nominal, the calibrated
/// modified-DH and the calibrated zero-reference models against the measured pose, and the
/// book's values for its pose of the same number.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct HeldOutRow {
    /// Held-out pose number (from 1), as in Table 6.13.
    pub pose: usize,
    /// δr (in) of the nominal model (eq. 6.41).
    pub nominal_dr_in: f64,
    /// δθ (deg) of the nominal model (eq. 6.42).
    pub nominal_dtheta_deg: f64,
    /// δr (in) of the calibrated modified-DH model.
    pub mdh_dr_in: f64,
    /// δθ (deg) of the calibrated modified-DH model.
    pub mdh_dtheta_deg: f64,
    /// δr (in) of the calibrated zero-reference model.
    pub zrp_dr_in: f64,
    /// δθ (deg) of the calibrated zero-reference model.
    pub zrp_dtheta_deg: f64,
    /// The book's row of the same number (`None` beyond the table).
    pub book: Option<BookAccuracy>,
}

/// The result of `armcal study puma`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PumaStudy {
    /// Seed of the measurement noise ([`PumaSettings::seed`]).
    pub seed: u64,
    /// Seed of the poses ([`PumaSettings::pose_seed`]).
    pub pose_seed: u64,
    /// σ of the simulated CMM: position (mm, per axis) and rotation (rad, per axis).
    pub sigma_mm: [f64; 3],
    /// Rotation σ (rad, per axis).
    pub sigma_rad: f64,
    /// Poses used for identification (50).
    pub identification_poses: usize,
    /// Held-out poses (10).
    pub held_out_poses: usize,
    /// The modified-DH identification (Table 6.1 → Table 6.5).
    pub mdh: FitSummary,
    /// The zero-reference identification (Table 6.2, eq. 6.11).
    pub zrp: FitSummary,
    /// Tables 6.9/6.10: the zero-reference estimate converted to DH vs the modified-DH
    /// estimate (transforms B→0 … 4→5).
    pub conversion: Vec<ConversionRow>,
    /// Largest |converted − identified| over the conversion rows: lengths (in), angles (deg).
    pub conversion_max_dlength_in: f64,
    /// Largest |converted − identified| angle (deg).
    pub conversion_max_dangle_deg: f64,
    /// Table 6.13.
    pub held_out: Vec<HeldOutRow>,
    /// Means over the held-out poses (armcal) and of Table 6.13 (book).
    pub held_out_mean: BookAccuracy,
    /// Means of the book's Table 6.13.
    pub book_mean: BookAccuracy,
    /// Against the true (noise-free) held-out poses: mean δr (in), δθ (deg) of the
    /// modified-DH and zero-reference models.
    pub exact_mean_mdh: (f64, f64),
    /// Mean δr (in), δθ (deg) of the zero-reference model against the true held-out poses.
    pub exact_mean_zrp: (f64, f64),
}

fn mean_pair(e: &[(f64, f64)]) -> (f64, f64) {
    let n = e.len().max(1) as f64;
    (
        e.iter().map(|x| x.0).sum::<f64>() / n / MM_PER_IN,
        e.iter().map(|x| x.1).sum::<f64>() / n,
    )
}

fn rms_pair(e: &[(f64, f64)]) -> (f64, f64) {
    let n = e.len().max(1) as f64;
    (
        (e.iter().map(|x| x.0 * x.0).sum::<f64>() / n).sqrt() / MM_PER_IN,
        (e.iter().map(|x| x.1 * x.1).sum::<f64>() / n).sqrt(),
    )
}

/// Fixes the parameters of `m` these configurations cannot identify from pose
/// measurements; returns them with the reasons.
fn fix_unidentifiable(m: &mut Model, qs: &[Vec<f64>]) -> Result<Vec<(String, String)>, Error> {
    let opts = IdentifiabilitySettings {
        measurement: Measurement::Pose,
        ..Default::default()
    };
    let report = analyze_at(m, &m.nominal(), qs, &opts)?;
    report.apply(m)?;
    Ok(report
        .excluded
        .into_iter()
        .map(|e| (e.name, e.reason))
        .collect())
}

/// Standard deviations of the free parameters by name (internal units).
type ParameterSigmas = Vec<(String, f64)>;

fn fit(
    name: &str,
    m: &Model,
    data: &Dataset,
    noise: &NoiseModel,
    unidentifiable: Vec<(String, String)>,
    observer: &mut dyn Observer,
) -> Result<(Vec<f64>, FitSummary, ParameterSigmas), Error> {
    let mut problem = Problem::new(m, data, noise)?;
    let (sol, _, _) = solve(
        &mut problem,
        &m.nominal(),
        &IdentifySettings::default(),
        observer,
    )?;
    let (r, t) = rms_pair(&pose_errors(m, &sol.params, data));
    let unc = problem.uncertainty_at(&sol.params)?;
    let sigmas = problem.free_names().into_iter().zip(unc.sigma).collect();
    let summary = FitSummary {
        model: name.into(),
        free: problem.columns(),
        unidentifiable,
        iterations: sol.iterations,
        converged: sol.status.is_converged(),
        ssq: 2.0 * sol.cost(),
        variance_factor: unc.variance_factor,
        rows: problem.rows(),
        fit_rms_dr_in: r,
        fit_rms_dtheta_deg: t,
    };
    Ok((sol.params, summary, sigmas))
}

/// Parameters 1–3 of a book transform (Type 1 = armcal `dh`: d, l, α; Type 2 = `hayati`:
/// l, α, β; Type 3: dx, dy, dz) in inches and degrees.
fn book_p123(g: &LinkGeometry) -> ([String; 3], [f64; 3]) {
    let fields: [&str; 3] = match g.convention {
        Convention::Dh => ["d", "a", "alpha"],
        Convention::Hayati => ["a", "alpha", "beta"],
        Convention::BookType3 => ["dx", "dy", "dz"],
        _ => ["", "", ""],
    };
    let mut v = [f64::NAN; 3];
    for (k, f) in fields.iter().enumerate() {
        if let Some(x) = g.get(f, None) {
            v[k] = if matches!(*f, "alpha" | "beta") {
                x.to_degrees()
            } else {
                x / MM_PER_IN
            };
        }
    }
    (fields.map(String::from), v)
}

/// The PUMA study (module documentation); `observer` follows the two fits.
pub fn run(s: &PumaSettings, observer: &mut dyn Observer) -> Result<PumaStudy, Error> {
    let noise = table_6_4_noise();
    let NoiseModel::Constant { sigma, sigma_angle } = noise else {
        unreachable!("Table 6.4 is a constant noise model")
    };
    let table_6_1 = book_dh_spec("table-6.1", TABLE_6_1)?;
    let mdh = with_tcp(&table_6_1)?;
    let truth_model = book_model("table-6.5", TABLE_6_5)?;
    let truth = truth_model.nominal();
    let (train, test) = book_poses(&mdh, s.pose_seed)?;

    let data = simulate(&truth_model, &truth, &train, Some(&noise), s.seed)?;
    let measured = simulate(
        &truth_model,
        &truth,
        &test,
        Some(&noise),
        s.seed.wrapping_add(1),
    )?;
    let exact = simulate(&truth_model, &truth, &test, None, 0)?;

    // (a) Modified DH from Table 6.1.
    let mut mdh = mdh;
    let mdh_fixed = fix_unidentifiable(&mut mdh, &train)?;
    let (mdh_params, mdh_summary, mdh_sigma) = fit(
        "modified DH (Table 6.1)",
        &mdh,
        &data,
        &noise,
        mdh_fixed,
        observer,
    )?;

    // (b) Zero reference from Table 6.2 / eq. 6.11: u, p, offsets and T₀ free as the
    // data identify them; the base is the CMM frame (identity, fixed).
    let mut zrp = with_tcp(&book_zrp_spec("table-6.2", TABLE_6_2, EQ_6_11)?)?;
    zrp.set_status("tool", ParameterStatus::Free)?;
    zrp.set_status("base", ParameterStatus::Fixed)?;
    let zrp_fixed = fix_unidentifiable(&mut zrp, &train)?;
    let (zrp_params, zrp_summary, _) = fit(
        "zero reference (Table 6.2, eq. 6.11)",
        &zrp,
        &data,
        &noise,
        zrp_fixed,
        observer,
    )?;

    // (c) Zero reference → DH with Table 6.1's link types and sign rules.
    let converted = zrp_to_dh(&zrp.spec_at(&zrp_params), Some(&table_6_1))?;
    let identified = mdh.spec_at(&mdh_params);
    let truth_spec = truth_model.spec_at(&truth);
    let book_rows = csv_rows(TABLE_6_9);
    let transforms = ["B->0", "0->1", "1->2", "2->3", "3->4", "4->5"];
    let links = ["base", "j1", "j2", "j3", "j4", "j5"];
    let find = |spec: &ModelSpec, name: &str| -> Result<LinkGeometry, Error> {
        spec.links
            .iter()
            .find(|l| l.name == name)
            .map(|l| l.geometry.clone())
            .ok_or_else(|| Error::Conversion(format!("`{}` has no link `{name}`", spec.name)))
    };
    let mut conversion = Vec::new();
    let (mut dl, mut da) = (0.0f64, 0.0f64);
    for (k, (&transform, &link)) in transforms.iter().zip(&links).enumerate() {
        let (fields, c) = book_p123(&find(&converted, link)?);
        let (_, i) = book_p123(&find(&identified, link)?);
        let (_, t) = book_p123(&find(&truth_spec, link)?);
        let book = |o: usize| -> [f64; 3] {
            book_rows
                .get(k)
                .map(|r| [num(&r[o]), num(&r[o + 1]), num(&r[o + 2])])
                .unwrap_or([f64::NAN; 3])
        };
        let mut sig = [f64::NAN; 3];
        for (j, f) in fields.iter().enumerate() {
            let name = format!("{link}.{f}");
            if let Some((_, x)) = mdh_sigma.iter().find(|(n, _)| *n == name) {
                sig[j] = if matches!(f.as_str(), "alpha" | "beta") {
                    x.to_degrees()
                } else {
                    x / MM_PER_IN
                };
            }
        }
        for j in 0..3 {
            let d = (c[j] - i[j]).abs();
            if matches!(fields[j].as_str(), "alpha" | "beta") {
                da = da.max(d);
            } else {
                dl = dl.max(d);
            }
        }
        conversion.push(ConversionRow {
            transform: transform.into(),
            link: link.into(),
            fields,
            converted: c,
            identified: i,
            identified_sigma: sig,
            truth: t,
            book_converted: book(2),
            book_identified: book(5),
        });
    }

    // (d) Held-out accuracy (Table 6.13).
    let nominal_e = pose_errors(&mdh, &mdh.nominal(), &measured);
    let mdh_e = pose_errors(&mdh, &mdh_params, &measured);
    let zrp_e = pose_errors(&zrp, &zrp_params, &measured);
    let book = table_6_13();
    let held_out: Vec<HeldOutRow> = (0..test.len())
        .map(|k| HeldOutRow {
            pose: k + 1,
            nominal_dr_in: nominal_e[k].0 / MM_PER_IN,
            nominal_dtheta_deg: nominal_e[k].1,
            mdh_dr_in: mdh_e[k].0 / MM_PER_IN,
            mdh_dtheta_deg: mdh_e[k].1,
            zrp_dr_in: zrp_e[k].0 / MM_PER_IN,
            zrp_dtheta_deg: zrp_e[k].1,
            book: book.get(k).copied(),
        })
        .collect();
    let ours: Vec<BookAccuracy> = held_out
        .iter()
        .map(|r| BookAccuracy {
            nominal_dr_in: r.nominal_dr_in,
            nominal_dtheta_deg: r.nominal_dtheta_deg,
            mdh_dr_in: r.mdh_dr_in,
            mdh_dtheta_deg: r.mdh_dtheta_deg,
            zrp_dr_in: r.zrp_dr_in,
            zrp_dtheta_deg: r.zrp_dtheta_deg,
        })
        .collect();
    Ok(PumaStudy {
        seed: s.seed,
        pose_seed: s.pose_seed,
        sigma_mm: sigma,
        sigma_rad: sigma_angle,
        identification_poses: train.len(),
        held_out_poses: test.len(),
        mdh: mdh_summary,
        zrp: zrp_summary,
        conversion,
        conversion_max_dlength_in: dl,
        conversion_max_dangle_deg: da,
        held_out,
        held_out_mean: mean_accuracy(&ours),
        book_mean: mean_accuracy(&book),
        exact_mean_mdh: mean_pair(&pose_errors(&mdh, &mdh_params, &exact)),
        exact_mean_zrp: mean_pair(&pose_errors(&zrp, &zrp_params, &exact)),
    })
}
