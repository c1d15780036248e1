//! The planning scene in force: the world objects and fixed frames that `collision_object`,
//! `planning_scene_world`, `planning_scene` and `apply_planning_scene` change, as MoveIt's
//! `PlanningScene::processCollisionObjectMsg`, `processPlanningSceneWorldMsg` and
//! `setPlanningSceneDiffMsg` / `setPlanningSceneMsg` change them, and the scene as
//! `getPlanningSceneMsg` gives it back. Every message is applied whole or not at all: a refusal
//! leaves the scene as it was (MoveIt keeps the objects of a message before a bad one; a
//! half-applied message would be a world neither side meant).

use super::collision_object::{object_to_add, pose_of, MAX_OBJECT_TRIANGLES};
use super::planning_world::{PlanningWorld, WorldError};
use super::skip::{Skip, SkipCause};
use crate::checker::{Attached, BodyCache, Checker, CheckerError, CollisionMatrix, LinkSizes, WorldShape};
use crate::math::Pose;
use crate::msgs::planning_scene::{
    AllowedCollisionEntry, AllowedCollisionMatrix, AttachedCollisionObject, CollisionObject, LinkPadding, LinkScale, MeshTriangle, Plane, PlanningScene,
    PlanningSceneComponents, PlanningSceneWorld, Point32, Polygon, ShapeMesh, SolidPrimitive, MAX_SCENE_OBJECTS,
};
use crate::msgs::{Header, Point, PoseMsg, Quaternion, Time, Transform, TransformStamped, Vector3};
use std::collections::BTreeMap;

/// Triangles the scene holds over all its objects.
pub(crate) const MAX_SCENE_TRIANGLES: usize = 20_000_000;

/// The world objects, attached objects and fixed frames in force (the environment and robot are
/// the checker's).
#[derive(Clone, Debug, Default)]
pub(crate) struct SceneState {
    pub(super) world: PlanningWorld<WorldShape>,
    /// Objects attached to robot links, by id.
    pub(super) attached: BTreeMap<String, AttachedObject>,
    /// `fixed_frame_transforms`: frames objects may be given in, by name, posed in the world.
    pub(super) fixed_frames: BTreeMap<String, Pose>,
    /// The allowed collision matrix a scene message gave, in place of the SRDF's.
    pub(super) matrix: Option<CollisionMatrix>,
    /// `link_padding` and `link_scale` a scene message gave for robot links.
    pub(super) sizes: LinkSizes,
}

/// An object attached to a robot link: it moves with the link.
#[derive(Clone, Debug)]
pub(crate) struct AttachedObject {
    pub link: String,
    /// Shapes with their poses in the link's frame.
    pub shapes: Vec<(WorldShape, Pose)>,
    pub touch_links: Vec<String>,
}

/// What the frames of a message are resolved against besides the scene: the checker (world
/// frame, environment links, robot links) and the pose of a robot link (by index) in the robot's
/// current state (computed when a message names a robot link).
pub(super) struct FrameContext<'a> {
    pub checker: &'a Checker,
    pub robot_link: &'a dyn Fn(usize) -> Result<Pose, String>,
}

pub(super) fn refuse(cause: SkipCause, message: String) -> Skip {
    Skip { cause, message }
}

impl SceneState {
    /// Nothing here changes the checker: no objects, no attached objects, no matrix, no link sizes.
    pub(super) fn is_empty(&self) -> bool {
        self.world.len() == 0 && self.attached.is_empty() && self.matrix.is_none() && self.sizes.is_empty()
    }

    /// The attached objects as the checker takes them.
    pub(super) fn attached_specs(&self) -> Vec<Attached<'_>> {
        self.attached.iter().map(|(id, a)| Attached { id, link: &a.link, shapes: &a.shapes, touch_links: &a.touch_links }).collect()
    }

    /// `base` (its environment and robot) with this scene's objects, attached objects, matrix and
    /// link sizes, mesh cells from `cache` when it holds them.
    pub(super) fn checker_on(&self, base: &Checker, cache: &mut BodyCache) -> Result<Checker, CheckerError> {
        let objects = self.world.objects().map(|(id, o)| (id, &o.pose, o.shapes.as_slice()));
        base.with_scene(objects, &self.attached_specs(), self.matrix.as_ref(), &self.sizes, cache)
    }

    /// The pose in the world of `frame` (a leading `/` ignored): the world frame, a fixed frame,
    /// an object or `object/subframe`, an environment link, a robot link at the current state.
    pub(super) fn frame(&self, ctx: &FrameContext, frame: &str, id: &str) -> Result<Pose, Skip> {
        let name = frame.strip_prefix('/').unwrap_or(frame);
        let world = &ctx.checker.params().world_frame;
        if name == world {
            return Ok(Pose::IDENTITY);
        }
        if let Some(p) = self.fixed_frames.get(name) {
            return Ok(*p);
        }
        if let Some(o) = self.world.get(name) {
            return Ok(o.pose);
        }
        if let Some((object, sub)) = name.split_once('/') {
            if let Some((_, p)) = self.world.get(object).and_then(|o| o.subframes.iter().find(|(n, _)| n == sub).map(|(n, p)| (n, o.pose * *p))) {
                return Ok(p);
            }
        }
        if let Some(p) = ctx.checker.environment_frame(name) {
            return Ok(p);
        }
        if let Some(li) = ctx.checker.robot().link(name) {
            return (ctx.robot_link)(li)
                .map_err(|e| refuse(SkipCause::SceneFrame, format!("collision object '{id}': header.frame_id '{frame}' is a robot link, but {e}")));
        }
        Err(refuse(
            SkipCause::SceneFrame,
            format!(
                "collision object '{id}': header.frame_id '{frame}' is not a known frame (world_frame '{world}', an environment or robot link, an object or \
                 object/subframe, or a fixed_frame_transforms frame)"
            ),
        ))
    }

    /// One `moveit_msgs/CollisionObject`, applied to this scene (unchanged on error).
    pub(super) fn apply_object(&mut self, ctx: &FrameContext, msg: &CollisionObject) -> Result<(), Skip> {
        let id = msg.id.as_str();
        let op = msg.operation;
        if op == CollisionObject::REMOVE {
            return self.world.remove(id).map_err(world_refusal);
        }
        if op != CollisionObject::ADD && op != CollisionObject::APPEND && op != CollisionObject::MOVE {
            return Err(refuse(
                SkipCause::SceneOperation,
                format!("collision object '{id}': operation {op} is not one of ADD (0), REMOVE (1), APPEND (2), MOVE (3)"),
            ));
        }
        if id.is_empty() {
            return Err(refuse(SkipCause::SceneId, "collision object '': id: an object to add or move needs an id".into()));
        }
        if op != CollisionObject::MOVE {
            if ctx.checker.environment_frame(id).is_some() {
                return Err(refuse(SkipCause::SceneId, format!("collision object '{id}': id: names a link of the environment")));
            }
            if ctx.checker.robot().link(id).is_some() {
                return Err(refuse(SkipCause::SceneId, format!("collision object '{id}': id: names a link of the robot")));
            }
        }
        let header = self.frame(ctx, &msg.header.frame_id, id)?;
        if op == CollisionObject::MOVE {
            let pose = pose_of(&msg.pose, id, "pose").map_err(|e| refuse(SkipCause::SceneGeometry, e))?;
            let given = [&msg.primitive_poses, &msg.mesh_poses, &msg.plane_poses];
            let shape_poses = if given.iter().all(|p| p.is_empty()) {
                None
            } else {
                let all = given.iter().flat_map(|p| p.iter()).enumerate();
                Some(
                    all.map(|(k, p)| pose_of(p, id, &format!("shape pose {k}")))
                        .collect::<Result<Vec<_>, _>>()
                        .map_err(|e| refuse(SkipCause::SceneGeometry, e))?,
                )
            };
            return self.world.move_object(id, header, pose, shape_poses).map_err(world_refusal);
        }
        let triangles: usize = msg.meshes.iter().map(|m| m.triangles.len()).sum();
        if triangles > MAX_OBJECT_TRIANGLES {
            return Err(refuse(
                SkipCause::SceneBounds,
                format!("collision object '{id}': meshes: {triangles} triangles, more than the {MAX_OBJECT_TRIANGLES} an object may hold"),
            ));
        }
        let add = object_to_add(msg, header).map_err(|e| refuse(SkipCause::SceneGeometry, e))?;
        if op == CollisionObject::ADD { self.world.add(id, add) } else { self.world.append(id, add) }.map_err(world_refusal)?;
        self.check_bounds(id)
    }

    /// The scene's bounds after an object `id` grew: objects, and triangles per object and in all.
    pub(super) fn check_bounds(&self, id: &str) -> Result<(), Skip> {
        if self.world.len() + self.attached.len() > MAX_SCENE_OBJECTS {
            return Err(refuse(SkipCause::SceneBounds, format!("collision object '{id}': the scene would hold more than {MAX_SCENE_OBJECTS} objects")));
        }
        let per_object = |o: &super::planning_world::WorldObject<WorldShape>| -> usize {
            o.shapes.iter().map(|(s, _)| if let WorldShape::Mesh(m) = s { m.triangles.len() } else { 0 }).sum()
        };
        let mesh_triangles =
            |shapes: &[(WorldShape, Pose)]| -> usize { shapes.iter().map(|(s, _)| if let WorldShape::Mesh(m) = s { m.triangles.len() } else { 0 }).sum() };
        let attached = self.attached.get(id).map_or(0, |a| mesh_triangles(&a.shapes));
        if self.world.get(id).map_or(0, per_object).max(attached) > MAX_OBJECT_TRIANGLES {
            return Err(refuse(
                SkipCause::SceneBounds,
                format!("collision object '{id}': meshes: more than the {MAX_OBJECT_TRIANGLES} triangles an object may hold"),
            ));
        }
        let all: usize =
            self.world.objects().map(|(_, o)| per_object(o)).sum::<usize>() + self.attached.values().map(|a| mesh_triangles(&a.shapes)).sum::<usize>();
        if all > MAX_SCENE_TRIANGLES {
            return Err(refuse(
                SkipCause::SceneBounds,
                format!("collision object '{id}': the scene would hold {all} triangles, more than {MAX_SCENE_TRIANGLES}"),
            ));
        }
        Ok(())
    }

    /// A `PlanningSceneWorld` (the `planning_scene_world` topic): the world objects replaced by
    /// the message's, applied in order. Its octomap is refused (warned, counted by the caller).
    pub(super) fn apply_world(&mut self, ctx: &FrameContext, msg: &PlanningSceneWorld) -> Result<(), Skip> {
        self.world = PlanningWorld::default();
        msg.collision_objects.iter().try_for_each(|o| self.apply_object(ctx, o))
    }

    /// A `PlanningScene`, a difference (`is_diff`) or the whole scene, in MoveIt's order: the
    /// allowed collision matrix (one with entries replaces the one in force), fixed frames, link
    /// padding and scale (each entry replaces the link's; a whole scene's replace them all), the
    /// robot state's attached objects (all replaced when `robot_state.is_diff` is false), world
    /// objects. The robot state's joint positions are not used: states come from `joint_states`.
    pub(super) fn apply_scene(&mut self, ctx: &FrameContext, msg: &PlanningScene) -> Result<(), Skip> {
        let (padding, scale) = link_sizes_of(ctx.checker, msg)?;
        if !msg.is_diff {
            *self = SceneState::default();
        }
        self.sizes.padding.extend(padding);
        self.sizes.scale.extend(scale);
        let acm = &msg.allowed_collision_matrix;
        if !acm.entry_names.is_empty() || !acm.default_entry_names.is_empty() {
            self.matrix = Some(matrix_of(acm)?);
        }
        let world = &ctx.checker.params().world_frame;
        for (k, t) in msg.fixed_frame_transforms.iter().enumerate() {
            let parent = t.header.frame_id.strip_prefix('/').unwrap_or(&t.header.frame_id);
            if parent != world {
                return Err(refuse(
                    SkipCause::SceneFrame,
                    format!("planning scene: fixed_frame_transforms[{k}]: header.frame_id '{parent}' is not world_frame '{world}' (MoveIt takes them in the planning frame)"),
                ));
            }
            let pose = transform_pose(&t.transform).ok_or_else(|| {
                refuse(SkipCause::SceneGeometry, format!("planning scene: fixed_frame_transforms[{k}] ('{}'): not a finite rigid transform", t.child_frame_id))
            })?;
            let _ = self.fixed_frames.insert(t.child_frame_id.clone(), pose);
        }
        let state = &msg.robot_state;
        if !(state.attached_collision_objects.is_empty() && state.joint_state.name.is_empty() && state.multi_dof_joint_state.joint_names.is_empty()) {
            if !state.is_diff {
                self.attached.clear();
            }
            state.attached_collision_objects.iter().try_for_each(|a| self.apply_attached(ctx, a))?;
        }
        msg.world.collision_objects.iter().try_for_each(|o| self.apply_object(ctx, o))
    }

    /// The scene as `get_planning_scene` answers with the `components` asked for, as MoveIt's
    /// `getPlanningSceneMsg` fills it: objects in `world_frame` with their shapes relative to them.
    pub(super) fn message(&self, checker: &Checker, components: u32, stamp: Time) -> PlanningScene {
        let world = checker.params().world_frame.clone();
        let mut scene = PlanningScene { name: String::new(), robot_model_name: checker.robot().name.clone(), is_diff: false, ..Default::default() };
        scene.robot_state.is_diff = true;
        let header = Header { stamp, frame_id: world.clone() };
        if components & (PlanningSceneComponents::WORLD_OBJECT_NAMES | PlanningSceneComponents::WORLD_OBJECT_GEOMETRY) != 0 {
            let geometry = components & PlanningSceneComponents::WORLD_OBJECT_GEOMETRY != 0;
            scene.world.collision_objects = self
                .world
                .objects()
                .map(|(id, o)| {
                    let mut msg = CollisionObject { header: header.clone(), id: id.to_owned(), operation: CollisionObject::ADD, ..Default::default() };
                    msg.pose = pose_msg(&o.pose);
                    if geometry {
                        fill_shapes(&mut msg, &o.shapes);
                        (msg.subframe_names, msg.subframe_poses) = o.subframes.iter().map(|(n, p)| (n.clone(), pose_msg(p))).unzip();
                    }
                    msg
                })
                .collect();
        }
        if components & PlanningSceneComponents::ROBOT_STATE_ATTACHED_OBJECTS != 0 {
            scene.robot_state.attached_collision_objects = self
                .attached
                .iter()
                .map(|(id, a)| {
                    let link_header = Header { stamp, frame_id: a.link.clone() };
                    let mut object = CollisionObject { header: link_header, id: id.clone(), operation: CollisionObject::ADD, ..Default::default() };
                    object.pose = pose_msg(&Pose::IDENTITY);
                    fill_shapes(&mut object, &a.shapes);
                    AttachedCollisionObject { link_name: a.link.clone(), object, touch_links: a.touch_links.clone(), ..Default::default() }
                })
                .collect();
        }
        if components & PlanningSceneComponents::ALLOWED_COLLISION_MATRIX != 0 {
            scene.allowed_collision_matrix = match &self.matrix {
                Some(m) => matrix_message(m.parts()),
                None => {
                    let (names, rows) = checker.collision_matrix_in_force();
                    matrix_message((&names, &rows, &BTreeMap::new()))
                }
            };
        }
        if components & PlanningSceneComponents::LINK_PADDING_AND_SCALING != 0 {
            let robot = checker.robot();
            scene.link_padding = robot.links.iter().map(|l| LinkPadding { link_name: l.name.clone(), padding: checker.link_padding(&l.name) }).collect();
            scene.link_scale = robot.links.iter().map(|l| LinkScale { link_name: l.name.clone(), scale: checker.link_scale(&l.name) }).collect();
        }
        if components & PlanningSceneComponents::TRANSFORMS != 0 {
            scene.fixed_frame_transforms = self
                .fixed_frames
                .iter()
                .map(|(name, p)| TransformStamped { header: header.clone(), child_frame_id: name.clone(), transform: transform_msg(p) })
                .collect();
        }
        scene
    }
}

/// Largest `link_scale` taken (a link scaled further is no robot a planner means).
pub(crate) const MAX_LINK_SCALE: f64 = 1e3;

/// The message's `link_padding` and `link_scale` for robot links (names that are no robot link
/// are ignored: there is nothing to size), or why a value cannot be used: a padding that is not
/// from 0 to 1e4 m (the `padding` parameter's range), a scale that is not above 0 and at most
/// [`MAX_LINK_SCALE`] (MoveIt refuses both too).
#[allow(clippy::type_complexity)]
fn link_sizes_of(checker: &Checker, msg: &PlanningScene) -> Result<(Vec<(String, f64)>, Vec<(String, f64)>), Skip> {
    let robot = checker.robot();
    let hi = crate::limits::LENGTH_RANGE[1];
    let mut padding = Vec::new();
    for (k, p) in msg.link_padding.iter().enumerate().filter(|(_, p)| robot.link(&p.link_name).is_some()) {
        if !(p.padding >= 0.0 && p.padding <= hi) {
            return Err(refuse(
                SkipCause::SceneGeometry,
                format!(
                    "planning scene: link_padding[{k}] ('{}'): padding {:?} must be from 0 to {hi:e} m; the scene is left as it was",
                    p.link_name, p.padding
                ),
            ));
        }
        padding.push((p.link_name.clone(), p.padding));
    }
    let mut scale = Vec::new();
    for (k, l) in msg.link_scale.iter().enumerate().filter(|(_, l)| robot.link(&l.link_name).is_some()) {
        if !(l.scale > 0.0 && l.scale <= MAX_LINK_SCALE) {
            return Err(refuse(
                SkipCause::SceneGeometry,
                format!(
                    "planning scene: link_scale[{k}] ('{}'): scale {:?} must be above 0 and at most {MAX_LINK_SCALE}; the scene is left as it was",
                    l.link_name, l.scale
                ),
            ));
        }
        scale.push((l.link_name.clone(), l.scale));
    }
    Ok((padding, scale))
}

/// The message's matrix, or why it cannot be read.
fn matrix_of(acm: &AllowedCollisionMatrix) -> Result<CollisionMatrix, Skip> {
    if acm.default_entry_names.len() != acm.default_entry_values.len() {
        let (n, v) = (acm.default_entry_names.len(), acm.default_entry_values.len());
        return Err(refuse(
            SkipCause::SceneGeometry,
            format!("planning scene: allowed_collision_matrix: {n} default_entry_names but {v} default_entry_values"),
        ));
    }
    let rows = acm.entry_values.iter().map(|r| r.enabled.clone()).collect();
    let defaults = acm.default_entry_names.iter().cloned().zip(acm.default_entry_values.iter().copied()).collect();
    CollisionMatrix::new(acm.entry_names.clone(), rows, defaults)
        .map_err(|e| refuse(SkipCause::SceneGeometry, format!("planning scene: allowed_collision_matrix: {e}")))
}

fn matrix_message((names, rows, defaults): (&[String], &[Vec<bool>], &BTreeMap<String, bool>)) -> AllowedCollisionMatrix {
    AllowedCollisionMatrix {
        entry_names: names.to_vec(),
        entry_values: rows.iter().map(|r| AllowedCollisionEntry { enabled: r.clone() }).collect(),
        default_entry_names: defaults.keys().cloned().collect(),
        default_entry_values: defaults.values().copied().collect(),
    }
}

fn world_refusal(e: WorldError) -> Skip {
    let cause = match e {
        WorldError::Unknown(_) => SkipCause::SceneUnknownId,
        WorldError::NoShapes(_) | WorldError::ShapePoses { .. } => SkipCause::SceneGeometry,
    };
    refuse(cause, e.to_string())
}

/// A transform of the message as a rigid pose, or None.
fn transform_pose(t: &Transform) -> Option<Pose> {
    let msg = PoseMsg { position: Point { x: t.translation.x, y: t.translation.y, z: t.translation.z }, orientation: t.rotation };
    pose_of(&msg, "", "").ok()
}

pub(super) fn pose_msg(p: &Pose) -> PoseMsg {
    let (t, r) = (p.translation, p.rotation);
    PoseMsg { position: Point { x: t.x, y: t.y, z: t.z }, orientation: Quaternion { x: r.x, y: r.y, z: r.z, w: r.w } }
}

fn transform_msg(p: &Pose) -> Transform {
    let (t, r) = (p.translation, p.rotation);
    Transform { translation: Vector3 { x: t.x, y: t.y, z: t.z }, rotation: Quaternion { x: r.x, y: r.y, z: r.z, w: r.w } }
}

/// The object's shapes as the message's primitives and meshes, each with its pose.
fn fill_shapes(msg: &mut CollisionObject, shapes: &[(WorldShape, Pose)]) {
    for (shape, pose) in shapes {
        let primitive = |kind: u8, dimensions: Vec<f64>| SolidPrimitive { kind, dimensions, ..Default::default() };
        let p = match shape {
            WorldShape::Box(s) => primitive(SolidPrimitive::BOX, s.to_vec()),
            WorldShape::Sphere(r) => primitive(SolidPrimitive::SPHERE, vec![*r]),
            WorldShape::Cylinder { height, radius } => primitive(SolidPrimitive::CYLINDER, vec![*height, *radius]),
            WorldShape::Cone { height, radius } => primitive(SolidPrimitive::CONE, vec![*height, *radius]),
            WorldShape::Prism { height, polygon } => SolidPrimitive {
                kind: SolidPrimitive::PRISM,
                dimensions: vec![*height],
                polygon: Polygon { points: polygon.iter().map(|[x, y]| Point32 { x: *x as f32, y: *y as f32, z: 0.0 }).collect() },
            },
            WorldShape::Plane(coef) => {
                msg.planes.push(Plane { coef: *coef });
                msg.plane_poses.push(pose_msg(pose));
                continue;
            }
            WorldShape::Mesh(m) => {
                msg.meshes.push(ShapeMesh {
                    triangles: m.triangles.iter().map(|t| MeshTriangle { vertex_indices: *t }).collect(),
                    vertices: m.vertices.iter().map(|v| Point { x: v.x, y: v.y, z: v.z }).collect(),
                });
                msg.mesh_poses.push(pose_msg(pose));
                continue;
            }
        };
        msg.primitives.push(p);
        msg.primitive_poses.push(pose_msg(pose));
    }
}
