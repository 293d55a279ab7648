//! libFuzzer driver of `kerf_fuzz::mesh_stl`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| kerf_fuzz::mesh_stl(data));
