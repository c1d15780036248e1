//! Fuzz target `cdr`: see `fuzz_harness::cdr` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| fuzz_harness::cdr(data));
