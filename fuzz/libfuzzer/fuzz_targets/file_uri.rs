//! libFuzzer driver of `kerf_fuzz::file_uri`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| kerf_fuzz::file_uri(data));
