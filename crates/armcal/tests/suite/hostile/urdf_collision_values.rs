//! Issue 30: a URDF `<collision>` shape with a negative or non-finite dimension, or a
//! non-finite origin, was bounded by a capsule of negative or NaN radius — silent garbage in
//! the arm's collision model. Each is an error naming the link and the dimension.

use armcal::model::urdf::{from_urdf_str_with_collisions, CollisionGeometry};

/// A two-joint URDF whose `link1` has the collision `geometry` at `origin_xyz`.
fn urdf(geometry: &str, origin_xyz: &str) -> String {
    format!(
        r#"<robot name="r2">
  <link name="base_link"/>
  <link name="link1"><collision><origin xyz="{origin_xyz}" rpy="0 0 0"/><geometry>{geometry}</geometry></collision></link>
  <link name="link2"/>
  <joint name="joint1" type="revolute"><parent link="base_link"/><child link="link1"/><origin xyz="0 0 0.3" rpy="0 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="0" velocity="0"/></joint>
  <joint name="joint2" type="revolute"><parent link="link1"/><child link="link2"/><origin xyz="0 0 0.4" rpy="0 0 0"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="0" velocity="0"/></joint>
</robot>"#
    )
}

#[test]
fn negative_or_nan_collision_dimensions_are_errors_naming_the_link() {
    for (geometry, what) in [
        (
            r#"<cylinder radius="-0.1" length="0.4"/>"#,
            "cylinder radius is -0.1 m",
        ),
        (
            r#"<cylinder radius="0.1" length="inf"/>"#,
            "cylinder length is inf m",
        ),
        (r#"<sphere radius="NaN"/>"#, "sphere radius is NaN m"),
        (r#"<box size="0.1 -0.2 0.4"/>"#, "box size y is -0.2 m"),
    ] {
        let e = from_urdf_str_with_collisions(&urdf(geometry, "0 0 0.2"), None)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("link `link1`") && e.contains(what),
            "{geometry}: {e}"
        );
    }
    let e = from_urdf_str_with_collisions(&urdf(r#"<sphere radius="0.05"/>"#, "0 nan 0.2"), None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("link `link1`") && e.contains("origin"), "{e}");
}

#[test]
fn valid_collision_shapes_are_read_in_millimetres() {
    let (_, shapes) = from_urdf_str_with_collisions(
        &urdf(r#"<cylinder radius="0.1" length="0" />"#, "0 0 0.2"),
        None,
    )
    .unwrap();
    assert_eq!(shapes.len(), 1);
    assert_eq!(shapes[0].link, "link1");
    assert_eq!(shapes[0].geometry, CollisionGeometry::Cylinder(100.0, 0.0));
}
