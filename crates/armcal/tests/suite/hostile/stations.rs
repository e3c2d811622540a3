//! Found by `fuzz/data_csv` (issue 15): a data file whose `station` column gives every row a
//! station of its own (60 rows, 60 stations) made the identification carry 360 instrument
//! parameters that no row could locate, and a long such file would grow the problem without
//! bound (each station adds 6 parameters to a dense fit): the fuzzer's run timed out. A station
//! needs rows of its own that locate it, and a fit takes at most `MAX_STATIONS`.

use armcal::measure::csv::read_str;
use armcal::measure::stations::MAX_STATIONS;
use armcal::{identify, Cell, IdentifySettings, Silent};
use std::path::Path;

const HEADER: &str = "station,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg,target,x_mm,y_mm,z_mm\n";

/// The fuzzer's input, minimized by hand: three rows, each at its own station.
const FOUND: &str = "1,-30.6,-24.8,3.6,73.6,87,-121.5,smr1,-1815.2,-943.1,-4978.8\n\
                     2,-27.8,-20.4,-6.1,84.2,87,-101.6,smr1,-1921.0,-974.2,-4885.6\n\
                     3,-20.0,-10.0,10.0,20.0,30,-40.0,smr1,-1700.0,-900.0,-4800.0\n";

fn paper_cell() -> Cell {
    Cell::from_file(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper-cell.toml"))
        .unwrap()
}

fn identify_text(cell: &Cell, text: &str) -> String {
    let (data, _) = read_str(text, "found.csv", &cell.model, None).unwrap();
    identify(cell, &data, &IdentifySettings::default(), &mut Silent)
        .unwrap_err()
        .to_string()
}

#[test]
fn a_station_with_too_few_rows_of_its_own_is_named() {
    let e = identify_text(&paper_cell(), &format!("{HEADER}{FOUND}"));
    assert!(
        e.contains("station `1` (first row on line 2) cannot be located")
            && e.contains("1 × position"),
        "{e}"
    );
}

#[test]
fn more_stations_than_a_fit_takes_are_refused() {
    let row = FOUND.lines().next().unwrap().split_once(',').unwrap().1;
    let mut text = HEADER.to_string();
    for s in 0..=MAX_STATIONS {
        for _ in 0..2 {
            text.push_str(&format!("s{s},{row}\n"));
        }
    }
    let e = identify_text(&paper_cell(), &text);
    assert!(
        e.contains(&format!("{} instrument stations", MAX_STATIONS + 1))
            && e.contains(&format!("at most {MAX_STATIONS}")),
        "{e}"
    );
}
