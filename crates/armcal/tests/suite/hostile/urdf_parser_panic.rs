//! Found by `fuzz/urdf` (issue 15): the XML parser under urdf-rs panicked ("No namespace
//! prefix bound") on an attribute list with a stray `:`; armcal must answer with an error.

use armcal::model::urdf::from_urdf_str;

/// The fuzzer's input, minimized by hand: one joint whose `<limit>` has `"0":velocity`.
const FOUND: &str = r#"<robot name="r">
  <link name="a"/>
  <link name="b"/>
  <joint name="q1" type="revolute">
    <parent link="a"/>
    <child link="b"/>
    <limit xmlns="0" upper="0" effort="0":velocity="0"/>
  </joint>
</robot>"#;

#[test]
fn a_urdf_the_xml_parser_cannot_handle_is_an_error() {
    let e = from_urdf_str(FOUND, None).unwrap_err().to_string();
    assert!(e.contains("not a valid URDF document"), "{e}");
}
