//! libFuzzer driver of `kerf_fuzz::mill_numbers`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| kerf_fuzz::mill_numbers(data));
