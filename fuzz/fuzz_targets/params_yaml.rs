//! Fuzz target `params_yaml`: see `fuzz_harness::params_yaml` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| fuzz_harness::params_yaml(data));
