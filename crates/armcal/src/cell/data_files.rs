//! A cell's joint and data files: read and written as the cell lays them out (its `[data]`
//! column mapping, its controller's axis columns), so a program names a file and the cell,
//! not the CSV reader's internals ([`crate::measure::csv`]). The built-in robots a cell
//! can be loaded from ([`Cell::robots`]).

use super::Cell;
use crate::measure::csv::{self, Import};
use crate::measure::read_report::ReadReport;
use crate::measure::Dataset;
use crate::Error;
use std::path::Path;

impl Cell {
    /// The built-in robots ([`Cell::load`] takes their names): each name with a one-line
    /// summary.
    pub fn robots() -> Vec<(String, String)> {
        crate::robots::list()
    }

    /// Reads a data file laid out as the cell says ([`Cell::data_format`]), with the
    /// reader's remarks (ignored columns, rows read with a warning).
    pub fn read_data(&self, path: &Path) -> Result<(Dataset, ReadReport), Error> {
        csv::read_with(path, &self.model, &self.data_format())
    }

    /// Reads a data file laid out as the cell says and writes it in armcal's own CSV (what
    /// `armcal import` writes), with the reader's remarks.
    pub fn import_data(&self, path: &Path) -> Result<Import, Error> {
        csv::import(path, &self.model, &self.data_format())
    }

    /// Joint configurations (a pose list, a measured design) laid out as the cell's data
    /// files are ([`Cell::data_format`]): each pose's id (`pose_id`, or its row number) and
    /// its joint values (rad, mm).
    pub fn read_poses(&self, path: &Path) -> Result<Vec<(String, Vec<f64>)>, Error> {
        csv::read_configurations_with(path, &self.model, &self.data_format())
    }

    /// Joint configurations in armcal's own CSV (`pose_id` and the model's joint columns, a
    /// design or pose list armcal wrote), whatever the cell's `[data]` mapping says.
    pub fn read_armcal_poses(&self, path: &Path) -> Result<Vec<(String, Vec<f64>)>, Error> {
        csv::read_configurations(path, &self.model, None)
    }

    /// Joint configurations the robot must take (a pose list to measure), in armcal's CSV or
    /// the cell's controller columns: a joint outside its limits is an error naming the
    /// file, line, pose and joint.
    pub fn read_reachable_poses(&self, path: &Path) -> Result<Vec<(String, Vec<f64>)>, Error> {
        csv::read_reachable_configurations(path, &self.model, &self.controller)
    }

    /// A data set in armcal's CSV as this cell writes it (with its controller's axis
    /// columns, [`Cell::with_controller_columns`]).
    pub fn write_data(&self, data: &Dataset) -> Result<String, Error> {
        self.with_controller_columns(csv::write_string(data, &self.model)?)
    }

    /// Poses (each with its id; joint values in rad, mm) in armcal's CSV as this cell writes
    /// them (with its controller's axis columns).
    pub fn write_poses(&self, poses: &[(String, &[f64])]) -> Result<String, Error> {
        self.with_controller_columns(csv::write_poses(&self.model, poses))
    }
}
