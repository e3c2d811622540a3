//! The paths a fuzzed input flows through, one function per target (issue 15).
//!
//! Each function reads its input as armcal's CLI would and then drives the value read through
//! what the CLI does with it. An `Err` is a correct answer to a bad input; a panic, a hang or an
//! unbounded allocation is a finding. The round trips (`export` → read, `write` → read) assert
//! armcal's own promise that every file it writes, it can read (issue 12).

use armcal::design::plan_from_pool;
use armcal::measure::csv;
use armcal::model::{random_configurations, tool_pose};
use armcal::report::{page, Document, Input, ReportContent};
use armcal::{
    analyze_model, evaluate_design, export_model, unmeasurable_poses, Cell, ExportFormat,
    IdentifiabilitySettings, IdentifySettings, LinkForm, Model, PoolSettings, Silent,
};
use std::path::Path;
use std::sync::OnceLock;

/// Few configurations and iterations: a fuzz execution must stay in milliseconds.
const POSES: usize = 8;

/// The folder a fuzzed cell is read in: empty, so relative file names in it resolve to nothing.
fn empty_dir() -> &'static Path {
    static DIR: OnceLock<std::path::PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let d = std::env::temp_dir().join(format!("armcal-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(&d).expect("a temporary folder");
        d
    })
}

/// Cell TOML → cell → model analysis (identifiability, rank deficit) in one of the
/// conventions, constraints and prediction at random poses, and one export read back as a
/// cell. The input's length chooses the convention and the export (one of each keeps an
/// execution fast; the fuzzer's mutations change the length, so every pair is reached).
pub fn cell(text: &str) {
    let Ok(cell) = Cell::from_toml(text, "fuzz.toml", empty_dir()) else {
        return;
    };
    let settings = IdentifiabilitySettings {
        poses: POSES,
        ..cell.identifiability_settings()
    };
    let forms = [
        None,
        Some(LinkForm::Dh),
        Some(LinkForm::Mdh),
        Some(LinkForm::Zrp),
    ];
    let _ = analyze_model(&cell, &settings, forms[text.len() % forms.len()]);
    let design = random_configurations(&cell.model, POSES, 1);
    let _ = evaluate_design(&cell, &design, true, Some(50.0));
    let formats = ["dh", "mdh", "zrp", "cell", "json", "urdf"];
    let format = ExportFormat::from_name(formats[text.len() / 4 % formats.len()]).expect("known");
    let Ok(exported) = export_model(&cell.model.spec(), Some(&cell), format) else {
        return;
    };
    if let ExportFormat::Cell(_) = format {
        if let Err(e) = Cell::from_toml(&exported.content, "exported.toml", empty_dir()) {
            panic!(
                "armcal cannot read the cell it exported: {e}\n{}",
                exported.content
            );
        }
    }
}

/// The built-in cells a fuzzed data file is read for: the paper cell (armcal's own columns)
/// and the UR10 cell (a vendor's `;`-separated, decimal-comma file through a `[data]` mapping).
fn data_cells() -> &'static [Cell; 3] {
    static CELLS: OnceLock<[Cell; 3]> = OnceLock::new();
    CELLS.get_or_init(|| {
        let read = |text: &str, name: &str| {
            Cell::from_toml(text, name, Path::new(".")).expect("a built-in example cell")
        };
        [
            read(armcal::cell::builtin::PAPER_CELL, "paper-cell.toml"),
            read(
                include_str!("../../examples/ur10-leica-cell.toml"),
                "ur10-leica-cell.toml",
            ),
            read(
                include_str!("../../examples/paper-payload-cell.toml"),
                "paper-payload-cell.toml",
            ),
        ]
    })
}

/// A CSV file through one of armcal's CSV readers; the first byte chooses the cell (bit 0:
/// paper or UR10; bit 3 set: the paper cell with compliance and payloads, for the `payload`
/// column) and the reader (bits 1–2): a data file (0), a pose list or pose pool (1), a
/// program of Cartesian targets (2).
pub fn data_csv(bytes: &[u8]) {
    let Some((&choice, rest)) = bytes.split_first() else {
        return;
    };
    let Ok(text) = std::str::from_utf8(rest) else {
        return;
    };
    let cell = &data_cells()[if choice & 8 != 0 {
        2
    } else {
        usize::from(choice & 1)
    }];
    match (choice >> 1) & 3 {
        1 => configurations(cell, text),
        2 => {
            let _ = csv::read_targets_str(text, "fuzz.csv", &cell.model, Some(&cell.controller));
        }
        _ => measurements(cell, text),
    }
}

/// Data CSV → dataset → a short identification, and the dataset written in armcal's format
/// read back with the same rows.
fn measurements(cell: &Cell, text: &str) {
    let Ok((data, _)) = csv::read_format_str(text, "fuzz.csv", &cell.model, &cell.data_format())
    else {
        return;
    };
    let mut settings = IdentifySettings {
        holdout: 0.0,
        ..IdentifySettings::default()
    };
    settings.lm.tolerances.max_iterations = 3;
    let _ = armcal::identify(cell, &data, &settings, &mut Silent);
    let Ok(written) = csv::write_string(&data, &cell.model) else {
        return;
    };
    let joints: Vec<String> = cell.model.joints.iter().map(csv::joint_column).collect();
    match csv::read_str(&written, "written.csv", &cell.model, Some(&joints)) {
        Ok((again, _)) => assert_eq!(
            again.measurements.len(),
            data.measurements.len(),
            "a written data file reads back with another number of rows"
        ),
        Err(e) => panic!("armcal cannot read the data file it wrote: {e}\n{written}"),
    }
}

/// Pose list CSV → configurations → the measurability check of `simulate` and a plan from
/// them as a pose pool (`plan --pool`, the fewest poses, no collision model).
fn configurations(cell: &Cell, text: &str) {
    let Ok(poses) =
        csv::read_configurations_format_str(text, "fuzz.csv", &cell.model, &cell.data_format())
    else {
        return;
    };
    let _ = unmeasurable_poses(cell, &poses);
    let settings = PoolSettings {
        poses: 1,
        collisions: false,
        ..PoolSettings::default()
    };
    let _ = plan_from_pool(cell, &poses, "fuzz.csv", &settings, &[], &mut Silent);
}

/// URDF → model → forward kinematics → URDF → model: the same tool pose.
pub fn urdf(text: &str) {
    let Ok((spec, shapes)) = armcal::model::urdf::from_urdf_str_with_collisions(text, None) else {
        return;
    };
    // Every collision shape read is bounded by a capsule of finite ends and radius ≥ 0.
    for shape in &shapes {
        if let Some(c) = armcal::robots::bounding::bounding_capsule(shape) {
            assert!(
                c.radius >= 0.0
                    && c.radius.is_finite()
                    && c.a.iter().chain(&c.b).all(|v| v.is_finite()),
                "a collision shape of link `{}` was bounded by {c:?}",
                shape.link
            );
        }
    }
    let Ok(model) = Model::from_spec(&spec) else {
        return;
    };
    let qs = random_configurations(&model, 3, 1);
    let poses: Vec<_> = qs
        .iter()
        .map(|q| tool_pose(&model, &model.nominal(), q))
        .collect();
    let Ok(xml) = armcal::model::urdf::to_urdf(&spec) else {
        return;
    };
    let again = armcal::model::urdf::from_urdf_str(&xml, None)
        .and_then(|s| Model::from_spec(&s))
        .unwrap_or_else(|e| panic!("armcal cannot read the URDF it wrote: {e}\n{xml}"));
    for (q, before) in qs.iter().zip(&poses) {
        let after = tool_pose(&again, &again.nominal(), q);
        let scale = 1.0 + before.trans.norm();
        assert!(
            (after.trans - before.trans).norm() <= 1e-6 * scale || !before.trans.norm().is_finite(),
            "the URDF round trip moved the tool: {:?} → {:?}",
            before.trans,
            after.trans
        );
    }
}

/// The tool poses of `spec` at three seeded configurations, and those of `again`: the same
/// to 1e-6 of their size (a file armcal wrote, read back).
fn same_tool_poses(spec: &armcal::model::ModelSpec, again: &armcal::model::ModelSpec, file: &str) {
    let (Ok(model), Ok(back)) = (Model::from_spec(spec), Model::from_spec(again)) else {
        panic!("armcal cannot build the model of the file it wrote:\n{file}");
    };
    for q in random_configurations(&model, 3, 1) {
        let (a, b) = (
            tool_pose(&model, &model.nominal(), &q),
            tool_pose(&back, &back.nominal(), &q),
        );
        let scale = 1.0 + a.trans.norm();
        assert!(
            (a.trans - b.trans).norm() <= 1e-6 * scale || !a.trans.norm().is_finite(),
            "reading back moved the tool: {:?} → {:?}\n{file}",
            a.trans,
            b.trans
        );
    }
}

/// UR kinematics YAML → model → UR kinematics file → model: the same tool pose.
pub fn ur_kinematics(text: &str) {
    use armcal::model::ur_kinematics::{from_ur_kinematics_str, to_ur_kinematics};
    let Ok(spec) = from_ur_kinematics_str(text) else {
        return;
    };
    if Model::from_spec(&spec).is_err() {
        return;
    }
    let Ok(file) = to_ur_kinematics(&spec, "fuzz") else {
        return;
    };
    let again = from_ur_kinematics_str(&file.text).unwrap_or_else(|e| {
        panic!(
            "armcal cannot read the UR file it wrote: {e}\n{}",
            file.text
        )
    });
    same_tool_poses(&spec, &again, &file.text);
}

/// ROS 2 joint corrections applied to the built-in UR10 → model → corrections against the
/// UR10's URDF chain → applied again: the same tool pose.
pub fn joint_corrections(text: &str) {
    use armcal::model::urdf::joint_corrections::{apply_joint_corrections, to_joint_corrections};
    let nominal = armcal::robots::robot("ur10").expect("built in").spec;
    let Ok(spec) = apply_joint_corrections(text, &nominal) else {
        return;
    };
    if Model::from_spec(&spec).is_err() {
        return;
    }
    // The corrected chain is a URDF chain; its nominal is the UR10's URDF chain.
    let Ok(chain) = armcal::model::urdf::to_urdf(&nominal)
        .and_then(|x| armcal::model::urdf::from_urdf_str(&x, None))
    else {
        return;
    };
    let Ok(file) = to_joint_corrections(&spec, &chain, "fuzz") else {
        return;
    };
    let again = apply_joint_corrections(&file.text, &chain).unwrap_or_else(|e| {
        panic!(
            "armcal cannot read the corrections it wrote: {e}\n{}",
            file.text
        )
    });
    same_tool_poses(&spec, &again, &file.text);
}

/// armcal JSON (estimate, design, study, demo summary, tree estimate) → the report page; an
/// estimate also through every export and a prediction, a design through its evaluation, a
/// tree estimate through its exports.
pub fn records(text: &str) {
    let Ok(document) = Document::from_json(text, "fuzz.json") else {
        return;
    };
    match &document {
        Document::Estimate(e) => {
            let _ = e.check_usable(&armcal::Acceptance {
                accepted: false,
                accept: "accept",
                raise_iterations: "raise",
            });
            for format in ["dh", "mdh", "zrp", "cell", "json", "urdf"] {
                let format = ExportFormat::from_name(format).expect("a known format");
                let _ = export_model(&e.model, None, format);
            }
            if let Ok(model) = Model::from_spec(&e.model) {
                if let Ok(params) = e.params_for(&model) {
                    let poses: Vec<(String, Vec<f64>)> = random_configurations(&model, 3, 1)
                        .into_iter()
                        .enumerate()
                        .map(|(i, q)| (format!("p{i}"), q))
                        .collect();
                    let _ = e.outside_fitted_ranges(&model, &poses);
                    for payload in std::iter::once(None).chain((0..model.payloads.len()).map(Some))
                    {
                        for measured in [armcal::Measurement::Position, armcal::Measurement::Pose] {
                            let _ = armcal::predict(&model, &params, &poses, payload, measured);
                        }
                    }
                }
            }
            drift_check(e);
        }
        Document::Design(d) => {
            let cell = &data_cells()[0];
            if let Ok(design) = d.design_for(&cell.model) {
                let _ = evaluate_design(cell, &design, true, Some(50.0));
            }
        }
        Document::Campaign(state) => {
            // a campaign after a drift check: its prior applied to the paper cell
            if let Some(prior) = &state.settings.prior {
                let _ = prior.apply(&data_cells()[0]);
            }
        }
        Document::TreeEstimate(e) => {
            // a tree's estimate through its two exports (the other formats are refused)
            let acceptance = armcal::Acceptance {
                accepted: true,
                accept: "accept",
                raise_iterations: "raise",
            };
            for format in ["urdf", "cell"] {
                let format = ExportFormat::from_name(format).expect("a known format");
                let _ = armcal::export_tree_estimate(e, None, format, &acceptance);
            }
        }
        Document::Study(_) | Document::Demo(_) | Document::Truth(_) | Document::Check(_) => {}
    }
    let inputs = [Input {
        label: "fuzz".into(),
        source: "fuzz.json".into(),
        document,
    }];
    if let Ok(p) = page(&ReportContent {
        title: "fuzz",
        inputs: &inputs,
        ..ReportContent::default()
    }) {
        let _ = p.render();
    }
}

/// An estimate of the paper cell → a drift check on three simulated poses of its robot, and
/// the prior of a campaign after it (the first group released).
fn drift_check(e: &armcal::Estimate) {
    let cell = &data_cells()[0];
    let Ok(params) = e.params_for(&cell.model) else {
        return;
    };
    let qs = random_configurations(&cell.model, 3, 2);
    let Ok(data) = armcal::simulate(&cell.model, &params, &qs, None, 0) else {
        return;
    };
    let settings = armcal::CheckSettings::default();
    if let Ok(c) = armcal::check(cell, e, &data, &settings) {
        let released = c.moved_groups().into_iter().take(1).collect::<Vec<_>>();
        if let Ok(p) = armcal::CampaignPrior::from_estimate(cell, e, "fuzz.json", &released) {
            let _ = p.apply(cell);
        }
    }
}

/// The built-in cells a fuzzed controller program is filtered for: the robot each language's
/// samples are written for (KUKA KR 15 for KRL, ABB IRB 120 for RAPID, UR10 for UR script),
/// with a calibration that differs from the nominal model so every target is solved.
fn program_cell(language: armcal::ProgramLanguage) -> &'static (Cell, Vec<f64>) {
    use armcal::ProgramLanguage as Language;
    static CELLS: OnceLock<[(Cell, Vec<f64>); 3]> = OnceLock::new();
    let cells = CELLS.get_or_init(|| {
        ["kr15", "irb120", "ur10"].map(|name| {
            let cell = Cell::load(name).expect("a built-in robot");
            let calibrated = cell
                .model
                .registry
                .iter()
                .enumerate()
                .map(|(i, p)| p.nominal + 1e-3 * ((i + 1) as f64).sin())
                .collect();
            (cell, calibrated)
        })
    });
    &cells[match language {
        Language::Krl => 0,
        Language::Rapid => 1,
        Language::UrScript => 2,
    }]
}

/// A controller program through `armcal compensate --program`: read, every target
/// compensated (as joints with `to_joints` on odd lengths), written back; the output is read
/// again and must have as many motion targets as the input.
pub fn controller_program(text: &str, language: armcal::ProgramLanguage) {
    use armcal::ProgramSettings;
    let (cell, calibrated) = program_cell(language);
    let settings = ProgramSettings {
        language,
        to_joints: text.len() % 2 == 1,
        ik: armcal::IkSettings::default(),
    };
    let run = |t: &str| {
        armcal::filter_controller_program(
            &cell.model,
            calibrated,
            &cell.controller,
            t,
            "fuzz",
            &settings,
        )
    };
    let Ok(first) = run(text) else {
        return;
    };
    match run(&first.text) {
        Ok(second) => assert_eq!(
            first.targets.len(),
            second.targets.len(),
            "the filtered program has another number of targets:\n{}",
            first.text
        ),
        Err(e) => panic!(
            "armcal cannot read the program it wrote: {e}\n{}",
            first.text
        ),
    }
}
