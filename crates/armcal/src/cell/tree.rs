//! A cell that describes a kinematic tree ([`crate::model::tree`]): a torso with several
//! arms, coupled joints. The cell file marks a tree by a link's `parent` or `coupled`, or a
//! target's `link` (the cell reference, "Trees and coupled joints"); [`crate::Cell`] refuses
//! such a file and [`TreeCell`] reads it.

use crate::model::identifiability::{Identifiability, IdentifiabilitySettings, Measurement};
use crate::model::tree::identifiability::analyze_tree;
use crate::model::tree::{Tree, TreeSpec};
use crate::Error;
use std::path::Path;

/// A tree cell: the tree as described and compiled, and what the instrument measures.
#[derive(Clone, Debug)]
pub struct TreeCell {
    /// Cell name (`name` at the top of the file, else the robot's name).
    pub name: String,
    /// The file it was read from.
    pub origin: String,
    /// The tree as the file describes it (links with parents and couplings, targets).
    pub spec: TreeSpec,
    /// The tree, compiled (one registry, its branches).
    pub tree: Tree,
    /// `[parameters] measurement`; default pose if every target is a frame, else position.
    pub measurement: Measurement,
}

impl TreeCell {
    /// Reads a tree cell file.
    pub fn from_file(path: &Path) -> Result<TreeCell, Error> {
        let text =
            crate::input::read_capped(path, crate::input::TEXT_CAP).map_err(|e| Error::File {
                file: path.display().to_string(),
                message: e.to_string(),
            })?;
        TreeCell::from_toml(&text, &path.display().to_string())
    }

    /// Parses a tree cell from TOML text; `file` names it in errors.
    pub fn from_toml(text: &str, file: &str) -> Result<TreeCell, Error> {
        super::raw::parse_tree(text, file)
    }

    /// The identifiability of the tree's parameters over every target's measurement at
    /// `poses` random configurations of its joints (seeded).
    pub fn identifiability(&self, poses: usize, seed: u64) -> Result<Identifiability, Error> {
        let opts = IdentifiabilitySettings {
            measurement: self.measurement,
            poses,
            seed,
            ..Default::default()
        };
        analyze_tree(&self.tree, &self.tree.nominal(), None, &opts)
    }
}

/// Whether the cell file at `path` describes a tree (a link names a `parent` or is
/// `coupled`, or a target names its `link`): read it with [`TreeCell`], not
/// [`crate::Cell`].
pub fn describes_tree(path: &Path) -> Result<bool, Error> {
    let file = path.display().to_string();
    let text =
        crate::input::read_capped(path, crate::input::TEXT_CAP).map_err(|e| Error::File {
            file: file.clone(),
            message: e.to_string(),
        })?;
    let table: toml::Table = toml::from_str(&text).map_err(|e| Error::File {
        file,
        message: e.to_string(),
    })?;
    let entries = |v: Option<&toml::Value>| -> Vec<toml::Table> {
        v.and_then(|v| v.as_array())
            .map(|a| a.iter().filter_map(|e| e.as_table().cloned()).collect())
            .unwrap_or_default()
    };
    let links = entries(table.get("robot").and_then(|r| r.get("links")));
    let targets = entries(table.get("targets"));
    Ok(links
        .iter()
        .any(|l| l.contains_key("parent") || l.contains_key("coupled"))
        || targets.iter().any(|t| t.contains_key("link")))
}

/// A tree cell with the identifiability of its parameters (what `armcal model` prints for a
/// tree).
#[derive(Clone, Debug)]
pub struct TreeAnalysis {
    /// The cell.
    pub cell: TreeCell,
    /// Its parameters' identifiability over every target
    /// ([`crate::model::tree::identifiability::analyze_tree`]).
    pub identifiability: Identifiability,
}

/// Reads the tree cell at `path` and analyses the identifiability of its parameters at
/// `poses` random configurations (seeded by `seed`) from `measurement` (default: the
/// cell's).
pub fn analyze_tree_file(
    path: &Path,
    measurement: Option<Measurement>,
    poses: usize,
    seed: u64,
) -> Result<TreeAnalysis, Error> {
    let mut cell = TreeCell::from_file(path)?;
    if let Some(m) = measurement {
        cell.measurement = m;
    }
    let identifiability = cell.identifiability(poses, seed)?;
    Ok(TreeAnalysis {
        cell,
        identifiability,
    })
}
