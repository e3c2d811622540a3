//! Real data: the UR10 + Leica T-Mac series (`data/ipa-ur10-leica/`, Landgraf et al., IEEE
//! CASE 2021) read as they come through the mapping of `examples/ur10-leica-cell.toml`:
//! `;`-separated, decimal comma (also `2,78E-17`), CRLF, the D hand-eye file with LF and a NUL
//! byte ending every row. Rows are checked against values computed here from the raw text
//! (own split, own comma → point, own `Rx·Ry·Rz` multiplied out, own σ propagation), and the
//! conventions against the data themselves:
//! * the measured angles are intrinsic X-Y'-Z'': in the hand-eye files the relative rotation
//!   between two measured T-Mac poses equals that between the two reported flange poses
//!   (quaternions, scalar last) — `R_meas = R_Y R_flange R_Z`, so `R_iᵀ R_j` differ by a
//!   conjugation only. Measured: 0.049° / 0.055° RMS (B / D); reading the angles as `rpy`
//!   gives 4.7° / 65° (bounds 0.1° and 1°). (Relative angles cannot tell a quaternion's
//!   component order: `|q_i·q_j|` is the same for every order; the unit tests of
//!   `measure::angles` show scalar first ≠ scalar last);
//! * the commanded `Goal` pose (m, `rpy` in rad) is `Rz(180°)·FK(q)·inv(Trafo_TM_F_init)` with
//!   the nominal UR10 at the reported joints. Measured max 0.61 / 0.34 / 0.45 mm and 0.12 /
//!   0.03 / 0.04° (A / B / D; bound 1 mm, 0.2°); a wrong joint unit or order, or a wrong Goal
//!   convention, gives tens of millimetres.

use armcal::measure::angles::Orientation;
use armcal::measure::csv;
use armcal::measure::format::{ColumnUnit, Columns, DataFormat, OrientationColumns};
use armcal::measure::MeasurementKind;
use armcal::model::rotation_log;
use armcal::model::{tool_pose, Pose};
use armcal::{Cell, Dataset};
use nalgebra::{Matrix3, Vector3};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn data_file(name: &str) -> PathBuf {
    root().join("data/ipa-ur10-leica").join(name)
}

fn cell() -> Cell {
    Cell::from_file(&root().join("examples/ur10-leica-cell.toml")).unwrap()
}

/// The raw text as lines of fields: own split on `;`, NUL and CR stripped.
fn raw_rows(file: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let text = String::from_utf8(std::fs::read(data_file(file)).unwrap()).unwrap();
    let mut lines = text.split('\n').map(|l| {
        l.trim_end_matches(['\r', '\0'])
            .split(';')
            .map(str::to_string)
            .collect::<Vec<_>>()
    });
    let header = lines.next().unwrap();
    (header, lines.filter(|l| l.len() > 1).collect())
}

/// A raw field as a number: comma → point by hand.
fn num(header: &[String], row: &[String], name: &str) -> f64 {
    let i = header.iter().position(|h| h == name).unwrap();
    row[i].replace(',', ".").parse().unwrap()
}

/// `Rx(a)·Ry(b)·Rz(c)` multiplied out (a, b, c in degrees).
fn rx_ry_rz(a: f64, b: f64, c: f64) -> Matrix3<f64> {
    let (sa, ca) = a.to_radians().sin_cos();
    let (sb, cb) = b.to_radians().sin_cos();
    let (sc, cc) = c.to_radians().sin_cos();
    Matrix3::new(
        cb * cc,
        -cb * sc,
        sb,
        ca * sc + sa * sb * cc,
        ca * cc - sa * sb * sc,
        -sa * cb,
        sa * sc - ca * sb * cc,
        sa * cc + ca * sb * sc,
        ca * cb,
    )
}

const SERIES: [(&str, usize, bool); 3] = [
    ("Series_A/measurements_grid.csv", 11_911, false),
    (
        "Series_B/measurements_joint_configurations.csv",
        1_495,
        true,
    ),
    ("Series_D/measurements_iso_cubes.csv", 632, true),
];

const JOINTS: [&str; 6] = [
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
];

fn pose_of(data: &Dataset, i: usize) -> (Pose<f64>, Option<[f64; 6]>) {
    match &data.measurements[i].kind {
        MeasurementKind::Pose { value, sigma } => (*value, *sigma),
        other => panic!("row {i}: a {} measurement", other.name()),
    }
}

#[test]
fn every_series_file_reads_with_the_right_units_and_conventions() {
    let cell = cell();
    let format = cell.data_format();
    for (file, rows, has_sigma) in SERIES {
        let (data, report) = csv::read_with(&data_file(file), &cell.model, &format).unwrap();
        assert_eq!(data.measurements.len(), rows, "{file}");
        assert_eq!(data.configurations.len(), rows, "{file}");
        assert!(report.ignored.iter().any(|c| c == "Goal x"), "{file}");
        let (header, raw) = raw_rows(file);
        assert_eq!(raw.len(), rows, "{file}: own count");
        for r in [0, rows / 2, rows - 1] {
            let (row, m) = (&raw[r], &data.measurements[r]);
            assert_eq!(m.line, r + 2, "{file}");
            let n = |name: &str| num(&header, row, name);
            for (j, name) in JOINTS.iter().enumerate() {
                let q = data.configurations[m.config][j];
                assert!((q - n(name)).abs() < 1e-15, "{file} line {}: {name}", r + 2);
            }
            let (pose, sigma) = pose_of(&data, r);
            let p = Vector3::new(n("measurement_x"), n("measurement_y"), n("measurement_z"));
            assert!((pose.trans - p).norm() < 1e-12, "{file} line {}", r + 2);
            let (a, b, c) = (
                n("measurement_rx"),
                n("measurement_ry"),
                n("measurement_rz"),
            );
            assert!(
                (pose.rot - rx_ry_rz(a, b, c)).norm() < 1e-12,
                "{file} line {}",
                r + 2
            );
            let t = m.covariates.temperature_c.unwrap();
            assert_eq!(t, n("measurement_temperature"), "{file}");
            assert_eq!(sigma.is_some(), has_sigma, "{file}");
            if let Some(s) = sigma {
                for (k, axis) in ["x", "y", "z"].iter().enumerate() {
                    assert!((s[k] - n(&format!("measurement_std_{axis}"))).abs() < 1e-15);
                }
                // σ of the rotation rows: E = [x̂, Rx(a)ŷ, Rx(a)Ry(b)ẑ] by hand,
                // diag(E diag(σ²) Eᵀ)^½.
                let (sa, ca) = a.to_radians().sin_cos();
                let (sb, cb) = b.to_radians().sin_cos();
                let e = Matrix3::new(1.0, 0.0, sb, 0.0, ca, -sa * cb, 0.0, sa, ca * cb);
                let sr = ["rx", "ry", "rz"]
                    .map(|k| n(&format!("measurement_std_{k}")).to_radians().powi(2));
                for k in 0..3 {
                    let var: f64 = (0..3).map(|l| e[(k, l)].powi(2) * sr[l]).sum();
                    assert!((s[3 + k] - var.sqrt()).abs() < 1e-15, "{file} σ row {k}");
                }
            }
        }
    }
}

#[test]
fn the_measured_angles_are_intrinsic_xyz() {
    // The plan's fixture, Series B line 2: (rx, ry, rz) = (−90.179302, −20.118749, −90.169308)°,
    // first row of R = Rx·Ry·Rz computed independently.
    let cell = cell();
    let (data, _) =
        csv::read_with(&data_file(SERIES[1].0), &cell.model, &cell.data_format()).unwrap();
    let r = pose_of(&data, 0).0.rot;
    let want = [-0.00277467, 0.938977646, -0.343966978];
    for (k, w) in want.iter().enumerate() {
        assert!((r[(0, k)] - w).abs() < 1e-8, "{k}: {}", r[(0, k)]);
    }
    // And the angles come back from the matrix.
    let back = Orientation::XyzIntrinsic.from_rot(&r);
    let given = [-90.179302, -20.118749, -90.169308];
    for (b, g) in back.iter().zip(given) {
        assert!((b.to_degrees() - g).abs() < 1e-9);
    }
}

/// A format for the hand-eye files: position and orientation from the given columns.
fn handeye_format(
    position: [&str; 3],
    unit: ColumnUnit,
    orientation: OrientationColumns,
) -> DataFormat {
    DataFormat {
        delimiter: ';',
        decimal: armcal::measure::format::Decimal::Comma,
        joints: None,
        joint_unit: None,
        position: Some(Columns {
            columns: position.map(String::from),
            unit,
            optional: false,
        }),
        orientation: Some(orientation),
        sigma_position: None,
        sigma_orientation: None,
        temperature: None,
        controller: None,
        controller_columns: None,
    }
}

/// RMS over consecutive pairs of |angle(A_iᵀ A_j) − angle(B_iᵀ B_j)| (deg).
fn relative_angle_rms(a: &[Matrix3<f64>], b: &[Matrix3<f64>]) -> f64 {
    let angle = |r: &[Matrix3<f64>], i: usize, j: usize| {
        rotation_log(&(r[i].transpose() * r[j])).norm().to_degrees()
    };
    let n = a.len();
    let sum: f64 = (0..n)
        .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
        .map(|(i, j)| (angle(a, i, j) - angle(b, i, j)).powi(2))
        .sum();
    (sum / (n * (n - 1) / 2) as f64).sqrt()
}

#[test]
fn hand_eye_quaternions_scalar_last_agree_with_the_intrinsic_angles() {
    // The hand-eye files have no joint columns and the reader wants one per model joint:
    // six numeric columns stand in for them (their values are not used here).
    let cell = cell();
    let joints: Vec<String> = [
        "flange_x",
        "flange_y",
        "flange_z",
        "flange_qx",
        "flange_qy",
        "flange_qz",
    ]
    .map(String::from)
    .to_vec();
    let measured = |o: Orientation| OrientationColumns {
        columns: ["measurement_rx", "measurement_ry", "measurement_rz"]
            .map(String::from)
            .to_vec(),
        unit: Some(ColumnUnit::Deg),
        convention: o,
    };
    let flange = |o: Orientation, cols: [&str; 4]| OrientationColumns {
        columns: cols.map(String::from).to_vec(),
        unit: None,
        convention: o,
    };
    let read = |file: &str, f: DataFormat| -> Vec<Matrix3<f64>> {
        let f = DataFormat {
            joints: Some(joints.clone()),
            joint_unit: Some(ColumnUnit::Rad),
            ..f
        };
        let (data, _) = csv::read_with(&data_file(file), &cell.model, &f).unwrap();
        (0..data.measurements.len())
            .map(|i| pose_of(&data, i).0.rot)
            .collect()
    };
    let m_pos = ["measurement_x", "measurement_y", "measurement_z"];
    let f_pos = ["flange_x", "flange_y", "flange_z"];
    let xyzw = ["flange_qx", "flange_qy", "flange_qz", "flange_qw"];
    for (file, rows) in [
        ("Series_B/calibration_handeye.csv", 25),
        ("Series_D/calibration_handeye.csv", 26),
    ] {
        let meas = read(
            file,
            handeye_format(m_pos, ColumnUnit::Mm, measured(Orientation::XyzIntrinsic)),
        );
        let as_rpy = read(
            file,
            handeye_format(m_pos, ColumnUnit::Mm, measured(Orientation::Rpy)),
        );
        let fl = read(
            file,
            handeye_format(f_pos, ColumnUnit::M, flange(Orientation::QuatXyzw, xyzw)),
        );
        assert_eq!((meas.len(), fl.len()), (rows, rows), "{file}");
        let good = relative_angle_rms(&meas, &fl);
        let bad = relative_angle_rms(&as_rpy, &fl);
        println!("{file}: relative-angle RMS {good:.3}° (xyz-intrinsic), {bad:.3}° (rpy)");
        assert!(good < 0.1, "{file}: {good}");
        assert!(bad > 1.0, "{file}: {bad}");
    }
}

/// `Trafo_TM_F_init.txt`: 4 rows of 4 space-separated numbers (mm).
fn trafo(file: &str) -> Pose<f64> {
    let text = std::fs::read_to_string(data_file(file)).unwrap();
    let m: Vec<Vec<f64>> = text
        .lines()
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(m.len(), 4, "{file}");
    Pose {
        rot: Matrix3::from_fn(|i, j| m[i][j]),
        trans: Vector3::new(m[0][3], m[1][3], m[2][3]),
    }
}

#[test]
fn the_commanded_pose_is_the_nominal_ur10_with_the_planned_tcp() {
    // Goal (m, rpy in rad, ROS base_link) = Rz(180°) · FK(q) · inv(Trafo_TM_F_init), read
    // through the same mapping with the Goal columns as the "measurement".
    let cell = cell();
    let ur10 = Cell::load("ur10").unwrap();
    let params = ur10.model.nominal();
    let base_link = Pose {
        rot: Orientation::Rpy.to_rot(&[0.0, 0.0, std::f64::consts::PI]),
        trans: Vector3::zeros(),
    };
    for (series, (file, rows, _)) in ["A", "B", "D"].iter().zip(SERIES) {
        let format = DataFormat {
            position: Some(Columns {
                columns: ["Goal x", "Goal y", "Goal z"].map(String::from),
                unit: ColumnUnit::M,
                optional: false,
            }),
            orientation: Some(OrientationColumns {
                columns: ["Goal roll", "Goal pitch", "Goal yaw"]
                    .map(String::from)
                    .to_vec(),
                unit: Some(ColumnUnit::Rad),
                convention: Orientation::Rpy,
            }),
            sigma_position: None,
            sigma_orientation: None,
            ..cell.data_format()
        };
        let (data, _) = csv::read_with(&data_file(file), &cell.model, &format).unwrap();
        assert_eq!(data.measurements.len(), rows);
        let tcp = trafo(&format!("Series_{series}/Trafo_TM_F_init.txt")).inverse();
        let (mut max_mm, mut max_deg) = (0.0f64, 0.0f64);
        for (i, m) in data.measurements.iter().enumerate() {
            let q = &data.configurations[m.config];
            let planned = base_link
                .compose(&tool_pose(&ur10.model, &params, q))
                .compose(&tcp);
            let goal = pose_of(&data, i).0;
            max_mm = max_mm.max((planned.trans - goal.trans).norm());
            max_deg = max_deg.max(planned.rotation_angle_to(&goal).to_degrees());
        }
        println!(
            "Series {series}: Goal vs Rz(180°)·FK·inv(Trafo): max {max_mm:.3} mm, {max_deg:.3}°"
        );
        assert!(
            max_mm < 1.0 && max_deg < 0.2,
            "Series {series}: {max_mm} mm, {max_deg}°"
        );
    }
}

#[test]
fn an_exported_cell_keeps_the_data_mapping() {
    let cell = cell();
    let text = armcal::cell::to_cell_toml(&cell, &cell.model, &cell.model.spec()).unwrap();
    let back = Cell::from_toml(&text, "export.toml", Path::new(".")).unwrap();
    assert_eq!(back.data_format(), cell.data_format());
}
