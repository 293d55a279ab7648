//! libFuzzer driver of `kerf_fuzz::cdr`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| kerf_fuzz::cdr(data));
