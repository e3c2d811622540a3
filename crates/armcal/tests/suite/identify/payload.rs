//! A known payload in the compliance model (issue 14 item 1): a cell's `[[payload]]`, a data
//! file's `payload` column, the joints' own compliance `<joint>.compliance.payload`
//! identified from measurements with and without the payload, its exact columns, the
//! estimate refusing to predict at a payload it cannot, and the calibrated IK at a payload.

use super::compliance::assert_recovered;
use armcal::compensate::CalibratedIk;
use armcal::measure::csv;
use armcal::model::{
    forward_kinematics, identification_jacobian, observed_position, random_configurations, Data,
    Observed, Rows,
};
use armcal::{
    identify, perturbed_truth, simulate_carrying, Cell, Dataset, IdentifySettings, IkSettings,
    IkTarget, Model, Perturbation, Silent, Unit,
};
use nalgebra::DMatrix;
use std::path::Path;

const PAYLOADS: &str = "\n[[payload]]\nname = \"gripper\"\nmass_kg = 12.5\ncom_mm = [40, -20, 150]\n\n[[payload]]\nname = \"probe\"\nmass_kg = 3\ncom_m = [0, 0.05, 0.08]\n";

/// The paper cell with compliant q2, q3 and the text `payloads` appended.
fn cell_with(payloads: &str, tag: &str) -> Result<Cell, armcal::Error> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let text = std::fs::read_to_string(dir.join("paper-cell.toml")).unwrap();
    let text = text.replace(
        "measurement = \"position\"",
        "measurement = \"position\"\ncompliance = [\"q2\", \"q3\"]",
    ) + payloads;
    crate::common::cell_from_text(&text, &format!("payload-{tag}"))
}

fn payload_cell() -> Cell {
    cell_with(PAYLOADS, "ok").unwrap()
}

/// `n` random configurations, each measured once without a payload and once with each of
/// `payloads`, on the robot `truth`, noise-free.
fn measured(model: &Model, truth: &[f64], n: usize, payloads: &[Option<usize>]) -> Dataset {
    let qs = random_configurations(model, n, 21);
    let mut all_q = Vec::new();
    let mut all_p = Vec::new();
    for p in payloads {
        all_q.extend(qs.iter().cloned());
        all_p.extend(std::iter::repeat_n(*p, n));
    }
    simulate_carrying(model, truth, &all_q, &all_p, None, 0).unwrap()
}

#[test]
fn the_cell_gives_each_compliant_joint_a_payload_term() {
    let cell = payload_cell();
    let m = &cell.model;
    assert_eq!(m.payloads.len(), 2);
    assert_eq!(
        m.payloads[1].com_mm,
        [0.0, 50.0, 80.0],
        "com_m is read in metres"
    );
    let names: Vec<&str> = m
        .registry
        .iter()
        .filter(|p| p.unit == Unit::RadPerNmm)
        .map(|p| p.name.as_str())
        .collect();
    assert_eq!(names, ["q2.compliance.payload", "q3.compliance.payload"]);
    // without [[payload]] there is no payload term
    let rigid_load = cell_with("", "none").unwrap();
    assert!(rigid_load
        .model
        .registry
        .iter()
        .all(|p| p.unit != Unit::RadPerNmm));
}

#[test]
fn the_cell_refuses_a_bad_payload_with_line_and_field() {
    for (text, says) in [
        ("\n[[payload]]\nname = \"g\"\nmass_kg = -1\n", "mass_kg"),
        (
            "\n[[payload]]\nname = \"g\"\nmass_kg = 1\ncom_mm = [0, 0, 1e300]\n",
            "com_mm",
        ),
        (
            "\n[[payload]]\nname = \"g\"\nmass_kg = 1\nmass_g = 3\n",
            "unknown field `mass_g`",
        ),
        ("\n[[payload]]\nmass_kg = 1\n", "missing `name`"),
        ("\n[[payload]]\nname = \"none\"\nmass_kg = 1\n", "`none`"),
        (
            "\n[[payload]]\nname = \"a b\"\nmass_kg = 1\n",
            "cannot contain",
        ),
        (
            "\n[[payload]]\nname = \"g\"\nmass_kg = 1\n\n[[payload]]\nname = \"g\"\nmass_kg = 2\n",
            "named twice",
        ),
    ] {
        let e = cell_with(text, "bad").unwrap_err().to_string();
        assert!(
            e.contains(says) && e.contains("line") && e.contains("payload["),
            "{text}: {e}"
        );
    }
}

#[test]
fn the_payload_column_is_read_and_an_unknown_payload_names_its_line() {
    let cell = payload_cell();
    let m = &cell.model;
    let head = "pose_id,payload,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg,target,x_mm,y_mm,z_mm\n";
    let row = |id: &str, p: &str| format!("{id},{p},0,-30,40,0,20,0,smr1,1000,0,500\n");
    let text = format!(
        "{head}{}{}{}",
        row("a", "gripper"),
        row("a", "none"),
        row("b", "")
    );
    let (data, _) = csv::read_str(&text, "d.csv", m, None).unwrap();
    // one pose with two payload states is two configurations
    assert_eq!(data.configurations.len(), 3);
    assert_eq!(data.payload_of(0), Some("gripper"));
    assert_eq!(data.payload_of(1), None);
    assert_eq!(data.payload_of(2), None);
    // written back with its payload column, and read again alike
    let again = csv::write_string(&data, m).unwrap();
    assert!(
        again.lines().next().unwrap().contains(",payload,"),
        "{again}"
    );
    let (back, _) = csv::read_str(&again, "again.csv", m, None).unwrap();
    assert_eq!(back.config_payloads, data.config_payloads);
    let bad = format!("{head}{}{}", row("a", "gripper"), row("b", "gripper2"));
    let e = csv::read_str(&bad, "d.csv", m, None)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("d.csv")
            && e.contains("line 3")
            && e.contains("`payload`")
            && e.contains("gripper2")
            && e.contains("gripper, probe"),
        "{e}"
    );
}

#[test]
fn payload_columns_match_finite_differences() {
    let cell = payload_cell();
    let model = &cell.model;
    let mut params = perturbed_truth(model, &Perturbation::default(), 3);
    for p in model.registry.iter().filter(|p| p.unit == Unit::RadPerNmm) {
        let i = model.registry.index_of(&p.name).unwrap();
        params[i] = 2e-8; // 20 µrad/(N·m): a soft joint, so the chain rule matters
    }
    let n = model.param_count();
    let columns: Vec<usize> = (0..n).collect();
    let obs = Observed::Target(0);
    // the kinematics at (p, q) carrying `payload`
    let at = |p: &[f64], q: &[f64], payload: Option<usize>| {
        let mut d = Data::new(model);
        d.payload = payload;
        forward_kinematics(model, &mut d, p, q);
        d
    };
    // the target in the instrument frame (identification rows) and the world (joint rows)
    let position = |p: &[f64], q: &[f64], payload| observed_position(&at(p, q, payload), obs);
    let world = |q: &[f64], payload| at(&params, q, payload).targets[0].trans;
    for (k, q) in random_configurations(model, 5, 4).iter().enumerate() {
        let payload = [None, Some(0), Some(1)][k % 3];
        let data = at(&params, q, payload);
        let mut jac = DMatrix::zeros(3, n);
        identification_jacobian(model, &data, obs, Rows::Position, &columns, &mut jac, 0);
        for j in 0..n {
            // steps that move the tool by about a micrometre
            let h = match model.registry.get(j).unit {
                Unit::RadPerNmm => 1e-12,
                Unit::RadPerMm => 1e-9,
                _ => 1e-6,
            };
            let (mut a, mut b) = (params.clone(), params.clone());
            a[j] += h;
            b[j] -= h;
            let fd = (position(&a, q, payload) - position(&b, q, payload)) / (2.0 * h);
            let scale = jac.column(j).abs().max().max(1.0);
            for r in 0..3 {
                assert!(
                    (jac[(r, j)] - fd[r]).abs() <= 1e-5 * scale,
                    "{} row {r} payload {payload:?}: {} vs {}",
                    model.registry.get(j).name,
                    jac[(r, j)],
                    fd[r]
                );
            }
        }
        // joint derivative through q + Δq(q): the joint Jacobian of the commanded joints
        let commanded = armcal::model::joint_jacobian(&data, obs);
        for i in 0..model.dof() {
            let (mut a, mut b) = (q.clone(), q.clone());
            a[i] += 1e-6;
            b[i] -= 1e-6;
            let fd = (world(&a, payload) - world(&b, payload)) / 2e-6;
            for r in 0..3 {
                assert!(
                    (commanded[(r, i)] - fd[r]).abs() <= 1e-5 * fd.norm().max(1.0),
                    "d/dq{i} row {r} payload {payload:?}: {} vs {}",
                    commanded[(r, i)],
                    fd[r]
                );
            }
        }
    }
}

#[test]
fn two_payload_states_recover_the_joint_compliance_noise_free() {
    let cell = payload_cell();
    let model = &cell.model;
    let truth = perturbed_truth(model, &Perturbation::default(), 8);
    let data = measured(model, &truth, 50, &[None, Some(0), Some(1)]);
    let est = identify(&cell, &data, &IdentifySettings::default(), &mut Silent).unwrap();
    assert!(est.solver.status.is_converged());
    let params = est.params_for(model).unwrap();
    assert_recovered(model, &params, &truth);
    assert_eq!(est.payloads_measured, ["none", "gripper", "probe"]);
    // every payload state measured, and an unmeasured one would be predicted too
    assert!(est.payload_for(model, Some("probe")).is_ok());
}

#[test]
fn without_a_payload_the_terms_are_left_out_and_other_payloads_refused() {
    let cell = payload_cell();
    let model = &cell.model;
    let truth = perturbed_truth(model, &Perturbation::default(), 9);
    let data = measured(model, &truth, 60, &[None]);
    let est = identify(&cell, &data, &IdentifySettings::default(), &mut Silent).unwrap();
    assert!(est.solver.status.is_converged());
    for term in ["q2.compliance.payload", "q3.compliance.payload"] {
        let why = est
            .fixed_reasons
            .iter()
            .find(|(n, _)| n == term)
            .unwrap_or_else(|| panic!("{term} has a reason: {:?}", est.fixed_reasons));
        assert!(
            why.1.contains("no measurement carried a payload"),
            "{why:?}"
        );
    }
    // at the calibration's own state the prediction is honest; at a payload it is refused
    assert_eq!(est.payload_for(model, None).unwrap().0, None);
    let e = est
        .payload_for(model, Some("gripper"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("gripper")
            && e.contains("q2.compliance.payload")
            && e.contains("payload` column"),
        "{e}"
    );
}

#[test]
fn the_calibrated_ik_at_a_payload_reaches_the_target_on_the_loaded_truth() {
    let cell = payload_cell();
    let model = &cell.model;
    let p = Perturbation {
        joint_compliance: 2e-8, // 20 µrad/(N·m): a deflection the IK must hold
        ..Perturbation::default()
    };
    let truth = perturbed_truth(model, &p, 10);
    let nominal = model.nominal();
    let settings = IkSettings {
        payload: Some(0),
        ..IkSettings::default()
    };
    let mut ik = CalibratedIk::new(model, &nominal, &truth, settings);
    let mut rigid_ik = CalibratedIk::new(model, &nominal, &truth, IkSettings::default());
    let mut worst_rigid: f64 = 0.0;
    for q in random_configurations(model, 40, 5) {
        let mut d = Data::new(model);
        forward_kinematics(model, &mut d, &nominal, &q);
        let target = IkTarget::Pose(*d.tool());
        let r = ik.solve(&target, &q);
        if !r.status.status().is_converged() {
            continue;
        }
        // the loaded truth at the compensated joints reaches the target
        let mut loaded = Data::new(model);
        loaded.payload = Some(0);
        forward_kinematics(model, &mut loaded, &truth, &r.q);
        let miss = (loaded.tool().trans - d.tool().trans).norm();
        assert!(miss < 1e-5, "miss {miss} mm");
        // compensating without the payload leaves its deflection
        let rr = rigid_ik.solve(&target, &q);
        forward_kinematics(model, &mut loaded, &truth, &rr.q);
        worst_rigid = worst_rigid.max((loaded.tool().trans - d.tool().trans).norm());
    }
    assert!(
        worst_rigid > 0.1,
        "the payload's deflection is visible: {worst_rigid} mm"
    );
}

#[test]
fn accuracy_and_the_nonparametric_fit_see_each_rows_payload() {
    use armcal::{
        accuracy_report, commanded_poses, AccuracyOrientation, CorrectionInputs,
        ResidualCorrection, SamePose,
    };
    let cell = payload_cell();
    let model = &cell.model;
    let p = Perturbation {
        joint_compliance: 2e-8,
        ..Perturbation::default()
    };
    let truth = perturbed_truth(model, &p, 12);
    let data = measured(model, &truth, 30, &[None, Some(0)]);
    // the robot that measured them predicts every row, loaded or not
    let poses = commanded_poses(
        model,
        &data.configurations,
        &data.config_ids,
        &SamePose::default(),
    );
    let report = accuracy_report(
        model,
        &truth,
        &data,
        &poses,
        AccuracyOrientation::IfMeasured,
    )
    .unwrap();
    assert!(
        report.errors.max < 1e-9,
        "max error {} mm",
        report.errors.max
    );
    let c = ResidualCorrection::fit(model, &truth, &data, CorrectionInputs::ArmJoints, 2).unwrap();
    assert!(
        c.polynomial.training_rms_before < 1e-9,
        "{}",
        c.polynomial.training_rms_before
    );
    // a data file of a cell with payloads has the payload column even without a loaded row
    let bare = measured(model, &truth, 3, &[None]);
    let text = csv::write_string(&bare, model).unwrap();
    assert!(text.lines().next().unwrap().contains(",payload,"), "{text}");
}
