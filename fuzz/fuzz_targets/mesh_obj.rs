//! Fuzz target `mesh_obj`: see `thickness_collision::fuzz_entry::mesh_obj` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| thickness_collision::fuzz_entry::mesh_obj(data));
