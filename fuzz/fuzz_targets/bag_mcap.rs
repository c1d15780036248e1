//! Fuzz target `bag_mcap`: see `fuzz_harness::bag_mcap` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| fuzz_harness::bag_mcap(data));
