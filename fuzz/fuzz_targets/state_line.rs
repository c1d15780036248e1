//! Fuzz target `state_line`: see `fuzz_harness::state_line` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| fuzz_harness::state_line(data));
