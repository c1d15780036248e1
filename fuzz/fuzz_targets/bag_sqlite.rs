//! Fuzz target `bag_sqlite`: see `thickness_collision::fuzz_entry::bag_sqlite` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| thickness_collision::fuzz_entry::bag_sqlite(data));
