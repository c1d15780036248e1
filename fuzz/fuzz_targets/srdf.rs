//! Fuzz target `srdf`: see `fuzz_harness::srdf` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| fuzz_harness::srdf(data));
