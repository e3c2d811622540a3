//! `armcal accuracy`: ISO 9283 pose accuracy and repeatability (position and orientation)
//! of every commanded pose of a data file, before calibration (the nominal robot with its
//! frames fitted) and after it (an estimate), and the models' errors.

use super::output::{
    load_cell, load_data, load_estimate, with_note, AcceptUnconverged, NoteStyle, Outputs,
};
use super::progress::Progress;
use armcal::{
    performance, AccuracyOrientation, AccuracyReport, Calibrated, GroupingSummary,
    PerformanceRecord, PerformanceSettings, PoseFigures, SamePose, Table, ISO_CYCLES,
};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// Cell file or built-in robot.
    #[arg(long)]
    pub cell: String,
    /// Data file; rows whose nominal tool poses agree within --same-pose-mm and
    /// --same-pose-deg are repeated approaches of one commanded pose.
    #[arg(long)]
    pub data: PathBuf,
    /// The calibration to test ("after"), identified for this set-up (its instrument and
    /// tool frames fitted to these data); without it only "before" (the nominal robot with
    /// its frames fitted to these data).
    #[arg(long)]
    pub estimate: Option<PathBuf>,
    /// Largest distance between the nominal tool positions of one commanded pose's
    /// approaches (mm).
    #[arg(long, default_value_t = SamePose::default().position_mm)]
    pub same_pose_mm: f64,
    /// Largest angle between the nominal tool orientations of one commanded pose's
    /// approaches (deg).
    #[arg(long, default_value_t = SamePose::default().orientation_deg)]
    pub same_pose_deg: f64,
    /// Require orientation figures: refuse data that measure positions only.
    #[arg(long)]
    pub orientation: bool,
    /// Write the figures of every pose, before and after, to this CSV file.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Overwrite an existing output file (never an input file).
    #[arg(long)]
    pub force: bool,
    /// Print the record as JSON instead of tables.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub accept: AcceptUnconverged,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let mut inputs = vec![Path::new(&a.cell), &a.data];
    inputs.extend(a.estimate.as_deref());
    let planned: Vec<&Path> = a.out.as_deref().into_iter().collect();
    let outputs = Outputs::plan(a.force, &inputs, &planned)?;
    let same_pose = SamePose {
        position_mm: a.same_pose_mm,
        orientation_deg: a.same_pose_deg,
    };
    same_pose.check(["--same-pose-mm", "--same-pose-deg"])?;
    let cell = load_cell(&a.cell)?;
    let data = load_data(&cell, &a.data)?;
    let estimate = a
        .estimate
        .as_deref()
        .map(|p| {
            let (est, note) = load_estimate(p, &a.accept, Some(&cell.model))?;
            Ok::<_, anyhow::Error>((p.display().to_string(), est.params_for(&cell.model)?, note))
        })
        .transpose()?;
    let settings = PerformanceSettings {
        same_pose,
        orientation: if a.orientation {
            AccuracyOrientation::Required
        } else {
            AccuracyOrientation::IfMeasured
        },
    };
    let calibrated = estimate.as_ref().map(|(name, params, _)| Calibrated {
        name: name.clone(),
        params,
    });
    let rec = performance(
        &cell,
        &data,
        calibrated,
        &settings,
        &mut Progress::new(a.json),
    )?;
    let note = estimate.as_ref().and_then(|e| e.2.as_deref());
    if let Some(out) = &a.out {
        let csv = with_note(pose_table(&rec), note, NoteStyle::Hash);
        outputs.commit(&[(out, &csv)])?;
    }
    if a.json {
        let json = serde_json::to_string_pretty(&rec)?;
        println!("{}", with_note(json, note, NoteStyle::Json));
        return Ok(());
    }
    if let Some(n) = note {
        println!("{n}");
    }
    print_grouping(&rec.data, &rec.grouping);
    println!();
    print_report(&rec.before.model, &rec.before.report);
    if rec.grouping.poses < FEW_POSES {
        println!(
            "  note: the frames were fitted to these {}: AP before is what they leave, and with fewer than {FEW_POSES} poses they take most of it",
            count(rec.grouping.poses, "pose")
        );
    }
    if let Some(m) = &rec.after {
        println!();
        print_report(&m.model, &m.report);
    }
    if let Some(out) = &a.out {
        println!("\nevery pose's figures → {}", out.display());
    }
    Ok(())
}

/// `n` things, in the singular for one.
fn count(n: usize, thing: &str) -> String {
    if n == 1 {
        format!("1 {thing}")
    } else {
        format!("{n} {thing}s")
    }
}

/// Below this many commanded poses the frames fitted for "before" (up to 6 instrument and
/// 6 tool parameters) take much of the AP with them.
const FEW_POSES: usize = 12;

/// "n poses approached k times", in words.
fn times(k: usize) -> String {
    match k {
        1 => "once".into(),
        2 => "twice".into(),
        _ => format!("{k} times"),
    }
}

fn print_grouping(data: &str, g: &GroupingSummary) {
    let counts: Vec<String> = g
        .approaches
        .iter()
        .map(|[k, n]| format!("{n} approached {}", times(*k)))
        .collect();
    println!(
        "{data}: {} configurations, {} (same pose within {} mm and {}°): {}",
        g.configurations,
        count(g.poses, "commanded pose"),
        g.tolerance.position_mm,
        g.tolerance.orientation_deg,
        counts.join(", ")
    );
    println!(
        "largest spread of one pose's approaches: {:.3} mm, {:.4}°",
        g.largest_spread_mm, g.largest_spread_deg
    );
    if let Some(c) = &g.closest {
        println!(
            "note: the closest distinct poses, {} and {}, are {:.3} mm and {:.4}° apart (within 3× the tolerance: check that they are two poses)",
            c.a, c.b, c.distance_mm, c.angle_deg
        );
    }
}

/// A figure, or `-` where there is none.
fn fig(v: Option<f64>, digits: usize) -> String {
    v.map_or("-".into(), |v| format!("{v:.digits$}"))
}

fn print_report(model: &str, r: &AccuracyReport) {
    let e = &r.errors;
    println!(
        "{model}: {} measurements, position error mean {:.4}, RMS {:.4}, max {:.4}, p95 {:.4} mm",
        e.count, e.mean, e.rms, e.max, e.p95
    );
    if let Some(o) = &r.orientation_errors {
        println!(
            "  orientation error mean {:.4}, RMS {:.4}, max {:.4}, p95 {:.4}°",
            o.mean, o.rms, o.max, o.p95
        );
    }
    let s = &r.summary;
    println!(
        "  ISO 9283 over {}: AP_P mean {:.4}, max {:.4} mm; RP_l mean {}, max {} mm ({} approached at least twice, {} at least {ISO_CYCLES} times)",
        count(s.poses, "pose"),
        s.ap.mean,
        s.ap.max,
        fig(s.rp.as_ref().map(|x| x.mean), 4),
        fig(s.rp.as_ref().map(|x| x.max), 4),
        s.repeated,
        s.iso_cycles
    );
    if let Some(ap) = s.ap_abc_max_deg {
        let rp = s.rp_abc_max_deg;
        println!(
            "  orientation: largest |AP_a|, |AP_b|, |AP_c| {:.4}, {:.4}, {:.4}°; largest RP_a, RP_b, RP_c ±{}, ±{}, ±{}°",
            ap[0],
            ap[1],
            ap[2],
            fig(rp.map(|x| x[0]), 4),
            fig(rp.map(|x| x[1]), 4),
            fig(rp.map(|x| x[2]), 4)
        );
    }
    if s.repeated == 0 {
        println!("  no pose was approached twice: no repeatability (RP needs at least 2 approaches of a pose; ISO 9283 asks {ISO_CYCLES})");
        return;
    }
    if s.repeated < s.poses {
        println!(
            "  {} approached once {} AP only (RP needs at least 2 approaches; ISO 9283 asks {ISO_CYCLES})",
            count(s.poses - s.repeated, "pose"),
            if s.poses - s.repeated == 1 { "has" } else { "have" }
        );
    }
    println!("  repeated poses (mm, deg):");
    println!(
        "  {:>8} {:>3} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>7} {:>7} {:>7}",
        "pose",
        "n",
        "AP_P",
        "AP_x",
        "AP_y",
        "AP_z",
        "RP_l",
        "AP_a",
        "AP_b",
        "AP_c",
        "RP_a",
        "RP_b",
        "RP_c"
    );
    for p in r.poses.iter().filter(|p| p.repeatability.is_some()) {
        let c = cells(p);
        println!(
            "  {:>8} {:>3} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>7} {:>7} {:>7}",
            p.pose_id,
            p.approaches,
            c[0],
            c[1],
            c[2],
            c[3],
            c[4],
            c[7],
            c[8],
            c[9],
            c[10],
            c[11],
            c[12]
        );
    }
}

/// A pose's figures as text: AP_P, AP_x, AP_y, AP_z, RP_l, l̄, S_l (mm, 4 decimals), AP_a,
/// AP_b, AP_c, RP_a, RP_b, RP_c (deg, 4 decimals); `-` where there is none.
fn cells(p: &PoseFigures) -> [String; 13] {
    let a = &p.accuracy;
    let r = p.repeatability.as_ref();
    let oa = p.orientation.as_ref().map(|o| &o.accuracy);
    let or = p
        .orientation
        .as_ref()
        .and_then(|o| o.repeatability.as_ref());
    [
        Some(a.ap),
        Some(a.apx),
        Some(a.apy),
        Some(a.apz),
        r.map(|r| r.rp),
        r.map(|r| r.mean_distance),
        r.map(|r| r.std_distance),
        oa.map(|o| o.apa_deg),
        oa.map(|o| o.apb_deg),
        oa.map(|o| o.apc_deg),
        or.map(|o| o.rpa_deg),
        or.map(|o| o.rpb_deg),
        or.map(|o| o.rpc_deg),
    ]
    .map(|v| fig(v, 4))
}

/// Every pose's figures, before and after (`--out`).
fn pose_table(rec: &PerformanceRecord) -> String {
    let mut t = Table::new([
        "model",
        "pose_id",
        "observed",
        "approaches",
        "command_x_mm",
        "command_y_mm",
        "command_z_mm",
        "ap_p_mm",
        "ap_x_mm",
        "ap_y_mm",
        "ap_z_mm",
        "rp_l_mm",
        "l_mean_mm",
        "s_l_mm",
        "ap_a_deg",
        "ap_b_deg",
        "ap_c_deg",
        "rp_a_deg",
        "rp_b_deg",
        "rp_c_deg",
    ]);
    for m in std::iter::once(&rec.before).chain(&rec.after) {
        for p in &m.report.poses {
            let mut row = vec![
                m.model.clone(),
                p.pose_id.clone(),
                p.observed.clone(),
                p.approaches.to_string(),
            ];
            row.extend(p.command_mm.iter().map(|v| format!("{v:.4}")));
            row.extend(
                cells(p)
                    .into_iter()
                    .map(|c| if c == "-" { String::new() } else { c }),
            );
            t.row(row);
        }
    }
    t.into_string()
}
