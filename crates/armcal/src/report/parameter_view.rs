//! What an estimate says about its parameters, as figures: how far each moved from the
//! nominal in units of its σ, how strongly the free parameters are correlated (the
//! correlation matrix of C_p), and — when the true robot is known (the demo, a simulation's
//! truth record) — how far each estimate is from the truth. Read from the records only.

use super::html::{escape, fixed, number, table, tagged, Section};
use super::parameter_charts::{hbar_figure, heatmap_figure};
use crate::identify::Estimate;
use crate::sim::TruthRecord;
use crate::Error;
use nalgebra::DMatrix;

/// `(name, (estimate − nominal)/σ)` of every free parameter with a positive σ, in registry
/// order (display units cancel).
pub fn change_over_sigma(e: &Estimate) -> Vec<(String, f64)> {
    e.parameters
        .iter()
        .filter(|p| p.free)
        .filter_map(|p| {
            let s = p.sigma.filter(|s| *s > 0.0)?;
            Some((p.name.clone(), (p.estimate - p.nominal) / s))
        })
        .collect()
}

/// The correlation matrix of the free parameters from the estimate's covariance C_p:
/// `ρ_ij = C_ij / √(C_ii C_jj)` (book §4.5.2), with the names of its rows (the order of
/// C_p). An error if C_p and the names disagree or a variance is not positive.
pub fn correlation(e: &Estimate) -> Result<(Vec<String>, DMatrix<f64>), Error> {
    let c = &e.uncertainty.covariance;
    let n = e.free.len();
    if c.nrows() != n || c.ncols() != n {
        return Err(Error::Input(format!(
            "the estimate's C_p is {}×{} but it names {n} free parameters",
            c.nrows(),
            c.ncols()
        )));
    }
    if let Some(i) = (0..n).find(|&i| !(c[(i, i)] > 0.0 && c[(i, i)].is_finite())) {
        return Err(Error::Input(format!(
            "the estimate's variance of `{}` is {}, not positive: no correlations",
            e.free[i],
            c[(i, i)]
        )));
    }
    let d: Vec<f64> = (0..n).map(|i| c[(i, i)].sqrt()).collect();
    Ok((
        e.free.clone(),
        DMatrix::from_fn(n, n, |i, j| c[(i, j)] / (d[i] * d[j])),
    ))
}

/// One free parameter against the truth.
#[derive(Clone, Debug, PartialEq)]
pub struct TruthError {
    /// The parameter's name.
    pub name: String,
    /// Its display unit (mm, deg).
    pub unit: String,
    /// Estimate − truth (display unit).
    pub error: f64,
    /// The estimate's σ (display unit).
    pub sigma: f64,
}

/// Estimate − truth of every free parameter with a σ that `truth` knows (by name).
pub fn estimate_minus_truth(e: &Estimate, truth: &TruthRecord) -> Vec<TruthError> {
    e.parameters
        .iter()
        .filter(|p| p.free)
        .filter_map(|p| {
            let t = truth.parameters.iter().find(|t| t.name == p.name)?;
            Some(TruthError {
                name: p.name.clone(),
                unit: p.unit.clone(),
                error: p.estimate - t.truth,
                sigma: p.sigma?,
            })
        })
        .collect()
}

/// Appends to `s` the parameter figures of `e` (labelled `label`): change / σ, the
/// correlation heatmap and, with `truth`, estimate − truth; bars in palette colour `fill`
/// (the design's).
pub fn parameter_blocks(
    s: &mut Section,
    label: &str,
    e: &Estimate,
    truth: Option<&TruthRecord>,
    fill: usize,
) -> Result<(), Error> {
    let change = change_over_sigma(e);
    if !change.is_empty() {
        s.html("<h3>Parameter change / σ</h3>\n");
        s.figure(
            tagged(
                hbar_figure(
                    &format!("Change from nominal in units of σ — {label}"),
                    "(estimate − nominal) / σ",
                    &change,
                    fill,
                    &[3.0],
                )?,
                "change-sigma",
            ),
            format!(
                "(estimate − nominal)/σ of each of the {} free parameters of <em>{}</em>. Beyond the dashed ±3 lines the data show a change from the nominal far beyond the parameter's uncertainty; near zero the nominal value was confirmed (or the data say little — compare σ).",
                change.len(),
                escape(label)
            ),
        );
    }
    match correlation(e) {
        Ok((names, rho)) if names.len() >= 2 => {
            s.html("<h3>Correlation of the parameters</h3>\n");
            s.figure(
                tagged(
                    heatmap_figure(
                        &format!("Correlation matrix of the free parameters — {label}"),
                        &names,
                        &rho,
                    )?,
                    "correlation",
                ),
                format!(
                    "ρ_ij = C_ij/√(C_ii C_jj) of the {} free parameters of <em>{}</em> (from C_p): blue negative, vermillion positive, white uncorrelated; the diagonal is 1. Strong off-diagonal colour marks pairs the data separate poorly.",
                    names.len(),
                    escape(label)
                ),
            );
        }
        Ok(_) => {}
        Err(err) => s.html(format!(
            "<p class=\"note\">No correlation heatmap: {}</p>\n",
            escape(&err.to_string())
        )),
    }
    if let Some(t) = truth {
        let errors = estimate_minus_truth(e, t);
        if !errors.is_empty() {
            s.html("<h3>Estimate − truth (simulation)</h3>\n<p class=\"note\">The campaign was simulated, so the true robot is known: how far each identified parameter is from its true value, in its unit and in units of its σ. About 95 % should lie within ±2 σ if the σ's are right.</p>\n");
            let rows: Vec<Vec<String>> = errors
                .iter()
                .map(|x| {
                    let z = x.error / x.sigma;
                    vec![
                        format!(
                            "{}{}",
                            if z.abs() > 3.0 { "!" } else { "" },
                            escape(&x.name)
                        ),
                        escape(&x.unit),
                        fixed(x.error, if x.unit == "deg" { 4 } else { 3 }),
                        number(x.sigma),
                        fixed(z, 2),
                    ]
                })
                .collect();
            s.html(table(
                &[
                    "parameter",
                    "unit",
                    "estimate − truth",
                    "σ",
                    "(estimate − truth)/σ",
                ],
                &rows,
                &[2, 3, 4],
            ));
            let within = errors
                .iter()
                .filter(|x| (x.error / x.sigma).abs() <= 2.0)
                .count();
            let z: Vec<(String, f64)> = errors
                .iter()
                .map(|x| (x.name.clone(), x.error / x.sigma))
                .collect();
            s.figure(
                tagged(
                    hbar_figure(
                        &format!("Estimate − truth in units of σ — {label}"),
                        "(estimate − truth) / σ",
                        &z,
                        fill,
                        &[2.0],
                    )?,
                    "truth-error",
                ),
                format!(
                    "(estimate − truth)/σ of the {} free parameters of <em>{}</em>; {} of them ({} %) within the dashed ±2 σ.",
                    errors.len(),
                    escape(label),
                    within,
                    fixed(100.0 * within as f64 / errors.len() as f64, 0)
                ),
            );
        }
    }
    Ok(())
}
