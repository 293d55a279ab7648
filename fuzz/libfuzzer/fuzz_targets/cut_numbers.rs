//! libFuzzer driver of `kerf_fuzz::cut_numbers`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| kerf_fuzz::cut_numbers(data));
