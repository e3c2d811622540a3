//! The equivalent parameter set nearest the nominal. A fitted model has many parameter
//! vectors with identical forward kinematics; a solver may stop in any of them (an angle of
//! 360.13° for 0.13°, or a DH link with θ and `a` flipped). [`nearest_branch`] maps a
//! parameter vector to the exactly equivalent one whose angles are nearest the nominal, and
//! flags the angles that stay far from nominal because no equivalent brings them closer.
//!
//! Exact equivalences (each an affine map `v ↦ ±v + c` of some fields; `R(π)` commutes with
//! the translation along its own axis and `Rz(π) Tx(a) = Tx(−a) Rz(π)`,
//! `Rz(π) Rx(φ) = Rx(−φ) Rz(π)`, `Rz(π) Ry(φ) = Ry(−φ) Rz(π)`, `Rz(π)² = I`):
//!
//! * Wrap: every angle `φ ≡ φ ± 2π`.
//! * DH split: `Rz(θ+q) Tz(d) Tx(a) Rx(α) = Rz(θ−π+q) Tz(d) Tx(−a) Rx(−α) · Rz(π)`
//!   (prismatic: `Tz(d+q)`, same map). Hayati split: `Rz(θ+q) Tx(a) Rx(α) Ry(β) =
//!   Rz(θ−π+q) Tx(−a) Rx(−α) Ry(−β) · Rz(π)` (prismatic `Rz(θ) Tz(d+q) Tx(a) Rx(α) Ry(β)`:
//!   the same with `d` kept). Craig MDH split: `Rx(α) Tx(a) Rz(θ+q) Tz(d) =
//!   Rx(α) Tx(a) Rz(θ−π+q) Tz(d) · Rz(π)`. S-model split: `γ → γ − π` (`Rz(γ) Tz(b) =
//!   Rz(γ−π) Tz(b) Rz(π)`). The `Rz(π)` split off a link is passed on to the next link.
//! * Absorbing a leading `Rz(π)`: DH, Hayati: `θ → θ + π`; S-model: `β → β + π`; book
//!   Type 3: `tz → tz + π`; MDH: `Rz(π) Rx(α) Tx(a) Rz(θ+q) Tz(d) =
//!   Rx(−α) Tx(−a) Rz(θ+π+q) Tz(d)`; frame6 and the URDF origin:
//!   `Rz(π) T(x,y,z) Rz(rz) … = T(−x,−y,z) Rz(rz+π) …`; a point passes it on:
//!   `Rz(π) T(x,y,z) = T(−x,−y,z) Rz(π)`. So a DH link flip `(θ, d, a, α) → (θ−π, d, −a, −α)`
//!   is exact when the next link absorbs the `Rz(π)`, and an MDH flip
//!   `(α, a, θ, d) → (−α, −a, θ+π, d)` is exact when the previous link splits one off.
//! * Within one link: the Z-Y-X Euler angles of frame6, the URDF origin and book Type 3,
//!   `Rz(a) Ry(b) Rx(c) = Rz(a+π) Ry(π−b) Rx(c+π)` (since `Rz(π) Ry(π−b) Rx(π) = Ry(b)`);
//!   the S-model `(β, r, l, α, γ, b) → (β−π, r, −l, −α, γ−π, b)` (its `Rz(γ)` absorbs the
//!   `Rz(π)` of the DH-like front part).
//!
//! The chain (base, links, tool) is searched by dynamic programming over "an `Rz(π)` is
//! passed on or not" for the combination of these maps with the smallest total angular
//! distance `Σ |wrap(φ − φ_nom)| + Σ |ℓ − ℓ_nom| / 1000 mm` (angles, and lengths at 1 rad
//! per metre; ties: fewer changes); instrument and targets only get the maps
//! within a link. Only free parameters change: a map that would change a fixed parameter or
//! one with a prior (its prior row depends on the value) is not used. Every map has a
//! diagonal ±1 Jacobian, so the covariance of the mapped parameters is `S C_p S`.
//!
//! (Over 600 lines with its tests, ~270 of them: one algorithm, the code itself ~360 lines.)

use crate::model::convert::wrap;
use crate::model::link::{Convention, JointKind};
use crate::model::registry::{ParameterStatus, Unit};
use crate::model::{Link, Model};
use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_2, PI};

/// One exact map of a link's fields: `(field, sign, shift)` means `v ↦ sign·v + shift`.
type Map = &'static [(usize, f64, f64)];

/// The exact maps a convention admits (see the module documentation).
#[derive(Default)]
struct Maps {
    /// Absorbs a leading `Rz(π)`; `true` if an `Rz(π)` is passed on (a point).
    absorb: Option<(Map, bool)>,
    /// Splits off a trailing `Rz(π)`, passed on to the next link.
    split: Option<Map>,
    /// Equivalent values of the link on its own.
    within: Option<Map>,
}

const EULER: Map = &[(3, 1.0, PI), (4, -1.0, PI), (5, 1.0, PI)];
const ORIGIN_ABSORB: Map = &[(0, -1.0, 0.0), (1, -1.0, 0.0), (5, 1.0, PI)];
const THETA_ABSORB: Map = &[(0, 1.0, PI)];

fn maps(convention: Convention, kind: Option<JointKind>) -> Maps {
    let prismatic = kind == Some(JointKind::Prismatic);
    match convention {
        Convention::Dh => Maps {
            absorb: Some((THETA_ABSORB, false)),
            split: Some(&[(0, 1.0, -PI), (2, -1.0, 0.0), (3, -1.0, 0.0)]),
            within: None,
        },
        Convention::Hayati if prismatic => Maps {
            absorb: Some((THETA_ABSORB, false)),
            split: Some(&[
                (0, 1.0, -PI),
                (2, -1.0, 0.0),
                (3, -1.0, 0.0),
                (4, -1.0, 0.0),
            ]),
            within: None,
        },
        Convention::Hayati => Maps {
            absorb: Some((THETA_ABSORB, false)),
            split: Some(&[
                (0, 1.0, -PI),
                (1, -1.0, 0.0),
                (2, -1.0, 0.0),
                (3, -1.0, 0.0),
            ]),
            within: None,
        },
        Convention::Mdh => Maps {
            absorb: Some((&[(0, -1.0, 0.0), (1, -1.0, 0.0), (2, 1.0, PI)], false)),
            split: Some(&[(2, 1.0, -PI)]),
            within: None,
        },
        // `Rz(π) Rx(α) Tx(a) Ry(β) = Rx(−α) Tx(−a) Ry(−β) Rz(π)`, into θ.
        Convention::MdhBeta => Maps {
            absorb: Some((
                &[(0, -1.0, 0.0), (1, -1.0, 0.0), (2, -1.0, 0.0), (3, 1.0, PI)],
                false,
            )),
            split: Some(&[(3, 1.0, -PI)]),
            within: None,
        },
        Convention::SModel => Maps {
            absorb: Some((THETA_ABSORB, false)),
            split: Some(&[(4, 1.0, -PI)]),
            within: Some(&[(0, 1.0, -PI), (2, -1.0, 0.0), (3, -1.0, 0.0), (4, 1.0, -PI)]),
        },
        Convention::Frame6 | Convention::Urdf => Maps {
            absorb: Some((ORIGIN_ABSORB, false)),
            split: None,
            within: Some(EULER),
        },
        Convention::BookType3 => Maps {
            absorb: Some((&[(5, 1.0, PI)], false)),
            split: None,
            within: Some(EULER),
        },
        Convention::Point => Maps {
            absorb: Some((&[(0, -1.0, 0.0), (1, -1.0, 0.0)], true)),
            ..Maps::default()
        },
        Convention::Zrp => Maps::default(),
    }
}

/// A link's values with the signs of the maps applied so far.
#[derive(Clone, Debug)]
struct Form {
    values: Vec<f64>,
    signs: Vec<f64>,
    /// An `Rz(π)` is passed on to the next link.
    passes: bool,
}

impl Form {
    fn apply(&self, map: Map) -> Form {
        let mut f = self.clone();
        for &(k, s, c) in map {
            f.values[k] = s * f.values[k] + c;
            f.signs[k] *= s;
        }
        f
    }
}

/// The exactly equivalent forms of link `link` at `params`, given whether an `Rz(π)` comes
/// in from the previous link. Empty if the link cannot absorb it.
fn forms(link: &Link, params: &[f64], incoming: bool) -> Vec<Form> {
    let kind = link.spec.joint.as_ref().map(|j| j.kind);
    let m = maps(link.spec.geometry.convention, kind);
    let n = link.param_count();
    let own = Form {
        values: params[link.first_param..link.first_param + n].to_vec(),
        signs: vec![1.0; n],
        passes: false,
    };
    let start = match (incoming, m.absorb) {
        (false, _) => own,
        (true, Some((map, passes))) => Form {
            passes,
            ..own.apply(map)
        },
        (true, None) => return Vec::new(),
    };
    let mut out = vec![start.clone()];
    if let Some(w) = m.within {
        out.push(start.apply(w));
    }
    if let Some(split) = m.split {
        for f in out.clone() {
            out.push(Form {
                passes: !f.passes,
                ..f.apply(split)
            });
        }
    }
    out
}

/// Total angular distance of a form from the nominal, or `None` if it changes a parameter
/// that is not free (when `respect_status`).
fn cost(model: &Model, link: &Link, params: &[f64], f: &Form, respect_status: bool) -> Option<f64> {
    let mut total = 0.0;
    for (k, (&v, &s)) in f.values.iter().zip(&f.signs).enumerate() {
        let i = link.first_param + k;
        let p = model.registry.get(i);
        let changed = match p.unit {
            Unit::Rad => wrap(v - params[i]).abs() > 1e-12,
            _ => (v - params[i]).abs() > 1e-12 * (1.0 + params[i].abs()),
        };
        if respect_status && changed && !matches!(p.status, ParameterStatus::Free) {
            return None;
        }
        if p.unit == Unit::Rad {
            total += wrap(v - p.nominal).abs();
        } else {
            // Lengths count at 1 rad per metre: of two forms with equally near angles the
            // one with lengths near nominal wins (a = 145 over a = −145).
            total += 1e-3 * (v - p.nominal).abs();
        }
        // Prefer fewer changes among equally near forms.
        if s < 0.0 || changed {
            total += 1e-9;
        }
    }
    Some(total)
}

/// The cheapest sequence of forms for links passed in order, where an `Rz(π)` passed on by
/// one link enters the next and none may leave the last one.
fn cheapest(model: &Model, links: &[Link], params: &[f64], respect_status: bool) -> Vec<Form> {
    // best[s]: (cost, forms so far) with `s` = an Rz(π) is pending.
    let mut best: [Option<(f64, Vec<Form>)>; 2] = [Some((0.0, Vec::new())), None];
    for link in links {
        let mut next: [Option<(f64, Vec<Form>)>; 2] = [None, None];
        for (pending, state) in best.iter().enumerate() {
            let Some((c0, chosen)) = state else { continue };
            for f in forms(link, params, pending == 1) {
                let Some(c) = cost(model, link, params, &f, respect_status) else {
                    continue;
                };
                let slot = &mut next[f.passes as usize];
                if slot.as_ref().is_none_or(|(b, _)| c0 + c < *b) {
                    let mut path = chosen.clone();
                    path.push(f);
                    *slot = Some((c0 + c, path));
                }
            }
        }
        best = next;
    }
    // The unchanged forms are always a path without a pending Rz(π).
    best[0].take().map(|b| b.1).unwrap_or_default()
}

/// An angle still more than 90° from its nominal value after the mapping.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FarAngle {
    /// Registry name of the angle (`j4.theta`).
    pub name: String,
    /// Mapped estimate (deg).
    pub estimate_deg: f64,
    /// Nominal value (deg).
    pub nominal_deg: f64,
    /// Sentence saying whether an equivalent within 90° exists and which fixed parameters
    /// it would change.
    pub reason: String,
    /// The fixed parameters (or ones with a prior) an equivalent within 90° would change;
    /// empty when no exactly equivalent parameter set brings the angle within 90°.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub blocked_by: Vec<String>,
}

/// The equivalent parameter vector nearest the nominal.
#[derive(Clone, Debug)]
pub struct NearestBranch {
    /// The mapped full parameter vector (same forward kinematics at every q).
    pub params: Vec<f64>,
    /// `∂(mapped)/∂(original)` of every parameter: +1 or −1.
    pub signs: Vec<f64>,
    /// Free angles more than 90° from nominal that no exact equivalent brings closer.
    pub far: Vec<FarAngle>,
}

/// Every chain of the model: (links, may pass an `Rz(π)` from link to link).
fn chains(model: &Model) -> Vec<(&[Link], bool)> {
    let mut out = vec![(model.links.as_slice(), true)];
    if let Some(i) = &model.instrument {
        out.push((std::slice::from_ref(i), false));
    }
    for t in &model.targets {
        out.push((std::slice::from_ref(t), false));
    }
    out
}

/// Applies the cheapest forms (with or without respecting the free/fixed status) and wraps
/// every free angle to within π of its nominal value.
fn mapped(model: &Model, params: &[f64], respect_status: bool) -> (Vec<f64>, Vec<f64>) {
    let mut out = params.to_vec();
    let mut signs = vec![1.0; params.len()];
    for (links, coupled) in chains(model) {
        let forms = if coupled {
            cheapest(model, links, params, respect_status)
        } else {
            // Separate links: each on its own, nothing passed on.
            links
                .iter()
                .flat_map(|l| cheapest(model, std::slice::from_ref(l), params, respect_status))
                .collect()
        };
        for (link, f) in links.iter().zip(&forms) {
            for (k, (&v, &s)) in f.values.iter().zip(&f.signs).enumerate() {
                out[link.first_param + k] = v;
                signs[link.first_param + k] = s;
            }
        }
    }
    for (i, p) in model.registry.iter().enumerate() {
        if p.unit == Unit::Rad && (matches!(p.status, ParameterStatus::Free) || !respect_status) {
            out[i] = p.nominal + wrap(out[i] - p.nominal);
        } else if p.unit == Unit::Rad {
            // A fixed angle keeps its value up to a whole turn.
            out[i] = params[i] + wrap(out[i] - params[i]);
        }
    }
    (out, signs)
}

/// Maps `params` to the exactly equivalent parameter vector whose angles are nearest the
/// nominal (see the module documentation) and flags free angles still more than 90° from
/// nominal, saying whether an equivalent exists that would need a fixed parameter changed.
pub fn nearest_branch(model: &Model, params: &[f64]) -> NearestBranch {
    let (out, signs) = mapped(model, params, true);
    let far_of = |v: &[f64]| -> Vec<usize> {
        (0..v.len())
            .filter(|&i| {
                let p = model.registry.get(i);
                p.unit == Unit::Rad
                    && p.status.is_free()
                    && wrap(v[i] - p.nominal).abs() > FRAC_PI_2 + 1e-9
            })
            .collect()
    };
    let far_idx = far_of(&out);
    let mut far = Vec::new();
    if !far_idx.is_empty() {
        let (free_of_status, _) = mapped(model, params, false);
        let still_far = far_of(&free_of_status);
        let blocking: Vec<&str> = (0..params.len())
            .filter(|&i| {
                let p = model.registry.get(i);
                !matches!(p.status, ParameterStatus::Free)
                    && (free_of_status[i] - params[i]).abs() > 1e-12 * (1.0 + params[i].abs())
            })
            .map(|i| model.registry.get(i).name.as_str())
            .collect();
        for i in far_idx {
            let p = model.registry.get(i);
            let f = p.unit.display_factor();
            let none = still_far.contains(&i) || blocking.is_empty();
            let reason = if none {
                "no exactly equivalent parameter set brings it within 90° of nominal: the fit \
                 differs from the nominal robot here (check the nominal model and the data)"
                    .to_string()
            } else {
                format!(
                    "an equivalent parameter set within 90° of nominal exists but changes {} (fixed or with a prior): free it to let armcal map the estimate",
                    blocking.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
                )
            };
            far.push(FarAngle {
                name: p.name.clone(),
                estimate_deg: out[i] * f,
                nominal_deg: p.nominal * f,
                reason,
                blocked_by: if none {
                    Vec::new()
                } else {
                    blocking.iter().map(|n| n.to_string()).collect()
                },
            });
        }
    }
    NearestBranch {
        params: out,
        signs,
        far,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{tool_pose, Joint, LinkGeometry, LinkSpec, ModelSpec, Pose};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn takes_joint(c: Convention) -> bool {
        c.joint_field(JointKind::Revolute).is_some()
    }

    /// A link of convention `c` with random values (lengths ±400 mm, angles ±π).
    fn random_link(name: &str, c: Convention, kind: JointKind, r: &mut ChaCha8Rng) -> LinkSpec {
        let joint = takes_joint(c).then(|| Joint {
            name: format!("q_{name}"),
            kind,
            lower: -3.0,
            upper: 3.0,
        });
        let k = joint.as_ref().map(|j| j.kind);
        let values = c
            .fields(k)
            .iter()
            .map(|(_, u)| match u {
                Unit::Rad => r.random_range(-PI..PI),
                _ => r.random_range(-400.0..400.0),
            })
            .collect();
        let mut geometry = LinkGeometry::new(c, values);
        if c == Convention::Urdf {
            geometry.axis = Some([0.3, -0.2, 0.9]);
        }
        LinkSpec {
            name: name.into(),
            geometry,
            joint,
        }
    }

    fn model_of(links: Vec<LinkSpec>) -> Model {
        Model::from_spec(&ModelSpec {
            compliance: None,
            periodic: None,
            payloads: Vec::new(),
            name: "test".into(),
            instrument: None,
            links,
            targets: Vec::new(),
        })
        .unwrap()
    }

    /// Largest position (mm) and rotation (rad) difference of the tool pose at random q.
    fn max_pose_difference(m: &Model, a: &[f64], b: &[f64], r: &mut ChaCha8Rng) -> (f64, f64) {
        let mut worst: (f64, f64) = (0.0, 0.0);
        for _ in 0..20 {
            let q: Vec<f64> = (0..m.dof()).map(|_| r.random_range(-3.0..3.0)).collect();
            let (pa, pb): (Pose<f64>, Pose<f64>) = (tool_pose(m, a, &q), tool_pose(m, b, &q));
            worst.0 = worst.0.max((pa.trans - pb.trans).norm());
            worst.1 = worst.1.max((pa.rot - pb.rot).norm());
        }
        worst
    }

    fn apply(m: &Model, params: &[f64], link: usize, map: Map) -> Vec<f64> {
        let mut out = params.to_vec();
        for &(k, s, c) in map {
            let i = m.links[link].first_param + k;
            out[i] = s * out[i] + c;
        }
        out
    }

    const ALL_KINDS: [JointKind; 2] = [JointKind::Revolute, JointKind::Prismatic];

    /// Every split followed by every absorb (a point passes the `Rz(π)` on to a DH link)
    /// leaves the forward kinematics unchanged at random q, for random link values.
    #[test]
    fn split_then_absorb_is_exact() {
        let mut r = ChaCha8Rng::seed_from_u64(3);
        let mut checked = 0;
        for c1 in Convention::ALL {
            for k1 in ALL_KINDS {
                let Some(split) = maps(c1, Some(k1)).split else {
                    continue;
                };
                for c2 in Convention::ALL {
                    for k2 in ALL_KINDS {
                        let Some((absorb, passes)) = maps(c2, Some(k2)).absorb else {
                            continue;
                        };
                        let mut links = vec![
                            random_link("a", c1, k1, &mut r),
                            random_link("b", c2, k2, &mut r),
                        ];
                        if passes {
                            links.push(random_link("c", Convention::Dh, k2, &mut r));
                        }
                        let m = model_of(links);
                        let p = m.nominal();
                        let mut q = apply(&m, &p, 0, split);
                        q = apply(&m, &q, 1, absorb);
                        if passes {
                            q = apply(&m, &q, 2, THETA_ABSORB);
                        }
                        let (dt, dr) = max_pose_difference(&m, &p, &q, &mut r);
                        assert!(
                            dt < 1e-9 && dr < 1e-12,
                            "{c1:?} {k1:?} split, {c2:?} {k2:?} absorb: {dt:e} mm, {dr:e}"
                        );
                        // Without the absorbing link the split alone is not exact.
                        let only = apply(&m, &p, 0, split);
                        assert!(max_pose_difference(&m, &p, &only, &mut r).1 > 1e-3);
                        checked += 1;
                    }
                }
            }
        }
        assert_eq!(checked, 10 * 18);
    }

    /// The maps within a link (Z-Y-X Euler angles, S-model) and whole turns are exact.
    #[test]
    fn maps_within_a_link_and_wraps_are_exact() {
        let mut r = ChaCha8Rng::seed_from_u64(4);
        for c in Convention::ALL {
            for k in ALL_KINDS {
                let m = model_of(vec![random_link("a", c, k, &mut r)]);
                let p = m.nominal();
                if let Some(within) = maps(c, Some(k)).within {
                    let q = apply(&m, &p, 0, within);
                    let (dt, dr) = max_pose_difference(&m, &p, &q, &mut r);
                    assert!(dt < 1e-9 && dr < 1e-12, "{c:?} {k:?}: {dt:e} mm, {dr:e}");
                    assert!(q.iter().zip(&p).any(|(a, b)| (a - b).abs() > 1e-3));
                }
                let turned: Vec<f64> = p
                    .iter()
                    .zip(m.registry.iter())
                    .map(|(v, par)| match par.unit {
                        Unit::Rad => v + 2.0 * PI * r.random_range(-2..=2) as f64,
                        _ => *v,
                    })
                    .collect();
                let (dt, dr) = max_pose_difference(&m, &p, &turned, &mut r);
                assert!(
                    dt < 1e-9 && dr < 1e-12,
                    "{c:?} {k:?} turns: {dt:e} mm, {dr:e}"
                );
            }
        }
    }

    /// The paper robot with small random errors in every parameter, all free.
    fn paper_robot(r: &mut ChaCha8Rng) -> (Model, Vec<f64>) {
        let m = Model::from_spec(&crate::robots::robot("paper").unwrap().spec).unwrap();
        let p = m
            .nominal()
            .iter()
            .zip(m.registry.iter())
            .map(|(v, par)| match par.unit {
                Unit::Rad => v + r.random_range(-0.02..0.02),
                _ => v + r.random_range(-2.0..2.0),
            })
            .collect();
        (m, p)
    }

    /// Equal up to whole turns of the angles.
    fn same(m: &Model, a: &[f64], b: &[f64]) -> bool {
        m.registry
            .iter()
            .zip(a.iter().zip(b))
            .all(|(p, (x, y))| match p.unit {
                Unit::Rad => wrap(x - y).abs() < 1e-12,
                _ => (x - y).abs() < 1e-12 * (1.0 + y.abs()),
            })
    }

    fn index(m: &Model, name: &str) -> usize {
        m.registry.index_of(name).unwrap()
    }

    /// A fit in another branch (j3 flipped with its Rz(π) in j4, j2 flipped into j3, MDH-free
    /// robot, every angle turned by whole turns) maps back to the parameters near nominal.
    #[test]
    fn flipped_and_turned_estimates_map_back() {
        let mut r = ChaCha8Rng::seed_from_u64(5);
        for _ in 0..10 {
            let (m, near) = paper_robot(&mut r);
            let dh_split = maps(Convention::Dh, None).split.unwrap();
            let mut far = apply(&m, &near, 3, dh_split);
            far = apply(&m, &far, 4, THETA_ABSORB);
            let hayati_split = maps(Convention::Hayati, None).split.unwrap();
            far = apply(&m, &far, 2, hayati_split);
            far = apply(&m, &far, 3, THETA_ABSORB);
            for (v, par) in far.iter_mut().zip(m.registry.iter()) {
                if par.unit == Unit::Rad {
                    *v += 2.0 * PI * r.random_range(-2..=2) as f64;
                }
            }
            let (dt, dr) = max_pose_difference(&m, &near, &far, &mut r);
            assert!(dt < 1e-9 && dr < 1e-12);
            let b = nearest_branch(&m, &far);
            for (i, par) in m.registry.iter().enumerate() {
                assert!(
                    (b.params[i] - near[i]).abs() < 1e-9,
                    "{}: {} vs {}",
                    par.name,
                    b.params[i],
                    near[i]
                );
            }
            assert!(b.far.is_empty(), "{:?}", b.far);
            let flipped = ["j3.a", "j3.alpha", "j2.a", "j2.alpha", "j2.beta"];
            for (i, par) in m.registry.iter().enumerate() {
                let expect = if flipped.contains(&par.name.as_str()) {
                    -1.0
                } else {
                    1.0
                };
                assert_eq!(b.signs[i], expect, "{}", par.name);
            }
        }
    }

    /// An angle far from nominal with no equivalent is flagged as such; one whose equivalent
    /// needs a fixed parameter changed is flagged naming that parameter, and left as it is.
    #[test]
    fn far_angles_without_a_free_equivalent_are_flagged() {
        let mut r = ChaCha8Rng::seed_from_u64(6);
        let (mut m, near) = paper_robot(&mut r);
        let mut off = near.clone();
        off[index(&m, "j3.theta")] += PI;
        let b = nearest_branch(&m, &off);
        assert_eq!(b.far.len(), 1, "{:?}", b.far);
        assert_eq!(b.far[0].name, "j3.theta");
        assert!(
            b.far[0].reason.contains("no exactly equivalent"),
            "{}",
            b.far[0].reason
        );
        assert!(same(&m, &b.params, &off));

        // A robot whose joint 4 is turned by 180°, fitted as j3 flipped with j4.theta at
        // its nominal value: with j4.theta free the flip is undone; with j4.theta (and
        // j5.theta, the other partner) fixed it must stay.
        let (t4, t5) = (index(&m, "j4.theta"), index(&m, "j5.theta"));
        let mut truth = near.clone();
        truth[t4] = m.nominal()[t4] - PI;
        truth[t5] = m.nominal()[t5];
        let dh_split = maps(Convention::Dh, None).split.unwrap();
        let mut flipped = apply(&m, &truth, 3, dh_split);
        flipped = apply(&m, &flipped, 4, THETA_ABSORB);
        flipped[t4] = m.nominal()[t4];
        let free = nearest_branch(&m, &flipped);
        assert!((free.params[index(&m, "j3.a")] - truth[index(&m, "j3.a")]).abs() < 1e-9);
        assert_eq!(free.far.len(), 1, "{:?}", free.far);
        assert_eq!(free.far[0].name, "j4.theta");
        m.registry.set_status(t4, ParameterStatus::Fixed);
        m.registry.set_status(t5, ParameterStatus::Fixed);
        let b = nearest_branch(&m, &flipped);
        assert!(
            same(&m, &b.params, &flipped),
            "a fixed parameter must not change"
        );
        let names: Vec<&str> = b.far.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(names, ["j3.theta", "j3.alpha"], "{:?}", b.far);
        assert!(
            b.far[0].reason.contains("`j4.theta`"),
            "{}",
            b.far[0].reason
        );
    }
}
