//! `armcal import`: a vendor's file read through the cell's `[data]` mapping and written in
//! armcal's CSV, which armcal's own format reads back.

use crate::common::{armcal, scratch};

#[test]
fn import_writes_what_armcal_read_in_its_own_format() {
    let dir = scratch("import");
    let out = dir.join("series_d.csv");
    let out = out.to_str().unwrap();
    let raw = "data/ipa-ur10-leica/Series_D/measurements_iso_cubes.csv";
    let args = [
        "import",
        "--cell",
        "examples/ur10-leica-cell.toml",
        "--data",
        raw,
        "--out",
        out,
    ];
    let (ok, stdout, stderr) = armcal(&args);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("read 632 measurements at 632 configurations"),
        "{stdout}"
    );
    assert!(
        stderr.contains("ignored columns: Timestamp, Goal x"),
        "{stderr}"
    );
    let text = std::fs::read_to_string(out).unwrap();
    let header = text.lines().next().unwrap();
    assert_eq!(
        header,
        "pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg,target,x_mm,y_mm,z_mm,roll_deg,\
         pitch_deg,yaw_deg,sigma_x_mm,sigma_y_mm,sigma_z_mm,sigma_roll_deg,sigma_pitch_deg,\
         sigma_yaw_deg,temperature_c"
    );
    assert_eq!(text.lines().count(), 633);
    // An existing output is kept unless --force.
    let (ok, _, stderr) = armcal(&args);
    assert!(!ok && stderr.contains("--force"), "{stderr}");
    // The built-in robot (armcal's own format) reads the file back.
    let again = dir.join("again.csv");
    let (ok, stdout, stderr) = armcal(&[
        "import",
        "--cell",
        "ur10",
        "--data",
        out,
        "--out",
        again.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("read 632 measurements"), "{stdout}");
    assert!(stderr.is_empty(), "{stderr}");
}

/// What `import` writes, the same cell reads back (a cell's `[data]` mapping does not lock
/// it out of armcal's own CSV), and reads it to the same data: importing the import again
/// writes the same file, with a warning saying how the file was read.
#[test]
fn the_cell_that_imported_a_file_reads_the_import() {
    let dir = scratch("import_same_cell");
    let first = dir.join("first.csv");
    let second = dir.join("second.csv");
    let cell = "examples/ur10-leica-cell.toml";
    let import = |data: &str, out: &std::path::Path| {
        armcal(&[
            "import",
            "--cell",
            cell,
            "--data",
            data,
            "--out",
            out.to_str().unwrap(),
        ])
    };
    let (ok, _, stderr) = import(
        "data/ipa-ur10-leica/Series_D/measurements_iso_cubes.csv",
        &first,
    );
    assert!(ok, "{stderr}");
    let (ok, stdout, stderr) = import(first.to_str().unwrap(), &second);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("read 632 measurements"), "{stdout}");
    assert!(
        stderr.contains("the header has armcal's own columns")
            && stderr.contains("read as armcal's CSV"),
        "{stderr}"
    );
    assert_eq!(
        std::fs::read_to_string(&first).unwrap(),
        std::fs::read_to_string(&second).unwrap()
    );
}

/// A header that does not resolve: the error lists the columns the reader found and, when
/// another delimiter splits the header into more columns, names it and the `[data]` line.
#[test]
fn a_header_that_does_not_match_echoes_its_columns_and_guesses_the_delimiter() {
    let dir = scratch("import_delimiter");
    let repo = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let text = std::fs::read_to_string(repo.join("examples/ur10-leica-cell.toml")).unwrap();
    assert!(text.contains("delimiter = \";\"\n"));
    let cell = dir.join("cell.toml");
    let without = text
        .replace("delimiter = \";\"\n", "")
        .replace("decimal = \",\"\n", "");
    std::fs::write(&cell, without).unwrap();
    let raw = repo.join("data/ipa-ur10-leica/Series_D/measurements_iso_cubes.csv");
    let out = dir.join("out.csv");
    let (ok, _, stderr) = armcal(&[
        "import",
        "--cell",
        cell.to_str().unwrap(),
        "--data",
        raw.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok);
    for needle in [
        "measurements_iso_cubes.csv",
        "no column `shoulder_pan_joint`",
        "the header has 1 column with delimiter `,`: `Timestamp;Goal x;",
        "the header splits into",
        "columns with `;` — set `[data] delimiter = \";\"`",
    ] {
        assert!(stderr.contains(needle), "`{needle}` not in: {stderr}");
    }
    assert!(!out.exists(), "a failed import writes nothing");
    // A tab-separated armcal file read with the default delimiter: tab is named.
    let tabs = dir.join("tabs.csv");
    std::fs::write(&tabs, "pose_id\tq1_deg\tq2_deg\n1\t0\t0\n").unwrap();
    let (ok, _, stderr) = armcal(&[
        "import",
        "--cell",
        "paper-650-600",
        "--data",
        tabs.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok);
    assert!(
        stderr.contains("`pose_id\tq1_deg\tq2_deg`")
            && stderr.contains(
                "the header splits into 3 columns with tab — set `[data] delimiter = \"\\t\"`"
            ),
        "{stderr}"
    );
}

/// A full-pose cell without targets (the UR10 with its T-Mac) measures the tool frame's pose:
/// `predict` and `simulate` write its orientation, and `predict` reads a joint file in
/// armcal's own columns with that cell.
#[test]
fn predict_and_simulate_write_orientation_for_a_full_pose_cell() {
    let dir = scratch("predict_pose");
    let joints = dir.join("joints.csv");
    std::fs::write(
        &joints,
        "pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\n\
         a,0,-80,80,-90,-90,0\nb,20,-70,60,-80,-80,30\n",
    )
    .unwrap();
    let cell = "examples/ur10-leica-cell.toml";
    for command in ["predict", "simulate"] {
        let out = dir.join(format!("{command}.csv"));
        let input = if command == "predict" {
            "--joints"
        } else {
            "--poses"
        };
        let mut args = vec![
            command,
            "--cell",
            cell,
            input,
            joints.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        if command == "simulate" {
            // the cell's capsules block the beam at these poses; what is written is the point
            args.push("--allow-unmeasurable");
        }
        let (ok, _, stderr) = armcal(&args);
        assert!(ok, "{command}: {stderr}");
        let text = std::fs::read_to_string(&out).unwrap();
        let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
        for column in ["x_mm", "roll_deg", "pitch_deg", "yaw_deg"] {
            assert!(header.contains(&column), "{command}: {header:?}");
        }
        // Every row has its orientation.
        let roll = header.iter().position(|h| *h == "roll_deg").unwrap();
        for row in text.lines().skip(1) {
            let v: f64 = row.split(',').nth(roll).unwrap().parse().unwrap();
            assert!(v.is_finite(), "{command}: {row}");
        }
    }
}
