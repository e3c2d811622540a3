#![no_main]
//! Fuzz target `ur_kinematics`: see [`armcal_fuzz::ur_kinematics`].

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        armcal_fuzz::ur_kinematics(text);
    }
});
