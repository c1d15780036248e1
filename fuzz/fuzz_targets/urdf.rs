//! Fuzz target `urdf`: see `fuzz_harness::urdf` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| fuzz_harness::urdf(data));
