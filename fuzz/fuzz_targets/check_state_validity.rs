//! Fuzz target `check_state_validity`: see `thickness_collision::fuzz_entry::check_state_validity` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| thickness_collision::fuzz_entry::check_state_validity(data));
