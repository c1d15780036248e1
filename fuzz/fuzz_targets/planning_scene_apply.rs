//! Fuzz target `planning_scene_apply`: see `fuzz_harness::planning_scene_apply` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| fuzz_harness::planning_scene_apply(data));
