#![no_main]
//! Fuzz target `joint_corrections`: see [`armcal_fuzz::joint_corrections`].

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        armcal_fuzz::joint_corrections(text);
    }
});
