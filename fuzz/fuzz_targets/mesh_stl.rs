//! Fuzz target `mesh_stl`: see `fuzz_harness::mesh_stl` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| fuzz_harness::mesh_stl(data));
