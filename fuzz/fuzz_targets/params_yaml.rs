//! Fuzz target `params_yaml`: see `thickness_collision::fuzz_entry::params_yaml` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| thickness_collision::fuzz_entry::params_yaml(data));
