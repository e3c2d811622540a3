use armcal::cell::Cell;
use armcal::geometry::*;
use armcal::model::*;
use rand::{Rng, SeedableRng};
use std::path::Path;

const CELL: &str = include_str!("../../../examples/paper-cell-obstacles.toml");

#[test]
fn explore() {
    let cell = Cell::from_toml(CELL, "x", Path::new(".")).unwrap();
    let m = &cell.model;
    let p = m.nominal();
    let mut d = Data::<f64>::new(m);
    let deg = |v: [f64; 6]| v.map(f64::to_radians);
    for (name, q) in [
        ("zero", deg([0.0; 6])),
        ("q2=-77", deg([0.0, -77.0, 0.0, 0.0, 0.0, 0.0])),
        ("q2=-90", deg([0.0, -90.0, 0.0, 0.0, 0.0, 0.0])),
        ("q2=31", deg([0.0, 31.0, 0.0, 0.0, 0.0, 0.0])),
        ("work", deg([0.0, -30.0, 30.0, 0.0, -90.0, 0.0])),
        ("home", deg([0.0, -90.0, 90.0, 0.0, 0.0, 0.0])),
    ] {
        forward_kinematics(m, &mut d, &p, &q);
        println!("{name}:");
        for (l, f) in m.links.iter().zip(&d.frames) {
            println!(
                "  {:5} {:8.1} {:8.1} {:8.1}  z=({:5.2},{:5.2},{:5.2})",
                l.spec.name,
                f.trans[0],
                f.trans[1],
                f.trans[2],
                f.rot[(0, 2)],
                f.rot[(1, 2)],
                f.rot[(2, 2)]
            );
        }
        let t = &d.targets[0];
        println!(
            "  refl  {:8.1} {:8.1} {:8.1}",
            t.trans[0], t.trans[1], t.trans[2]
        );
    }
    println!("tracker {:?}", d.instrument.trans);
    let opts = ConstraintOptions::default();
    let set = ConstraintSet::new(&cell, &opts).unwrap();
    println!("{} constraints", set.len());
    for n in set.names() {
        println!("  {n}");
    }
    let inc = ConstraintSet::new(
        &cell,
        &ConstraintOptions {
            collisions: false,
            line_of_sight: false,
            ..opts.clone()
        },
    )
    .unwrap();
    let mut ws = set.workspace();
    let mut wi = inc.workspace();
    let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(9);
    let (lo, hi) = m.joint_limits();
    let n = 20000;
    let (mut ninc, mut nall) = (0, 0);
    let mut hist = std::collections::BTreeMap::<String, usize>::new();
    for _ in 0..n {
        let q: Vec<f64> = lo
            .iter()
            .zip(&hi)
            .map(|(a, b)| r.random_range(*a..*b))
            .collect();
        let fi = inc.feasible(&mut wi, &p, &q);
        if fi {
            ninc += 1;
        }
        if set.feasible(&mut ws, &p, &q) {
            nall += 1;
        } else if fi {
            // which fails?
            for (i, v) in ws.values.iter().enumerate() {
                if *v < 0.0 {
                    *hist.entry(set.name(i).to_string()).or_default() += 1;
                }
            }
        }
    }
    // collision-only stats
    let col = ConstraintSet::new(
        &cell,
        &ConstraintOptions {
            incidence: false,
            line_of_sight: false,
            ..opts.clone()
        },
    )
    .unwrap();
    let los = ConstraintSet::new(
        &cell,
        &ConstraintOptions {
            incidence: false,
            collisions: false,
            ..opts.clone()
        },
    )
    .unwrap();
    let mut wc = col.workspace();
    let mut wl = los.workspace();
    let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(10);
    let (mut ncol, mut nlos, mut nlos_inc, mut ninc2) = (0, 0, 0, 0);
    let mut h2 = std::collections::BTreeMap::<String, usize>::new();
    for _ in 0..n {
        let q: Vec<f64> = lo
            .iter()
            .zip(&hi)
            .map(|(a, b)| r.random_range(*a..*b))
            .collect();
        if col.feasible(&mut wc, &p, &q) {
            ncol += 1;
        } else {
            for (i, v) in wc.values.iter().enumerate() {
                if *v < 0.0 {
                    *h2.entry(col.name(i).to_string()).or_default() += 1;
                }
            }
        }
        let l = los.feasible(&mut wl, &p, &q);
        if l {
            nlos += 1;
        }
        if inc.feasible(&mut wi, &p, &q) {
            ninc2 += 1;
            if l {
                nlos_inc += 1;
            }
        }
    }
    println!(
        "collision-free {:.2}%  los {:.2}%  los|inc {:.2}%",
        100.0 * ncol as f64 / n as f64,
        100.0 * nlos as f64 / n as f64,
        100.0 * nlos_inc as f64 / ninc2 as f64
    );
    for (k, v) in h2 {
        println!("  {k}: {:.2}%", 100.0 * v as f64 / n as f64);
    }
    for (name, q) in [
        ("work", deg([0.0, -30.0, 30.0, 0.0, -90.0, 0.0])),
        ("home", deg([0.0, -90.0, 90.0, 0.0, 0.0, 0.0])),
        ("home77", deg([0.0, -77.0, 90.0, 0.0, 0.0, 0.0])),
    ] {
        let mut v = vec![0.0; set.len()];
        set.evaluate(&mut ws, &p, &q, &mut v, None);
        let m = set.min_margin(&v).unwrap();
        let mc = col.min_margin_at(&mut wc, &p, &q).unwrap();
        println!(
            "{name}: min {} {:.1}; collisions min {} {:.1}",
            m.name, m.value, mc.name, mc.value
        );
    }
    println!(
        "incidence only {:.2}%  all {:.2}%",
        100.0 * ninc as f64 / n as f64,
        100.0 * nall as f64 / n as f64
    );
    for (k, v) in hist {
        println!("  {k}: {v}");
    }
}
