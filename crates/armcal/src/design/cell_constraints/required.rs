//! The least value each constraint of a [`ConstraintSet`] must keep
//! ([`ConstraintSet::required`]): the cell's `[design]` clearance for robot and obstacle
//! distances, its line-of-sight margin for the beam, `cos(β_max − m) − cos β_max` for the
//! incidence with margin `m` (`β ≤ β_max − m`), 0 for a distance no configuration changes
//! and that lies below what it would need (see the [module documentation](super)).

use super::*;

/// Fills `set.required` from `options` (`max_incidence`: the cell's limit β_max, rad); an
/// error when the incidence margin leaves no angle below the limit.
pub(super) fn set_required(
    set: &mut ConstraintSet,
    options: &ConstraintSettings,
    max_incidence: Option<f64>,
) -> Result<(), Error> {
    if let Some(max) = max_incidence.filter(|_| options.incidence_margin > 0.0) {
        if options.incidence_margin >= max {
            return Err(Error::Input(format!(
                "an incidence margin of {:.3}° leaves no angle below the limit of {:.3}°",
                options.incidence_margin.to_degrees(),
                max.to_degrees()
            )));
        }
    }
    if options.clearance > 0.0 || options.line_of_sight_margin > 0.0 {
        // Exempt from the clearance: constant over 256 samples and below it everywhere.
        let dense = constraint_ranges(set, 256);
        for (i, r) in dense.into_iter().enumerate() {
            let wanted = match set.kind(i) {
                ConstraintKind::Incidence => 0.0,
                ConstraintKind::LineOfSight => options.line_of_sight_margin,
                _ => options.clearance,
            };
            if !(is_flat(r) && r.1 < wanted) {
                set.required[i] = wanted;
            }
        }
    }
    let incidence = (0..set.len()).find(|&i| set.kind(i) == ConstraintKind::Incidence);
    if let Some(i) = incidence.filter(|_| options.incidence_margin > 0.0) {
        // β ≤ β_max − m  ⇔  cos β − cos β_max ≥ cos(β_max − m) − cos β_max.
        let max = set.cos_max.acos();
        set.required[i] = (max - options.incidence_margin).cos() - set.cos_max;
    }
    Ok(())
}

impl ConstraintSet {
    /// Constraint `i` at value `v` below its [`ConstraintSet::required`] value, named with
    /// the `[design]` field that asks for it: `incidence 28.6° (incidence_margin_deg 2.0)`,
    /// `beam / car-roof 12.3 mm (line_of_sight_margin_mm 20.0)`, `capsule j2#0 / j4#0 3.1 mm
    /// (clearance_mm 5.0)`.
    pub fn shortfall(&self, i: usize, v: f64) -> String {
        let required = self.required(i);
        match self.kind(i) {
            ConstraintKind::Incidence => format!(
                "incidence {:.1}° (incidence_margin_deg {:.1})",
                self.incidence_angle(v).to_degrees(),
                (self.cos_max.acos() - self.incidence_angle(required)).to_degrees()
            ),
            ConstraintKind::LineOfSight => format!(
                "{} {v:.1} mm (line_of_sight_margin_mm {required:.1})",
                self.name(i)
            ),
            _ => format!("{} {v:.1} mm (clearance_mm {required:.1})", self.name(i)),
        }
    }
}
