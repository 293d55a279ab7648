//! libFuzzer driver of `kerf_fuzz::gcode_msg`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| kerf_fuzz::gcode_msg(data));
