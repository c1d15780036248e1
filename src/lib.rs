//! `thickness_collision`: reliable collision checks against thin surface meshes.
//!
//! A one-layer triangle mesh (a sheet-metal guard, a shelf, a scanned wall) has no inside, so a
//! robot link sampled between two states can pass through it unseen. This crate gives every
//! triangle a *thickness area* — a convex cell whose side walls are shared with its neighbours —
//! and checks convex robot links against the cells with a separating-axis test behind a BVH.
//!
//! The layers point one way: [`mesh`] (topology) ← [`thickness`] (cells) ← [`collision`]
//! (targets, SAT, scene) ← [`model`] (files) ← [`checker`] (a robot state against the scene) ←
//! [`pipeline`] (messages to checked states) ← the front doors: the node (`ros`), [`replay`] and
//! the CLI. The geometry core knows nothing of files or ROS; [`msgs`] are plain serde types.
#![warn(missing_docs)]
#![deny(unused_results)]

pub mod checker;
pub mod collision;
// The fuzz harness's way in to steps it fuzzes alone (fuzz/harness); not API.
#[doc(hidden)]
pub mod fuzz_access;
pub mod limits;
pub mod markers;
pub mod math;
pub mod mesh;
pub mod model;
pub mod msgs;
pub mod pipeline;
pub mod replay;
#[cfg(feature = "ros")]
pub mod ros;
pub mod thickness;

// The README's examples are compiled and run by `cargo test`, so they stay true to the API.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeExamples;
