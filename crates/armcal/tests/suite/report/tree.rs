//! A tree's estimate in the report (issue 32 item 5): `armcal report` of a tree estimate
//! shows the fit per target with the estimate's figures, every free parameter, and a 3D view
//! of every branch whose target positions agree with what the instrument reports (the
//! distance from the tracker to each target is the length of the target's position in the
//! instrument frame, computed here by the measurement model); an unconverged tree fit is
//! refused unless accepted.

use crate::common::*;
use armcal::model::tree::kinematics::{branch_kinematics, tree_observed_pose, TreeData};
use armcal::model::tree::Tree;
use armcal::{
    files_report, identify_tree, simulate_tree, Acceptance, IdentifySettings, Perturbation, Silent,
    TreeCell,
};
use serde_json::Value;

const CELL: &str = include_str!("../../../../../examples/dual-arm-tree-cell.toml");

fn acceptance(accepted: bool) -> Acceptance<'static> {
    Acceptance {
        accepted,
        accept: "--accept-unconverged",
        raise_iterations: "--max-iterations",
    }
}

/// The scene JSON of the tree's 3D view in `html`.
fn scene(html: &str) -> Value {
    let open = "<script type=\"application/json\" class=\"cell-view-data\">";
    let start = html.find(open).expect("a 3D view") + open.len();
    let end = start + html[start..].find("</script>").unwrap();
    serde_json::from_str(&html[start..end]).unwrap()
}

#[test]
fn a_tree_estimate_reports_its_fit_per_target_parameters_and_branches() {
    let cell = TreeCell::from_toml(CELL, "dual-arm-tree-cell.toml").unwrap();
    let poses = tree_poses(&cell.tree, 45, 4);
    let sim = simulate_tree(
        &cell.tree,
        cell.measurement,
        Some(&cell.noise),
        &poses,
        &[],
        &Perturbation::default(),
        3,
    )
    .unwrap();
    let opts = IdentifySettings {
        holdout: 0.3,
        ..IdentifySettings::default()
    };
    let est = identify_tree(&cell, &sim.data, &opts, &mut Silent).unwrap();
    assert!(est.solver.status.is_converged());
    let dir = std::env::temp_dir().join(format!("armcal-tree-report-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("tree-estimate.json");
    std::fs::write(&file, est.to_json().unwrap()).unwrap();
    let report = files_report(std::slice::from_ref(&file), "t", &acceptance(false)).unwrap();
    let html = report.page.render();
    assert!(
        report.page.subtitle.contains("tree estimate"),
        "{}",
        report.page.subtitle
    );
    assert!(html.contains("Tree estimate: tree-estimate"));
    // the fit per target: each target's held-out RMS as the estimate has it
    for t in &est.targets {
        assert!(t.held_out.count > 0);
        let row = format!("<td>{}</td>", t.target);
        let at = html
            .find(&row)
            .unwrap_or_else(|| panic!("a row of {}", t.target));
        let end = at + html[at..].find("</tr>").unwrap();
        assert!(
            html[at..end].contains(&format!("{:.4}", t.held_out.rms)),
            "{}",
            &html[at..end]
        );
    }
    // every free parameter is listed
    for p in est.parameters.iter().filter(|p| p.free) {
        assert!(html.contains(&format!("<td>{}</td>", p.name)), "{}", p.name);
    }
    // the 3D view: one segment per link (the torso once), both targets; at every
    // configuration the tracker-to-target distance is the measured position's length
    let scene = scene(&html);
    let tree = Tree::from_spec(&est.tree).unwrap();
    let mut names: Vec<&str> = Vec::new();
    for b in &tree.branches {
        for l in &b.model.links {
            if !names.contains(&l.spec.name.as_str()) {
                names.push(&l.spec.name);
            }
        }
    }
    assert_eq!(scene["robot"].as_array().unwrap().len(), names.len());
    assert_eq!(scene["target_names"].as_array().unwrap().len(), 2);
    let tracker: Vec<f64> = scene["tracker"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let view_poses = scene["designs"][0]["poses"].as_array().unwrap();
    assert_eq!(view_poses.len(), 9);
    let mut data = TreeData::new(&tree);
    let params = tree.nominal();
    for pose in view_poses {
        let q: Vec<f64> = pose["q"]
            .as_array()
            .unwrap()
            .iter()
            .zip(&tree.joints)
            .map(|(v, j)| v.as_f64().unwrap() / j.kind.unit().display_factor())
            .collect();
        for (t, shown) in pose["targets"].as_array().unwrap().iter().enumerate() {
            branch_kinematics(&tree, &mut data, tree.targets[t].1, &params, &q);
            let measured = tree_observed_pose(&tree, &data, t).trans.norm();
            let shown: Vec<f64> = shown
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            let d = ((shown[0] - tracker[0]).powi(2)
                + (shown[1] - tracker[1]).powi(2)
                + (shown[2] - tracker[2]).powi(2))
            .sqrt();
            // rounding: 0.1 mm per coordinate, joints to 0.01 display units
            assert!((d - measured).abs() < 2.0, "{d} vs {measured} mm");
        }
    }
    // an unconverged fit is refused, and reported with a note when accepted
    let mut unconverged = est.clone();
    unconverged.solver.status = armcal::Status::IterationLimit;
    std::fs::write(&file, unconverged.to_json().unwrap()).unwrap();
    let e = files_report(std::slice::from_ref(&file), "t", &acceptance(false))
        .err()
        .expect("refused")
        .to_string();
    assert!(
        e.contains("did not converge") && e.contains("--accept-unconverged"),
        "{e}"
    );
    let r = files_report(std::slice::from_ref(&file), "t", &acceptance(true)).unwrap();
    assert!(
        r.notes.iter().any(|n| n.contains("did not converge")),
        "{:?}",
        r.notes
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
