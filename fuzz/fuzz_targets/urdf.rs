//! Fuzz target `urdf`: see `thickness_collision::fuzz_entry::urdf` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| thickness_collision::fuzz_entry::urdf(data));
