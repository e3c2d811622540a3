//! Distance from a segment to the "ice-cream cone" `K = conv({p} ∪ B(t, D))`: the union of
//! every segment from a point `p` to a point of the ball of radius `D` about `t` — where a
//! laser beam from the reflector `p` can run when the tracker stands anywhere within `D` of
//! `t`.
//!
//! The union of the segments `p → t + δ`, `|δ| ≤ D`, is the union of the balls
//! `B(c(s), s D)` with centres `c(s) = p + s (t − p)`, `s ∈ [0, 1]` (the point at fraction `s`
//! of every such segment lies in `B(c(s), s D)`, and every point of that ball is on one). The
//! distance from a point `x` outside `K` to `K` is therefore
//! `min_s (|x − c(s)| − s D)`, and from a segment `A₀A₁`
//!
//! ```text
//! d(A₀A₁, K) = min_{s ∈ [0,1]} h(s),   h(s) = d(c(s), A₀A₁) − s D,
//! ```
//!
//! a negative value meaning the segment enters `K`. `h` is convex: the distance from an
//! affine point `c(s)` to a convex set is convex in `s`, and `s D` is linear. A golden-section
//! search over `[0, 1]` therefore finds the minimum; 80 steps shrink the bracket below
//! `10⁻¹⁶`, so the result is exact to rounding (not a sample of directions). The minimiser
//! also gives the worst tracker offset: `δ = D (x − c(s))/|x − c(s)|` with `x` the segment's
//! closest point to `c(s)`. Checked against the definition (every offset of a sample on and
//! inside the sphere, and the minimiser's offset attaining the value) in
//! `tests/suite/design/tracker_shift.rs`.

use super::point_segment_distance;
use nalgebra::Vector3;

/// Golden-section steps: `0.618⁸⁰ ≈ 2·10⁻¹⁷` of the unit bracket.
const STEPS: usize = 80;

/// The distance from segment `A₀A₁` to `conv({p} ∪ B(t, radius))` (negative: the segment
/// enters it) and the parameter `s` of the cone section `B(p + s (t − p), s · radius)` that
/// comes closest. With `radius = 0` this is the distance between the segments `pt` and
/// `A₀A₁`.
pub fn segment_cone_distance(
    p: &Vector3<f64>,
    t: &Vector3<f64>,
    radius: f64,
    a0: &Vector3<f64>,
    a1: &Vector3<f64>,
) -> (f64, f64) {
    let h = |s: f64| point_segment_distance(&(p + (t - p) * s), a0, a1).0 - s * radius;
    let ratio = 0.5 * (5f64.sqrt() - 1.0);
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    let mut x1 = hi - ratio * (hi - lo);
    let mut x2 = lo + ratio * (hi - lo);
    let (mut f1, mut f2) = (h(x1), h(x2));
    for _ in 0..STEPS {
        if f1 <= f2 {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - ratio * (hi - lo);
            f1 = h(x1);
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + ratio * (hi - lo);
            f2 = h(x2);
        }
    }
    // The bracket's ends and the endpoints of [0, 1] (a minimum on the boundary).
    [(f1, x1), (f2, x2), (h(0.0), 0.0), (h(1.0), 1.0)]
        .into_iter()
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .unwrap_or((f64::INFINITY, 0.0))
}
