//! A capsule that bounds each URDF `<collision>` shape
//! ([`CollisionShape`]), in the shape's chain frame:
//!
//! | shape | bounding capsule |
//! |---|---|
//! | sphere, radius r | the zero-length capsule at its centre, radius r (exact) |
//! | capsule, radius r, length l | itself: ±l/2 along its z axis, radius r (exact) |
//! | cylinder, radius r, length l | ±l/2 along its z axis, radius r: the cylinder plus two end caps |
//! | box, edges a ≥ b ≥ c | ±a/2 along its longest edge, radius √((b/2)² + (c/2)²), the half-diagonal of the cross-section |
//! | mesh | none: armcal does not read meshes; the frame keeps its skeleton capsules |
//!
//! Every bound contains its shape: a box point is at most the half-diagonal of the other two
//! edges from the axis and projects inside ±a/2; a cylinder point at most r from the axis
//! within ±l/2. A bound is larger than the shape (a cube's capsule reaches 0.87 a beyond its
//! faces' centres, a cylinder's r beyond its ends), so the planner keeps more room than the
//! shape needs, never less.

use super::Capsule;
use crate::model::urdf::{CollisionGeometry, CollisionShape};
use nalgebra::Vector3;

/// The bounding capsule of `shape` (see the module documentation); `None` for a mesh.
pub fn bounding_capsule(shape: &CollisionShape) -> Option<Capsule> {
    let (axis, half_length, radius) = match &shape.geometry {
        CollisionGeometry::Sphere(r) => (Vector3::z(), 0.0, *r),
        CollisionGeometry::Capsule(r, l) | CollisionGeometry::Cylinder(r, l) => {
            (Vector3::z(), 0.5 * l, *r)
        }
        CollisionGeometry::Box(size) => {
            let long = (0..3)
                .max_by(|&i, &j| size[i].total_cmp(&size[j]))
                .expect("three edges");
            let others: f64 = (0..3)
                .filter(|&i| i != long)
                .map(|i| (0.5 * size[i]).powi(2))
                .sum();
            let mut axis = Vector3::zeros();
            axis[long] = 1.0;
            (axis, 0.5 * size[long], others.sqrt())
        }
        CollisionGeometry::Mesh(_) => return None,
    };
    let end = |sign: f64| {
        let p = shape.origin.transform_point(&(axis * (sign * half_length)));
        [p.x, p.y, p.z]
    };
    Some(Capsule {
        frame: shape.frame.clone(),
        a: end(-1.0),
        b: end(1.0),
        radius,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::point_segment_distance;
    use crate::model::Pose;
    use rand::{Rng, SeedableRng};

    /// Points sampled in each shape (its corners and random interior points) lie inside the
    /// bounding capsule; the capsule is no fatter than it needs to be (a box corner or a
    /// cylinder's rim touches its surface).
    #[test]
    fn every_bound_contains_its_shape_and_touches_it() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
        for _ in 0..200 {
            let origin = Pose::from_xyz_rpy(
                [rng.random_range(-100.0..100.0), 20.0, -5.0],
                [
                    rng.random_range(-3.0..3.0),
                    rng.random_range(-1.5..1.5),
                    0.4,
                ],
            );
            let size = [
                rng.random_range(5.0..300.0),
                rng.random_range(5.0..300.0),
                rng.random_range(5.0..300.0),
            ];
            let (r, l) = (rng.random_range(5.0..80.0), rng.random_range(0.0..300.0));
            for (geometry, corners) in [
                (
                    CollisionGeometry::Box(size),
                    (0..8)
                        .map(|k| {
                            let s = |bit: usize| if k & bit != 0 { 0.5 } else { -0.5 };
                            Vector3::new(s(1) * size[0], s(2) * size[1], s(4) * size[2])
                        })
                        .collect::<Vec<_>>(),
                ),
                (
                    CollisionGeometry::Cylinder(r, l),
                    vec![
                        Vector3::new(r, 0.0, 0.5 * l),
                        Vector3::new(0.0, -r, -0.5 * l),
                    ],
                ),
                (
                    CollisionGeometry::Sphere(r),
                    vec![Vector3::new(0.0, 0.0, r)],
                ),
                (
                    CollisionGeometry::Capsule(r, l),
                    vec![Vector3::new(0.0, 0.0, 0.5 * l + r)],
                ),
            ] {
                let shape = CollisionShape {
                    frame: "j2".into(),
                    link: "upper_arm".into(),
                    origin,
                    geometry,
                };
                let c = bounding_capsule(&shape).expect("not a mesh");
                let (a, b) = (Vector3::from(c.a), Vector3::from(c.b));
                let dist =
                    |p: &Vector3<f64>| point_segment_distance(&origin.transform_point(p), &a, &b).0;
                let worst = corners.iter().map(dist).fold(0.0, f64::max);
                assert!(
                    (worst - c.radius).abs() < 1e-9 * (1.0 + c.radius),
                    "{:?}: farthest corner {worst} mm from the axis, radius {}",
                    shape.geometry,
                    c.radius
                );
                // Interior points (convex combinations of the corners) are inside.
                for _ in 0..20 {
                    let w: Vec<f64> = corners.iter().map(|_| rng.random_range(0.0..1.0)).collect();
                    let total: f64 = w.iter().sum();
                    let p = corners
                        .iter()
                        .zip(&w)
                        .map(|(c, w)| c * (*w / total))
                        .sum::<Vector3<f64>>();
                    assert!(dist(&p) <= c.radius + 1e-9);
                }
            }
        }
        let mesh = CollisionShape {
            frame: "j3".into(),
            link: "forearm".into(),
            origin: Pose::identity(),
            geometry: CollisionGeometry::Mesh("package://arm/forearm.stl".into()),
        };
        assert!(bounding_capsule(&mesh).is_none());
    }
}
