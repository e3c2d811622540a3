//! `armcal plan --pool`: a 2000-row pool of the paper cell (uniform random configurations, so
//! most rows are ones the tracker cannot see, and ten rows beyond a joint limit). The chosen
//! rows are feasible (`armcal evaluate` agrees) and none of the listed infeasible rows;
//! `--refine-radius` keeps every joint within the radius of its pool row (from the files'
//! degrees); bad pools and flags give clear errors.

use crate::common::{armcal, scratch};
use armcal::measure::csv::write_configurations;
use armcal::model::random_configurations;
use armcal::Cell;
use std::collections::BTreeSet;
use std::path::Path;

/// The data rows of a CSV file of ours: `pose_id` and the numbers after it.
fn rows(path: &Path) -> Vec<(String, Vec<f64>)> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            let mut f = l.split(',');
            let id = f.next().unwrap().to_string();
            (id, f.map(|v| v.parse().unwrap()).collect())
        })
        .collect()
}

/// `armcal evaluate` finds every pose of `design` feasible.
fn assert_every_pose_feasible(design: &Path) {
    let (ok, out, err) = armcal(&[
        "evaluate",
        "--cell",
        "examples/paper-cell.toml",
        "--design",
        design.to_str().unwrap(),
    ]);
    assert!(ok && out.contains("every pose feasible"), "{out}\n{err}");
}

fn plan(pool: &str, extra: &[&str], out: &str) -> (bool, String, String) {
    let mut args = vec![
        "plan",
        "--cell",
        "examples/paper-cell.toml",
        "--pool",
        pool,
        "--out",
        out,
        "--quiet",
    ];
    args.extend_from_slice(extra);
    armcal(&args)
}

#[test]
fn plan_from_a_2000_row_pool() {
    let dir = scratch("pool-cli");
    let cell = Cell::from_file(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/paper-cell.toml"
    )))
    .unwrap();
    let mut qs = random_configurations(&cell.model, 2000, 17);
    // Ten rows beyond a joint's upper limit, at rows 100, 300, …, 1900.
    let beyond: BTreeSet<usize> = (0..10).map(|k| 100 + 200 * k).collect();
    for (k, &r) in beyond.iter().enumerate() {
        let j = k % 6;
        qs[r - 1][j] = cell.model.joints[j].upper + 5f64.to_radians();
    }
    let pool = dir.join("pool.csv");
    std::fs::write(&pool, write_configurations(&cell.model, &qs)).unwrap();
    let pool_rows = rows(&pool);
    let design = dir.join("design.csv");
    let (ok, out, err) = plan(
        pool.to_str().unwrap(),
        &["--criterion", "d", "--poses", "40"],
        design.to_str().unwrap(),
    );
    assert!(ok, "{out}\n{err}");
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("design.json")).unwrap()).unwrap();
    let p = &record["pool"];
    let infeasible: BTreeSet<usize> = p["infeasible"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["row"].as_u64().unwrap() as usize)
        .collect();
    let feasible = p["feasible"].as_u64().unwrap() as usize;
    assert_eq!(p["rows"], 2000);
    assert_eq!(feasible + infeasible.len(), 2000);
    assert!(beyond.is_subset(&infeasible));
    assert!((40..1000).contains(&feasible), "{feasible}");
    assert!(
        err.contains(&format!(
            "2000 rows, {feasible} feasible, {} infeasible",
            infeasible.len()
        )),
        "{err}"
    );
    assert!(err.contains("joint limits: "), "{err}");
    // The design is the chosen pool rows, none of them infeasible.
    let chosen: Vec<usize> = p["chosen"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["row"].as_u64().unwrap() as usize)
        .collect();
    let design_rows = rows(&design);
    assert_eq!(chosen.len(), 40);
    assert_eq!(chosen.iter().collect::<BTreeSet<_>>().len(), 40);
    for (r, (_, q)) in chosen.iter().zip(&design_rows) {
        assert!(!infeasible.contains(r));
        assert_eq!(q, &pool_rows[r - 1].1);
    }
    assert_every_pose_feasible(&design);

    // Refined within 1.5° of the pool poses.
    let refined = dir.join("refined.csv");
    let (ok, out, err) = plan(
        pool.to_str().unwrap(),
        &[
            "--criterion",
            "d",
            "--poses",
            "40",
            "--refine-radius",
            "1.5",
        ],
        refined.to_str().unwrap(),
    );
    assert!(ok, "{out}\n{err}");
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("refined.json")).unwrap()).unwrap();
    let mut largest = 0.0f64;
    for (r, (_, q)) in record["pool"]["chosen"]
        .as_array()
        .unwrap()
        .iter()
        .zip(rows(&refined))
    {
        let row = r["row"].as_u64().unwrap() as usize;
        assert!(!infeasible.contains(&row));
        for (x, p0) in q.iter().zip(&pool_rows[row - 1].1) {
            largest = largest.max((x - p0).abs());
        }
    }
    assert!(
        largest <= 1.5 + 2e-6 && largest > 0.01,
        "largest move {largest}°"
    );
    assert_every_pose_feasible(&refined);

    // The report shows where each pose came from and the rows refused.
    let (ok, out, err) = armcal(&[
        "report",
        dir.join("refined.json").to_str().unwrap(),
        "--out",
        dir.join("report").to_str().unwrap(),
        "--quiet",
    ]);
    assert!(ok, "{out}\n{err}");
    let page = std::fs::read_to_string(dir.join("report/report.html")).unwrap();
    assert!(
        page.contains(&format!(
            "2000 rows, {feasible} feasible, {} infeasible (never chosen); refined within ±1.5",
            infeasible.len()
        )),
        "the pose pool summary"
    );
    assert!(page.contains("<h3>Pose pool</h3>"));
    let first_chosen = &record["pool"]["chosen"][0];
    assert!(page.contains(&format!(
        "<td class=\"num\">1</td><td class=\"num\">{}</td>",
        first_chosen["row"]
    )));
    assert!(
        page.contains(&format!("the first 200 of {}", infeasible.len())) || infeasible.len() <= 200
    );

    // Too few feasible rows: the first 30 rows hold fewer than the 9 poses 27 parameters need.
    let small = dir.join("small.csv");
    std::fs::write(&small, write_configurations(&cell.model, &qs[..30])).unwrap();
    let (ok, _, err) = plan(
        small.to_str().unwrap(),
        &[],
        dir.join("x.csv").to_str().unwrap(),
    );
    assert!(
        !ok && err.contains("small.csv") && err.contains("needs at least 9 poses"),
        "{err}"
    );
    // Wrong columns.
    let wrong = dir.join("wrong.csv");
    std::fs::write(&wrong, "pose_id,a1,a2,a3,a4,a5,a6\n1,0,0,0,0,0,0\n").unwrap();
    let (ok, _, err) = plan(
        wrong.to_str().unwrap(),
        &[],
        dir.join("x.csv").to_str().unwrap(),
    );
    assert!(
        !ok && err.contains("wrong.csv") && err.contains("q1"),
        "{err}"
    );
    // Flags that do not go with a pool, or need one.
    let (ok, _, err) = plan(
        pool.to_str().unwrap(),
        &["--starts", "4"],
        dir.join("x.csv").to_str().unwrap(),
    );
    assert!(!ok && err.contains("--starts"), "{err}");
    let (ok, _, err) = armcal(&[
        "plan",
        "--cell",
        "examples/paper-cell.toml",
        "--refine-radius",
        "2",
        "--out",
        dir.join("x.csv").to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("--pool"), "{err}");
    assert!(!dir.join("x.csv").exists());
}
