//! The paper's cells, built into the library (the demo, the paper study and the tests start
//! from them). The files live inside the crate (`crates/armcal/cells/`) so the packaged crate
//! is self-contained; `examples/` holds the same files for users to copy, and a test
//! (`tests/suite/repository/builtin_cells.rs`) keeps the two byte-identical.

/// The paper's cell without obstacles (`examples/paper-cell.toml`): joint limits and the
/// tracker's incidence limit (paper §5.1).
pub const PAPER_CELL: &str = include_str!("../../cells/paper-cell.toml");

/// The paper's cell with the car body and the wall (`examples/paper-cell-obstacles.toml`,
/// paper §5.2).
pub const PAPER_CELL_OBSTACLES: &str = include_str!("../../cells/paper-cell-obstacles.toml");

/// The paper's cell ([`PAPER_CELL`]) parsed: the starting point of the examples and the
/// demo.
pub fn paper_cell() -> Result<crate::Cell, crate::Error> {
    crate::Cell::from_toml(PAPER_CELL, "paper-cell.toml (built in)", ".".as_ref())
}
