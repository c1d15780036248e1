//! Fuzz target `mesh_stl`: see `thickness_collision::fuzz_entry::mesh_stl` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| thickness_collision::fuzz_entry::mesh_stl(data));
