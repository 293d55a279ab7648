//! libFuzzer driver of `kerf_fuzz::mesh_obj`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| kerf_fuzz::mesh_obj(data));
