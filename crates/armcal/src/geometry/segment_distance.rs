//! Closest points between two line segments and the gradient of their distance with
//! respect to the four endpoints.
//!
//! The capsule–capsule constraint of the paper (Jost et al. 2017, eq. 20) is
//! `d(b₁, b₂) = d_P(b₁, b₂) − (r₁ + r₂) ≥ 0`, with `d_P` the distance between the capsules'
//! axis segments (eq. 21). The paper computes `d_P` with Lumelsky's algorithm; here it is
//! the equivalent clamped-parameter method of Ericson, *Real-Time Collision Detection*
//! (2005) §5.1.9: minimise
//!
//! ```text
//! |P(s) − Q(t)|²,  P(s) = A₀ + s (A₁ − A₀),  Q(t) = B₀ + t (B₁ − B₀),  s, t ∈ [0, 1],
//! ```
//!
//! by solving the 2×2 normal equations of the two infinite lines, clamping `s` to [0, 1],
//! recomputing `t` for that `s`, and, if `t` had to be clamped, recomputing and clamping `s`.
//! With `d₁ = A₁ − A₀`, `d₂ = B₁ − B₀`, `r = A₀ − B₀`, `a = d₁·d₁`, `e = d₂·d₂`, `b = d₁·d₂`,
//! `c = d₁·r`, `f = d₂·r`, the line solution is `s = (b f − c e) / (a e − b²)` and
//! `t = (b s + f) / e`.
//!
//! Special cases (the three of the paper's Lumelsky test, handled explicitly so no division
//! by a vanishing quantity happens):
//! - a segment shorter than `1e-14` of the problem's size is treated as its first endpoint
//!   (the point–segment or point–point distance is exact);
//! - parallel segments (`a e − b² ≤ 8 ε a e`, i.e. an angle below ≈ 4·10⁻⁸ rad): the
//!   distance is attained along the whole overlap of the two projections; `s` is taken at
//!   the middle of the overlap (or at the nearer end when the projections do not overlap)
//!   and `t` is the projection of `P(s)` onto the second segment.
//!
//! # Gradient
//! With `n = (P − Q) / |P − Q|` the unit vector from the second segment's closest point to the
//! first's, the envelope theorem (at an optimal `(s, t)`, either `∂d/∂s = 0` or `s` sits on a
//! bound that does not move with the endpoints) gives
//!
//! ```text
//! ∂d/∂A₀ = (1 − s) n,   ∂d/∂A₁ = s n,   ∂d/∂B₀ = −(1 − t) n,   ∂d/∂B₁ = −t n.
//! ```
//!
//! For a rigid motion of either segment, this means the rate of `d` is `n · (velocity of P)`
//! minus `n · (velocity of Q)`: only the closest points' velocities along `n` matter.
//!
//! Where `d` is not differentiable the returned vector is still an element of its Clarke
//! subdifferential:
//! - **`d = 0`** (the segments intersect): `n` and all four gradients are **zero**. The
//!   distance attains its global minimum 0 there, so zero is a valid subgradient, but it
//!   gives no direction: a solver that needs one should keep capsules from ever reaching
//!   `d = 0` (a capsule constraint `d − r₁ − r₂ ≥ 0` is violated long before);
//! - parallel, overlapping segments: the closest points are not unique; the gradient is the
//!   one at the middle of the overlap (the average of the one-sided rotation derivatives).
//!
//! The function allocates nothing and takes ≈ 20 ns with its gradient (`benches/geometry.rs`).

use nalgebra::Vector3;

/// Result of [`segment_distance`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentDistance {
    /// Distance between the segments, `|P − Q|` (≥ 0).
    pub distance: f64,
    /// Parameter of the closest point on the first segment: `P = A₀ + s (A₁ − A₀)`, in [0, 1].
    pub s: f64,
    /// Parameter of the closest point on the second segment: `Q = B₀ + t (B₁ − B₀)`, in [0, 1].
    pub t: f64,
    /// Closest point on the first segment.
    pub p: Vector3<f64>,
    /// Closest point on the second segment.
    pub q: Vector3<f64>,
    /// Unit vector `(P − Q) / |P − Q|`; zero when the distance is zero.
    pub normal: Vector3<f64>,
}

impl SegmentDistance {
    /// Gradient of the distance with respect to `[A₀, A₁, B₀, B₁]`:
    /// `[(1 − s) n, s n, −(1 − t) n, −t n]` (all zero when the distance is zero; see the
    /// module documentation).
    #[inline]
    pub fn gradient(&self) -> [Vector3<f64>; 4] {
        let n = self.normal;
        [
            n * (1.0 - self.s),
            n * self.s,
            -n * (1.0 - self.t),
            -n * self.t,
        ]
    }
}

/// Closest points, distance and parameters between segments `A₀A₁` and `B₀B₁` (Ericson
/// §5.1.9, robust for parallel and point-like segments; see the module documentation).
#[inline]
pub fn segment_distance(
    a0: &Vector3<f64>,
    a1: &Vector3<f64>,
    b0: &Vector3<f64>,
    b1: &Vector3<f64>,
) -> SegmentDistance {
    let d1 = a1 - a0;
    let d2 = b1 - b0;
    let r = a0 - b0;
    let a = d1.dot(&d1);
    let e = d2.dot(&d2);
    let f = d2.dot(&r);
    // A segment is a point when its squared length is below (1e-14 · size)².
    let tiny = 1e-28 * (a + e + r.dot(&r));
    let (s, t) = if a <= tiny && e <= tiny {
        (0.0, 0.0)
    } else if a <= tiny {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e <= tiny {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            if denom > 8.0 * f64::EPSILON * a * e {
                // General position: line solution, clamped (Ericson §5.1.9).
                let mut s = ((b * f - c * e) / denom).clamp(0.0, 1.0);
                let mut t = (b * s + f) / e;
                if t < 0.0 {
                    t = 0.0;
                    s = (-c / a).clamp(0.0, 1.0);
                } else if t > 1.0 {
                    t = 1.0;
                    s = ((b - c) / a).clamp(0.0, 1.0);
                }
                (s, t)
            } else {
                // Parallel: projections of B₀ and B₁ onto the first segment's line.
                let p0 = -c / a;
                let p1 = (b - c) / a;
                let (lo_b, hi_b) = if p0 <= p1 { (p0, p1) } else { (p1, p0) };
                let lo = lo_b.max(0.0);
                let hi = hi_b.min(1.0);
                let s = if lo <= hi {
                    0.5 * (lo + hi)
                } else if lo_b > 1.0 {
                    1.0
                } else {
                    0.0
                };
                let t = ((b * s + f) / e).clamp(0.0, 1.0);
                // Back-project so that P is the closest point of the first segment to Q.
                let s = ((b * t - c) / a).clamp(0.0, 1.0);
                (s, t)
            }
        }
    };
    let p = a0 + d1 * s;
    let q = b0 + d2 * t;
    let diff = p - q;
    let distance = diff.norm();
    let normal = if distance > 0.0 {
        diff / distance
    } else {
        Vector3::zeros()
    };
    SegmentDistance {
        distance,
        s,
        t,
        p,
        q,
        normal,
    }
}

/// Distance from point `x` to segment `A₀A₁` and the parameter of the closest point.
#[inline]
pub fn point_segment_distance(
    x: &Vector3<f64>,
    a0: &Vector3<f64>,
    a1: &Vector3<f64>,
) -> (f64, f64) {
    let d = a1 - a0;
    let dd = d.dot(&d);
    let s = if dd > 0.0 {
        ((x - a0).dot(&d) / dd).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ((a0 + d * s - x).norm(), s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use parry3d_f64::math::{Pose, Vector};
    use parry3d_f64::query;
    use parry3d_f64::shape::{Capsule, Segment};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn v(x: &Vector3<f64>) -> Vector {
        Vector::new(x[0], x[1], x[2])
    }

    fn random_point(r: &mut ChaCha8Rng, scale: f64) -> Vector3<f64> {
        Vector3::new(
            r.random_range(-scale..scale),
            r.random_range(-scale..scale),
            r.random_range(-scale..scale),
        )
    }

    /// Random segment pairs of every kind: general, parallel (same or opposite direction,
    /// overlapping or not), collinear, point-like, crossing, identical.
    fn random_pair(r: &mut ChaCha8Rng, k: usize) -> [Vector3<f64>; 4] {
        let a0 = random_point(r, 1000.0);
        let a1 = random_point(r, 1000.0);
        let b0 = random_point(r, 1000.0);
        let b1 = random_point(r, 1000.0);
        match k % 8 {
            0 | 1 => [a0, a1, b0, b1],
            2 => {
                // parallel: B = B₀ + λ (A₁ − A₀)
                let lambda = r.random_range(-1.5..1.5);
                let off = random_point(r, 300.0);
                let start = a0 + (a1 - a0) * r.random_range(-1.0..1.5) + off;
                [a0, a1, start, start + (a1 - a0) * lambda]
            }
            3 => {
                // collinear, possibly overlapping
                let d = a1 - a0;
                let s0 = r.random_range(-1.5..2.0);
                let s1 = r.random_range(-1.5..2.0);
                [a0, a1, a0 + d * s0, a0 + d * s1]
            }
            4 => [a0, a0, b0, b1],
            5 => [a0, a1, b0, b0],
            6 => [a0, a0, b0, b0],
            _ => {
                // crossing: both segments pass through one point
                let x = random_point(r, 500.0);
                let u = random_point(r, 500.0);
                let w = random_point(r, 500.0);
                let (s, t) = (r.random_range(0.0..1.0), r.random_range(0.0..1.0));
                [x - u * s, x + u * (1.0 - s), x - w * t, x + w * (1.0 - t)]
            }
        }
    }

    #[test]
    fn agrees_with_parry_on_random_pairs() {
        let mut r = ChaCha8Rng::seed_from_u64(7);
        let mut worst = 0.0f64;
        let n = 20_000;
        for k in 0..n {
            let [a0, a1, b0, b1] = random_pair(&mut r, k);
            let ours = segment_distance(&a0, &a1, &b0, &b1);
            let s1 = Segment::new(v(&a0), v(&a1));
            let s2 = Segment::new(v(&b0), v(&b1));
            let theirs = query::distance(&Pose::identity(), &s1, &Pose::identity(), &s2)
                .expect("segment distance is supported")
                .distance;
            let err = (ours.distance - theirs).abs();
            worst = worst.max(err);
            assert!(
                err < 1e-9 * (1.0 + theirs),
                "pair {k}: ours {} parry {theirs}",
                ours.distance
            );
            // The reported points are on the segments and realise the distance.
            assert!((ours.p - ours.q).norm() - ours.distance <= 1e-12 * (1.0 + ours.distance));
            assert!((0.0..=1.0).contains(&ours.s) && (0.0..=1.0).contains(&ours.t));
            // Symmetry.
            let back = segment_distance(&b0, &b1, &a0, &a1);
            assert!((back.distance - ours.distance).abs() < 1e-9 * (1.0 + theirs));
        }
        eprintln!("segment distance vs parry: {n} pairs, max |Δ| = {worst:.3e} mm");
    }

    #[test]
    fn capsule_distance_agrees_with_parry() {
        let mut r = ChaCha8Rng::seed_from_u64(11);
        let mut worst = 0.0f64;
        let mut compared = 0;
        for k in 0..5_000 {
            let [a0, a1, b0, b1] = random_pair(&mut r, k);
            let (ra, rb) = (r.random_range(1.0..80.0), r.random_range(1.0..80.0));
            let ours = segment_distance(&a0, &a1, &b0, &b1).distance - ra - rb;
            let c1 = Capsule::new(v(&a0), v(&a1), ra);
            let c2 = Capsule::new(v(&b0), v(&b1), rb);
            let theirs = query::distance(&Pose::identity(), &c1, &Pose::identity(), &c2)
                .expect("capsule distance is supported")
                .distance;
            // parry reports 0 for overlapping capsules.
            if ours <= 0.0 {
                assert!(theirs <= 1e-6, "pair {k}: ours {ours} parry {theirs}");
                continue;
            }
            compared += 1;
            let err = (ours - theirs).abs();
            worst = worst.max(err);
            assert!(
                err < 1e-6 * (1.0 + theirs),
                "pair {k}: ours {ours} parry {theirs}"
            );
        }
        eprintln!(
            "capsule distance vs parry (GJK): {compared} separated pairs, max |Δ| = {worst:.3e} mm"
        );
    }

    #[test]
    fn gradient_matches_finite_differences() {
        let mut r = ChaCha8Rng::seed_from_u64(3);
        let h = 1e-5;
        let mut checked = 0;
        for k in 0..4_000 {
            // General position only: parallel overlap and contact are not differentiable.
            let pts = random_pair(&mut r, 0);
            let sd = segment_distance(&pts[0], &pts[1], &pts[2], &pts[3]);
            if sd.distance < 1.0 {
                continue;
            }
            let g = sd.gradient();
            for (i, gi) in g.iter().enumerate() {
                for c in 0..3 {
                    let mut plus = pts;
                    let mut minus = pts;
                    plus[i][c] += h;
                    minus[i][c] -= h;
                    let dp = segment_distance(&plus[0], &plus[1], &plus[2], &plus[3]).distance;
                    let dm = segment_distance(&minus[0], &minus[1], &minus[2], &minus[3]).distance;
                    let fd = (dp - dm) / (2.0 * h);
                    assert!(
                        (fd - gi[c]).abs() < 1e-6,
                        "pair {k}, endpoint {i}, coordinate {c}: analytic {} fd {fd}",
                        gi[c]
                    );
                }
            }
            checked += 1;
        }
        assert!(checked > 3_000);
    }

    #[test]
    fn gradient_of_parallel_and_point_cases() {
        // Parallel, non-overlapping: unique closest points (end to end), differentiable.
        let a0 = Vector3::new(0.0, 0.0, 0.0);
        let a1 = Vector3::new(100.0, 0.0, 0.0);
        let b0 = Vector3::new(150.0, 30.0, 0.0);
        let b1 = Vector3::new(300.0, 30.0, 0.0);
        let sd = segment_distance(&a0, &a1, &b0, &b1);
        assert_eq!((sd.s, sd.t), (1.0, 0.0));
        assert!((sd.distance - (50.0f64.powi(2) + 30.0f64.powi(2)).sqrt()).abs() < 1e-12);
        // Parallel, overlapping: middle of the overlap [50, 100] on A.
        let b0 = Vector3::new(50.0, 30.0, 0.0);
        let sd = segment_distance(&a0, &a1, &b0, &b1);
        assert!((sd.s - 0.75).abs() < 1e-12, "s = {}", sd.s);
        assert!((sd.distance - 30.0).abs() < 1e-12);
        // Translating B along n changes d at rate 1; along the axis not at all.
        let g = sd.gradient();
        assert!((g[2] + g[3] - Vector3::new(0.0, 1.0, 0.0)).norm() < 1e-12);
        // Point vs segment and point vs point.
        let sd = segment_distance(&a0, &a0, &b0, &b1);
        assert!((sd.distance - (50.0f64.powi(2) + 30.0f64.powi(2)).sqrt()).abs() < 1e-12);
        let sd = segment_distance(&a0, &a0, &a0, &a0);
        assert_eq!(sd.distance, 0.0);
        assert_eq!(sd.gradient(), [Vector3::zeros(); 4]);
        // Crossing segments: distance zero, zero gradient.
        let sd = segment_distance(
            &Vector3::new(-1.0, 0.0, 0.0),
            &Vector3::new(1.0, 0.0, 0.0),
            &Vector3::new(0.0, -1.0, 0.0),
            &Vector3::new(0.0, 1.0, 0.0),
        );
        assert_eq!(sd.distance, 0.0);
        assert_eq!(sd.normal, Vector3::zeros());
    }

    #[test]
    fn point_segment_matches_degenerate_segment() {
        let mut r = ChaCha8Rng::seed_from_u64(5);
        for _ in 0..1000 {
            let x = random_point(&mut r, 1000.0);
            let a0 = random_point(&mut r, 1000.0);
            let a1 = random_point(&mut r, 1000.0);
            let (d, s) = point_segment_distance(&x, &a0, &a1);
            let sd = segment_distance(&a0, &a1, &x, &x);
            assert!((d - sd.distance).abs() < 1e-9);
            assert!((s - sd.s).abs() < 1e-9 || d < 1e-9);
        }
    }
}
