//! Issue 15, found #5: every input is read with a size cap, so `/dev/zero` (or any huge file)
//! given as a cell, URDF, JSON record or data file is an error, not a machine out of memory.

use armcal::model::urdf::read_urdf;
use armcal::report::Document;
use armcal::{read_capped, Cell, Estimate, TEXT_CAP};
use std::path::Path;

const ZERO: &str = "/dev/zero";

fn assert_capped(e: armcal::Error) {
    let e = e.to_string();
    assert!(e.contains(ZERO), "{e}");
    assert!(
        e.contains("larger than 64 MiB") && e.contains("ARMCAL_MAX_INPUT_MIB"),
        "{e}"
    );
}

#[test]
fn an_endless_file_is_refused_at_the_cap() {
    let e = read_capped(Path::new(ZERO), TEXT_CAP).unwrap_err();
    assert_eq!(e.kind(), std::io::ErrorKind::InvalidData);
    assert_capped(Cell::from_file(Path::new(ZERO)).unwrap_err());
    assert_capped(read_urdf(ZERO, None).unwrap_err());
    assert_capped(Estimate::from_file(Path::new(ZERO)).unwrap_err());
    assert_capped(Document::from_file(Path::new(ZERO)).unwrap_err());
}

#[test]
fn a_cell_naming_an_endless_urdf_is_refused() {
    let e = Cell::from_toml(
        "[robot]\nurdf = \"/dev/zero\"\n",
        "cell.toml",
        Path::new("."),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("`robot.urdf`") && e.contains("larger than 64 MiB"),
        "{e}"
    );
}

#[test]
fn a_small_file_reads_whole() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper-cell.toml");
    let text = read_capped(&path, TEXT_CAP).unwrap();
    assert_eq!(text, std::fs::read_to_string(&path).unwrap());
}
