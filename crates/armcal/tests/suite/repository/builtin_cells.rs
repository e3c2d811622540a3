//! The library's built-in paper cells are the files users find in `examples/`.

use armcal::cell::builtin::{PAPER_CELL, PAPER_CELL_OBSTACLES};
use std::path::Path;

#[test]
fn built_in_cells_are_the_example_files() {
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    for (name, text) in [
        ("paper-cell.toml", PAPER_CELL),
        ("paper-cell-obstacles.toml", PAPER_CELL_OBSTACLES),
    ] {
        let file = std::fs::read_to_string(examples.join(name)).unwrap();
        assert_eq!(
            file, text,
            "examples/{name} and crates/armcal/cells/{name} differ: copy one onto the other"
        );
    }
}
