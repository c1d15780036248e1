//! Fuzz target `state_line`: see `thickness_collision::fuzz_entry::state_line` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| thickness_collision::fuzz_entry::state_line(data));
