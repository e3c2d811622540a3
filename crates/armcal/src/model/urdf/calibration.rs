//! A calibrated model as ROS calibration tools write it: the nominal robot's URDF with its
//! joint origins edited and every joint's zero offset in `<calibration rising="δ"/>`
//! (robot_calibration's `update_urdf` adds a joint's offset to `rising` and composes the
//! frame corrections into the joint origins; the joint then moves by `q + rising`). armcal
//! reads `rising` back as that offset ([`super::import`]). A consumer that ignores
//! `<calibration>` (robot_state_publisher, MoveIt) predicts without the offsets: the writer
//! says by how much.
//!
//! The **conservative** variant keeps only the corrections beyond `k` times their σ
//! (`|p̂ − p₀| > k σ`); every other parameter goes back to its nominal value, and each one
//! dropped is listed with its correction, its σ and the TCP shift its omission causes.

use super::export::{urdf_robot, write};
use crate::model::chain::{Model, ModelSpec};
use crate::model::tcp_shift::{max_tcp_shift, spec_shift, NotHeld};
use crate::Error;
use serde::{Deserialize, Serialize};

/// Default `k` of the conservative variant: a correction within 3 σ of zero is dropped.
pub const DEFAULT_K_SIGMA: f64 = 3.0;

/// Joint `i`'s zero offset of `calibrated` against `nominal`: the difference of the value of
/// the field the joint acts on (θ, d, the URDF or zero-reference offset). Both specs must
/// have the same links in the same conventions (an estimate and its nominal model).
pub(crate) fn joint_offsets(
    calibrated: &ModelSpec,
    nominal: &ModelSpec,
) -> Result<Vec<f64>, Error> {
    same_structure(calibrated, nominal)?;
    Ok(calibrated
        .links
        .iter()
        .zip(&nominal.links)
        .filter_map(|(c, n)| {
            let j = c.joint.as_ref()?;
            let f = c.geometry.convention.joint_field(j.kind)?;
            Some(c.geometry.values[f] - n.geometry.values[f])
        })
        .collect())
}

/// Whether `a` and `b` are one robot at two parameter sets: same links, names, conventions
/// and joints.
pub(crate) fn same_structure(a: &ModelSpec, b: &ModelSpec) -> Result<(), Error> {
    let shape = |s: &ModelSpec| -> Vec<(String, &'static str, Option<String>)> {
        s.links
            .iter()
            .map(|l| {
                (
                    l.name.clone(),
                    l.geometry.convention.name(),
                    l.joint.as_ref().map(|j| j.name.clone()),
                )
            })
            .collect()
    };
    if shape(a) != shape(b) {
        return Err(Error::Model(format!(
            "the calibrated model `{}` and the nominal model `{}` do not have the same links in \
             the same conventions: corrections against the nominal need one chain",
            a.name, b.name
        )));
    }
    Ok(())
}

/// The URDF of `calibrated` with its joint offsets (against `nominal`) as
/// `<calibration rising>`, and what a consumer that ignores `<calibration>` loses.
pub fn to_urdf_calibrated(
    calibrated: &ModelSpec,
    nominal: &ModelSpec,
) -> Result<(String, Option<NotHeld>), Error> {
    let offsets = joint_offsets(calibrated, nominal)?;
    let text = write(&urdf_robot(calibrated, &offsets)?, &calibrated.name)?;
    if offsets.iter().all(|&o| o == 0.0) {
        return Ok((text, None));
    }
    // What a reader that ignores <calibration> builds: the same origins, offsets zero.
    let mut ignored = urdf_robot(calibrated, &offsets)?;
    for j in &mut ignored.joints {
        j.calibration = None;
    }
    let without = super::import::from_urdf_robot(&ignored, None)?;
    let with = super::import::from_urdf_robot(&urdf_robot(calibrated, &offsets)?, None)?;
    let shift = spec_shift(&with, &without)?;
    Ok((
        text,
        Some(NotHeld {
            what: "the joint offsets in <calibration rising> by a reader that ignores \
                   <calibration> (robot_state_publisher, MoveIt): export `urdf` for those, with \
                   the offsets folded into the origins"
                .into(),
            tcp_shift_mm: shift,
        }),
    ))
}

/// A correction the conservative variant drops: within `k σ` of zero.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Dropped {
    /// Parameter name.
    pub name: String,
    /// Its correction `p̂ − p₀` (internal units: mm or rad).
    pub correction: f64,
    /// Its σ (internal units).
    pub sigma: f64,
    /// Largest TCP shift its omission alone causes (mm, over random configurations).
    pub tcp_shift_mm: f64,
}

/// `calibrated` with every robot correction within `k σ` of zero reset to `nominal` (σ by
/// parameter name from `sigma`, internal units; a parameter without σ keeps its value; the
/// instrument frame is left as it is),
/// the dropped corrections, and the TCP shift of dropping them all.
pub fn conservative(
    calibrated: &ModelSpec,
    nominal: &ModelSpec,
    sigma: &dyn Fn(&str) -> Option<f64>,
    k: f64,
) -> Result<(ModelSpec, Vec<Dropped>, f64), Error> {
    if !(k.is_finite() && k >= 0.0) {
        return Err(Error::Input(format!(
            "the σ multiple k of the conservative export is {k}: give a finite k ≥ 0"
        )));
    }
    same_structure(calibrated, nominal)?;
    let model = Model::from_spec(calibrated)?;
    let full = model.nominal();
    let p0 = Model::from_spec(nominal)?.nominal();
    let mut kept = full.clone();
    let mut dropped = Vec::new();
    // The instrument frame is the cell's, not the robot's: no URDF holds it.
    for (i, p) in model.registry.iter().enumerate() {
        if p.segment == crate::model::Segment::Instrument {
            continue;
        }
        let correction = full[i] - p0[i];
        let Some(s) = sigma(&p.name) else { continue };
        if correction != 0.0 && correction.abs() <= k * s {
            let mut one = full.clone();
            one[i] = p0[i];
            dropped.push(Dropped {
                name: p.name.clone(),
                correction,
                sigma: s,
                tcp_shift_mm: max_tcp_shift(&model, &full, &model, &one)?,
            });
            kept[i] = p0[i];
        }
    }
    let total = max_tcp_shift(&model, &full, &model, &kept)?;
    Ok((model.spec_at(&kept), dropped, total))
}
