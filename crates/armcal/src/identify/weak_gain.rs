//! Parameters a fit would free only because it left the nominal geometry, and only weakly:
//! held at their nominal, each named with its reason.
//!
//! `identify` decides its free set at the fit, not at the nominal
//! ([`super::identifiable_model`]): a target whose offset the cell does not know and writes
//! as `[0, 0, 0]` lies on the last joint axis at the nominal, where two of that joint's
//! parameters have no effect, and the fit, which finds the real offset tens of millimetres
//! off the axis, identifies them well. But a target that *is* on (or near) the axis fits a
//! fraction of a millimetre off it, and those parameters then become "identifiable" with a
//! column within a degree of the others': freed, they take σ's of millimetres and ρ ≈ 0.999
//! and inflate the TCP covariance 10⁴-fold over what `plan` predicted at the nominal for the
//! same poses (a KR 6 with its reflector on the q6 axis: `plan` 0.000095 mm², the fit
//! 0.46–0.79 mm²). A parameter the analysis at the nominal leaves out (the same free set
//! and the data's configurations: the rule by which `model` prints and `plan` designs for
//! the set at the nominal) is therefore freed at the fit only if the data determine it: its
//! variance inflation there, `VIFᵢ = 1 / sin² θᵢ` over the data's configurations
//! ([`crate::model::identifiability::Identifiability::variance_inflation`]), at most
//! [`DETERMINED_VIF`] (its column more than 0.57° from the span of the others': the same
//! threshold by which the frames-first start decides which flange offsets the data
//! determine). Otherwise it stays at its nominal — its stated prior then enters the model
//! floor ([`super::model_floor`]), so the TCP σ still counts it — and the estimate names it
//! with its variance inflation and, for a target on the last axis at the nominal, how far
//! from that axis the fit put it.

use super::DETERMINED_VIF;
use crate::model::identifiability::{analyze_at, Identifiability, IdentifiabilitySettings};
use crate::model::rank_deficit::{last_axis_distances, ON_AXIS_MM};
use crate::model::{Model, ParameterStatus};
use crate::Error;

/// The analysis of `model`'s free set at `at` over the configurations `qs`, with every
/// parameter that the same analysis at the nominal leaves out and that is identifiable at
/// `at` only with a variance inflation above [`DETERMINED_VIF`] fixed in `model` (the
/// weakest first, then the analysis again), and the reason for each held one.
pub(super) fn analyze_holding_weak(
    model: &mut Model,
    at: &[f64],
    qs: &[Vec<f64>],
    settings: &IdentifiabilitySettings,
) -> Result<(Identifiability, Vec<(String, String)>), Error> {
    // The same free set, configurations and stations at the nominal: what is gained at `at`
    // is gained only by the fit's geometry (not by a term left out, nor by other data).
    let nominal = &analyze_at(model, &model.nominal(), qs, settings)?;
    let mut held = Vec::new();
    loop {
        let report = analyze_at(model, at, qs, settings)?;
        let weakest = report
            .identifiable
            .iter()
            .zip(&report.variance_inflation)
            .filter(|(name, vif)| {
                !nominal.identifiable.contains(*name) && (vif.is_nan() || **vif > DETERMINED_VIF)
            })
            .max_by(|a, b| a.1.total_cmp(b.1));
        let Some((name, &vif)) = weakest else {
            return Ok((report, held));
        };
        let i = model.registry.require(name)?;
        model.registry.set_status(i, ParameterStatus::Fixed);
        held.push((name.clone(), reason(model, at, nominal, name, vif)));
    }
}

/// Why `name` (variance inflation `vif` at `at`) stays at its nominal.
fn reason(model: &Model, at: &[f64], nominal: &Identifiability, name: &str, vif: f64) -> String {
    let angle = (1.0 / vif.sqrt()).min(1.0).asin().to_degrees();
    let at_nominal = nominal
        .excluded
        .iter()
        .find(|e| e.name == name)
        .map_or(String::new(), |e| format!("; at the nominal, {}", e.reason));
    let before = last_axis_distances(model, &model.nominal());
    let axis: String = last_axis_distances(model, at)
        .into_iter()
        .zip(before)
        .filter(|(_, (_, _, d0))| *d0 < ON_AXIS_MM)
        .map(|((what, joint, d), _)| {
            format!("; {what} lies on the axis of {joint} at the nominal and {d:.3} mm from it at the fit")
        })
        .collect();
    format!(
        "`{name}` is weakly identifiable, only because the fit differs from the nominal robot: \
         its variance inflation at the fit is {vif:.0} (above {DETERMINED_VIF:.0}: its column \
         lies {angle:.2}° from the span of the others'){axis}{at_nominal}. It stays at its \
         nominal, and its stated prior enters the model floor"
    )
}
