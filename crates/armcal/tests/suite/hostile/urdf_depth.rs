//! Issue 15, found #4: a deeply nested URDF overflowed the stack inside the URDF parser;
//! the nesting depth is checked first, and the error names the file.

use armcal::model::urdf::depth::MAX_DEPTH;
use armcal::model::urdf::{from_urdf_str, read_urdf};

fn nested(levels: usize) -> String {
    format!(
        "<robot name=\"r\"><link name=\"a\">{}{}</link></robot>",
        "<visual>".repeat(levels),
        "</visual>".repeat(levels)
    )
}

#[test]
fn thirteen_thousand_nested_elements_are_an_error_naming_the_file() {
    let dir = std::env::temp_dir().join(format!("armcal-urdf-depth-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("deep.urdf");
    std::fs::write(&path, nested(13_000)).unwrap();
    let e = read_urdf(&path, None).unwrap_err().to_string();
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(e.contains("deep.urdf"), "{e}");
    assert!(
        e.contains("13002 levels deep") && e.contains(&format!("at most {MAX_DEPTH}")),
        "{e}"
    );
}

#[test]
fn nesting_up_to_the_limit_reaches_the_parser() {
    let e = from_urdf_str(&nested(MAX_DEPTH - 2), None);
    assert!(e.map_or_else(|e| !e.to_string().contains("levels deep"), |_| true));
}
