//! The fuzz targets' entry points, one function per target, shared by the `cargo fuzz` crate in
//! `fuzz/` and by the main crate's `tests/fuzz_regressions.rs`, which replays every saved input on
//! stable: a crash the fuzzer found stays found by `cargo test`. A crate of its own so the library
//! carries none of it; it calls the library's public API, and `thickness_collision::fuzz_access`
//! (hidden, not API) for the steps it fuzzes alone: the mesh parsers behind their guards, the bag
//! reader, the node's request services.
//!
//! Every entry takes raw bytes and must never panic, abort or hang, whatever the bytes. Each goes
//! as deep as the front door it stands for: URDF text is loaded and the robot checked in a few
//! states against a small scene; a decoded message goes through a
//! [`Pipeline`](thickness_collision::pipeline::Pipeline) the way the node hands it over, and the
//! states it yields are checked against the bundled workcell.
//!
//! Reproducibility: the pipeline's input policy (merged joint states, the TF tree) keeps state
//! between messages, so each input gets a fresh pipeline on the bundled robot with an empty
//! environment (cheap to build); its states are then checked against one workcell pipeline built
//! once, whose `check` keeps no state. The same input gives the same run in any order.
//!
//! Panics that the library contains on purpose (`limits::contain_panic` around mesh-loader) are
//! not failures; they are noted on standard error once per place, with the prefix
//! [`CONTAINED_PANIC_PREFIX`], so a campaign can count new ones.
#![warn(missing_docs)]
#![deny(unused_results)]

mod cdr_records;
mod entries;
mod fixtures;
mod requests;
mod seeds;

pub use self::cdr_records::{cdr_records, split_records, CdrKind};
pub use self::entries::{bag_mcap, bag_sqlite, cdr, mesh_dae, mesh_obj, mesh_stl, params_yaml, planning_scene, planning_scene_apply, srdf, state_line, urdf};
pub use self::fixtures::{workcell, CONTAINED_PANIC_PREFIX};
pub use self::requests::{assert_validity_answer, check_state_validity, check_trajectory};
pub use self::seeds::seeds;

/// A target's entry: raw bytes in, nothing out, never a panic.
pub type Entry = fn(&[u8]);

/// Every target: its name (the `fuzz/fuzz_targets/<name>.rs` file and the
/// `fuzz/regressions/<name>/` folder) and its entry.
pub const TARGETS: &[(&str, Entry)] = &[
    ("urdf", urdf),
    ("mesh_stl", mesh_stl),
    ("mesh_obj", mesh_obj),
    ("mesh_dae", mesh_dae),
    ("cdr", cdr),
    ("state_line", state_line),
    ("params_yaml", params_yaml),
    ("bag_mcap", bag_mcap),
    ("bag_sqlite", bag_sqlite),
    ("check_trajectory", check_trajectory),
    ("check_state_validity", check_state_validity),
    ("srdf", srdf),
    ("planning_scene", planning_scene),
    ("planning_scene_apply", planning_scene_apply),
];
