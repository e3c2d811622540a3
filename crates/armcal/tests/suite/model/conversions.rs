//! Every conversion of `model::convert` keeps the forward kinematics: tool and targets agree
//! to 1e-9 mm and their rotations to 1e-12 on random configurations, for the paper robot,
//! the book's PUMA 560 (both models) and random chains. Round trips recover the parameters.

use crate::common;
use armcal::model::convert::{dh_to_mdh, mdh_to_dh, to_zrp, zrp_to_dh};
use armcal::model::*;
use armcal::{robots, JointKind, Model, Unit};
use common::*;

const POS_TOL: f64 = 1e-9;
const ROT_TOL: f64 = 1e-12;

/// Tool and every target of `b` against `a` at 50 random configurations of `a`'s limits.
fn assert_same_fk(a: &ModelSpec, b: &ModelSpec, seed: u64, what: &str) {
    let ma = Model::from_spec(a).unwrap_or_else(|e| panic!("{what}: {e}"));
    let mb = Model::from_spec(b).unwrap_or_else(|e| panic!("{what}: converted model: {e}"));
    assert_eq!(ma.dof(), mb.dof(), "{what}: joint count");
    let (pa, pb) = (ma.nominal(), mb.nominal());
    let mut r = rng(seed);
    let (mut da, mut db) = (Data::new(&ma), Data::new(&mb));
    for _ in 0..50 {
        let q = random_q(&ma, &mut r);
        forward_kinematics(&ma, &mut da, &pa, &q);
        forward_kinematics(&mb, &mut db, &pb, &q);
        let mut pairs = vec![(da.tool(), db.tool(), "tool".to_string())];
        for (k, t) in ma.targets.iter().enumerate() {
            pairs.push((&da.targets[k], &db.targets[k], t.spec.name.clone()));
        }
        for (x, y, name) in pairs {
            let dp = (x.trans - y.trans).amax();
            let dr = (x.rot - y.rot).amax();
            assert!(
                dp <= POS_TOL && dr <= ROT_TOL,
                "{what}: {name} differs by {dp:.3e} mm / {dr:.3e} in rotation at q = {q:?}"
            );
        }
    }
}

/// Values of two links with the same convention, equal to 1e-9 (mm) / 1e-12 (rad).
fn assert_same_values(a: &LinkSpec, b: &LinkSpec, what: &str) {
    assert_eq!(
        a.geometry.convention, b.geometry.convention,
        "{what}: link `{}`",
        a.name
    );
    for (i, (x, y)) in a.geometry.values.iter().zip(&b.geometry.values).enumerate() {
        let (field, unit) = a
            .geometry
            .convention
            .fields(a.joint.as_ref().map(|j| j.kind))[i];
        let tol = if unit == Unit::Mm { POS_TOL } else { ROT_TOL };
        assert!(
            (x - y).abs() <= tol,
            "{what}: `{}.{field}` = {x} vs {y}",
            a.name
        );
    }
}

fn robot(name: &str) -> ModelSpec {
    robots::robot(name).unwrap().spec
}

fn zrp_of(spec: &ModelSpec) -> ModelSpec {
    let m = Model::from_spec(spec).unwrap();
    to_zrp(&m, &m.nominal())
}

/// Random chain of `n` links of one convention (revolute and prismatic joints alternating
/// with a fixed link every fourth), between random base and tool frames.
fn random_chain(c: Convention, n: usize, seed: u64) -> ModelSpec {
    let mut r = rng(seed);
    let mut links = vec![LinkSpec {
        name: "base".into(),
        geometry: random_geometry(Convention::Frame6, None, &mut r),
        joint: None,
    }];
    for i in 1..=n {
        let kind = match i % 4 {
            0 => None,
            2 => Some(JointKind::Prismatic),
            _ => Some(JointKind::Revolute),
        };
        links.push(LinkSpec {
            name: format!("j{i}"),
            geometry: random_geometry(c, kind, &mut r),
            joint: kind.map(|k| joint(&format!("q{i}"), k)),
        });
    }
    links.push(LinkSpec {
        name: "tool".into(),
        geometry: random_geometry(Convention::Frame6, None, &mut r),
        joint: None,
    });
    ModelSpec {
        compliance: None,
        periodic: None,
        payloads: Vec::new(),
        name: format!("random-{c}"),
        instrument: None,
        links,
        targets: vec![],
    }
}

#[test]
fn to_zrp_is_exact() {
    for seed in 0..4 {
        let m = every_convention_model(seed);
        let zrp = to_zrp(&m, &m.nominal());
        assert_same_fk(&m.spec(), &zrp, seed, "every convention → zrp");
        assert!(zrp.links[1..zrp.links.len() - 1]
            .iter()
            .all(|l| l.geometry.convention == Convention::Zrp));
    }
    for name in ["paper", "puma560", "puma560-zrp"] {
        assert_same_fk(&robot(name), &zrp_of(&robot(name)), 7, name);
    }
}

#[test]
fn zrp_to_dh_is_exact() {
    for seed in 0..4 {
        let m = every_convention_model(seed);
        let dh = zrp_to_dh(&m.spec(), None).unwrap();
        assert_same_fk(&m.spec(), &dh, seed, "every convention → dh");
        let zrp = to_zrp(&m, &m.nominal());
        let dh = zrp_to_dh(&zrp, None).unwrap();
        assert_same_fk(&zrp, &dh, seed, "every convention → zrp → dh");
        let inner = &dh.links[..dh.links.len() - 1];
        assert!(inner
            .iter()
            .all(|l| l.geometry.convention == Convention::Dh));
    }
    // The paper robot and the PUMA have exactly parallel axes 2 and 3 (the parallel rule)
    // and intersecting wrist axes; the paper robot's axis 1 is the world z axis (coincident).
    for name in ["paper", "puma560", "puma560-zrp"] {
        let spec = robot(name);
        assert_same_fk(&spec, &zrp_to_dh(&spec, None).unwrap(), 3, name);
        let zrp = zrp_of(&spec);
        assert_same_fk(&zrp, &zrp_to_dh(&zrp, None).unwrap(), 4, name);
        assert_same_fk(&zrp, &zrp_to_dh(&zrp, Some(&spec)).unwrap(), 5, name);
    }
}

/// DH → ZRP → DH with the PUMA's own Table 6.1 as nominal gives Table 6.1 back: the common
/// normals, the Hayati link 1→2, the sign rule and the Type 3 last link are all recovered.
#[test]
fn puma_round_trip_through_zrp_recovers_table_6_1() {
    let puma = robot("puma560");
    let back = zrp_to_dh(&zrp_of(&puma), Some(&puma)).unwrap();
    assert_eq!(back.links.len(), puma.links.len());
    for (a, b) in back.links.iter().zip(&puma.links) {
        assert_eq!(a.name, b.name);
        assert_same_values(a, b, "puma560 → zrp → dh");
    }
}

/// The same for the paper robot, except its last link: without a Type 3 link in the nominal
/// the last joint becomes `Rz(θ+q)` and the tool frame takes the rest.
#[test]
fn paper_round_trip_through_zrp_recovers_its_links() {
    let paper = robot("paper");
    let back = zrp_to_dh(&zrp_of(&paper), Some(&paper)).unwrap();
    assert_same_fk(&paper, &back, 11, "paper → zrp → dh");
    for name in ["j1", "j2", "j3", "j4", "j5"] {
        let find = |s: &ModelSpec| s.links.iter().find(|l| l.name == name).unwrap().clone();
        assert_same_values(&find(&back), &find(&paper), "paper → zrp → dh");
    }
}

#[test]
fn dh_and_mdh_regroup_exactly() {
    for seed in 0..6 {
        let dh = random_chain(Convention::Dh, 9, seed);
        let mdh = dh_to_mdh(&dh).unwrap();
        assert_same_fk(&dh, &mdh, seed, "dh → mdh");
        let back = mdh_to_dh(&mdh).unwrap();
        assert_same_fk(&dh, &back, seed, "dh → mdh → dh");
        // The last DH link's Tx(a) Rx(α) went into the tool frame and stays there.
        for (a, b) in back.links[1..back.links.len() - 2]
            .iter()
            .zip(&dh.links[1..dh.links.len() - 2])
        {
            assert_same_values(a, b, "dh → mdh → dh");
        }

        let mdh = random_chain(Convention::Mdh, 9, 100 + seed);
        let dh = mdh_to_dh(&mdh).unwrap();
        assert_same_fk(&mdh, &dh, seed, "mdh → dh");
        assert_same_fk(&mdh, &dh_to_mdh(&dh).unwrap(), seed, "mdh → dh → mdh");
    }
    // Whole robots, through their all-DH form (the base is then a fixed DH link).
    for name in ["paper", "puma560", "puma560-zrp"] {
        let dh = zrp_to_dh(&robot(name), None).unwrap();
        let mdh = dh_to_mdh(&dh).unwrap();
        assert_same_fk(&dh, &mdh, 21, name);
        assert_same_fk(&dh, &mdh_to_dh(&mdh).unwrap(), 22, name);
    }
}

/// The paper robot's Hayati link j2 (parallel axes 2–3) regroups into modified DH with β:
/// `Tx(a) Rx(α) Ry(β)` leads link j3, which becomes `mdh_beta` (issue 10, item 8).
#[test]
fn a_hayati_link_regroups_into_modified_dh_with_beta() {
    let mut paper = robot("paper");
    let j2 = paper.links.iter().position(|l| l.name == "j2").unwrap();
    paper.links[j2].geometry.values[3] = 0.05f64.to_radians();
    let mdh = dh_to_mdh(&paper).unwrap();
    let j3 = mdh.links.iter().find(|l| l.name == "j3").unwrap();
    assert_eq!(j3.geometry.convention, Convention::MdhBeta);
    assert!((j3.geometry.values[2] - 0.05f64.to_radians()).abs() < 1e-15);
    assert_same_fk(&paper, &mdh, 23, "paper");
}

#[test]
fn regrouping_refuses_links_it_cannot_absorb() {
    // An MDH link ahead of a DH link's trailing Tx(a) Rx(α) cannot take it.
    let mut mixed = random_chain(Convention::Dh, 3, 3);
    mixed.links[2].geometry = armcal::model::LinkGeometry::mdh(0.1, 20.0, 0.2, 30.0);
    let e = dh_to_mdh(&mixed).unwrap_err().to_string();
    assert!(e.contains("(mdh)"), "{e}");
    // A DH chain that ends without a frame6 cannot place the last Tx(a) Rx(α).
    let mut dh = random_chain(Convention::Dh, 3, 1);
    dh.links.pop();
    let e = dh_to_mdh(&dh).unwrap_err().to_string();
    assert!(e.contains("ends the chain"), "{e}");
    // An MDH chain whose first link has α ≠ 0 and no frame before it.
    let mut mdh = random_chain(Convention::Mdh, 3, 2);
    mdh.links.remove(0);
    let e = mdh_to_dh(&mdh).unwrap_err().to_string();
    assert!(e.contains("`j1`") && e.contains("starts the chain"), "{e}");
}
