//! A tree estimate exported (`armcal export` of a tree's `estimate.json`, issue 32): the
//! whole tree at the estimate as one URDF file (mimic joints written back,
//! [`crate::model::urdf::tree_to_urdf`]) or as a tree cell file that every tree command
//! reads ([`crate::cell::tree::tree_cell_toml`]).

use super::TreeEstimate;
use crate::cell::export::{ExportFormat, Exported};
use crate::cell::tree::{tree_cell_toml, TreeCell};
use crate::identify::Acceptance;
use crate::model::identifiability::Measurement;
use crate::model::tcp_shift::tree_without_compliance;
use crate::model::urdf::tree_to_urdf;
use crate::model::Convention;
use crate::Error;

/// The tree of the estimate `est` in `format`: `urdf` (one URDF file of the whole tree; the
/// instrument frame is the cell's and is not in it, a note says so) or `cell` (a tree cell at
/// the estimate; with the `cell` it was identified in, its instrument noise and measurement
/// type, else the measurement its targets imply). Neither holds a joint compliance: the
/// tree is written rigid and a warning says how far a target moves without it. A fit that did not converge is refused
/// unless `acceptance` accepts it; the other formats are a serial chain's and are refused.
pub fn export_tree_estimate(
    est: &TreeEstimate,
    cell: Option<&TreeCell>,
    format: ExportFormat,
    acceptance: &Acceptance,
) -> Result<Exported, Error> {
    let mut warnings: Vec<String> = est.check_usable(acceptance)?.into_iter().collect();
    if let Some(c) = cell {
        est.params_for(&c.tree)?;
    }
    // neither file holds a joint compliance: the tree is written rigid, and the warning
    // says what that costs
    let (rigid, not_held) = tree_without_compliance(&est.tree)?;
    warnings.extend(not_held.map(|n| n.sentence()));
    let (content, notes) = match format {
        ExportFormat::Urdf => (
            tree_to_urdf(&rigid)?,
            vec![format!(
                "the instrument frame{} belongs to the cell and is not in the URDF; export \
                 `cell` to keep it",
                est.tree
                    .instrument
                    .as_ref()
                    .map(|i| format!(" `{}`", i.name))
                    .unwrap_or_default()
            )],
        ),
        ExportFormat::Cell(crate::model::complete::LinkForm::AsGiven) => {
            let measurement = cell.map(|c| c.measurement).unwrap_or_else(|| {
                if est
                    .tree
                    .targets
                    .iter()
                    .all(|t| t.target.geometry.convention != Convention::Point)
                {
                    Measurement::Pose
                } else {
                    Measurement::Position
                }
            });
            (
                tree_cell_toml(
                    cell.map(|c| c.name.as_str()).unwrap_or(&est.cell),
                    &rigid,
                    measurement,
                    cell.map(|c| &c.noise),
                )?,
                Vec::new(),
            )
        }
        _ => {
            return Err(Error::Input(format!(
                "tree `{}`: a tree exports as `urdf` (one file, the whole tree) or `cell` (its \
                 links in their own conventions); the other formats write a serial chain",
                est.cell
            )))
        }
    };
    Ok(Exported {
        content,
        table_csv: None,
        warnings,
        notes,
    })
}
