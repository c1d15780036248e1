//! Fuzz target `check_trajectory`: see `fuzz_harness::check_trajectory` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| fuzz_harness::check_trajectory(data));
