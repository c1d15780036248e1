//! The checker: a robot, its targets and an environment scene, built together and never changed
//! after, and what can be read of them.

use super::link_targets::LinkTargets;
use super::motion_bounds::{Ladder, MotionBounds};
use super::self_pairs::SelfPairs;
use crate::collision::{CollideSettings, Scene, Target, TargetReport};
use crate::model::{Params, RobotModel};
use nalgebra::Isometry3;
use std::collections::BTreeMap;
use std::sync::{Arc, OnceLock};

/// What was loaded (printed by the CLI and the node at start).
#[derive(Clone, Debug, Default)]
pub struct BuildSummary {
    /// Robot file (or `robot_description`).
    pub robot_source: String,
    /// Environment file.
    pub environment_source: String,
    /// Links of the robot.
    pub robot_links: usize,
    /// Links checked (with geometry and matching `checked_links`).
    pub checked_links: usize,
    /// Thin surfaces (meshes with cells).
    pub thin_surfaces: usize,
    /// Convex solids.
    pub solids: usize,
    /// Cells in all thin surfaces.
    pub cells: usize,
    /// Mesh files read (each once).
    pub meshes_read: usize,
    /// Seconds to load and build everything.
    pub build_seconds: f64,
}

/// Robot, environment, targets and scene: everything needed to check a state. Built once from
/// validated parameters and never changed after (a new robot or new parameters build a new one),
/// so its parts stay consistent with each other.
pub struct Checker {
    pub(super) params: Params,
    pub(super) robot: RobotModel,
    pub(super) targets: Vec<LinkTargets>,
    /// Shared by the checkers that differ only in their self pairs (an SRDF that arrives later).
    pub(super) scene: Arc<Scene>,
    pub(super) summary: BuildSummary,
    pub(super) base: Isometry3<f64>,
    /// `allowed[target index][object index]`.
    pub(super) allowed: Vec<Vec<bool>>,
    /// Levers and grown parts for motion checks, built on the first motion.
    pub(super) motion: OnceLock<MotionBounds>,
    /// The growth ladders of the robot's links, from the checker this one was made from when
    /// only attached objects changed (see [`MotionBounds::new`]): a pick and place does not
    /// build them again at each attach.
    pub(super) robot_ladders: Vec<Arc<Ladder>>,
    /// The link pairs checked against each other.
    pub(super) self_pairs: SelfPairs,
    /// `moving[j]`: joint `j` takes a position from joint states and moves a checked link (itself,
    /// or through a mimic). A state is complete when all of these are known.
    pub(super) moving: Vec<bool>,
    /// While a planning scene's collision matrix decides the robot's pairs: the pairs of the
    /// SRDF (or the default reasoning) it replaced, which come back with a scene without one.
    pub(super) srdf_pairs: Option<Arc<Vec<(usize, usize)>>>,
    /// The first targets are the robot's links; objects attached to them follow.
    pub(super) robot_targets: usize,
    /// The scene's first objects are the environment's; planning-scene objects follow.
    pub(super) environment_objects: usize,
    /// The environment's links by name, with their poses in the world: frames a planning-scene
    /// object may be given in.
    pub(super) environment_frames: Arc<BTreeMap<String, crate::math::Pose>>,
    /// The padding and scale a planning scene set for robot links.
    pub(super) link_sizes: Arc<super::link_sizes::LinkSizes>,
}

impl Checker {
    /// The parameters in force.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The robot.
    pub fn robot(&self) -> &RobotModel {
        &self.robot
    }

    /// The checked links' targets, in model order.
    pub fn targets(&self) -> &[LinkTargets] {
        &self.targets
    }

    /// The environment.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// What was loaded.
    pub fn summary(&self) -> &BuildSummary {
        &self.summary
    }

    /// The pose of the robot's root link in the world (`robot_base_pose`).
    pub fn base_pose(&self) -> &Isometry3<f64> {
        &self.base
    }

    /// Whether joint `j` (model index) moves a checked link and takes its position from joint
    /// states: the joints a state must give before it can be checked.
    pub(crate) fn moves_checked_link(&self, j: usize) -> bool {
        self.moving.get(j).copied().unwrap_or(false)
    }

    /// Names `file` as the parameters' SRDF of a checker whose SRDF was applied from text held
    /// elsewhere (the pipeline's, for a robot that comes as a description).
    pub(crate) fn set_semantic_file_name(&mut self, file: String) {
        self.params.robot_semantic_file = file;
    }

    /// What target `ti` is: a robot link, or an object attached to one.
    pub(crate) fn target_kind(&self, ti: usize) -> super::state_report::ObjectType {
        if ti < self.robot_targets {
            super::state_report::ObjectType::RobotLink
        } else {
            super::state_report::ObjectType::AttachedObject
        }
    }

    /// The pose in the world of the environment's link `name`.
    pub(crate) fn environment_frame(&self, name: &str) -> Option<crate::math::Pose> {
        self.environment_frames.get(name).copied()
    }

    /// The self-collision pairs and the SRDF they come from.
    pub fn self_pairs(&self) -> &SelfPairs {
        &self.self_pairs
    }

    pub(crate) fn motion_bounds(&self) -> &MotionBounds {
        self.motion.get_or_init(|| MotionBounds::new(&self.robot, &self.targets, self.params.motion_tolerance, &self.robot_ladders))
    }

    /// Builds now what the motion checks otherwise build as they first need it: the motion
    /// bounds, and every link grown by each rung of the ladder up to the largest growth the
    /// loop tests (for the Panda's meshes about 0.35 s and 46 MiB, which a long run of motion
    /// checks builds anyway; once per robot: attaching or detaching objects keeps the links').
    /// The first motions are then as fast as the rest: the node does this at start, on a
    /// thread of its own, and the benchmarks before they time anything.
    pub fn prepare_motion_checks(&self) {
        self.motion_bounds().build_ladder(&self.targets, super::motion_sweep::MAX_TESTED_GROWTH);
    }

    /// Whether [`Checker::prepare_motion_checks`] has nothing left to build (false before the
    /// motion bounds exist).
    #[cfg(test)]
    pub(crate) fn motion_checks_prepared(&self) -> bool {
        self.motion.get().is_some_and(|bounds| bounds.ladder_built(super::motion_sweep::MAX_TESTED_GROWTH))
    }

    /// Target `ti` (a part of a checked link, posed) against the scene, without the objects the
    /// link may touch.
    pub(crate) fn collide_target(&self, ti: usize, target: &Target, settings: &CollideSettings) -> TargetReport {
        self.scene.collide_filtered(target, settings, |oi| !self.allowed[ti][oi])
    }
}
