//! What `armcal model` shows of a cell: its parameters, completeness and identifiability,
//! optionally of the model converted to another link convention, and the record it prints
//! with `--json`.
//!
//! A conversion ([`in_form`]: `zrp` by `to_zrp`, identity base, one zero-reference link per
//! joint, the tool pose at q = 0 as tool frame; `dh` by `zrp_to_dh` without a nominal,
//! standard DH links by the common normals, book §6.3.4; `mdh` by `dh_to_mdh` of that)
//! leaves forward kinematics unchanged. Its statuses, kept simple: the instrument and the
//! targets, which the conversion copies unchanged, keep the cell's declared statuses;
//! every chain parameter (base, links, tool) is a candidate, since the conversion
//! redistributes the geometry among the chain's links and a fixed base or tool of the cell
//! has no counterpart there. With `free = "auto"` in the cell the unidentifiable ones are
//! fixed, as for the original model.

use super::Cell;
use crate::model::complete::{in_form, FormChange, LinkForm};
use crate::model::identifiability::{self, Identifiability, IdentifiabilitySettings};
use crate::model::rank_deficit::{rank_deficit, RankDeficit};
use crate::model::{Joint, Model, ParameterStatus, Segment};
use crate::Error;
use serde::Serialize;

/// The analysis of a cell's model (or of its conversion).
#[derive(Clone, Debug)]
pub struct ModelAnalysis {
    /// The model analysed: the cell's, or its conversion with the statuses above.
    pub model: Model,
    /// The convention converted to, if any.
    pub convention: Option<LinkForm>,
    /// On the parameters the cell declared free, before the automatic reduction, so that
    /// every excluded parameter gets its reason.
    pub identifiability: Identifiability,
    /// Why fewer parameters are identifiable than the generic count, if so.
    pub rank_deficit: Option<RankDeficit>,
}

/// The cell's model converted to `form`, with the statuses of the module documentation
/// (before any automatic reduction).
pub(crate) fn converted(cell: &Cell, form: LinkForm) -> Result<Model, Error> {
    let original = &cell.model;
    let mut model = Model::from_spec(&in_form(&original.spec(), form)?.spec)?;
    for i in 0..model.param_count() {
        let p = model.registry.get(i);
        let status = match p.segment {
            Segment::Chain => ParameterStatus::Free,
            Segment::Instrument | Segment::Target(_) => {
                let k = original.registry.require(&p.name)?;
                if cell.declared_free.contains(&k) {
                    match original.registry.get(k).status {
                        ParameterStatus::Prior { sigma } => ParameterStatus::Prior { sigma },
                        _ => ParameterStatus::Free,
                    }
                } else {
                    ParameterStatus::Fixed
                }
            }
        };
        model.registry.set_status(i, status);
    }
    Ok(model)
}

/// Identifiability of the cell's model, or of its conversion to `convention`, with the
/// analysis options `opts`.
pub fn analyze_model(
    cell: &Cell,
    opts: &IdentifiabilitySettings,
    convention: Option<LinkForm>,
) -> Result<ModelAnalysis, Error> {
    let (model, identifiability, rank_deficit) = match convention {
        Some(form) => {
            let mut m = converted(cell, form)?;
            let report = identifiability::analyze(&m, &m.nominal(), opts)?;
            let deficit = rank_deficit(
                &m,
                &m.nominal(),
                report.count(&m).geometric,
                opts.measurement,
                None,
            )?;
            if cell.auto_free {
                report.apply(&mut m)?;
            }
            (m, report, deficit)
        }
        None => {
            let report = cell.identifiability(opts)?;
            let deficit = cell.rank_deficit(&report, &cell.model.nominal(), None)?;
            (cell.model.clone(), report, deficit)
        }
    };
    Ok(ModelAnalysis {
        model,
        convention,
        identifiability,
        rank_deficit,
    })
}

/// A parameter in display units (mm, deg).
#[derive(Clone, Debug, Serialize)]
pub struct ParameterRecord {
    /// The parameter's name in the registry (`j2.theta`).
    pub name: String,
    /// Its display unit (`mm`, `deg`, or empty).
    pub unit: String,
    /// Its nominal value in that unit.
    pub nominal: f64,
    /// Free, fixed or with a prior.
    pub status: ParameterStatus,
}

/// What `armcal model --json` prints.
#[derive(Clone, Debug, Serialize)]
pub struct ModelRecord {
    /// The cell's name.
    pub cell: String,
    /// The robot's source (datasheet, paper).
    pub source: String,
    /// Where the arm's capsules come from ([`crate::robots::Robot::collision`]).
    #[serde(default)]
    pub collision_model: String,
    /// The cell's capsules (robot and tool; mm, in their chain frames).
    #[serde(default)]
    pub capsules: Vec<crate::robots::Capsule>,
    /// The convention converted to (`dh`, `mdh`, `zrp`), if any.
    pub convention: Option<String>,
    /// The link form the cell asked for.
    pub form: String,
    /// Links the cell's form changed (Hayati / β across nearly parallel axes).
    pub form_changes: Vec<FormChange>,
    /// Nearly parallel axes left without a tilt parameter, with the fix.
    pub form_incomplete: Vec<String>,
    /// The joints with their limits (internal units).
    pub joints: Vec<Joint>,
    /// Every parameter of the model analysed.
    pub parameters: Vec<ParameterRecord>,
    /// The identifiability analysis.
    pub identifiability: Identifiability,
    /// Why fewer parameters are identifiable than the generic count, if so.
    pub rank_deficit: Option<RankDeficit>,
}

impl ModelRecord {
    /// The record of `analysis` of `cell`.
    pub fn new(cell: &Cell, analysis: &ModelAnalysis) -> ModelRecord {
        let model = &analysis.model;
        ModelRecord {
            cell: cell.name.clone(),
            source: cell.robot.source.clone(),
            collision_model: cell.robot.collision.clone(),
            capsules: cell.capsules.clone(),
            convention: analysis.convention.map(|f| f.name().to_string()),
            form: cell.form.name().to_string(),
            form_changes: cell.form_changes.clone(),
            form_incomplete: cell.form_incomplete.clone(),
            joints: model.joints.clone(),
            parameters: model
                .registry
                .iter()
                .map(|p| ParameterRecord {
                    name: p.name.clone(),
                    unit: p.unit.display_name().to_string(),
                    nominal: p.nominal * p.unit.display_factor(),
                    status: p.status,
                })
                .collect(),
            identifiability: analysis.identifiability.clone(),
            rank_deficit: analysis.rank_deficit.clone(),
        }
    }

    /// The record as JSON (keys in alphabetical order, see `crate::json`).
    pub fn to_json(&self) -> Result<String, Error> {
        crate::json::sorted_pretty(self)
    }
}
