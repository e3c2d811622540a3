#![no_main]
//! Fuzz target `cell`: see [`armcal_fuzz::cell`].

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        armcal_fuzz::cell(text);
    }
});
