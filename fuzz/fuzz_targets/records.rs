#![no_main]
//! Fuzz target `records`: see [`armcal_fuzz::records`].

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        armcal_fuzz::records(text);
    }
});
