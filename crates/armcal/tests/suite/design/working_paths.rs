//! KPIs along a working path (`[[working_path]]`, paper §6): the cell reads a path inline or
//! from a CSV, the mean KPI shares a path's weight among its configurations, `kpi-max` is a
//! smooth maximum between the largest variance and its bound with an exact gradient, and a
//! `kpi-max` design lowers the worst configuration of the path.

use armcal::design::SMOOTH_MAX_P;
use armcal::design::{DesignModel, DesignObjective};
use armcal::model::random_configurations;
use armcal::{assess, plan, Cell, Criterion, DesignAssessment, PlanSettings, Silent};
use std::path::Path;

/// The paper cell with `extra` appended, read from a scratch file (beside `files`, written
/// first: name and text).
fn cell_with(tag: &str, extra: &str, files: &[(&str, &str)]) -> Result<Cell, armcal::Error> {
    let base = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper-cell.toml"),
    )
    .unwrap();
    let dir = std::env::temp_dir().join(format!("armcal-paths-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let path = dir.join("cell.toml");
    std::fs::write(&path, format!("{base}\n{extra}")).unwrap();
    let cell = Cell::from_file(&path);
    std::fs::remove_dir_all(&dir).unwrap();
    cell
}

/// The value of criterion `c` in an assessment.
fn value_of(a: &DesignAssessment, c: Criterion) -> f64 {
    a.criteria.iter().find(|(k, _)| *k == c).unwrap().1
}

/// A horizontal sweep of the first joint, `n` configurations (deg).
fn sweep(n: usize) -> Vec<[f64; 6]> {
    (0..n)
        .map(|i| {
            let q1 = -60.0 + 120.0 * i as f64 / (n - 1) as f64;
            [q1, -20.0, 40.0, 0.0, 45.0, 0.0]
        })
        .collect()
}

/// [`sweep`] as a joint CSV (armcal's joint columns), rows named `p0`, `p1`, ….
fn sweep_csv(n: usize) -> String {
    let mut csv = String::from("pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\n");
    for (i, q) in sweep(n).iter().enumerate() {
        let v: Vec<String> = q.iter().map(|x| x.to_string()).collect();
        csv.push_str(&format!("p{i},{}\n", v.join(",")));
    }
    csv
}

fn inline_path(name: &str, weight: f64, points: &[[f64; 6]]) -> String {
    let rows: Vec<String> = points.iter().map(|q| format!("{q:?}")).collect();
    format!(
        "[[working_path]]\nname = \"{name}\"\nweight = {weight}\njoints_deg = [{}]\n",
        rows.join(", ")
    )
}

#[test]
fn a_path_reads_inline_and_from_a_file_alike() {
    let points = sweep(7);
    let inline = cell_with("inline", &inline_path("seam", 2.0, &points), &[]).unwrap();
    let csv = sweep_csv(7);
    let from_file = cell_with(
        "file",
        "[[working_path]]\nname = \"seam\"\nweight = 2\nfile = \"seam.csv\"\n",
        &[("seam.csv", &csv)],
    )
    .unwrap();
    assert_eq!(inline.working_paths, from_file.working_paths);
    let p = &inline.working_paths[0];
    assert_eq!(p.q.len(), 7);
    assert!((p.q[0][0] + 60f64.to_radians()).abs() < 1e-12);
    // The mean KPI's weights: the working pose keeps its own, the path's 2 is shared by its 7.
    let kpi = inline.kpi_configurations();
    assert_eq!(kpi.len(), 8);
    assert_eq!(kpi[0].1, 1.0);
    let shared: f64 = kpi[1..].iter().map(|(_, w)| w).sum();
    assert!((shared - 2.0).abs() < 1e-12 && (kpi[1].1 - 2.0 / 7.0).abs() < 1e-15);
}

#[test]
fn a_bad_path_says_where_and_why() {
    let cases = [
        ("[[working_path]]\nname = \"p\"\n", "missing `file`"),
        (
            "[[working_path]]\nfile = \"x.csv\"\njoints_deg = [[0, 0, 0, 0, 0, 0]]\n",
            "not both",
        ),
        (
            "[[working_path]]\njoints_deg = [[0, 0, 0]]\n",
            "has 3 values",
        ),
        ("[[working_path]]\njoints_deg = []\n", "no configurations"),
        (
            "[[working_path]]\njoints_deg = [[0, 0, 0, 0, 0, 0]]\nweight = -1\n",
            "positive",
        ),
        (
            "[[working_path]]\njoints_deg = [[0, 0, 0, 0, 0, 0]]\nspeed = 1\n",
            "unknown field `speed`",
        ),
        ("[[working_path]]\nfile = \"missing.csv\"\n", "missing.csv"),
    ];
    for (extra, expect) in cases {
        let e = cell_with("bad", extra, &[]).unwrap_err().to_string();
        assert!(
            e.contains("working_path[0]") && e.contains(expect),
            "{extra:?}: {e}"
        );
        assert!(e.contains("line "), "{e}");
    }
}

#[test]
fn the_path_kpis_match_the_same_points_as_working_poses() {
    let points = sweep(5);
    let with_path = cell_with("path", &inline_path("seam", 1.0, &points), &[]).unwrap();
    // The same points as [[working]] poses, one by one.
    let poses: String = points
        .iter()
        .enumerate()
        .map(|(i, q)| format!("[[working]]\nname = \"w{i}\"\njoints_deg = {q:?}\n"))
        .collect();
    let as_poses = cell_with("poses", &poses, &[]).unwrap();
    let design = random_configurations(&with_path.model, 30, 4);
    let a = assess(&with_path, &design).unwrap();
    let b = assess(&as_poses, &design).unwrap();
    let path = &a.paths[0];
    // b.tcp: q_work first, then w0…w4.
    for (k, v) in path.kpi.iter().enumerate() {
        assert!((v - b.tcp[k + 1].kpi).abs() <= 1e-12 * v, "point {k}");
    }
    let (worst, max) =
        b.tcp[1..].iter().enumerate().fold(
            (0, 0.0),
            |m, (i, t)| if t.kpi > m.1 { (i + 1, t.kpi) } else { m },
        );
    assert_eq!(path.worst, worst);
    assert!((path.max_kpi - max).abs() <= 1e-12 * max);
    // Mean KPI: (1·v_work + 1·mean along the path) / 2.
    let mean = (b.tcp[0].kpi + path.mean_kpi) / 2.0;
    let kpi = value_of(&a, Criterion::Kpi);
    assert!((kpi - mean).abs() <= 1e-10 * mean, "{kpi} vs {mean}");
    // KPI-max: between the largest variance and K^{1/p} times it.
    let largest = b.tcp.iter().map(|t| t.kpi).fold(0.0, f64::max);
    let smooth = value_of(&a, Criterion::KpiMax);
    let bound = largest * (b.tcp.len() as f64).powf(1.0 / SMOOTH_MAX_P);
    assert!(
        largest <= smooth && smooth <= bound,
        "{largest} ≤ {smooth} ≤ {bound}"
    );
}

#[test]
fn the_kpi_max_gradient_matches_finite_differences() {
    let cell = cell_with("grad", &inline_path("seam", 1.0, &sweep(9)), &[]).unwrap();
    let d = DesignModel::from_cell(&cell).unwrap();
    let qs = random_configurations(&d.model, 30, 11);
    let measured = random_configurations(&d.model, 3, 12);
    let q = qs.concat();
    for criterion in [Criterion::Kpi, Criterion::KpiMax] {
        let obj = DesignObjective::new(&d, criterion, &measured);
        let mut ws = obj.workspace(qs.len());
        let mut g = vec![0.0; q.len()];
        obj.value_and_gradient(&mut ws, &q, Some(&mut g)).unwrap();
        let gmax = g.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        for idx in (0..q.len()).step_by(5) {
            let h = 1e-5;
            let (mut qp, mut qm) = (q.clone(), q.clone());
            qp[idx] += h;
            qm[idx] -= h;
            let fd = (obj.value_and_gradient(&mut ws, &qp, None).unwrap()
                - obj.value_and_gradient(&mut ws, &qm, None).unwrap())
                / (2.0 * h);
            assert!(
                (g[idx] - fd).abs() <= 1e-6 * gmax + 1e-6 * fd.abs(),
                "{criterion:?} entry {idx}: analytic {} vs fd {fd}",
                g[idx]
            );
        }
    }
}

#[test]
fn a_kpi_max_design_lowers_the_worst_point_of_the_path() {
    // A long seam and the cell's forward-reaching working pose: the mean KPI spends poses
    // where most of the path is; the max criterion on the path's worst point.
    let cell = cell_with("plan", &inline_path("seam", 1.0, &sweep(15)), &[]).unwrap();
    let settings = PlanSettings {
        poses: 30,
        collisions: false,
        starts: 2,
        ..PlanSettings::default()
    };
    let mean = plan(&cell, &settings, &[], &mut Silent).unwrap();
    let max = plan(
        &cell,
        &PlanSettings {
            criterion: Criterion::KpiMax,
            ..settings.clone()
        },
        &[],
        &mut Silent,
    )
    .unwrap();
    let worst = |design: &[Vec<f64>]| {
        let a = assess(&cell, design).unwrap();
        let w = a
            .tcp
            .iter()
            .map(|t| t.kpi)
            .fold(a.paths[0].max_kpi, f64::max);
        let m = value_of(&a, Criterion::Kpi);
        (w, m)
    };
    let (w_mean, m_mean) = worst(&mean.design);
    let (w_max, m_max) = worst(&max.design);
    eprintln!("largest (1/3) tr C_s: mean-KPI design {w_mean:.4}, max design {w_max:.4}; mean KPI {m_mean:.4} vs {m_max:.4}");
    assert!(w_max < w_mean, "{w_max} vs {w_mean}");
    assert!(m_mean <= m_max * (1.0 + 1e-9), "{m_mean} vs {m_max}");
}

#[test]
fn an_exported_cell_keeps_its_paths_inline() {
    let csv = sweep_csv(4);
    let cell = cell_with(
        "export",
        "[[working_path]]\nname = \"a \\\"seam\\\"\"\nweight = 0.5\nfile = \"seam.csv\"\n",
        &[("seam.csv", &csv)],
    )
    .unwrap();
    let text = armcal::cell::to_cell_toml(&cell, &cell.model, &cell.model.spec()).unwrap();
    // Read back where the CSV does not exist: the exported cell stands alone.
    let back = Cell::from_toml(&text, "export.toml", Path::new("/nonexistent")).unwrap();
    assert_eq!(back.working_paths.len(), 1);
    let (a, b) = (&back.working_paths[0], &cell.working_paths[0]);
    assert_eq!((&a.name, a.weight), (&b.name, b.weight));
    for (qa, qb) in a.q.iter().zip(&b.q) {
        for (x, y) in qa.iter().zip(qb) {
            assert!((x - y).abs() < 1e-12);
        }
    }
}

#[test]
fn a_path_design_lowers_the_largest_sigma_along_a_50_pose_path_in_monte_carlo() {
    // Issue 16's evidence: a design for a 50-configuration path (`kpi-max` over the path and
    // the cell's working pose) against the single-pose KPI design (the cell without the
    // path), both judged by the largest (1/3) tr C_s along the path — predicted, and in 200
    // simulated calibrations of one virtual robot per design.
    let path = sweep(50);
    let single = cell_with("mc-single", "", &[]).unwrap();
    let with_path = cell_with("mc-path", &inline_path("seam", 1.0, &path), &[]).unwrap();
    let settings = PlanSettings {
        poses: 60,
        collisions: false,
        starts: 1,
        ..PlanSettings::default()
    };
    let single_design = plan(&single, &settings, &[], &mut Silent).unwrap().design;
    let path_design = plan(
        &with_path,
        &PlanSettings {
            criterion: Criterion::KpiMax,
            ..settings.clone()
        },
        &[],
        &mut Silent,
    )
    .unwrap()
    .design;
    let predicted = |design: &[Vec<f64>]| assess(&with_path, design).unwrap().paths[0].max_kpi;
    let (pred_single, pred_path) = (predicted(&single_design), predicted(&path_design));
    let configs: Vec<Vec<f64>> = path
        .iter()
        .map(|q| q.iter().map(|v| v.to_radians()).collect())
        .collect();
    let truth = armcal::perturbed_truth(&with_path.model, &armcal::Perturbation::default(), 8);
    let largest = |design: &[Vec<f64>], seed: u64| {
        crate::common::monte_carlo_tcp_covariances(&with_path, &truth, design, &configs, 200, seed)
            .iter()
            .map(|c| c.trace() / 3.0)
            .fold(0.0, f64::max)
    };
    let (mc_single, mc_path) = (
        largest(&single_design, 30_000),
        largest(&path_design, 40_000),
    );
    eprintln!(
        "largest (1/3) tr C_s along the 50-configuration path: single-pose KPI design {pred_single:.4} \
         predicted, {mc_single:.4} Monte Carlo; path design {pred_path:.4} predicted, {mc_path:.4} Monte Carlo"
    );
    assert!(
        pred_path < 0.9 * pred_single,
        "{pred_path} vs {pred_single}"
    );
    assert!(mc_path < mc_single, "{mc_path} vs {mc_single}");
    for (mc, pred) in [(mc_single, pred_single), (mc_path, pred_path)] {
        assert!(
            (mc / pred - 1.0).abs() <= 0.15,
            "Monte Carlo {mc} vs predicted {pred}"
        );
    }
}
