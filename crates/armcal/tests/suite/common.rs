//! Helpers shared by the integration tests.
#![allow(dead_code)]

use armcal::model::*;
use armcal::{Cell, Joint, JointKind, Model, ParameterStatus, Unit};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;

pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// Random values for a convention's fields: lengths in ±400 mm, angles in ±π, ZRP axes
/// random non-unit vectors.
pub fn random_geometry(c: Convention, kind: Option<JointKind>, r: &mut ChaCha8Rng) -> LinkGeometry {
    let fields = c.fields(kind);
    let values = fields
        .iter()
        .map(|(_, u)| match u {
            Unit::Mm => r.random_range(-400.0..400.0),
            Unit::Rad => r.random_range(-3.0..3.0),
            Unit::Unitless => r.random_range(-1.5..1.5),
            Unit::RadPerMm | Unit::RadPerNmm => r.random_range(0.0..1e-6),
            Unit::Arcsec => r.random_range(-1e-3..1e-3),
        })
        .collect();
    let mut g = LinkGeometry::new(c, values);
    if c == Convention::Urdf {
        g.axis = Some([
            r.random_range(-1.0..1.0),
            r.random_range(-1.0..1.0),
            r.random_range(0.2..1.0),
        ]);
    }
    g
}

pub fn joint(name: &str, kind: JointKind) -> Joint {
    let (lower, upper) = match kind {
        JointKind::Revolute => (-3.2, 3.2),
        JointKind::Prismatic => (-500.0, 500.0),
    };
    Joint {
        name: name.into(),
        kind,
        lower,
        upper,
    }
}

/// A chain that uses every joint convention once with a revolute and once with a prismatic
/// joint, plus instrument, base, tool, a point target and a frame target.
pub fn every_convention_model(seed: u64) -> Model {
    let mut r = rng(seed);
    let mut links = vec![LinkSpec {
        name: "base".into(),
        geometry: random_geometry(Convention::Frame6, None, &mut r),
        joint: None,
    }];
    let mut n = 0;
    for c in [
        Convention::Dh,
        Convention::Hayati,
        Convention::Mdh,
        Convention::SModel,
        Convention::BookType3,
        Convention::Urdf,
        Convention::Zrp,
    ] {
        for kind in [JointKind::Revolute, JointKind::Prismatic] {
            n += 1;
            links.push(LinkSpec {
                name: format!("j{n}"),
                geometry: random_geometry(c, Some(kind), &mut r),
                joint: Some(joint(&format!("q{n}"), kind)),
            });
        }
    }
    links.push(LinkSpec {
        name: "tool".into(),
        geometry: random_geometry(Convention::Frame6, None, &mut r),
        joint: None,
    });
    let spec = ModelSpec {
        compliance: None,
        periodic: None,
        payloads: Vec::new(),
        name: "every-convention".into(),
        instrument: Some(LinkSpec {
            name: "tracker".into(),
            geometry: random_geometry(Convention::Frame6, None, &mut r),
            joint: None,
        }),
        links,
        targets: vec![
            LinkSpec {
                name: "smr1".into(),
                geometry: random_geometry(Convention::Point, None, &mut r),
                joint: None,
            },
            LinkSpec {
                name: "tcp".into(),
                geometry: random_geometry(Convention::BookType3, None, &mut r),
                joint: None,
            },
        ],
    };
    Model::from_spec(&spec).expect("valid model")
}

/// [`every_convention_model`] with joint compliance: lumped terms on revolute joints of
/// several conventions (DH, MDH, book type 3, ZRP), point masses at later joints' axis points
/// (revolute and prismatic), a random gravity direction and κ large enough (10⁻⁴ rad/mm,
/// deflections of a tenth of a radian) that the chain rule through `q + Δq` matters.
pub fn compliant_model(seed: u64) -> Model {
    let mut r = rng(1000 + seed);
    let mut spec = every_convention_model(seed).spec();
    let term = |joint: &str, at: &str, value: f64| armcal::model::compliance::ComplianceTerm {
        joint: joint.into(),
        mass: format!("at_{at}"),
        at: Some(at.into()),
        value,
    };
    let mut k = || r.random_range(0.2e-5..1.5e-5);
    let terms = vec![
        term("q1", "q4", k()),
        term("q1", "q9", k()),
        term("q5", "q6", k()),
        term("q9", "q13", k()),
        term("q13", "q14", k()),
    ];
    let gravity = [r.random_range(-1.0..1.0), r.random_range(-1.0..1.0), -1.0];
    let levers = every_convention_model(seed).nominal();
    // levers slightly away from the evaluated geometry, as after an identification
    let levers = levers.iter().map(|x| x * 1.01).collect();
    spec.compliance = Some(armcal::model::compliance::ComplianceSpec {
        gravity,
        levers,
        terms,
        bending: Vec::new(),
    });
    Model::from_spec(&spec).expect("valid compliant model")
}

/// [`compliant_model`] with periodic joint errors as well: harmonics 1 and 3 on `q1`, 2 on
/// `q7` and `q13` (two of them compliant too), amplitudes of 0.01–0.05 rad so that the
/// chain rule through `q + Δq` matters.
pub fn corrected_model(seed: u64) -> Model {
    use armcal::model::periodic::{PeriodicSpec, PeriodicTerm, Phase};
    let mut r = rng(2000 + seed);
    let mut spec = compliant_model(seed).spec();
    let mut terms = Vec::new();
    for (joint, harmonic) in [("q1", 1), ("q1", 3), ("q7", 2), ("q13", 2)] {
        for phase in [Phase::Sin, Phase::Cos] {
            terms.push(PeriodicTerm {
                joint: joint.into(),
                harmonic,
                phase,
                value: r.random_range(0.01..0.05) * if r.random_bool(0.5) { 1.0 } else { -1.0 },
            });
        }
    }
    spec.periodic = Some(PeriodicSpec { terms });
    Model::from_spec(&spec).expect("valid model with periodic errors")
}

/// The test models of a seed: every convention rigid, compliant, and compliant with periodic
/// joint errors.
pub fn derivative_models(seed: u64) -> [Model; 3] {
    [
        every_convention_model(seed),
        compliant_model(seed),
        corrected_model(seed),
    ]
}

pub fn random_q(model: &Model, r: &mut ChaCha8Rng) -> Vec<f64> {
    model
        .joints
        .iter()
        .map(|j| r.random_range(j.lower..j.upper))
        .collect()
}

/// Observed position and rotation of `obs` in the instrument frame.
pub fn measure(model: &Model, params: &[f64], q: &[f64], obs: Observed) -> Pose<f64> {
    let mut d = Data::new(model);
    forward_kinematics(model, &mut d, params, q);
    observed_pose(&d, obs)
}

/// Central finite difference of the 6-D measurement (position, rotation vector) along
/// a perturbation applied by `perturb(±h)`.
pub fn fd_pose(mut eval: impl FnMut(f64) -> Pose<f64>, h: f64) -> [f64; 6] {
    let p = eval(h);
    let m = eval(-h);
    let c = eval(0.0);
    let dt = (p.trans - m.trans) / (2.0 * h);
    let dr = (p.rot - m.rot) / (2.0 * h) * c.rot.transpose();
    [
        dt[0],
        dt[1],
        dt[2],
        0.5 * (dr[(2, 1)] - dr[(1, 2)]),
        0.5 * (dr[(0, 2)] - dr[(2, 0)]),
        0.5 * (dr[(1, 0)] - dr[(0, 1)]),
    ]
}

/// |a − b| ≤ tol · max(1, |b|) element-wise, with a message naming the entry.
pub fn assert_close(a: f64, b: f64, tol: f64, what: &str) {
    let scale = b.abs().max(1.0);
    assert!(
        (a - b).abs() <= tol * scale,
        "{what}: analytic {a:.12e} vs reference {b:.12e} (rel. error {:.3e})",
        (a - b).abs() / scale
    );
}

/// The cell file `name` of the repository's `examples/` folder.
pub fn example_cell(name: &str) -> Cell {
    Cell::from_file(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples")
            .join(name),
    )
    .unwrap()
}

/// The built-in paper cell with the default `[design]` margins (its zero clearance and
/// margins deleted): poses planned for it stay measurable on a simulated robot whose
/// instrument is centimetres off, as a real campaign needs.
pub fn paper_cell_with_default_margins() -> Cell {
    let text: String = armcal::cell::builtin::PAPER_CELL
        .lines()
        .filter(|l| {
            ![
                "clearance_mm = 0",
                "joint_margin_deg = 0",
                "incidence_margin_deg = 0",
                "line_of_sight_margin_mm = 0",
            ]
            .contains(l)
        })
        .map(|l| format!("{l}\n"))
        .collect();
    let cell = Cell::from_toml(&text, "paper-cell.toml", Path::new(".")).unwrap();
    assert_eq!(cell.design, armcal::cell::DesignClearance::default());
    cell
}

/// The paper cell with its tracker "unplaced" (nominal pose: the robot base frame, 5.4 m
/// and ~135° from where it is), and the true parameters of the placed cell with its free
/// parameters perturbed (seed `seed`). With `frames_only` the free parameters are only the
/// tracker and the reflector (an explicit free list).
pub fn unplaced_tracker_paper_cell(frames_only: bool, seed: u64) -> (Cell, Vec<f64>) {
    let placed = example_cell("paper-cell.toml");
    let truth = armcal::perturbed_truth(&placed.model, &armcal::Perturbation::default(), seed);
    let text = armcal::cell::builtin::PAPER_CELL
        .replace("xyz_mm = [2730.88, 4554.68, 1397.67]", "xyz_mm = [0, 0, 0]")
        .replace("rpy_deg = [-95.63, -95.63, 0.23]", "rpy_deg = [0, 0, 0]");
    assert_ne!(
        text,
        armcal::cell::builtin::PAPER_CELL,
        "the tracker pose lines moved"
    );
    let mut cell = Cell::from_toml(&text, "paper-cell.toml", Path::new(".")).unwrap();
    for i in 0..cell.model.param_count() {
        if frames_only && !armcal::identify::is_frame_parameter(&placed.model, i) {
            cell.model.registry.set_status(i, ParameterStatus::Fixed);
        }
    }
    if frames_only {
        cell.auto_free = false;
        cell.declared_free = cell.model.registry.free();
    }
    (cell, truth)
}

/// Monte Carlo of the TCP covariance: `runs` calibrations (seeds `seed..seed + runs`) of
/// `truth` measured at `design` with the cell's instrument noise, each identified from the
/// nominal; returns the empirical covariance of the identified model's tool position
/// (mm²) at each of `configs`.
pub fn monte_carlo_tcp_covariances(
    cell: &Cell,
    truth: &[f64],
    design: &[Vec<f64>],
    configs: &[Vec<f64>],
    runs: u64,
    seed: u64,
) -> Vec<nalgebra::Matrix3<f64>> {
    let poses = monte_carlo_tcp_poses(cell, truth, design, configs, runs, seed);
    (0..configs.len())
        .map(|k| sample_covariance(poses.iter().map(|run| run[k].trans)))
        .collect()
}

/// `runs` calibrations (seeds `seed..seed + runs`) of `truth` measured at `design` as the
/// cell measures (its `measurement`: positions, or full poses) with its instrument noise,
/// each identified from the nominal; returns each run's identified tool pose (instrument
/// frame) at each of `configs`.
pub fn monte_carlo_tcp_poses(
    cell: &Cell,
    truth: &[f64],
    design: &[Vec<f64>],
    configs: &[Vec<f64>],
    runs: u64,
    seed: u64,
) -> Vec<Vec<Pose<f64>>> {
    use armcal::identify::{solve, Problem};
    use armcal::{IdentifySettings, Silent};
    use rayon::prelude::*;
    let model = &cell.model;
    let noise = cell.noise();
    (seed..seed + runs)
        .into_par_iter()
        .map(|s| {
            let data = armcal::simulate_measuring(
                model,
                truth,
                design,
                &[],
                cell.measurement,
                Some(&noise),
                s,
            )
            .unwrap();
            let mut p = Problem::new(model, &data, &noise).unwrap();
            let (sol, _, _) = solve(
                &mut p,
                &model.nominal(),
                &IdentifySettings::default(),
                &mut Silent,
            )
            .unwrap();
            let mut data = Data::new(model);
            configs
                .iter()
                .map(|q| {
                    forward_kinematics(model, &mut data, &sol.params, q);
                    observed_pose(&data, Observed::Tool)
                })
                .collect()
        })
        .collect()
}

/// The sample covariance (n − 1) of 3-vectors.
pub fn sample_covariance(
    xs: impl Iterator<Item = nalgebra::Vector3<f64>> + Clone,
) -> nalgebra::Matrix3<f64> {
    use nalgebra::{Matrix3, Vector3};
    let n = xs.clone().count() as f64;
    let mean = xs.clone().fold(Vector3::zeros(), |a, x| a + x) / n;
    xs.fold(Matrix3::zeros(), |a, x| {
        a + (x - mean) * (x - mean).transpose()
    }) / (n - 1.0)
}

/// Every parameter of the estimate `e` of `model` within 1e-6 (display units) of `truth`
/// (internal units, registry order).
pub fn assert_estimate_is(model: &Model, e: &armcal::Estimate, truth: &[f64]) {
    for p in &e.parameters {
        let i = model.registry.require(&p.name).unwrap();
        let f = model.registry.get(i).unit.display_factor();
        assert!(
            (p.estimate - truth[i] * f).abs() < 1e-6,
            "{} = {} vs truth {}",
            p.name,
            p.estimate,
            truth[i] * f
        );
    }
}

/// The paper cell's text with `extra` added to its `[parameters]` section.
pub fn paper_cell_with(extra: &str, tag: &str) -> Result<Cell, armcal::Error> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let text = std::fs::read_to_string(dir.join("paper-cell.toml")).unwrap();
    let text = text.replace(
        "measurement = \"position\"",
        &format!("measurement = \"position\"\n{extra}"),
    );
    cell_from_text(&text, tag)
}

/// The cell file `text` read through a temporary file (tagged `tag`), as a user's file is.
pub fn cell_from_text(text: &str, tag: &str) -> Result<Cell, armcal::Error> {
    // one file per call: tests run in parallel and share tags
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let path = std::env::temp_dir().join(format!(
        "armcal-cell-{tag}-{}-{call}.toml",
        std::process::id()
    ));
    std::fs::write(&path, text).unwrap();
    let cell = Cell::from_file(&path);
    std::fs::remove_file(&path).unwrap();
    cell
}

/// The UR10 + Leica T-Mac full-pose cell (`examples/ur10-leica-cell.toml`, `measurement =
/// "pose"`: the T-Mac frame's position and orientation) with its tracker placed where the
/// Series B fit puts it, the tracker's noise stated (σ 0.05 mm per axis, 0.005° per
/// rotation axis) and a working pose `w` reaching forward.
pub fn ur10_pose_cell() -> Cell {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let text = std::fs::read_to_string(dir.join("ur10-leica-cell.toml")).unwrap();
    let instrument = "kind = \"laser-tracker\"";
    assert!(text.contains(instrument));
    let text = text.replace(
        instrument,
        "kind = \"laser-tracker\"\nxyz_mm = [747, 3526, 1224]\nrpy_deg = [0, 0, -20]\n\
         noise = { model = \"constant\", sigma_mm = 0.05, sigma_angle_deg = 0.005 }",
    ) + "\n[[working]]\nname = \"w\"\njoints_deg = [30, -60, 90, -120, -90, 0]\n";
    let cell = cell_from_text(&text, "ur10-pose").unwrap();
    assert_eq!(cell.measurement, armcal::Measurement::Pose);
    cell
}

/// `n` configurations (named 1, 2, …) of `tree`'s joints, uniform within ±60 % of their
/// limits (seeded): the poses the tree tests simulate and fit.
pub fn tree_poses(
    tree: &armcal::model::tree::Tree,
    n: usize,
    seed: u64,
) -> Vec<(String, Vec<f64>)> {
    let mut r = rng(seed);
    (0..n)
        .map(|i| {
            let q = tree
                .joints
                .iter()
                .map(|j| 0.6 * r.random_range(j.lower..j.upper))
                .collect();
            (format!("{}", i + 1), q)
        })
        .collect()
}
