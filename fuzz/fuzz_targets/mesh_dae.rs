//! Fuzz target `mesh_dae`: see `fuzz_harness::mesh_dae` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| fuzz_harness::mesh_dae(data));
