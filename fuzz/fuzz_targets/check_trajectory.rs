//! Fuzz target `check_trajectory`: see `thickness_collision::fuzz_entry::check_trajectory` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| thickness_collision::fuzz_entry::check_trajectory(data));
