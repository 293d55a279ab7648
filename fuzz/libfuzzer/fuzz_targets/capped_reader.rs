//! libFuzzer driver of `kerf_fuzz::capped_reader`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| kerf_fuzz::capped_reader(data));
