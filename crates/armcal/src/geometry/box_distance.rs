//! Signed distance between a line segment and a box (a rectangular cuboid of any
//! orientation), the closest — or deepest — point of the segment, and the gradient of the
//! distance with respect to the segment's endpoints: what a capsule–box constraint needs
//! (a capsule of radius `r` clears the box iff `d − r ≥ 0`).
//!
//! In the box's own frame (centre at the origin, edges along the axes, half extents `h`) the
//! signed distance of a point `x` is
//!
//! ```text
//! φ(x) = |x − clamp(x, −h, h)|            outside the box,
//! φ(x) = maxᵢ (|xᵢ| − hᵢ)  (≤ 0)           inside (minus the depth below the nearest face),
//! ```
//!
//! a convex function of `x` (Ericson, *Real-Time Collision Detection* §5.1.3 for the outside
//! part). The segment's signed distance is `d = min_{s∈[0,1]} φ(x(s))`, `x(s) = A₀ + s (A₁ −
//! A₀)`, a one-dimensional convex minimisation solved exactly:
//! - the segment misses the box (slab test): `φ²(x(s))` is a quadratic on each interval
//!   between the parameters where `x(s)` crosses one of the six face planes (at most six
//!   crossings, seven intervals); each interval's quadratic is minimised in closed form;
//! - the segment meets the box: on the part inside, `φ` is the largest of the six affine
//!   functions `±xᵢ(s) − hᵢ`; the minimum of such a maximum lies at an end of that part or
//!   where two of the six cross, so the at most 2 + 15 candidates are compared.
//!
//! Inside, `−d` is the depth of the segment's deepest point below the box's surface. That is
//! the penetration depth (the least translation that separates the two) when one end of the
//! segment dips through one face, the overlaps a well-planned pose comes close to; a segment
//! deep across the box can need a longer translation, so `−d` never exceeds the penetration
//! depth. Either way `d − r < 0` exactly when the capsule and the box overlap.
//!
//! # Gradient
//! With `s*` the minimising parameter and `n` the unit outward normal of `φ` at `x(s*)` (the
//! direction from the box's closest point to `x(s*)` outside, the normal of the deepest face
//! inside), the envelope theorem gives `∂d/∂A₀ = (1 − s*) n`, `∂d/∂A₁ = s* n`: a rigid motion
//! changes `d` at the rate `n · (velocity of x(s*))`. Where `d` is not differentiable (a tie
//! between faces or intervals), the value is that of one minimiser and is an element of the
//! Clarke subdifferential. Inside, at a crossing of two faces' values (the deepest point of a
//! segment that passes through the box), `n` is the combination of the two face normals whose
//! component along the segment vanishes (Danskin's theorem), not a unit vector.
//!
//! Allocates nothing: fixed arrays of at most 17 candidates.

use nalgebra::{Matrix3, Vector3};

/// A box: centre, orientation (the columns of `rotation` are its edge directions in the
/// world) and half extents along those edges (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cuboid {
    /// Centre (world, mm).
    pub center: Vector3<f64>,
    /// Rotation from the box frame to the world (orthonormal columns).
    pub rotation: Matrix3<f64>,
    /// Half the edge lengths along the box's x, y and z (mm, ≥ 0).
    pub half: Vector3<f64>,
}

/// Result of [`segment_box_distance`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentBoxDistance {
    /// Signed distance: ≥ 0 the gap between segment and box, < 0 minus the depth of the
    /// segment's deepest point below the box surface.
    pub distance: f64,
    /// Parameter of the segment's closest (or deepest) point: `P = A₀ + s (A₁ − A₀)`.
    pub s: f64,
    /// That point (world).
    pub p: Vector3<f64>,
    /// Outward normal of the box's signed distance at `p` (world): the distance grows at the
    /// rate `normal · Ṗ` when the segment moves. A unit vector, except where the deepest
    /// point sits between two faces (the segment crosses the box): there it is the
    /// combination of the two faces' normals that makes the rate along the segment zero.
    pub normal: Vector3<f64>,
}

impl SegmentBoxDistance {
    /// Gradient of the distance with respect to `[A₀, A₁]`: `[(1 − s) n, s n]`.
    #[inline]
    pub fn gradient(&self) -> [Vector3<f64>; 2] {
        [self.normal * (1.0 - self.s), self.normal * self.s]
    }
}

/// Signed distance from segment `A₀A₁` to `cuboid`, with the segment's closest (deepest)
/// point and the distance's normal (see the module documentation).
pub fn segment_box_distance(
    a0: &Vector3<f64>,
    a1: &Vector3<f64>,
    cuboid: &Cuboid,
) -> SegmentBoxDistance {
    let rt = cuboid.rotation.transpose();
    let x0 = rt * (a0 - cuboid.center);
    let d = rt * (a1 - a0);
    let h = cuboid.half;
    let (s, distance, local) = match slab_interval(&x0, &d, &h) {
        Some((lo, hi)) => deepest(&x0, &d, &h, lo, hi),
        None => closest_outside(&x0, &d, &h),
    };
    SegmentBoxDistance {
        distance,
        s,
        p: a0 + (a1 - a0) * s,
        normal: cuboid.rotation * local,
    }
}

/// The parameters `[lo, hi] ⊂ [0, 1]` where `x0 + s d` lies in the closed box, if any.
fn slab_interval(x0: &Vector3<f64>, d: &Vector3<f64>, h: &Vector3<f64>) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for i in 0..3 {
        if d[i] == 0.0 {
            if x0[i].abs() > h[i] {
                return None;
            }
            continue;
        }
        let t1 = (-h[i] - x0[i]) / d[i];
        let t2 = (h[i] - x0[i]) / d[i];
        lo = lo.max(t1.min(t2));
        hi = hi.min(t1.max(t2));
    }
    (lo <= hi).then_some((lo, hi))
}

/// A segment that misses the box: minimise the piecewise quadratic `φ²` interval by interval.
/// Returns `(s, distance, normal in the box frame)`.
fn closest_outside(
    x0: &Vector3<f64>,
    d: &Vector3<f64>,
    h: &Vector3<f64>,
) -> (f64, f64, Vector3<f64>) {
    let mut cuts = [0.0f64; 8];
    let mut n = 0;
    cuts[n] = 0.0;
    n += 1;
    cuts[n] = 1.0;
    n += 1;
    for i in 0..3 {
        if d[i] != 0.0 {
            for bound in [-h[i], h[i]] {
                let t = (bound - x0[i]) / d[i];
                if t > 0.0 && t < 1.0 {
                    cuts[n] = t;
                    n += 1;
                }
            }
        }
    }
    let cuts = &mut cuts[..n];
    cuts.sort_unstable_by(f64::total_cmp);
    let at = |t: f64| x0 + d * t;
    let mut best = (f64::INFINITY, 0.0);
    for w in cuts.windows(2) {
        let (ta, tb) = (w[0], w[1]);
        let mid = at(0.5 * (ta + tb));
        // On this interval each coordinate stays below, inside or above its slab:
        // φ² = Σ_out (x0ᵢ − bᵢ + t dᵢ)² = A t² + 2 B t + C.
        let (mut qa, mut qb) = (0.0, 0.0);
        for i in 0..3 {
            let b = if mid[i] > h[i] {
                h[i]
            } else if mid[i] < -h[i] {
                -h[i]
            } else {
                continue;
            };
            qa += d[i] * d[i];
            qb += d[i] * (x0[i] - b);
        }
        let t = if qa > 0.0 {
            (-qb / qa).clamp(ta, tb)
        } else {
            ta
        };
        let v = outside_sq(&at(t), h);
        if v < best.0 {
            best = (v, t);
        }
    }
    let (sq, s) = best;
    let x = at(s);
    let diff = x - clamp(&x, h);
    let dist = sq.sqrt();
    let normal = if dist > 0.0 {
        diff / dist
    } else {
        Vector3::zeros()
    };
    (s, dist, normal)
}

fn clamp(x: &Vector3<f64>, h: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(
        x[0].clamp(-h[0], h[0]),
        x[1].clamp(-h[1], h[1]),
        x[2].clamp(-h[2], h[2]),
    )
}

fn outside_sq(x: &Vector3<f64>, h: &Vector3<f64>) -> f64 {
    (x - clamp(x, h)).norm_squared()
}

/// A segment that meets the box on `[lo, hi]`: minimise `max_k (±xᵢ(s) − hᵢ)` there; the
/// candidates are `lo`, `hi` and the crossings of two of the six affine functions.
/// Returns `(s, distance, normal in the box frame)`.
fn deepest(
    x0: &Vector3<f64>,
    d: &Vector3<f64>,
    h: &Vector3<f64>,
    lo: f64,
    hi: f64,
) -> (f64, f64, Vector3<f64>) {
    // Face k = 2i + (0: +xᵢ, 1: −xᵢ): value c_k + m_k s.
    let mut c = [0.0; 6];
    let mut m = [0.0; 6];
    for i in 0..3 {
        c[2 * i] = x0[i] - h[i];
        m[2 * i] = d[i];
        c[2 * i + 1] = -x0[i] - h[i];
        m[2 * i + 1] = -d[i];
    }
    let face_max = |s: f64| {
        let mut best = (f64::NEG_INFINITY, 0);
        for k in 0..6 {
            let v = c[k] + m[k] * s;
            if v > best.0 {
                best = (v, k);
            }
        }
        best
    };
    let mut best = (f64::INFINITY, lo, 0);
    let mut consider = |s: f64| {
        let (v, k) = face_max(s);
        if v < best.0 {
            best = (v, s, k);
        }
    };
    consider(lo);
    consider(hi);
    for j in 0..6 {
        for k in j + 1..6 {
            let dm = m[j] - m[k];
            if dm != 0.0 {
                let s = (c[k] - c[j]) / dm;
                if s > lo && s < hi {
                    consider(s);
                }
            }
        }
    }
    let (v, s, k) = best;
    let face_normal = |k: usize| {
        let mut n = Vector3::zeros();
        n[k / 2] = if k.is_multiple_of(2) { 1.0 } else { -1.0 };
        n
    };
    // At a crossing inside (the minimum where one face's value rises and another's falls),
    // the derivative is the combination λ n_j + (1 − λ) n_l with λ m_j + (1 − λ) m_l = 0
    // (Danskin: the value does not change along s to first order).
    let tol = 1e-12 * (1.0 + v.abs() + d.norm());
    let active = (0..6).filter(|&j| (c[j] + m[j] * s - v).abs() <= tol);
    let rising = active.clone().max_by(|&a, &b| m[a].total_cmp(&m[b]));
    let falling = active.min_by(|&a, &b| m[a].total_cmp(&m[b]));
    let normal = match (rising, falling) {
        (Some(j), Some(l)) if s > lo && s < hi && m[j] > 0.0 && m[l] < 0.0 => {
            let lambda = -m[l] / (m[j] - m[l]);
            face_normal(j) * lambda + face_normal(l) * (1.0 - lambda)
        }
        _ => face_normal(k),
    };
    (s, v.min(0.0), normal)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;
    use parry3d_f64::math::{Pose, Rot3, Vector};
    use parry3d_f64::query;
    use parry3d_f64::shape::{Capsule, Cuboid as ParryCuboid};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn v(x: &Vector3<f64>) -> Vector {
        Vector::new(x[0], x[1], x[2])
    }

    fn point(r: &mut ChaCha8Rng, scale: f64) -> Vector3<f64> {
        Vector3::new(
            r.random_range(-scale..scale),
            r.random_range(-scale..scale),
            r.random_range(-scale..scale),
        )
    }

    fn random_box(r: &mut ChaCha8Rng, min_half: f64) -> (Cuboid, Pose) {
        let center = point(r, 300.0);
        let axis = point(r, 1.0);
        let angle = r.random_range(-3.0..3.0);
        let rot = Rotation3::from_scaled_axis(axis.normalize() * angle);
        let half = Vector3::new(
            r.random_range(min_half..400.0),
            r.random_range(min_half..400.0),
            r.random_range(min_half..400.0),
        );
        let q = nalgebra::UnitQuaternion::from_rotation_matrix(&rot);
        let pose = Pose::from_parts(v(&center), Rot3::from_xyzw(q.i, q.j, q.k, q.w).normalize());
        (
            Cuboid {
                center,
                rotation: *rot.matrix(),
                half,
            },
            pose,
        )
    }

    /// Random segments near, across and inside random boxes, parallel to faces or not,
    /// point-like; against parry's capsule–cuboid distance (GJK) where they are apart.
    #[test]
    fn distance_agrees_with_parry() {
        let mut r = ChaCha8Rng::seed_from_u64(3);
        let (mut worst, mut apart, mut overlapping) = (0.0f64, 0, 0);
        for k in 0..6_000 {
            let (cuboid, pose) = random_box(&mut r, 10.0);
            let mut a0 = point(&mut r, 900.0);
            let mut a1 = point(&mut r, 900.0);
            match k % 4 {
                // parallel to a box edge
                1 => a1 = a0 + cuboid.rotation.column(k % 3) * r.random_range(-600.0..600.0),
                // a point
                2 => a1 = a0,
                // starting inside the box
                3 => {
                    a0 = cuboid.center
                        + cuboid.rotation * point(&mut r, 0.8).component_mul(&cuboid.half)
                }
                _ => {}
            }
            let radius: f64 = r.random_range(0.0..60.0);
            let ours = segment_box_distance(&a0, &a1, &cuboid);
            // The reported point is on the segment and its signed distance is the value.
            assert!((0.0..=1.0).contains(&ours.s));
            let c = Capsule::new(v(&a0), v(&a1), radius.max(1e-9));
            let b = ParryCuboid::new(v(&cuboid.half));
            let theirs = query::distance(&Pose::identity(), &c, &pose, &b)
                .expect("capsule–cuboid distance is supported")
                .distance;
            let value = ours.distance - radius;
            if value <= 0.0 {
                overlapping += 1;
                assert!(theirs <= 1e-6, "case {k}: ours {value} parry {theirs}");
                continue;
            }
            apart += 1;
            let err = (value - theirs).abs();
            worst = worst.max(err);
            assert!(
                err < 1e-6 * (1.0 + theirs),
                "case {k}: ours {value} parry {theirs}"
            );
        }
        assert!(
            apart > 1000 && overlapping > 1000,
            "{apart} apart, {overlapping} overlapping"
        );
        eprintln!("segment–box vs parry: {apart} apart, {overlapping} overlapping, max |Δ| = {worst:.3e} mm");
    }

    /// Overlaps: one end of a capsule dips through one face (the penetration depth is then
    /// the deepest point's depth plus the radius): against parry's signed contact distance.
    /// A segment across the box: our depth never exceeds parry's penetration depth.
    #[test]
    fn penetration_agrees_with_parry_contact() {
        let mut r = ChaCha8Rng::seed_from_u64(5);
        for k in 0..2_000 {
            // Half extents ≥ 50 mm: the end is nearer the +z face than any other, and the
            // segment leaves through it.
            let (cuboid, pose) = random_box(&mut r, 50.0);
            let h = cuboid.half;
            // An end 0.1–20 mm below the middle part of the +z face, the segment leaving
            // upwards and away, steeply.
            let depth: f64 = r.random_range(0.1..20.0);
            let inside = Vector3::new(
                r.random_range(-0.5..0.5) * h.x,
                r.random_range(-0.5..0.5) * h.y,
                h.z - depth.min(0.5 * h.z),
            );
            let up = Vector3::new(r.random_range(-0.3..0.3), r.random_range(-0.3..0.3), 1.0);
            let outside = inside + up * r.random_range(100.0..500.0);
            let world = |x: Vector3<f64>| cuboid.center + cuboid.rotation * x;
            let (a0, a1) = (world(inside), world(outside));
            let radius: f64 = r.random_range(0.0..20.0);
            let ours = segment_box_distance(&a0, &a1, &cuboid).distance - radius;
            let c = Capsule::new(v(&a0), v(&a1), radius.max(1e-9));
            let b = ParryCuboid::new(v(&h));
            let contact = query::contact(&Pose::identity(), &c, &pose, &b, 0.0)
                .expect("supported")
                .expect("they overlap");
            assert!(
                (ours - contact.dist).abs() < 1e-6 * (1.0 + ours.abs()),
                "case {k}: ours {ours}, parry contact {}",
                contact.dist
            );
            // A segment across: never deeper than parry's penetration.
            let (b0, b1) = (
                world(point(&mut r, 1.0).component_mul(&h) * 0.9),
                world(point(&mut r, 3.0).component_mul(&h)),
            );
            let across = segment_box_distance(&b0, &b1, &cuboid).distance - radius;
            let c = Capsule::new(v(&b0), v(&b1), radius.max(1e-9));
            let contact = query::contact(&Pose::identity(), &c, &pose, &b, 0.0)
                .expect("supported")
                .expect("they overlap");
            assert!(
                across < 0.0 && across >= contact.dist - 1e-6,
                "case {k}: ours {across}, parry {}",
                contact.dist
            );
        }
    }

    /// The gradient `[(1 − s) n, s n]` against central finite differences of the distance,
    /// apart and overlapping, away from ties.
    #[test]
    fn gradient_matches_finite_differences() {
        let mut r = ChaCha8Rng::seed_from_u64(9);
        let mut checked = 0;
        for _ in 0..3_000 {
            let (cuboid, _) = random_box(&mut r, 10.0);
            let a = [point(&mut r, 700.0), point(&mut r, 700.0)];
            let base = segment_box_distance(&a[0], &a[1], &cuboid);
            let grad = base.gradient();
            let eps = 1e-4;
            let mut fd = [Vector3::zeros(); 2];
            for (e, fd_e) in fd.iter_mut().enumerate() {
                for i in 0..3 {
                    let mut plus = a;
                    let mut minus = a;
                    plus[e][i] += eps;
                    minus[e][i] -= eps;
                    let f = |p: &[Vector3<f64>; 2]| {
                        segment_box_distance(&p[0], &p[1], &cuboid).distance
                    };
                    fd_e[i] = (f(&plus) - f(&minus)) / (2.0 * eps);
                }
            }
            // Skip kinks (ties between faces or pieces): the one-sided slopes differ there.
            let kink = (0..2).any(|e| {
                (0..3).any(|i| {
                    let mut plus = a;
                    plus[e][i] += 2.0 * eps;
                    let f = |p: &[Vector3<f64>; 2]| {
                        segment_box_distance(&p[0], &p[1], &cuboid).distance
                    };
                    let one_sided = (f(&plus) - base.distance) / (2.0 * eps);
                    (one_sided - fd[e][i]).abs() > 1e-4
                })
            });
            if kink {
                continue;
            }
            checked += 1;
            for e in 0..2 {
                assert!(
                    (grad[e] - fd[e]).norm() < 1e-5,
                    "endpoint {e}: analytic {:?} fd {:?} (d = {})",
                    grad[e],
                    fd[e],
                    base.distance
                );
            }
        }
        assert!(checked > 2_500, "only {checked} cases away from kinks");
    }
}
