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
//!
//! # The API
//!
//! Each layer keeps its files private and re-exports what callers use from its `mod.rs`:
//! - [`mesh`], [`thickness`], [`collision`]: a triangle soup to a
//!   [`MeshTopology`](mesh::MeshTopology), its [`ThicknessArea`](thickness::ThicknessArea), and a
//!   [`Scene`](collision::Scene) that [`Target`](collision::Target)s are collided with;
//! - [`model`]: [`Params`](model::Params) (every parameter and input path),
//!   [`RobotModel`](model::RobotModel), [`Srdf`](model::Srdf), mesh files
//!   ([`read_mesh`](model::read_mesh));
//! - [`checker`]: a [`Checker`](checker::Checker) built from them, answering a state or a motion
//!   with a [`StateReport`](checker::StateReport) or a [`MotionReport`](checker::MotionReport);
//! - [`pipeline`]: the [`Pipeline`](pipeline::Pipeline) the front doors feed with messages, and
//!   the `check --states` lines; [`msgs`]: the messages it takes and gives, and the node's own
//!   services;
//! - [`replay`]: [`replay::replay`] of a bag, reporting through a
//!   [`ReplayObserver`](replay::ReplayObserver); `ros::run`: the node (feature `ros`);
//! - [`limits`] (the bounds a front door applies itself), [`math`] (the scalar and the types).
//!
//! What only the node and replay use stays private to the crate. Test fixtures are behind the
//! `testing` feature; the fuzz harness reaches the steps it fuzzes alone through a hidden module.
//! `docs/library.md` has the API in full and how its size is measured.
#![warn(missing_docs)]
#![deny(unused_results)]

pub mod checker;
pub mod collision;
// The fuzz harness's way in to steps it fuzzes alone (fuzz/harness, tests/fuzz_regressions.rs);
// not API.
#[doc(hidden)]
pub mod fuzz_access;
pub mod limits;
mod markers;
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
