//! Fuzz target `check_state_validity`: see `fuzz_harness::check_state_validity` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| fuzz_harness::check_state_validity(data));
