//! Fuzz target `mesh_dae`: see `thickness_collision::fuzz_entry::mesh_dae` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| thickness_collision::fuzz_entry::mesh_dae(data));
