//! A cell that describes a kinematic tree ([`crate::model::tree`]): a torso with several
//! arms, coupled joints. The cell file marks a tree by a link's `parent` or `coupled`, or a
//! target's `link` (the cell reference, "Trees and coupled joints"); [`crate::Cell`] refuses
//! such a file and [`TreeCell`] reads it.

use crate::measure::{csv, Dataset, NoiseModel};
use crate::model::controller::ControllerConvention;
use crate::model::identifiability::{Identifiability, IdentifiabilitySettings, Measurement};
use crate::model::tree::identifiability::analyze_tree;
use crate::model::tree::{Tree, TreeSpec};
use crate::model::{LinkSpec, Model, ModelSpec};
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
    /// The instrument's noise (`[instrument] noise`; default [`NoiseModel::default`]).
    pub noise: NoiseModel,
    /// The tree's joints (the non-coupled ones, in link order) and targets as a serial
    /// model, for reading and writing data files only: its joints name a data file's joint
    /// columns (with their units and limits) and its targets the `target` column's values;
    /// its kinematics is not the tree's and is never evaluated.
    data_model: Model,
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

    /// The cell of `tree` (built from `spec`), with its data model (the tree's joints and
    /// targets, [`TreeCell::read_data`]).
    pub(crate) fn new(
        name: String,
        origin: String,
        spec: TreeSpec,
        tree: Tree,
        measurement: Measurement,
        noise: NoiseModel,
    ) -> Result<TreeCell, Error> {
        let joint_links: Vec<LinkSpec> = spec
            .links
            .iter()
            .filter(|l| l.link.joint.is_some() && l.coupling.is_none())
            .map(|l| l.link.clone())
            .collect();
        let data_model = Model::from_spec(&ModelSpec {
            name: spec.name.clone(),
            instrument: spec.instrument.clone(),
            links: joint_links,
            targets: spec.targets.iter().map(|t| t.target.clone()).collect(),
            compliance: None,
            periodic: None,
            payloads: Vec::new(),
        })?;
        Ok(TreeCell {
            name,
            origin,
            spec,
            tree,
            measurement,
            noise,
            data_model,
        })
    }

    /// Reads a data file of this tree in armcal's CSV: a column per tree joint that is not
    /// coupled (`<joint>_deg`, `_rad`, `_mm`, … by joint name; a coupled joint follows its
    /// coupling and has no column), and a `target` column naming the target each row saw
    /// (one file may mix the targets of several branches). With `target`, every row saw that
    /// target (a file of one arm's poses; a `target` column then names it on every row).
    /// Errors name the file, line and field.
    pub fn read_data(&self, path: &Path, target: Option<&str>) -> Result<Dataset, Error> {
        let Some(name) = target else {
            return Ok(csv::read(path, &self.data_model, None)?.0);
        };
        let t = self
            .tree
            .targets
            .iter()
            .position(|t| t.0 == name)
            .ok_or_else(|| {
                let names: Vec<&str> = self.tree.targets.iter().map(|t| t.0.as_str()).collect();
                Error::Input(format!(
                    "{}: no target `{name}` in tree cell `{}` (it has: {})",
                    path.display(),
                    self.name,
                    names.join(", ")
                ))
            })?;
        let mut spec = self.data_model.spec_at(&self.data_model.nominal());
        spec.targets = vec![spec.targets[t].clone()];
        let mut data = csv::read(path, &Model::from_spec(&spec)?, None)?.0;
        for m in &mut data.measurements {
            m.observed = crate::model::Observed::Target(t);
        }
        Ok(data)
    }

    /// Reads joint configurations of this tree (`pose_id` and a column per tree joint that
    /// is not coupled, as [`TreeCell::read_data`]), each within the joint limits.
    pub fn read_poses(&self, path: &Path) -> Result<Vec<(String, Vec<f64>)>, Error> {
        // a tree cell has no controller convention (its joints are the model's)
        let model_angles = ControllerConvention::model_angles(self.data_model.dof());
        csv::read_reachable_configurations(path, &self.data_model, &model_angles)
    }

    /// `data` in armcal's CSV for this tree ([`TreeCell::read_data`] reads it back).
    pub fn write_data(&self, data: &Dataset) -> Result<String, Error> {
        csv::write_string(data, &self.data_model)
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

/// `spec` (a tree, e.g. at an estimate) as a tree cell file that [`TreeCell::from_file`]
/// reads back to the same tree: every link with its convention, values (mm, degrees),
/// joint, `parent` (written on every link but the root) and `coupled` (coefficients as
/// given, the offset in `offset_deg` or `offset_mm`), the instrument frame with `noise`, the
/// targets with the `link` each hangs from, and `[parameters] measurement`.
pub(crate) fn tree_cell_toml(
    name: &str,
    spec: &TreeSpec,
    measurement: Measurement,
    noise: Option<&NoiseModel>,
) -> Result<String, Error> {
    use crate::model::export::{frame_fields, instrument_section, link_toml_with};
    use crate::model::{Convention, JointKind};
    use crate::toml_text::string;
    use std::fmt::Write;
    Tree::from_spec(spec)?;
    let mut out = format!(
        "# armcal tree export: {}\nname = {}\n\n[robot]\nname = {}\n\n",
        string(&spec.name),
        string(name),
        string(&spec.name)
    );
    for (i, l) in spec.links.iter().enumerate() {
        let mut extra = String::new();
        let parent = match (&l.parent, i) {
            (Some(p), _) => Some(p.as_str()),
            (None, 0) => None,
            (None, _) => Some(spec.links[i - 1].link.name.as_str()),
        };
        if let Some(p) = parent {
            let _ = writeln!(extra, "parent = {}", string(p));
        }
        if let (Some(c), Some(j)) = (&l.coupling, &l.link.joint) {
            let mut terms: Vec<String> = c
                .terms
                .iter()
                .map(|(n, a)| format!("{} = {a:?}", string(n)))
                .collect();
            terms.push(match j.kind {
                JointKind::Revolute => format!("offset_deg = {:?}", c.offset.to_degrees()),
                JointKind::Prismatic => format!("offset_mm = {:?}", c.offset),
            });
            let _ = writeln!(extra, "coupled = {{ {} }}", terms.join(", "));
        }
        link_toml_with(&mut out, "robot.links", &l.link, true, &extra);
    }
    if let Some(i) = &spec.instrument {
        let _ = writeln!(out, "{}", instrument_section(i)?);
        if let Some(n) = noise {
            let _ = writeln!(out, "noise = {}\n", super::export::noise_toml(n));
        }
    }
    for t in &spec.targets {
        let v = &t.target.geometry.values;
        let geometry = match t.target.geometry.convention {
            Convention::Point => format!("xyz_mm = [{:?}, {:?}, {:?}]\n", v[0], v[1], v[2]),
            Convention::Frame6 => frame_fields(v),
            c => {
                return Err(Error::Conversion(format!(
                    "target `{}` ({c}) has no cell-file form",
                    t.target.name
                )))
            }
        };
        let _ = writeln!(
            out,
            "[[targets]]\nname = {}\nlink = {}\n{geometry}",
            string(&t.target.name),
            string(&t.parent)
        );
    }
    let _ = writeln!(
        out,
        "[parameters]\nmeasurement = \"{}\"",
        measurement.words()
    );
    Ok(out)
}
