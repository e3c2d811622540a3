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
