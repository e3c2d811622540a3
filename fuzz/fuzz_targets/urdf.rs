#![no_main]
//! Fuzz target `urdf`: see [`armcal_fuzz::urdf`].

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        armcal_fuzz::urdf(text);
    }
});
