#![no_main]
//! Fuzz target `data_csv`: see [`armcal_fuzz::data_csv`].

libfuzzer_sys::fuzz_target!(|data: &[u8]| armcal_fuzz::data_csv(data));
