//! libFuzzer driver of `kerf_fuzz::document`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| kerf_fuzz::document(data));
