//! The joint ranges an estimate was fitted on and the warning outside them: a revolute joint
//! is compared in the turn nearest its range (every term of the model is periodic in the
//! angle), a prismatic joint is not, and a little slack at the ends is inside.

use armcal::identify::fitted_ranges::{outside_warning, FittedRange};
use armcal::{Joint, JointKind};

fn joint(kind: JointKind) -> Joint {
    Joint {
        name: "q1".into(),
        kind,
        lower: -10.0,
        upper: 10.0,
    }
}

/// The warning for one configuration with the joint at `v` (display units) against the
/// range [`lower`, `upper`].
fn warning(kind: JointKind, lower: f64, upper: f64, v: f64) -> Option<String> {
    let range = FittedRange {
        joint: "q1".into(),
        unit: "deg".into(),
        lower,
        upper,
    };
    let f = kind.unit().display_factor();
    outside_warning(&[range], &[joint(kind)], &[("p".into(), vec![v / f])])
}

#[test]
fn a_revolute_joint_is_compared_in_the_turn_nearest_its_fitted_range() {
    let r = JointKind::Revolute;
    assert_eq!(warning(r, -10.0, 10.0, 5.0), None);
    let w = warning(r, -10.0, 10.0, 20.0).unwrap();
    assert!(
        w.starts_with("1 of 1 configurations lie outside")
            && w.contains("`q1` fitted on [-10.000, 10.000] deg, up to 10.000 deg beyond at `p`"),
        "{w}"
    );
    assert!(warning(r, -10.0, 10.0, -25.0)
        .unwrap()
        .contains("up to 15.000 deg"));
    // 355° is −5°, 370° is 10°: inside; 380° is 20°, 10° beyond.
    assert_eq!(warning(r, -10.0, 10.0, 355.0), None);
    assert_eq!(warning(r, -10.0, 10.0, 370.0), None);
    assert!(warning(r, -10.0, 10.0, 380.0)
        .unwrap()
        .contains("up to 10.000 deg"));
    // A range a full turn wide holds every angle.
    assert_eq!(warning(r, -200.0, 170.0, -300.0), None);
    // Slack: 0.1 % of the width (at least of 1 unit).
    assert_eq!(warning(r, -10.0, 10.0, 10.015), None);
    assert!(warning(r, -10.0, 10.0, 10.03).is_some());
    // A prismatic joint does not wrap.
    assert!(warning(JointKind::Prismatic, -10.0, 10.0, 350.0)
        .unwrap()
        .contains("up to 340.000"));
    // An estimate of an older armcal records no ranges: no warning.
    assert_eq!(
        outside_warning(&[], &[joint(r)], &[("p".into(), vec![9.0])]),
        None
    );
}
