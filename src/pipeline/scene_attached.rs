//! Objects attached to robot links, as MoveIt's `PlanningScene::processAttachedCollisionObjectMsg`
//! attaches and detaches them: placed at the node's current merged joint state, moving with
//! their link from then on.

use super::collision_object::object_to_add;
use super::planning_world::{AddObject, PlanningWorld};
use super::scene_state::{refuse, AttachedObject, FrameContext, SceneState};
use super::skip::{Skip, SkipCause};
use crate::checker::WorldShape;
use crate::math::Pose;
use crate::msgs::planning_scene::{AttachedCollisionObject, CollisionObject};

impl SceneState {
    /// One `moveit_msgs/AttachedCollisionObject`, applied to this scene (unchanged on error).
    /// `ADD` with geometry attaches it to `link_name` (a world object of that id is removed);
    /// without geometry it moves the world object of that id onto the link, keeping its world
    /// pose; `APPEND` adds shapes to an attached object; `REMOVE` detaches it back into the world
    /// where it is (an empty id: every object on `link_name`, or every object for an empty link).
    pub(super) fn apply_attached(&mut self, ctx: &FrameContext, msg: &AttachedCollisionObject) -> Result<(), Skip> {
        let (id, op) = (msg.object.id.as_str(), msg.object.operation);
        let what = format!("attached collision object '{id}' on link '{}'", msg.link_name);
        match op {
            CollisionObject::REMOVE => self.detach(ctx, msg, &what),
            CollisionObject::ADD | CollisionObject::APPEND => self.attach(ctx, msg, &what),
            CollisionObject::MOVE => {
                Err(refuse(SkipCause::SceneOperation, format!("{what}: operation MOVE: an attached object moves with its link (detach it first)")))
            }
            other => Err(refuse(SkipCause::SceneOperation, format!("{what}: operation {other} is not one of ADD (0), REMOVE (1), APPEND (2), MOVE (3)"))),
        }
    }

    /// The pose of link `link` at the current state, or why there is none.
    fn link_pose(ctx: &FrameContext, link: &str, what: &str) -> Result<Pose, Skip> {
        let li =
            ctx.checker.robot().link(link).ok_or_else(|| refuse(SkipCause::SceneFrame, format!("{what}: link_name: '{link}' is not a link of the robot")))?;
        (ctx.robot_link)(li).map_err(|e| refuse(SkipCause::SceneFrame, format!("{what}: the link cannot be placed: {e}")))
    }

    fn attach(&mut self, ctx: &FrameContext, msg: &AttachedCollisionObject, what: &str) -> Result<(), Skip> {
        let object = &msg.object;
        let id = object.id.as_str();
        if id.is_empty() {
            return Err(refuse(SkipCause::SceneId, format!("{what}: id: an object to attach needs an id")));
        }
        if ctx.checker.robot().link(id).is_some() || ctx.checker.environment_frame(id).is_some() {
            return Err(refuse(SkipCause::SceneId, format!("{what}: id: names a link of the robot or the environment")));
        }
        let link_pose = Self::link_pose(ctx, &msg.link_name, what)?;
        let to_link = link_pose.inverse();
        let has_geometry = !(object.primitives.is_empty() && object.meshes.is_empty() && object.planes.is_empty());
        // With geometry, the object placed by the pose rules of a world object (a lone shape and
        // an empty pose); without, the world object of that id. Either way a world object of the
        // id is removed, as MoveIt does: the object is now held.
        let mut placed: PlanningWorld<WorldShape> = PlanningWorld::default();
        let source = if has_geometry {
            let header = self.frame(ctx, &object.header.frame_id, id)?;
            let add = object_to_add(object, header).map_err(|e| refuse(SkipCause::SceneGeometry, format!("attached {e}")))?;
            placed.add(id, add).map_err(|e| refuse(SkipCause::SceneGeometry, format!("attached {e}")))?;
            &placed
        } else {
            &self.world
        };
        let Some(o) = source.get(id) else {
            return Err(refuse(SkipCause::SceneUnknownId, format!("{what}: no geometry given and no world object '{id}' to attach")));
        };
        let shapes: Vec<(WorldShape, Pose)> = o.shapes.iter().map(|(s, p)| (s.clone(), to_link * o.pose * *p)).collect();
        let _ = self.world.remove(id);
        match self.attached.get_mut(id) {
            Some(a) if object.operation == CollisionObject::APPEND && a.link == msg.link_name => {
                a.shapes.extend(shapes);
                // Touch links merge, as MoveIt keeps them in a set.
                for l in &msg.touch_links {
                    if !a.touch_links.contains(l) {
                        a.touch_links.push(l.clone());
                    }
                }
            }
            Some(a) if object.operation == CollisionObject::APPEND => {
                return Err(refuse(SkipCause::SceneGeometry, format!("{what}: APPEND to an object attached to another link ('{}')", a.link)));
            }
            _ => {
                let _ = self.attached.insert(id.to_owned(), AttachedObject { link: msg.link_name.clone(), shapes, touch_links: msg.touch_links.clone() });
            }
        }
        self.check_bounds(id)
    }

    fn detach(&mut self, ctx: &FrameContext, msg: &AttachedCollisionObject, what: &str) -> Result<(), Skip> {
        let id = msg.object.id.as_str();
        let ids: Vec<String> = if id.is_empty() {
            self.attached.iter().filter(|(_, a)| msg.link_name.is_empty() || a.link == msg.link_name).map(|(k, _)| k.clone()).collect()
        } else if self.attached.contains_key(id) {
            vec![id.to_owned()]
        } else {
            return Err(refuse(SkipCause::SceneUnknownId, format!("{what}: no attached object '{id}' to detach")));
        };
        for id in ids {
            let Some(a) = self.attached.remove(&id) else { continue };
            // Back into the world where it is now: at its link's pose, its shapes where they are.
            let link_pose = Self::link_pose(ctx, &a.link, what)?;
            let add = AddObject { header: link_pose, pose: Some(Pose::IDENTITY), shapes: a.shapes, subframes: Vec::new() };
            self.world.add(&id, add).map_err(|e| refuse(SkipCause::SceneGeometry, e.to_string()))?;
        }
        Ok(())
    }
}
