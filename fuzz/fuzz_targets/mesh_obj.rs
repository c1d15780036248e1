//! Fuzz target `mesh_obj`: see `fuzz_harness::mesh_obj` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| fuzz_harness::mesh_obj(data));
