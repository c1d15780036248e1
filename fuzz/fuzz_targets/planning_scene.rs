//! Fuzz target `planning_scene`: see `fuzz_harness::planning_scene` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| fuzz_harness::planning_scene(data));
