#![no_main]
//! Fuzz target `program_krl`: see [`armcal_fuzz::controller_program`].

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        armcal_fuzz::controller_program(
            text,
            armcal::ProgramLanguage::Krl,
        );
    }
});
