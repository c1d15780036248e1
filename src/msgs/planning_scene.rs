//! MoveIt's planning scene as it travels: `moveit_msgs/msg/PlanningScene` and the closure of
//! messages it carries (RobotState, AttachedCollisionObject, CollisionObject, PlanningSceneWorld,
//! AllowedCollisionMatrix, LinkPadding, LinkScale, ObjectColor, PlanningSceneComponents), the
//! services `ApplyPlanningScene` and `GetPlanningScene`, and what they use from `shape_msgs`,
//! `object_recognition_msgs`, `octomap_msgs`, `sensor_msgs` and `geometry_msgs`. Plain serde
//! structs, field order = wire order (CDR), checked field by field against the `moveit_msgs`
//! ros2 branch, `common_interfaces` (humble and jazzy agree on every file used here),
//! `object_recognition_msgs` and `octomap_msgs` (ros2 branches). Constants are Rust constants
//! (they do not travel). `check_state_validity` carries the same RobotState and objects.
//!
//! Every sequence is bounded while it is decoded, before its elements are allocated, by the
//! bound of the field it fills (the error names the field): a scene is hostile input like any
//! joint state. The bounds are per sequence; what one message holds in all is bounded by the
//! size of the message (a DDS sample past 64 MiB never arrives, a bag record is at most
//! 256 MiB). Past a field's bound the message is refused whole. The bounds leave room for what
//! the scene refuses later with a reason (an object's triangles over the scene's own limit):
//!
//! | sequence | at most |
//! |---|---|
//! | `PlanningSceneWorld.collision_objects`, `RobotState.attached_collision_objects`, `PlanningScene.object_colors` | [`MAX_SCENE_OBJECTS`] |
//! | `Mesh.triangles`, `Mesh.vertices` | [`MAX_MESH_ENTRIES`] |
//! | an object's shapes, shape poses, subframe names and poses; `Polygon.points` | [`MAX_OBJECT_SHAPES`] |
//! | link names and per-link entries (`touch_links`, `link_padding`, `link_scale`, `fixed_frame_transforms`, the multi-DOF joint state's fields) | [`MAX_LINK_ENTRIES`] |
//! | the allowed collision matrix's names, rows and row entries | [`MAX_ACM_NAMES`] |
//! | `Octomap.data` | [`MAX_OCTOMAP_BYTES`] |
//! | `SolidPrimitive.dimensions` | 3 (`float64[<=3]`) |
//!
//! The joint state and the detach posture keep their own bounds (`JointState`,
//! `JointTrajectory`).

use super::{ColorRgba, Header, JointState, JointTrajectory, Point, PoseMsg, Transform, TransformStamped, Vector3, MAX_JOINT_STATE_ENTRIES};
use crate::limits::MAX_MESH_TRIANGLES;
use serde::{Deserialize, Deserializer, Serialize};

/// Collision objects in one world, objects attached in one robot state, and colours in one
/// scene: the scene's own bound on its objects.
pub(crate) const MAX_SCENE_OBJECTS: usize = 10_000;
/// Triangles, and vertices, of one `shape_msgs/Mesh`: as many triangles as a mesh file may hold.
/// (A triangle is 12 bytes on the wire and in memory, a vertex 24: a mesh costs what it weighs.)
pub(crate) const MAX_MESH_ENTRIES: usize = MAX_MESH_TRIANGLES;
/// Primitives, meshes, planes, the poses of each, subframe names and subframe poses of one
/// object, and the points of a prism's base. An empty shape is 8 to 12 bytes on the wire and
/// about 50 in memory.
pub(crate) const MAX_OBJECT_SHAPES: usize = 65_536;
/// Link names and per-link entries: as many as a joint state may name joints.
pub(crate) const MAX_LINK_ENTRIES: usize = MAX_JOINT_STATE_ENTRIES;
/// Names of the allowed collision matrix, its rows and each row's entries: every link and every
/// object may have one.
pub(crate) const MAX_ACM_NAMES: usize = MAX_LINK_ENTRIES + MAX_SCENE_OBJECTS;
/// Bytes of an octomap: the largest sample RustDDS reassembles (a byte costs one in memory).
pub(crate) const MAX_OCTOMAP_BYTES: usize = 64 << 20;

// One decoding function per bounded field, so the error names the field.
macro_rules! bounded_fields {
    ($($name:ident: $max:expr, $what:literal;)*) => {$(
        #[doc = concat!("`", $what, "`: at most `", stringify!($max), "` entries, refused as soon as it runs past.")]
        fn $name<'de, D: Deserializer<'de>, T: Deserialize<'de>>(d: D) -> Result<Vec<T>, D::Error> {
            super::bounded::bounded_vec(d, $max, $what)
        }
    )*};
}

bounded_fields! {
    polygon_points: MAX_OBJECT_SHAPES, "Polygon.points";
    multi_dof_joint_names: MAX_LINK_ENTRIES, "MultiDOFJointState.joint_names";
    multi_dof_transforms: MAX_LINK_ENTRIES, "MultiDOFJointState.transforms";
    multi_dof_twist: MAX_LINK_ENTRIES, "MultiDOFJointState.twist";
    multi_dof_wrench: MAX_LINK_ENTRIES, "MultiDOFJointState.wrench";
    primitive_dimensions: 3, "SolidPrimitive.dimensions";
    mesh_triangles: MAX_MESH_ENTRIES, "Mesh.triangles";
    mesh_vertices: MAX_MESH_ENTRIES, "Mesh.vertices";
    object_primitives: MAX_OBJECT_SHAPES, "CollisionObject.primitives";
    object_primitive_poses: MAX_OBJECT_SHAPES, "CollisionObject.primitive_poses";
    object_meshes: MAX_OBJECT_SHAPES, "CollisionObject.meshes";
    object_mesh_poses: MAX_OBJECT_SHAPES, "CollisionObject.mesh_poses";
    object_planes: MAX_OBJECT_SHAPES, "CollisionObject.planes";
    object_plane_poses: MAX_OBJECT_SHAPES, "CollisionObject.plane_poses";
    object_subframe_names: MAX_OBJECT_SHAPES, "CollisionObject.subframe_names";
    object_subframe_poses: MAX_OBJECT_SHAPES, "CollisionObject.subframe_poses";
    touch_links: MAX_LINK_ENTRIES, "AttachedCollisionObject.touch_links";
    attached_objects: MAX_SCENE_OBJECTS, "RobotState.attached_collision_objects";
    world_objects: MAX_SCENE_OBJECTS, "PlanningSceneWorld.collision_objects";
    octomap_data: MAX_OCTOMAP_BYTES, "Octomap.data";
    acm_entry_names: MAX_ACM_NAMES, "AllowedCollisionMatrix.entry_names";
    acm_entry_values: MAX_ACM_NAMES, "AllowedCollisionMatrix.entry_values";
    acm_enabled: MAX_ACM_NAMES, "AllowedCollisionEntry.enabled";
    acm_default_names: MAX_ACM_NAMES, "AllowedCollisionMatrix.default_entry_names";
    acm_default_values: MAX_ACM_NAMES, "AllowedCollisionMatrix.default_entry_values";
    fixed_frames: MAX_LINK_ENTRIES, "PlanningScene.fixed_frame_transforms";
    link_paddings: MAX_LINK_ENTRIES, "PlanningScene.link_padding";
    link_scales: MAX_LINK_ENTRIES, "PlanningScene.link_scale";
    object_colors: MAX_SCENE_OBJECTS, "PlanningScene.object_colors";
}

/// `geometry_msgs/msg/Twist`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Twist {
    /// Linear velocity.
    pub linear: Vector3,
    /// Angular velocity.
    pub angular: Vector3,
}

/// `geometry_msgs/msg/Wrench`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Wrench {
    /// Force.
    pub force: Vector3,
    /// Torque.
    pub torque: Vector3,
}

/// `geometry_msgs/msg/Point32`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Point32 {
    /// x.
    pub x: f32,
    /// y.
    pub y: f32,
    /// z.
    pub z: f32,
}

/// `geometry_msgs/msg/Polygon`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Polygon {
    /// Vertices.
    #[serde(deserialize_with = "polygon_points")]
    pub points: Vec<Point32>,
}

/// `sensor_msgs/msg/MultiDOFJointState`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MultiDofJointState {
    /// Header.
    pub header: Header,
    /// Joint names.
    #[serde(deserialize_with = "multi_dof_joint_names")]
    pub joint_names: Vec<String>,
    /// One transform per joint.
    #[serde(deserialize_with = "multi_dof_transforms")]
    pub transforms: Vec<Transform>,
    /// Velocities.
    #[serde(deserialize_with = "multi_dof_twist")]
    pub twist: Vec<Twist>,
    /// Wrenches.
    #[serde(deserialize_with = "multi_dof_wrench")]
    pub wrench: Vec<Wrench>,
}

/// `shape_msgs/msg/SolidPrimitive` (with the `polygon` field of humble and later).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SolidPrimitive {
    /// [`SolidPrimitive::BOX`], ... [`SolidPrimitive::PRISM`].
    #[serde(rename = "type")]
    pub kind: u8,
    /// `float64[<=3]`: BOX x, y, z; SPHERE radius; CYLINDER and CONE height, radius; PRISM
    /// height.
    #[serde(deserialize_with = "primitive_dimensions")]
    pub dimensions: Vec<f64>,
    /// The base of a PRISM.
    pub polygon: Polygon,
}

impl SolidPrimitive {
    /// A box.
    pub const BOX: u8 = 1;
    /// A sphere.
    pub const SPHERE: u8 = 2;
    /// A cylinder along z.
    pub const CYLINDER: u8 = 3;
    /// A cone along z.
    pub const CONE: u8 = 4;
    /// A prism: `polygon` extruded along z.
    pub const PRISM: u8 = 5;
}

/// `shape_msgs/msg/MeshTriangle`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MeshTriangle {
    /// `uint32[3]` (a fixed array: no length on the wire).
    pub vertex_indices: [u32; 3],
}

/// `shape_msgs/msg/Mesh`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ShapeMesh {
    /// Triangles.
    #[serde(deserialize_with = "mesh_triangles")]
    pub triangles: Vec<MeshTriangle>,
    /// Vertices.
    #[serde(deserialize_with = "mesh_vertices")]
    pub vertices: Vec<Point>,
}

/// `shape_msgs/msg/Plane`: `float64[4] coef` (a fixed array).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Plane {
    /// ax + by + cz + d = 0.
    pub coef: [f64; 4],
}

/// `object_recognition_msgs/msg/ObjectType`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ObjectType {
    /// Key.
    pub key: String,
    /// Database.
    pub db: String,
}

/// `moveit_msgs/msg/CollisionObject`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CollisionObject {
    /// Header.
    pub header: Header,
    /// Pose of the object in the header's frame; shapes and subframes are relative to it.
    pub pose: PoseMsg,
    /// Id.
    pub id: String,
    /// Type.
    #[serde(rename = "type")]
    pub kind: ObjectType,
    /// Primitives.
    #[serde(deserialize_with = "object_primitives")]
    pub primitives: Vec<SolidPrimitive>,
    /// Their poses.
    #[serde(deserialize_with = "object_primitive_poses")]
    pub primitive_poses: Vec<PoseMsg>,
    /// Meshes.
    #[serde(deserialize_with = "object_meshes")]
    pub meshes: Vec<ShapeMesh>,
    /// Their poses.
    #[serde(deserialize_with = "object_mesh_poses")]
    pub mesh_poses: Vec<PoseMsg>,
    /// Planes.
    #[serde(deserialize_with = "object_planes")]
    pub planes: Vec<Plane>,
    /// Their poses.
    #[serde(deserialize_with = "object_plane_poses")]
    pub plane_poses: Vec<PoseMsg>,
    /// Subframe names.
    #[serde(deserialize_with = "object_subframe_names")]
    pub subframe_names: Vec<String>,
    /// Subframe poses.
    #[serde(deserialize_with = "object_subframe_poses")]
    pub subframe_poses: Vec<PoseMsg>,
    /// `byte`: [`CollisionObject::ADD`], ... [`CollisionObject::MOVE`].
    pub operation: u8,
}

impl CollisionObject {
    /// Add the object, replacing one of the same id.
    pub const ADD: u8 = 0;
    /// Remove the object (every object for an empty id).
    pub const REMOVE: u8 = 1;
    /// Add the shapes to the object of that id.
    pub const APPEND: u8 = 2;
    /// Move the object of that id.
    pub const MOVE: u8 = 3;
}

/// `moveit_msgs/msg/AttachedCollisionObject`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct AttachedCollisionObject {
    /// The link it is attached to.
    pub link_name: String,
    /// The object.
    pub object: CollisionObject,
    /// Links it may touch.
    #[serde(deserialize_with = "touch_links")]
    pub touch_links: Vec<String>,
    /// Posture on detaching.
    pub detach_posture: JointTrajectory,
    /// Weight (kg).
    pub weight: f64,
}

/// `moveit_msgs/msg/RobotState`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RobotStateMsg {
    /// Single-DOF joints.
    pub joint_state: JointState,
    /// Multi-DOF joints.
    pub multi_dof_joint_state: MultiDofJointState,
    /// Attached collision objects.
    #[serde(deserialize_with = "attached_objects")]
    pub attached_collision_objects: Vec<AttachedCollisionObject>,
    /// Whether the state is a difference to the current one (a `check_state_validity` request
    /// is applied on top of the current state either way, as `move_group` does).
    pub is_diff: bool,
}

/// `octomap_msgs/msg/Octomap`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct Octomap {
    /// Header.
    pub header: Header,
    /// Only free / occupied (a `.bt` tree), else full occupancy (`.ot`).
    pub binary: bool,
    /// The octree's class.
    pub id: String,
    /// Side of the smallest node (metres).
    pub resolution: f64,
    /// The serialised tree: `int8[]` on the wire, kept as the bytes it is.
    #[serde(deserialize_with = "octomap_data")]
    pub data: Vec<u8>,
}

/// `octomap_msgs/msg/OctomapWithPose`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct OctomapWithPose {
    /// Header.
    pub header: Header,
    /// Pose of the tree in the header's frame.
    pub origin: PoseMsg,
    /// The tree.
    pub octomap: Octomap,
}

/// `moveit_msgs/msg/PlanningSceneWorld`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct PlanningSceneWorld {
    /// The world's objects.
    #[serde(deserialize_with = "world_objects")]
    pub collision_objects: Vec<CollisionObject>,
    /// An occupancy map (empty `octomap.data`: none).
    pub octomap: OctomapWithPose,
}

/// `moveit_msgs/msg/AllowedCollisionEntry`: one row of the matrix.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct AllowedCollisionEntry {
    /// Whether the row's name may touch each of `entry_names`, in their order.
    #[serde(deserialize_with = "acm_enabled")]
    pub enabled: Vec<bool>,
}

/// `moveit_msgs/msg/AllowedCollisionMatrix`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct AllowedCollisionMatrix {
    /// Links and objects, rows and columns in this order.
    #[serde(deserialize_with = "acm_entry_names")]
    pub entry_names: Vec<String>,
    /// One row per name.
    #[serde(deserialize_with = "acm_entry_values")]
    pub entry_values: Vec<AllowedCollisionEntry>,
    /// Names with a default for pairs the matrix does not list.
    #[serde(deserialize_with = "acm_default_names")]
    pub default_entry_names: Vec<String>,
    /// Their defaults.
    #[serde(deserialize_with = "acm_default_values")]
    pub default_entry_values: Vec<bool>,
}

/// `moveit_msgs/msg/LinkPadding`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct LinkPadding {
    /// Link.
    pub link_name: String,
    /// Padding (metres).
    pub padding: f64,
}

/// `moveit_msgs/msg/LinkScale`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct LinkScale {
    /// Link.
    pub link_name: String,
    /// Scale factor.
    pub scale: f64,
}

/// `moveit_msgs/msg/ObjectColor`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct ObjectColor {
    /// Object id.
    pub id: String,
    /// Colour.
    pub color: ColorRgba,
}

/// `moveit_msgs/msg/PlanningScene`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct PlanningScene {
    /// Name.
    pub name: String,
    /// The robot's state and attached objects.
    pub robot_state: RobotStateMsg,
    /// The robot model's name.
    pub robot_model_name: String,
    /// Frames fixed to the planning frame.
    #[serde(deserialize_with = "fixed_frames")]
    pub fixed_frame_transforms: Vec<TransformStamped>,
    /// The allowed collision matrix.
    pub allowed_collision_matrix: AllowedCollisionMatrix,
    /// Padding per link.
    #[serde(deserialize_with = "link_paddings")]
    pub link_padding: Vec<LinkPadding>,
    /// Scale per link.
    #[serde(deserialize_with = "link_scales")]
    pub link_scale: Vec<LinkScale>,
    /// Colours per object.
    #[serde(deserialize_with = "object_colors")]
    pub object_colors: Vec<ObjectColor>,
    /// The world.
    pub world: PlanningSceneWorld,
    /// A difference to the scene in force, or (false) the whole scene.
    pub is_diff: bool,
}

/// `moveit_msgs/msg/PlanningSceneComponents`: which parts `get_planning_scene` returns, a
/// bitmask of the constants.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub(crate) struct PlanningSceneComponents {
    /// Bitwise or of the constants.
    pub components: u32,
}

impl PlanningSceneComponents {
    /// Name and robot model name.
    pub const SCENE_SETTINGS: u32 = 1;
    /// Joint values (attached objects are not included).
    pub const ROBOT_STATE: u32 = 2;
    /// The attached objects (with the robot state).
    pub const ROBOT_STATE_ATTACHED_OBJECTS: u32 = 4;
    /// World object names.
    pub const WORLD_OBJECT_NAMES: u32 = 8;
    /// World object geometry (with their names).
    pub const WORLD_OBJECT_GEOMETRY: u32 = 16;
    /// The octomap.
    pub const OCTOMAP: u32 = 32;
    /// Fixed frame transforms.
    pub const TRANSFORMS: u32 = 64;
    /// The allowed collision matrix.
    pub const ALLOWED_COLLISION_MATRIX: u32 = 128;
    /// Link padding and scale.
    pub const LINK_PADDING_AND_SCALING: u32 = 256;
    /// Object colours.
    pub const OBJECT_COLORS: u32 = 512;
}

/// `moveit_msgs/srv/ApplyPlanningScene` request.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct ApplyPlanningSceneRequest {
    /// The scene or difference to apply.
    pub scene: PlanningScene,
}

/// `moveit_msgs/srv/ApplyPlanningScene` response.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct ApplyPlanningSceneResponse {
    /// The scene is applied.
    pub success: bool,
}

/// `moveit_msgs/srv/GetPlanningScene` request.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct GetPlanningSceneRequest {
    /// The parts wanted.
    pub components: PlanningSceneComponents,
}

/// `moveit_msgs/srv/GetPlanningScene` response.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct GetPlanningSceneResponse {
    /// The scene in force (the parts asked for).
    pub scene: PlanningScene,
}
