//! Fuzz target `bag_mcap`: see `thickness_collision::fuzz_entry::bag_mcap` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| thickness_collision::fuzz_entry::bag_mcap(data));
