//! The pipeline's planning-scene doors: the messages of MoveIt's `planning_scene_monitor`
//! (`collision_object`, `attached_collision_object`, `planning_scene`, `planning_scene_world`,
//! and the `apply_planning_scene` request) applied to the scene in force, and the scene as
//! `get_planning_scene` gives it. A change is in force when the call returns: every state checked
//! after it sees the new scene. A refusal is counted by cause and leaves the scene unchanged.

use super::scene_state::{FrameContext, SceneState};
use super::skip::{Skip, SkipCause};
use super::state_pipeline::Pipeline;
use crate::checker::BodyCache;
use crate::checker::Checker;
use crate::math::{pose_from_isometry, Pose};
use crate::model::PoseSource;
use crate::msgs::planning_scene::RobotStateMsg;
use crate::msgs::planning_scene::{AttachedCollisionObject, CollisionObject, OctomapWithPose, PlanningScene, PlanningSceneWorld};
use crate::msgs::Time;
use std::sync::Arc;

/// A scene message accepted and its next scene worked out, the cells still to build: what
/// [`ScenePlan::build`] does off the pipeline (the node builds without holding its state, so the
/// states that arrive meanwhile are checked against the scene in force), before
/// [`Pipeline::install_scene`] puts the result in force.
pub(crate) struct ScenePlan {
    next: SceneState,
    base: Arc<Checker>,
    bodies: BodyCache,
}

/// A built [`ScenePlan`]: the new scene and its checker, or why the scene could not be built.
pub(crate) struct BuiltScene {
    next: SceneState,
    checker: Result<Checker, Skip>,
    bodies: BodyCache,
}

impl ScenePlan {
    /// Builds the new scene's cells (those the cache lacks) and its checker.
    pub(crate) fn build(mut self) -> BuiltScene {
        let checker = self.next.checker_on(&self.base, &mut self.bodies).map_err(|e| Skip { cause: SkipCause::SceneGeometry, message: e.to_string() });
        BuiltScene { next: self.next, checker, bodies: self.bodies }
    }
}

impl Pipeline {
    /// A `moveit_msgs/CollisionObject` (the `collision_object` topic), applied as MoveIt applies
    /// it (docs/reference.md, "Planning scene"): in force when this returns. A refusal names the
    /// field and leaves the scene unchanged.
    pub fn collision_object(&mut self, msg: &CollisionObject) -> Result<(), Skip> {
        let plan = self.prepare_collision_object(msg)?;
        self.install_scene(plan.build())
    }

    /// A `moveit_msgs/PlanningSceneWorld` (the `planning_scene_world` topic): its objects replace
    /// the world's.
    pub(crate) fn planning_scene_world(&mut self, msg: &PlanningSceneWorld) -> Result<(), Skip> {
        let plan = self.prepare_planning_scene_world(msg)?;
        self.install_scene(plan.build())
    }

    /// A `moveit_msgs/PlanningScene` (the `planning_scene` topic, the `apply_planning_scene`
    /// request): a difference, or the whole scene when `is_diff` is false.
    pub(crate) fn planning_scene(&mut self, msg: &PlanningScene) -> Result<(), Skip> {
        let plan = self.prepare_planning_scene(msg)?;
        self.install_scene(plan.build())
    }

    /// A `moveit_msgs/AttachedCollisionObject` (the `attached_collision_object` topic).
    pub fn attached_collision_object(&mut self, msg: &AttachedCollisionObject) -> Result<(), Skip> {
        let plan = self.prepare_attached_collision_object(msg)?;
        self.install_scene(plan.build())
    }

    /// [`Pipeline::collision_object`] up to the cells: validated, frames resolved.
    pub(crate) fn prepare_collision_object(&mut self, msg: &CollisionObject) -> Result<ScenePlan, Skip> {
        self.prepare_scene(|s, ctx| s.apply_object(ctx, msg))
    }

    /// [`Pipeline::planning_scene_world`] up to the cells.
    pub(crate) fn prepare_planning_scene_world(&mut self, msg: &PlanningSceneWorld) -> Result<ScenePlan, Skip> {
        self.refuse_octomap(&msg.octomap);
        self.prepare_scene(|s, ctx| s.apply_world(ctx, msg))
    }

    /// [`Pipeline::planning_scene`] up to the cells.
    pub(crate) fn prepare_planning_scene(&mut self, msg: &PlanningScene) -> Result<ScenePlan, Skip> {
        self.refuse_octomap(&msg.world.octomap);
        self.prepare_scene(|s, ctx| s.apply_scene(ctx, msg))
    }

    /// [`Pipeline::attached_collision_object`] up to the cells.
    pub(crate) fn prepare_attached_collision_object(&mut self, msg: &AttachedCollisionObject) -> Result<ScenePlan, Skip> {
        self.prepare_scene(|s, ctx| s.apply_attached(ctx, msg))
    }

    /// Puts a built scene in force (a refusal is counted and leaves the scene as it was). The
    /// plan must be the last one prepared: nothing may change the pipeline's checker between.
    pub(crate) fn install_scene(&mut self, built: BuiltScene) -> Result<(), Skip> {
        self.bodies = built.bodies;
        match built.checker {
            Ok(checker) => {
                self.scene = built.next;
                self.swap(checker);
                Ok(())
            }
            Err(skip) => {
                self.count_skip(skip.cause, 1);
                Err(skip)
            }
        }
    }

    /// The scene in force as `get_planning_scene` answers (`components` as in
    /// `moveit_msgs/PlanningSceneComponents`), stamped `stamp`.
    pub(crate) fn planning_scene_message(&self, components: u32, stamp: Time) -> PlanningScene {
        self.scene.message(&self.checker, components, stamp)
    }

    /// The checker for a `check_state_validity` request's `robot_state` at joint positions `q`:
    /// its attached objects placed at `q` on top of the node's (in their place when `is_diff` is
    /// false). The checker in force when nothing changes; the reason when an object cannot be
    /// attached.
    pub(crate) fn request_checker(&self, state: &RobotStateMsg, q: &[f64]) -> Result<Arc<Checker>, String> {
        if state.attached_collision_objects.is_empty() && (state.is_diff || self.scene.attached.is_empty()) {
            return Ok(self.checker.clone());
        }
        let mut scene = self.scene.clone();
        if !state.is_diff {
            scene.attached.clear();
        }
        let robot = self.checker.robot();
        let poses = robot.forward_kinematics(q, self.checker.base_pose()).map_err(|e| e.to_string())?;
        let robot_link = |li: usize| poses.get(li).map(pose_from_isometry).ok_or_else(|| format!("no pose for link {li}"));
        let ctx = FrameContext { checker: &self.checker, robot_link: &robot_link };
        for a in &state.attached_collision_objects {
            // The scene of a request stays the node's: the held copy would meet the world's.
            if self.scene.world.get(&a.object.id).is_some() {
                return Err(format!(
                    "robot_state.attached_collision_objects: '{}' is a world object; attaching it in a request is not supported (attach it on attached_collision_object)",
                    a.object.id
                ));
            }
            scene.apply_attached(&ctx, a).map_err(|s| format!("robot_state.attached_collision_objects: {}", s.message))?;
        }
        self.checker
            .with_attached(&scene.attached_specs(), scene.matrix.as_ref())
            .map(Arc::new)
            .map_err(|e| format!("robot_state.attached_collision_objects: {e}"))
    }

    /// Planning-scene objects in force: in the world, and attached to the robot.
    pub fn scene_object_count(&self) -> (usize, usize) {
        (self.scene.world.len(), self.scene.attached.len())
    }

    /// An octomap (non-empty data) cannot be checked: refused with a warning the first time, and
    /// counted each time.
    fn refuse_octomap(&mut self, octomap: &OctomapWithPose) {
        if octomap.octomap.data.is_empty() {
            return;
        }
        self.count_skip(SkipCause::SceneOctomap, 1);
        if !self.octomap_warned {
            self.octomap_warned = true;
            self.warnings
                .push("planning scene: an octomap is not supported: refused, the rest of the message applies (warned once, counted as scene_octomap)".into());
        }
    }

    /// Applies `change` to a copy of the scene in force: the plan of the new scene, or the
    /// refusal (counted; nothing changes). The cell cache goes with the plan until it is installed.
    fn prepare_scene(&mut self, change: impl FnOnce(&mut SceneState, &FrameContext) -> Result<(), Skip>) -> Result<ScenePlan, Skip> {
        let mut next = self.scene.clone();
        let robot_link = |li| self.robot_link_pose(li);
        match change(&mut next, &FrameContext { checker: &self.checker, robot_link: &robot_link }) {
            Ok(()) => Ok(ScenePlan { next, base: Arc::clone(&self.checker), bodies: std::mem::take(&mut self.bodies) }),
            Err(skip) => {
                self.count_skip(skip.cause, 1);
                Err(skip)
            }
        }
    }

    /// The world pose of robot link `li` in the robot's current state, as MoveIt places an object
    /// given in a robot link's frame at its current state: from the merged joint state (a joint
    /// never received as the `missing_joint` rule has it), or with `pose_source: tf` from the TF
    /// tree.
    fn robot_link_pose(&self, li: usize) -> Result<Pose, String> {
        let (checker, params) = (&self.checker, self.params());
        let robot = checker.robot();
        if params.pose_source == PoseSource::Tf {
            let frame = format!("{}{}", params.frame_prefix, robot.links[li].name);
            return self.tf.world_pose(&frame, &params.world_frame).ok_or_else(|| format!("its /tf frame '{frame}' does not reach world_frame yet"));
        }
        let q = (0..robot.joints.len()).map(|j| self.left_out_position(j, "the message")).collect::<Result<Vec<f64>, String>>()?;
        let poses = robot.forward_kinematics(&q, checker.base_pose()).map_err(|e| e.to_string())?;
        poses.get(li).map(pose_from_isometry).ok_or_else(|| format!("no pose for link {li}"))
    }
}
