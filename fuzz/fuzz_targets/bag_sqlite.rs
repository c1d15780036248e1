//! Fuzz target `bag_sqlite`: see `fuzz_harness::bag_sqlite` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| fuzz_harness::bag_sqlite(data));
