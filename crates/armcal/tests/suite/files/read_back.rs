//! Every CSV armcal writes reads back in the reader that consumes it (issue 12, item 1): a
//! property test over random names (pose ids, joints, targets, robots) with commas, quotes,
//! `#` and semicolons, and over random IK statuses (`singular: residual …, …` has a comma).
//! The data file goes back through the data reader, the design through the configuration
//! reader, the compensated program through the program reader (and the compensator again),
//! the study table and the parameter table through a plain CSV reader.

use crate::common::{every_convention_model, measure, random_q, rng};
use armcal::measure::format::DataFormat;
use armcal::measure::{csv, Covariates, Measurement, MeasurementKind};
use armcal::model::{export, Observed};
use armcal::{
    compensate_program, perturbed_truth, Cell, Dataset, IkSettings, Model, PaperStudyRecord,
    PaperStudyRow, Perturbation, ProgramFile, Table,
};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use std::path::Path;

const CASES: u64 = 24;

/// A random name of 1–12 characters, many of them ones CSV must quote; never blank at either
/// end (armcal's readers trim fields).
fn name(r: &mut ChaCha8Rng) -> String {
    const CHARS: &[char] = &['a', 'Z', '7', ',', '"', '#', ' ', ';', '\'', 'é', '_', '-'];
    let n = r.random_range(1..=12);
    let s: String = (0..n)
        .map(|_| CHARS[r.random_range(0..CHARS.len())])
        .collect();
    format!("n{}x", s.trim())
}

/// `model` with every joint and target renamed at random (unique by their index).
fn renamed(model: &Model, r: &mut ChaCha8Rng) -> Model {
    let mut spec = model.spec();
    for (i, l) in spec.links.iter_mut().enumerate() {
        if let Some(j) = &mut l.joint {
            j.name = format!("{}{i}", name(r));
        }
    }
    for (i, t) in spec.targets.iter_mut().enumerate() {
        t.name = format!("{}{i}", name(r));
    }
    Model::from_spec(&spec).unwrap()
}

fn records(text: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let mut rdr = ::csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .from_reader(text.as_bytes());
    let header = rdr.headers().unwrap().iter().map(String::from).collect();
    let rows = rdr
        .records()
        .map(|r| r.unwrap().iter().map(String::from).collect())
        .collect();
    (header, rows)
}

fn close(a: &[f64], b: &[f64], tol: f64, what: &str) {
    assert_eq!(a.len(), b.len(), "{what}");
    for (x, y) in a.iter().zip(b) {
        assert!((x - y).abs() <= tol, "{what}: {a:?} vs {b:?}");
    }
}

#[test]
fn data_files_read_back_in_the_data_reader() {
    for case in 0..CASES {
        let r = &mut rng(100 + case);
        let model = renamed(&every_convention_model(case), r);
        let params = model.nominal();
        let mut data = Dataset {
            configurations: Vec::new(),
            config_ids: Vec::new(),
            measurements: Vec::new(),
            source: "random".into(),
            ..Default::default()
        };
        for i in 0..r.random_range(1..6) {
            let q = random_q(&model, r);
            let config = data.push_configuration(format!("{}{i}", name(r)), q.clone());
            for k in 0..model.targets.len() {
                let obs = Observed::Target(k);
                let value = measure(&model, &params, &q, obs).trans;
                let sigma = r
                    .random_bool(0.5)
                    .then_some(nalgebra::Vector3::new(0.1, 0.2, 0.3));
                data.measurements.push(Measurement {
                    config,
                    observed: obs,
                    kind: MeasurementKind::Position { value, sigma },
                    line: 0,
                    covariates: Covariates {
                        temperature_c: r.random_bool(0.5).then_some(20.5),
                    },
                });
            }
        }
        let text = csv::write_string(&data, &model).unwrap();
        let (back, _) = csv::read_str(&text, "data.csv", &model, None).unwrap();
        assert_eq!(back.config_ids, data.config_ids, "{text}");
        for (a, b) in back.configurations.iter().zip(&data.configurations) {
            close(a, b, 1e-8, "joints");
        }
        assert_eq!(back.measurements.len(), data.measurements.len());
        for (a, b) in back.measurements.iter().zip(&data.measurements) {
            assert_eq!(a.observed, b.observed);
            assert_eq!(a.covariates, b.covariates);
            match (&a.kind, &b.kind) {
                (
                    MeasurementKind::Position {
                        value: va,
                        sigma: sa,
                    },
                    MeasurementKind::Position {
                        value: vb,
                        sigma: sb,
                    },
                ) => {
                    close(va.as_slice(), vb.as_slice(), 1e-8, "position");
                    assert_eq!(sa.is_some(), sb.is_some(), "{text}");
                }
                other => panic!("{other:?}"),
            }
        }
    }
}

#[test]
fn designs_read_back_in_the_configuration_reader() {
    for case in 0..CASES {
        let r = &mut rng(200 + case);
        let model = renamed(&every_convention_model(case), r);
        let qs: Vec<Vec<f64>> = (0..r.random_range(1..8))
            .map(|_| random_q(&model, r))
            .collect();
        let text = csv::write_configurations(&model, &qs);
        let back = csv::read_configurations_str(&text, "design.csv", &model, None).unwrap();
        assert_eq!(back.len(), qs.len());
        for (i, ((id, q), want)) in back.iter().zip(&qs).enumerate() {
            assert_eq!(id, &(i + 1).to_string());
            close(q, want, 1e-6, "design joints");
        }
    }
}

fn paper_cell() -> Cell {
    Cell::from_file(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper-cell.toml"))
        .unwrap()
}

#[test]
fn compensated_programs_read_back_in_the_program_reader() {
    let cell = paper_cell();
    let mut statuses_with_commas = 0;
    for case in 0..CASES {
        let r = &mut rng(300 + case);
        let model = renamed(&cell.model, r);
        let calibrated = perturbed_truth(&model, &Perturbation::default(), case);
        let cartesian = case % 2 == 0;
        // A program with random ids: joint rows beyond the limits (joint-limits statuses),
        // Cartesian targets out of reach (`singular: residual …, …` and the like).
        let mut header = vec!["pose_id".to_string()];
        header.extend(model.joints.iter().map(csv::joint_column));
        if cartesian {
            header.extend(
                ["x_mm", "y_mm", "z_mm", "roll_deg", "pitch_deg", "yaw_deg"].map(String::from),
            );
        }
        let mut program = Table::new(&header);
        let n = r.random_range(2..7);
        for i in 0..n {
            let mut row = vec![format!("{}{i}", name(r))];
            let reach = r.random_range(-1500.0..3000.0);
            row.extend(
                (0..model.joints.len()).map(|_| format!("{:.3}", r.random_range(-120.0..120.0))),
            );
            if cartesian {
                row.extend([reach, 200.0, 900.0, 180.0, 0.0, 90.0].map(|x: f64| x.to_string()));
            }
            program.row(row);
        }
        let text = program.into_string();
        let file = ProgramFile::read(text, "program.csv", &model, &DataFormat::armcal()).unwrap();
        assert_eq!(file.cartesian, cartesian);
        let ids: Vec<String> = file.rows.iter().map(|(id, _)| id.clone()).collect();
        let out =
            compensate_program(&model, &calibrated, &file, &IkSettings::default(), None).unwrap();

        // The plain CSV view: every row as wide as the header, statuses whole.
        let (h, rows) = records(&out.csv);
        assert_eq!(rows.len(), n);
        let status = h.iter().position(|c| c == "status").unwrap();
        let mut failed = 0;
        for row in &rows {
            assert_eq!(row.len(), h.len(), "{}", out.csv);
            let s = &row[status];
            assert!(
                s == "converged"
                    || [
                        "joint-limits: ",
                        "singular: ",
                        "unreachable: ",
                        "max-iterations: ",
                        "joint-change-limit: "
                    ]
                    .iter()
                    .any(|p| s.starts_with(p))
                    || s.contains(": residual "),
                "{s}"
            );
            failed += usize::from(s != "converged");
            statuses_with_commas += usize::from(s.contains(','));
        }
        assert_eq!(failed, out.not_converged);

        // The consumer: the compensated program is a program again, of the same kind.
        let again = ProgramFile::read(
            out.csv.clone(),
            "compensated.csv",
            &model,
            &DataFormat::armcal(),
        )
        .unwrap();
        assert_eq!(again.cartesian, cartesian, "{}", out.csv);
        let back: Vec<String> = again.rows.iter().map(|(id, _)| id.clone()).collect();
        assert_eq!(back, ids);
        for ((_, q), row) in again.rows.iter().zip(&rows) {
            let shown: Vec<f64> = q.iter().map(|v| v.to_degrees()).collect();
            let written: Vec<f64> = row[1..=q.len()]
                .iter()
                .map(|f| f.parse().unwrap())
                .collect();
            close(&shown, &written, 1e-6, "compensated joints");
        }
        compensate_program(&model, &calibrated, &again, &IkSettings::default(), None).unwrap();
    }
    assert!(
        statuses_with_commas > 0,
        "no status with a comma was exercised"
    );
}

#[test]
fn study_and_parameter_tables_keep_their_columns() {
    for case in 0..CASES {
        let r = &mut rng(400 + case);
        let rows: Vec<PaperStudyRow> = (0..r.random_range(1..5))
            .map(|_| PaperStudyRow {
                robot: name(r),
                collisions: r.random_bool(0.5),
                heuristic: r.random_range(0.0..10.0),
                cp_optimal: r.random_range(0.0..10.0),
                cs_optimal: r.random_range(0.0..10.0),
                gain_vs_heuristic: r.random_range(0.0..1.0),
                gain_vs_cp: r.random_range(0.0..1.0),
                feasible: r.random_bool(0.5),
                seconds: 1.0,
                error: None,
            })
            .collect();
        let record = PaperStudyRecord {
            study: "paper".into(),
            collisions: true,
            seconds: 1.0,
            rows: rows.clone(),
        };
        let (h, back) = records(&record.to_csv());
        assert_eq!(back.len(), rows.len());
        for (b, row) in back.iter().zip(&rows) {
            assert_eq!(b.len(), h.len());
            assert_eq!(b[0], row.robot);
        }

        let model = renamed(&every_convention_model(case), r);
        let (h, back) = records(&export::to_table_csv(&model.spec()));
        let joint = h.iter().position(|c| c == "joint").unwrap();
        let names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
        for b in &back {
            assert_eq!(b.len(), h.len());
            assert!(
                b[joint].is_empty() || names.contains(&b[joint].as_str()),
                "{b:?}"
            );
        }
    }
}
