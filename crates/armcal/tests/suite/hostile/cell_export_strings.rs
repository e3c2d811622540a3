//! Found by `fuzz/cell` (issue 15): a cell whose instrument was named with backslashes
//! (`track\\…\L…er` in TOML: a name holding `\L`) exported a cell file that armcal could not
//! read ("missing escaped value"), because names were written between quotes unescaped.
//! Every string a cell export writes must read back as itself.

use armcal::{export_model, Cell, ExportFormat};
use std::path::Path;

/// The fuzzer's input, minimized by hand: the paper cell with the instrument's name.
const FOUND: &str = r#"name = "paper-651-600"

[robot]
builtin = "paper-650-600"

[instrument]
name = "track\\\\\\\\\\\\\\L\\\\er"
kind = "laser-tracker"

[parameters]
fixed = ["base", "tool"]
free = "auto"
"#;

/// Names with every character class that needs escaping in TOML, in every named place a cell
/// export writes: instrument, working pose, obstacles, targets.
const NAMES: &str = r#"name = "cell \"quoted\" \u001B[0m"

[robot]
builtin = "paper-650-600"

[instrument]
name = "tracker\t\\L"
kind = "laser-tracker"

[[targets]]
name = "smr \"1\""
xyz_mm = [0, 0, 100]

[parameters]
fixed = ["base", "tool"]
free = "auto"

[[working]]
name = "q \"work\"\n2"
joints_deg = [0, -30, 30, 0, -60, 0]

[[obstacles]]
name = "wall\\\u007F"
kind = "half-space"
normal = [1, 0, 0]
offset_mm = -450
"#;

fn read(text: &str, file: &str) -> Cell {
    Cell::from_toml(text, file, Path::new(".")).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

#[test]
fn every_cell_export_reads_back_with_the_same_names() {
    for (text, file) in [(FOUND, "found.toml"), (NAMES, "names.toml")] {
        let cell = read(text, file);
        for format in ["dh", "mdh", "zrp", "cell"] {
            let exported = export_model(
                &cell.model.spec(),
                Some(&cell),
                ExportFormat::from_name(format).expect("a format"),
            )
            .unwrap();
            let again = read(&exported.content, "exported.toml");
            assert_eq!(again.name, cell.name, "{format}");
            let names = |c: &Cell| -> Vec<String> {
                let m = c.model.spec();
                let mut v: Vec<String> = m.instrument.iter().map(|i| i.name.clone()).collect();
                v.extend(m.targets.iter().map(|t| t.name.clone()));
                v.extend(c.working.iter().map(|w| w.name.clone()));
                v.extend(c.obstacles.iter().map(|o| o.name().to_string()));
                v
            };
            assert_eq!(names(&again), names(&cell), "{format}");
        }
    }
}
