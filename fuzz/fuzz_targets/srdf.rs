//! Fuzz target `srdf`: see `thickness_collision::fuzz_entry::srdf` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| thickness_collision::fuzz_entry::srdf(data));
